"""An AMBF client script runs unmodified (`from ambf_client import Client`, `Client()`), in
lock-step and in real time, against a scene the test writes: it drives two arms by joint index
and by name, reads link poses that agree with forward kinematics computed here, grasps the needle
its ghost senses, and steps the world."""

from __future__ import annotations

import runpy
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import ARM1_POSE, BASES, forward_kinematics

from ambfplus import ambf_client

SCRIPT = Path(__file__).resolve().parent / "scripts" / "two_arms.py"


@pytest.mark.parametrize("realtime", [False, True], ids=["lock-step", "real-time"])
def test_an_ambf_client_script_runs_unmodified(two_arms, monkeypatch, realtime):
    monkeypatch.delitem(sys.modules, "ambf_client", raising=False)
    ambf_client.use_simulator(two_arms, realtime=realtime)
    ambf_client.install_alias()
    world = two_arms.world
    needle_start = world.get("needle").pose[:3, 3].copy()

    result = runpy.run_path(str(SCRIPT), run_name="__main__")

    # Joints reached their targets, by index (arm1) and by name (arm2).
    assert result["joints"]["arm1"] == pytest.approx(list(ARM1_POSE), abs=2e-3)
    assert result["joints"]["arm2"] == pytest.approx([-0.4, 0.9], abs=2e-3)
    # Link poses agree with forward kinematics of the joint positions the script read.
    for arm in ("arm1", "arm2"):
        fk = forward_kinematics(BASES[arm], *result["joints"][arm])
        for i, link in ((1, "link1"), (2, "link2")):
            x, y, z, roll, pitch, yaw = result["links"][f"{arm}_{link}"]
            assert (x, y, z) == pytest.approx(tuple(fk[link]), abs=2e-3), (arm, link)
            assert yaw == pytest.approx(fk[f"yaw{i}"], abs=2e-3), (arm, link)
            assert abs(roll) < 1e-2 and abs(pitch) < 1e-2
    # The ghost sensed the needle; the grasp carried it with the jaw.
    assert "needle" in result["sensed"]
    needle, jaw = np.array(result["carried"]["needle"]), np.array(result["carried"]["jaw"])
    carried_to = forward_kinematics(BASES["arm1"], 0.0, ARM1_POSE[1])["jaw"]
    assert jaw == pytest.approx(carried_to, abs=5e-3)
    assert np.linalg.norm(needle - needle_start) > 0.05  # it moved with the arm
    assert np.linalg.norm(needle - jaw) < 0.04  # and stayed at the jaw
    # Time passed by steps: the script stepped (lock-step) or the clock did (real time).
    assert result["sim_step"] > 100
    assert world.step_index >= result["sim_step"]
    stopped = world.time
    assert world.time == stopped  # clean_up stopped any real-time thread
