"""Finite input never becomes non-finite output: every fixture model stepped for 10 s of simulated
time under gravity, and the drilling fixture drilled for 10 s, keep every pose, velocity, joint
position, force and image finite."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import ambfplus

DESCRIPTIONS = Path("ambf") / "ambf_models" / "descriptions"
FIXTURE_MODELS = [
    "multi-bodies/puzzles/parallel_structure.yaml",
    "multi-bodies/puzzles/peg_and_base.yaml",
    "multi-bodies/puzzles/puzzle2.yaml",
    "multi-bodies/grippers/single joint1.yaml",
]
STEPS = 10_000  # 10 s at the engine's 1 kHz


def assert_state_finite(world, when: str) -> None:
    for body in world.bodies:
        assert np.all(np.isfinite(body.pose)), f"{body.name}'s pose {when}"
        assert np.all(np.isfinite(body.linear_velocity)), f"{body.name}'s velocity {when}"
        assert np.all(np.isfinite(body.angular_velocity)), f"{body.name}'s spin {when}"
    for joint in world.joints:
        assert np.isfinite(joint.position), f"joint {joint.name}'s position {when}"


def assert_images_finite(camera) -> None:
    frame = camera.capture(passes=["rgb", "depth"])
    assert np.all(np.isfinite(frame.depth)), "depth has non-finite pixels"
    assert np.all(frame.depth >= 0)
    assert frame.depth.max() > 0, "the camera sees the scene"


@pytest.mark.parametrize("model", FIXTURE_MODELS)
def test_fixture_models_stay_finite_for_10_seconds(fixtures, model):
    world = ambfplus.World()
    world.load_adf(fixtures / DESCRIPTIONS / "world" / "checkered_floor.yaml")
    world.load_adf(fixtures / DESCRIPTIONS / model)
    assert any(b.dynamic for b in world.bodies), "the model has something that moves"
    for _ in range(10):
        world.step(STEPS // 10)
        assert_state_finite(world, f"at step {world.step_index}")
    camera = world.add_camera("look", 160, 120, fov_y=1.0, near=0.05, far=50.0)
    centre = np.mean([b.pose[:3, 3] for b in world.bodies if b.dynamic], axis=0)
    camera.look_at(centre + (2.0, -2.0, 1.5), centre)
    assert_images_finite(camera)


@pytest.mark.slow
def test_drilling_fixture_stays_finite_while_drilling_for_10_seconds(fixtures):
    sim = ambfplus.Simulator.from_launch(
        fixtures / "volumetric_drilling" / "launch.yaml", models=[0, 2], strict=True
    )
    world, drill, camera = sim.world, sim.get("drill"), sim.get("main_camera")
    volume = world.volumes[0]
    hit = volume.raycast(camera.pose[:3, 3], camera.pose[:3, 2])
    into = -hit["normal"] / np.linalg.norm(hit["normal"])
    start = hit["position"] - into * (drill.burr_radius + 0.002)
    rotation = ambfplus.rotation_between((1, 0, 0), -into)
    drill.on = True
    forces = []
    for k in range(100):
        # Pushed 4 mm past the surface and swept sideways: the burr cuts and the proxy pushes back.
        depth = 0.006 * min(1.0, k / 20)
        side = np.cross(into, (0.0, 0.0, 1.0)) * 0.003 * np.sin(0.2 * k)
        drill.goal = ambfplus.make_pose(start + into * depth + side, rotation=rotation)
        world.step(STEPS // 100)
        forces.append(drill.force)
        assert np.all(np.isfinite(drill.force)), f"drill force at step {world.step_index}"
        assert np.all(np.isfinite(drill.pose)), f"drill pose at step {world.step_index}"
    assert_state_finite(world, "after drilling")
    assert len(drill.removed["step"]) > 0, "the burr cut bone"
    assert max(np.linalg.norm(f) for f in forces) > 0, "the bone pushed back"
    assert_images_finite(camera)
