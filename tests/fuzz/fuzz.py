"""Coverage-guided fuzzing of ambfplus's readers with atheris (``pip install "ambfplus[fuzz]"``).

    python tests/fuzz/fuzz.py nrrd --seconds 600          # one target, 10 minutes
    python tests/fuzz/fuzz.py all --seconds 60            # each target for a minute (CI)

Targets (``targets.py``): nrrd, slice_stack, recording, adf, mesh. Each starts from its regression
corpus (``corpus/<target>/``: seeds and every input a fuzzer ever found) and writes what it
learns to a scratch corpus (``--work``, default a temporary folder), never into the regression
corpus. A finding (a crash, a hang over ``--timeout`` seconds, or an exception that is not an
``ambfplus.Error``) is saved as ``<work>/<target>/finding-*``: fix it, then copy the input into
``corpus/<target>/`` so that the test suite replays it from then on. Prints one JSON line per
target: inputs executed, findings, seconds.

atheris instruments the Python code (the recording reader, the harness); the engine's C++
readers run uninstrumented, so there the search is guided by the structure the seeds give and by
which Python paths (accepted, which error) an input takes.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(target: str, work: Path, seconds: int, timeout: int) -> None:
    """Runs inside the fuzzing process: libFuzzer's main loop over one target."""
    import atheris

    with atheris.instrument_imports(include=["ambfplus", "targets"]):
        sys.path.insert(0, str(HERE))
        import targets
    function = targets.TARGETS[target]

    def one_input(data: bytes) -> None:
        function(data)

    corpus = work / "corpus"
    corpus.mkdir(parents=True, exist_ok=True)
    args = [
        sys.argv[0],
        str(corpus),
        str(targets.CORPUS / target),
        f"-max_total_time={seconds}",
        f"-timeout={timeout}",
        "-rss_limit_mb=3072",
        f"-max_len={max([65536] + [p.stat().st_size for p in targets.corpus_files(target)])}",
        f"-artifact_prefix={work}/finding-",
        "-print_final_stats=1",
    ]
    atheris.Setup(args, one_input)
    atheris.Fuzz()


def run(target: str, work: Path, seconds: int, timeout: int) -> dict:
    """Fuzzes one target in a child process; returns its figures."""
    work.mkdir(parents=True, exist_ok=True)
    started = time.monotonic()
    done = subprocess.run(
        [sys.executable, __file__, "--child", target, "--work", str(work),
         "--seconds", str(seconds), "--timeout", str(timeout)],
        capture_output=True, text=True, errors="replace",
    )  # fmt: skip
    log = done.stdout + done.stderr
    (work / "fuzz.log").write_text(log)
    executed = re.findall(r"stat::number_of_executed_units:\s*(\d+)", log)
    runs = re.findall(r"#(\d+)\s+(?:DONE|pulse|NEW|REDUCE|INITED)", log)
    findings = sorted(p.name for p in work.glob("finding-*"))
    return {
        "target": target,
        "seconds": round(time.monotonic() - started, 1),
        "executed": int(executed[-1]) if executed else (int(runs[-1]) if runs else 0),
        "findings": findings,
        "crashes": sum(n.startswith("finding-crash") for n in findings),
        "hangs": sum(n.startswith("finding-timeout") for n in findings),
        "out_of_memory": sum(n.startswith("finding-oom") for n in findings),
        "exit_code": done.returncode,
        "log": str(work / "fuzz.log"),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("target", help="nrrd, slice_stack, recording, adf, mesh or all")
    parser.add_argument("--seconds", type=int, default=60, help="fuzzing time per target")
    parser.add_argument("--timeout", type=int, default=10, help="seconds one input may take")
    parser.add_argument("--work", type=Path, help="scratch folder (default: a temporary one)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.target, args.work, args.seconds, args.timeout)
        return 0
    sys.path.insert(0, str(HERE))
    from targets import TARGETS

    names = list(TARGETS) if args.target == "all" else [args.target]
    work = args.work or Path(tempfile.mkdtemp(prefix="ambfplus-fuzz-work-"))
    failed = False
    for name in names:
        result = run(name, work / name, args.seconds, args.timeout)
        print(json.dumps(result), flush=True)
        failed = failed or bool(result["findings"]) or result["exit_code"] != 0
    return 1 if failed else 0


if __name__ == "__main__":
    if "--child" in sys.argv:
        # libFuzzer reads its own flags from sys.argv: keep ours out of its way.
        i = sys.argv.index("--child")
        target, work = sys.argv[i + 1], Path(sys.argv[sys.argv.index("--work") + 1])
        seconds = int(sys.argv[sys.argv.index("--seconds") + 1])
        timeout = int(sys.argv[sys.argv.index("--timeout") + 1])
        sys.argv = sys.argv[:1]
        child(target, work, seconds, timeout)
    else:
        sys.exit(main())
