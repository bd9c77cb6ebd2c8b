"""Every example runs with the installed package and writes what it says."""

from __future__ import annotations

import subprocess
import sys

import helpers
import pytest

# The paper's experiments need the torch extra and run at CI size in
# tests/learning/test_learning.py.
TESTED_ELSEWHERE = {"stereo_depth_experiment.py", "tracking_experiment.py"}
EXAMPLES = sorted(p for p in helpers.EXAMPLES.glob("*.py") if p.name not in TESTED_ELSEWHERE)
# Each example is a whole session (recording, dataset, bridge) in its own process.
pytestmark = pytest.mark.slow


@pytest.mark.parametrize("script", EXAMPLES, ids=[p.name for p in EXAMPLES])
def test_example_runs(script, tmp_path):
    out = subprocess.run(
        [sys.executable, str(script), str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
        cwd=tmp_path,
    )
    assert out.returncode == 0, out.stderr
    assert any(tmp_path.iterdir()), "an example should write its results"
