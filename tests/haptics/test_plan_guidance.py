"""Guidance that keeps the burr in a planned cavity ("stay in the plan", Drill.set_plan): a fixture
on the plan's boundary whose forbidden side is every labelled voxel outside it."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus
from ambfplus.scenes import drilling_phantom
from ambfplus.training import ProtectedField, TrainingRegion, novice_like

SEEDS = (3, 4, 5)
SECONDS = 8.0


def planned_cavity(data, half_extent=0.008, depth=0.004) -> np.ndarray:
    """The voxels within `half_extent` of the lateral face's centre (x, y) and within `depth` of
    the surface above them: a saucer like the trainee's region, with room for the burr."""
    labels = np.asarray(data.labels)
    nx, ny, nz = labels.shape
    voxel = np.asarray(data.voxel_size)
    size = np.asarray(data.dimensions)
    x = (np.arange(nx) + 0.5) * voxel[0] - size[0] / 2
    y = (np.arange(ny) + 0.5) * voxel[1] - size[1] / 2
    solid = labels != 0
    top = nz - 1 - np.argmax(solid[:, :, ::-1], axis=2)  # the top labelled voxel per column
    top[~solid.any(axis=2)] = -1
    k = np.arange(nz)[None, None, :]
    within = (np.abs(x)[:, None] <= half_extent) & (np.abs(y)[None, :] <= half_extent)
    deep = int(round(depth / voxel[2]))
    target = (k >= (top - deep)[:, :, None]) & within[:, :, None] & (top[:, :, None] >= 0)
    return target & solid


def novice_session(seed: int, plan: bool):
    """A novice-like trainee (plunging, drifting toward the facial nerve) on the built-in
    phantom, as training.drill_phantom runs one, with or without the plan's fixture."""
    scene = drilling_phantom(resolution=128)
    world, drill = scene.world, scene.drill
    data = drill.volume.data
    target = planned_cavity(data)
    if plan:
        drill.set_plan(target, start=0.001, max_force=1.0, stop=0.0003)
    nerve = ProtectedField(
        "facial nerve", ambfplus.DistanceField(data, "Facial_Nerve", 0.03), 0.001
    )
    trainee = novice_like(
        drill.volume,
        drill.pose[:3, 3],
        drill.burr_radius,
        np.random.default_rng(seed),
        protect=[nerve],
        region=TrainingRegion(),
    )
    trainee.plan(SECONDS)
    device = ambfplus.ScriptedDevice()
    device.set_callback(trainee, every=10)
    world.add_input_device(scene.device_name, device, drill, **scene.device_options)
    world.step(int(round(SECONDS / world.time_step)))
    removed = drill.take_removed()
    i, j, k = removed["voxel"].T
    inside = target[i, j, k]
    return int((~inside).sum()), int(inside.sum())


@pytest.fixture(scope="module")
def sessions():
    return {plan: [novice_session(seed, plan) for seed in SEEDS] for plan in (False, True)}


@pytest.mark.slow
def test_staying_in_the_plan_removes_far_less_outside_it(sessions):
    outside_without = sum(s[0] for s in sessions[False])
    outside_with = sum(s[0] for s in sessions[True])
    assert outside_without > 500, "the novice-like trainee strays well outside the plan"
    assert outside_with <= 0.1 * outside_without, (outside_with, outside_without)


def test_staying_in_the_plan_still_drills_the_plan(sessions):
    inside_without = sum(s[1] for s in sessions[False])
    inside_with = sum(s[1] for s in sessions[True])
    assert inside_with >= 0.3 * inside_without, (inside_with, inside_without)


def test_a_plan_from_labels_and_its_errors():
    scene = drilling_phantom(resolution=48)
    drill = scene.drill
    assert drill.plan is None
    drill.set_plan(["Bone", 9], start=0.001)
    plan = drill.plan
    assert plan["start"] == 0.001 and plan["stop"] is None and plan["enabled"] is True
    labels = np.asarray(drill.volume.data.labels)
    assert plan["voxels"] == int(np.isin(labels, [1, 9]).sum())
    with pytest.raises(ValueError, match="shape"):
        drill.set_plan(np.ones((4, 4, 4), bool), start=0.001)
    with pytest.raises(KeyError, match="Marrow"):
        drill.set_plan(["Marrow"], start=0.001)
    drill.clear_plan()
    assert drill.plan is None
