"""The self-contained wheel: its size, how long `pip install` of it takes (offline, from a local
wheelhouse, into a fresh venv), and the capture benchmark run by the wheel's engine against the
source build's (this Python's ambfplus), alternating in the same run.

    python tests/benchmarks/run.py --only wheel [--quick]     # AMBFPLUS_WHEEL=... to reuse one
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from helpers.wheel_tools import (  # noqa: E402
    download_wheelhouse,
    glibc_version,
    install_into_new_venv,
    wheel_or_build,
)

RUN = Path(__file__).resolve().parent / "run.py"


def capture_figures(python: str, quick: bool) -> dict[str, float]:
    """The capture benchmark's figures (ms per 640x480 capture) run by this interpreter."""
    command = [python, str(RUN), "--only", "capture"] + (["--quick"] if quick else [])
    out = subprocess.run(command, capture_output=True, text=True, check=True, cwd=RUN.parent).stdout
    lines = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    return {line["bench"]: line["value"] for line in lines} | {"renderer": lines[0]["renderer"]}


def folder_megabytes(*folders: Path) -> float:
    return sum(p.stat().st_size for f in folders for p in f.rglob("*") if p.is_file()) / 1e6


def wheel(args) -> Iterator[dict]:
    """Wheel size, install time and the wheel's capture cost against the source build's."""
    installs = 2 if args.quick else 5
    rounds = 2 if args.quick else 5
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        built = wheel_or_build(folder / "dist")
        wheelhouse = download_wheelhouse(
            built, folder / "wheelhouse", sys.version_info[:2], glibc_version()
        )
        seconds = []
        for i in range(installs):
            python, took = install_into_new_venv(folder / f"venv{i}", built, wheelhouse)
            seconds.append(took)
        site = next((folder / "venv0" / "lib").glob("python*/site-packages"))
        installed_mb = folder_megabytes(site / "ambfplus", site / "ambfplus.libs")
        yield {
            "bench": "wheel_size",
            "value": round(built.stat().st_size / 1e6, 1),
            "unit": "MB",
            "installed_mb": round(installed_mb, 1),
            "bundled_libraries": len(list((site / "ambfplus.libs").iterdir())),
            "wheel": built.name,
        }
        yield {
            "bench": "wheel_install_time",
            "value": round(statistics.median(seconds), 2),
            "unit": "s (median)",
            "worst_s": round(max(seconds), 2),
            "installs": installs,
            "what": "pip install of the wheel and its dependencies into a fresh venv, offline "
            "from a local wheelhouse (no compiler, no download)",
        }
        runs = {"wheel": [], "source": []}
        engines = {"wheel": str(python), "source": sys.executable}
        for i in range(rounds):
            # Each goes first in every other round, so whatever the machine does over time
            # falls on both alike.
            for name in ("wheel", "source") if i % 2 == 0 else ("source", "wheel"):
                runs[name].append(capture_figures(engines[name], args.quick))
    for name, what in (("capture_640x480_cpu", "process CPU"), ("capture_640x480_wall", "wall")):
        ours = [r[name] for r in runs["wheel"]]
        base = [r[name] for r in runs["source"]]
        value, baseline = statistics.median(ours), statistics.median(base)
        # Each round runs both engines back to back.
        paired = [o / b for o, b in zip(ours, base)]
        yield {
            "bench": f"wheel_{name}",
            "value": round(value, 4),
            "unit": "ms",
            "baseline": round(baseline, 4),
            "ratio": round(value / baseline, 4),
            "target_ratio": 1.05,
            "worst_round_ratio": round(max(paired), 4),
            "worst_ms": round(max(ours), 4),
            "baseline_worst_ms": round(max(base), 4),
            "rounds": rounds,
            "renderer": runs["wheel"][0]["renderer"],
            "what": f"{what} time per capture() of the capture benchmark (640x480 rgb + depth) "
            "by the wheel's engine; baseline: the source build's, alternating rounds",
        }


BENCHMARKS = {"wheel": wheel}
