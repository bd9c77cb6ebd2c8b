"""A scene for AMBF client scripts, written by the test: two planar arms (a static base and two
links on revolute joints about z), a ghost and a grasping actuator on the first arm's last link,
and a needle floating within the ghost's reach once the first arm is posed."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
from helpers.multi_arm import LINK, forward_kinematics, grasp_blocks

import ambfplus
from ambfplus import ambf_client

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


GRASP = "ghost objects: [GHOST arm1_jaw]\nactuators: [ACTUATOR arm1_grip]\n" + grasp_blocks(
    "arm1_jaw", "arm1_grip", "arm1_link2"
)


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
