"""Crash safety: what a SIGKILL loses.

``sigkill_loss``: a recorded drilling session on the phantom (a 160x120 stereo pair with rgb,
depth and labels and the step log every 40 steps, the recorder's default 1 s flush interval) is
killed with SIGKILL at 20 random moments of simulation time between 0.3 s and 4 s, while two
processes spin on the CPU (this machine has two cores). The loss of each run is the simulation
time the session had reached (what it printed after its last step) minus the latest time its
recording holds; the promise is at most one flush interval. Prints the median, p99 and worst
loss and how many runs kept nothing.
"""

from __future__ import annotations

import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

TESTS = Path(__file__).resolve().parents[1]


def sigkill_loss(args):
    sys.path.insert(0, str(TESTS))
    from helpers.killed_session import kill_session

    runs = 5 if getattr(args, "quick", False) else 20
    flush = 1.0
    rng = np.random.default_rng(20261127)
    moments = rng.uniform(0.3, 4.0, runs)
    hogs = [subprocess.Popen([sys.executable, "-c", "while True: pass"]) for _ in range(2)]
    losses, kept_nothing = [], 0
    try:
        with tempfile.TemporaryDirectory() as folder:
            for i, moment in enumerate(moments):
                result = kill_session(Path(folder) / str(i), float(moment), flush=flush)
                losses.append(result["loss"])
                kept_nothing += result["recorded"] == 0.0
    finally:
        for hog in hogs:
            hog.kill()
            hog.wait()
    yield {
        "bench": "sigkill_loss",
        "value": max(losses),
        "unit": "s of simulation time lost (worst)",
        "median": statistics.median(losses),
        "p99": float(np.percentile(losses, 99)),
        "max": max(losses),
        "flush_interval_s": flush,
        "runs": runs,
        "within_flush_interval": sum(loss <= flush for loss in losses),
        "kept_nothing": kept_nothing,
        "cpu_hogs": 2,
    }


BENCHMARKS = {"sigkill_loss": sigkill_loss}
