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


def follow_world():
    """A 20 mm cube at 0.2 mm voxels, bone (label 1) below z = 0, and a plan: the bone's top
    2 mm over the central 12 mm x 12 mm, so the plan's top voxel centres lie at z = -0.1 mm."""
    grid = np.zeros((100, 100, 100), np.uint8)
    grid[:, :, :50] = 1
    data = ambfplus.VolumeData(
        grid, voxel_size=(0.0002,) * 3, label_table=[ambfplus.Label(1, "Bone")]
    )
    world = ambfplus.World()
    volume = world.add_volume("bone", data)
    up = ambfplus.rotation_between((1, 0, 0), (0, 0, 1))
    drill = world.add_drill(
        "drill", volume, burr=1, cursors=1, pose=ambfplus.make_pose((0, 0, 0.01), rotation=up)
    )
    plan = np.zeros(grid.shape, bool)
    plan[20:80, 20:80, 40:50] = True
    return world, drill, volume, plan, up


def test_following_the_plan_draws_the_burr_toward_what_is_left_of_it():
    world, drill, volume, plan, up = follow_world()
    with pytest.raises(ambfplus.ArgumentError, match="set_plan first"):
        drill.follow_plan(max_force=0.6, start=0.002)
    drill.set_plan(plan, start=0.001, max_force=1.0, enabled=False)  # no "stay" force
    drill.follow_plan(max_force=0.6, start=0.002)
    assert drill.follows_plan == {"max_force": 0.6, "start": 0.002}
    radius = drill.burr_radius
    assert radius == pytest.approx(0.001)

    def force_at(z: float) -> np.ndarray:
        drill.pose = ambfplus.make_pose((0.0003, -0.0002, z), rotation=up)  # at rest there
        world.step()
        return drill.fixture_force

    def expected(d: float) -> float:
        """The law: rising over [0, s], held to 2 s, falling to 0 at 3 s (s = 2 mm)."""
        return 0.6 * float(np.clip(min(d / 0.002, 3.0 - d / 0.002), 0.0, 1.0))

    top = -0.0001  # the plan's top voxel centres; the burr's surface distance is measured to
    # them less half a voxel, as the fixtures' is
    for z in (0.0015, 0.002, 0.0035, 0.005, 0.0065, 0.008):
        d = z - top - radius - 0.0001
        np.testing.assert_allclose(force_at(z), (0, 0, -expected(d)), atol=1e-6, err_msg=z)
    # Drilled away under the burr: the 1 mm of plan beneath it is gone (an edit of the volume),
    # and kFollowTicks (50) steps later the burr is drawn toward what is left, 1 mm farther.
    volume.data.set_region((0, 0, 45), (100, 100, 50), 0)
    force_at(0.0025)
    for _ in range(50):
        world.step()
    d = 0.0025 - (top - 0.001) - radius - 0.0001
    np.testing.assert_allclose(force_at(0.0025), (0, 0, -expected(d)), atol=1e-6)
    assert expected(d) != pytest.approx(expected(d - 0.001))  # the edit changed the force
    # Off, and gone with the plan.
    drill.follow_plan(max_force=0.6, start=0.002, enabled=False)
    assert drill.follows_plan is None
    assert not force_at(0.0025).any()
    drill.follow_plan(max_force=0.6, start=0.002)
    drill.clear_plan()
    assert drill.follows_plan is None
    drill.set_plan(plan, start=0.001, enabled=False)
    with pytest.raises(ambfplus.ArgumentError, match="start must be a positive"):
        drill.follow_plan(start=0.0)
