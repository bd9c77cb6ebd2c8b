"""A scene for AMBF client scripts, written by the test: two planar arms (a static base and two
links on revolute joints about z), a ghost and a grasping actuator on the first arm's last link,
and a needle floating within the ghost's reach once the first arm is posed."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus import ambf_client

LINK = 0.2  # m, each link's length; a link's centre is half a link from its joint
BASES = {"arm1": (0.0, 0.0, 0.5), "arm2": (1.0, 0.0, 0.5)}
# The first arm's pose in the script: its jaw (the end of its last link) then lies just short of
# the needle.
ARM1_POSE = (0.5, -0.7)
NEEDLE_GAP = 0.03  # m beyond the jaw, along the last link


def arm_adf(prefix: str, extra: str = "") -> str:
    x, y, z = BASES[prefix]
    bodies = f"""
    bodies: [BODY {prefix}_base, BODY {prefix}_link1, BODY {prefix}_link2]
    joints: [JOINT {prefix}_base-link1, JOINT {prefix}_link1-link2]
    BODY {prefix}_base:
      name: {prefix}_base
      mass: 0.0
      shape: box
      geometry: {{x: 0.05, y: 0.05, z: 0.05}}
      location: {{position: {{x: {x}, y: {y}, z: {z}}}, orientation: {{r: 0, p: 0, y: 0}}}}
    """
    for i in (1, 2):
        centre = x + (i - 0.5) * LINK
        bodies += f"""
    BODY {prefix}_link{i}:
      name: {prefix}_link{i}
      mass: {0.6 - 0.2 * i}
      shape: box
      geometry: {{x: {LINK}, y: 0.03, z: 0.03}}
      location: {{position: {{x: {centre}, y: {y}, z: {z}}}, orientation: {{r: 0, p: 0, y: 0}}}}
    """
    for parent, child, pivot in (("base", "link1", 0.0), ("link1", "link2", LINK / 2)):
        bodies += f"""
    JOINT {prefix}_{parent}-{child}:
      name: {prefix}_{parent}-{child}
      parent: BODY {prefix}_{parent}
      child: BODY {prefix}_{child}
      parent pivot: {{x: {pivot}, y: 0.0, z: 0.0}}
      child pivot: {{x: {-LINK / 2}, y: 0.0, z: 0.0}}
      parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
      child axis: {{x: 0.0, y: 0.0, z: 1.0}}
      type: revolute
      controller: {{P: 5, I: 0, D: 0.4}}
    """
    return textwrap.dedent(bodies) + textwrap.dedent(extra)


GRASP = f"""
ghost objects: [GHOST arm1_jaw]
actuators: [ACTUATOR arm1_grip]
GHOST arm1_jaw:
  name: arm1_jaw
  parent: BODY arm1_link2
  shape: sphere
  geometry: {{radius: 0.03}}
  location: {{position: {{x: {LINK / 2}, y: 0.0, z: 0.0}}, orientation: {{r: 0, p: 0, y: 0}}}}
ACTUATOR arm1_grip:
  name: arm1_grip
  type: Constraint
  parent: BODY arm1_link2
  location: {{position: {{x: {LINK / 2}, y: 0.0, z: 0.0}}, orientation: {{r: 0, p: 0, y: 0}}}}
"""


def forward_kinematics(base, q0: float, q1: float) -> dict:
    """World positions of the links' centres and of the jaw, and the links' yaw, of a planar arm
    posed at (q0, q1): computed here, independently of the engine."""

    def along(angle: float, length: float) -> np.ndarray:
        return length * np.array([np.cos(angle), np.sin(angle), 0.0])

    base = np.asarray(base, dtype=float)
    elbow = base + along(q0, LINK)
    return {
        "link1": base + along(q0, LINK / 2),
        "link2": elbow + along(q0 + q1, LINK / 2),
        "jaw": elbow + along(q0 + q1, LINK),
        "yaw1": q0,
        "yaw2": q0 + q1,
    }


@pytest.fixture
def two_arms(tmp_path: Path) -> ambfplus.Simulator:
    """The scene, with gravity off so the needle floats where it is put."""
    jaw = forward_kinematics(BASES["arm1"], *ARM1_POSE)["jaw"]
    direction = np.array([np.cos(sum(ARM1_POSE)), np.sin(sum(ARM1_POSE)), 0.0])
    nx, ny, nz = jaw + NEEDLE_GAP * direction
    needle = f"""
    bodies: [BODY needle]
    BODY needle:
      name: needle
      mass: 0.02
      shape: sphere
      geometry: {{radius: 0.008}}
      location: {{position: {{x: {nx}, y: {ny}, z: {nz}}}, orientation: {{r: 0, p: 0, y: 0}}}}
    """
    (tmp_path / "arm1.yaml").write_text(arm_adf("arm1", GRASP))
    (tmp_path / "arm2.yaml").write_text(arm_adf("arm2"))
    (tmp_path / "needle.yaml").write_text(textwrap.dedent(needle))
    world = ambfplus.World()
    for name in ("arm1.yaml", "arm2.yaml", "needle.yaml"):
        world.load_adf(tmp_path / name)
    world.gravity = (0.0, 0.0, 0.0)
    yield world.simulator
    ambf_client.use_simulator(None)
