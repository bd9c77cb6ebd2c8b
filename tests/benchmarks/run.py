"""Benchmarks: one JSON line per figure, {"bench", "value", "unit"} plus "baseline" and "ratio"
where a figure is compared with a baseline measured in the same run.

    python tests/benchmarks/run.py [--only NAME] [--quick]
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from collections.abc import Callable, Iterator

import ambfplus
from ambfplus import _core
from ambfplus.scenes import demo_scene

BENCHMARKS: dict[str, Callable[[argparse.Namespace], Iterator[dict]]] = {}


def benchmark(fn):
    BENCHMARKS[fn.__name__] = fn
    return fn


@benchmark
def capture(args) -> Iterator[dict]:
    """640x480 rgb + depth capture() from Python, against the same draw and readback done in C++
    into buffers allocated once. Rounds alternate the two so machine noise hits both alike."""
    _, camera = demo_scene(640, 480)
    camera.capture()
    rounds, per_round = (3, 20) if args.quick else (7, 40)
    python_wall, python_cpu, bare_wall, bare_cpu = [], [], [], []
    for _ in range(rounds):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(per_round):
            frame = camera.capture()
            frame.rgb, frame.depth  # noqa: B018 (the views are part of the cost)
        python_wall.append((time.perf_counter() - t0) / per_round)
        python_cpu.append((time.process_time() - c0) / per_round)
        bare = _core._benchmark_bare_capture(camera, per_round)
        bare_wall.append(bare["wall_seconds"])
        bare_cpu.append(bare["cpu_seconds"])
    info = ambfplus.gl_info()
    for name, ours, base, what in [
        ("capture_640x480_wall", python_wall, bare_wall, "wall"),
        ("capture_640x480_cpu", python_cpu, bare_cpu, "process CPU"),
    ]:
        value, baseline = statistics.median(ours) * 1e3, statistics.median(base) * 1e3
        yield {
            "bench": name,
            "value": round(value, 4),
            "unit": "ms",
            "baseline": round(baseline, 4),
            "ratio": round(value / baseline, 4),
            "what": f"{what} time per capture(); baseline: same draw + bare readback in C++",
            "renderer": info["renderer"],
        }


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--only", choices=sorted(BENCHMARKS), help="run one benchmark")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args()
    for name in [args.only] if args.only else sorted(BENCHMARKS):
        for line in BENCHMARKS[name](args):
            print(json.dumps(line), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
