"""The drill: finger-proxy cursors on a volume, removal, forces, determinism."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus

UP = ambfplus.rotation_between((1, 0, 0), (0, 0, 1))  # shaft straight up, burr at the bottom


def slab(n=100, voxel=0.0002, labels=None):
    """A 20 mm cube (at 0.2 mm voxels) of bone below z = 0 (the cube is centred on the origin)."""
    grid = np.zeros((n, n, n), np.uint8)
    grid[:, :, : n // 2] = 1
    table = labels or [ambfplus.Label(1, "Bone")]
    return ambfplus.VolumeData(grid, voxel_size=(voxel,) * 3, label_table=table)


def drill_world(data, **options):
    world = ambfplus.World()
    volume = world.add_volume("bone", data)
    options.setdefault("pose", ambfplus.make_pose((0, 0, 0.01), rotation=UP))
    drill = world.add_drill("drill", volume, **options)
    return world, volume, drill


def plunge(world, drill, top, bottom, seconds, hold=0.3):
    drill.on = True
    drill.set_waypoints(
        [
            {"time": 0.0, "pose": ambfplus.make_pose(top, rotation=UP), "on": True},
            {"time": seconds, "pose": ambfplus.make_pose(bottom, rotation=UP), "on": True},
            {"time": seconds + hold, "pose": ambfplus.make_pose(bottom, rotation=UP), "on": True},
        ]
    )
    world.step(int(round((seconds + hold) / world.time_step)))


def test_a_plunge_removes_the_voxels_the_burr_sweeps():
    data = slab()
    before = np.asarray(data.labels).copy()
    world, volume, drill = drill_world(data, burr=2, cutting_rate=2e-6, stiffness=2000.0)
    r = drill.burr_radius
    top, bottom = (0.0003, -0.0001, r + 0.005), (0.0003, -0.0001, r - 0.010)
    plunge(world, drill, top, bottom, seconds=1.5)
    removed = drill.removed
    assert len(removed["step"]) > 0
    got = np.zeros(before.shape, bool)
    i, j, k = removed["voxel"].T
    got[i, j, k] = True
    assert (removed["label"] == 1).all() and (before[i, j, k] == 1).all()
    # An independent sweep: voxel centres within r of the burr centre's path.
    c = (np.arange(100) + 0.5 - 50) * 0.0002
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    zc = np.clip(z, bottom[2], top[2])
    dist = np.sqrt((x - top[0]) ** 2 + (y - top[1]) ** 2 + (z - zc) ** 2)
    expected = (dist <= r) & (before == 1)
    differ = got ^ expected
    assert expected.sum() > 5000
    # Differences only in the boundary layer, one voxel thick (the burr touches voxels whose
    # centres are half a voxel beyond its radius).
    assert np.abs(dist[differ] - r).max() <= 0.0002 * 1.01
    assert differ.sum() < 3 * 0.0002 / r * expected.sum()
    assert not np.asarray(data.labels)[got].any(), "the volume lost them too"


def test_removal_rate_is_independent_of_step_and_voxel_size():
    def removed_volume(voxel, dt):
        n = int(round(0.02 / voxel))
        world = ambfplus.World(time_step=dt)
        volume = world.add_volume("bone", slab(n, voxel))
        drill = world.add_drill(
            "drill",
            volume,
            burr=3,
            stiffness=1000.0,
            pose=ambfplus.make_pose((0, 0, 0.004), rotation=UP),
        )
        drill.on = True
        force = 1.0  # N pressed along the surface normal, whatever the surface does
        for _ in range(int(round(0.3 / dt))):
            goal = drill.goal
            tip = drill.cursor_proxies[0]
            normal = drill.tip_normal if drill.cursor_contacts[0] else np.array([0, 0, 1.0])
            goal[:3, 3] = tip - normal * (force / drill.stiffness)
            drill.goal = goal
            world.step()
        return len(drill.removed["step"]) * voxel**3

    reference = removed_volume(0.0002, 0.001)
    expected = 30e-9 * 1.0 * 0.3  # cutting rate x force x time
    assert reference == pytest.approx(expected, rel=0.05)
    assert removed_volume(0.0001, 0.001) == pytest.approx(reference, rel=0.05)
    assert removed_volume(0.0002, 0.0005) == pytest.approx(reference, rel=0.05)


def test_shaft_contact_blocks_removal_and_moves_the_drill():
    grid = np.zeros((100, 100, 100), np.uint8)
    grid[:, :, :50] = 1  # floor, z < 0
    grid[:40, :, :] = 1  # wall, x < -2 mm
    data = ambfplus.VolumeData(
        grid, voxel_size=(0.0002,) * 3, label_table=[ambfplus.Label(1, "Bone")]
    )
    axis = np.array([-1.0, 0.0, 1.0]) / np.sqrt(2)
    rotation = ambfplus.rotation_between((1, 0, 0), axis)
    world = ambfplus.World()
    volume = world.add_volume("bone", data)
    start = ambfplus.make_pose((0.008, 0, 0.003), rotation=rotation)
    drill = world.add_drill("drill", volume, burr=2, pose=start, cutting_rate=2e-6)
    r = drill.burr_radius
    drill.on = True
    shaft_led = removed_while_shaft_led = 0
    for step in range(400):
        # The tip pressed 0.2 mm into the floor while the drill moves towards the wall.
        x = 0.008 - step * 0.00002
        drill.goal = ambfplus.make_pose((x, 0, r - 0.0002), rotation=rotation)
        before = len(drill.removed["step"])
        world.step()
        if drill.leading_cursor > 0:
            shaft_led += 1
            removed_while_shaft_led += len(drill.removed["step"]) - before
            lead = drill.leading_cursor
            expected = drill.cursor_proxies[lead] - axis * 0.0015 * lead
            assert np.allclose(drill.pose[:3, 3], expected, atol=1e-9)
    assert shaft_led > 50
    assert removed_while_shaft_led == 0
    assert len(drill.removed["step"]) > 0, "before the shaft met the wall the tip cut the floor"


def run_script(removal="physical"):
    world, volume, drill = drill_world(
        ambfplus.phantom(96, seed=5),
        burr=3,
        removal=removal,
        cutting_rate=1e-6,
        pose=ambfplus.make_pose((0.0, 0.0, 0.03), rotation=UP),
    )
    forces = []
    drill.set_waypoints(
        [
            {
                "time": 0.05,
                "pose": ambfplus.make_pose((0.001, 0.002, 0.006), rotation=UP),
                "on": True,
            },
            {
                "time": 0.15,
                "pose": ambfplus.make_pose((0.004, 0.0, 0.004), rotation=UP),
                "on": True,
            },
        ]
    )
    for _ in range(150):
        world.step()
        forces.append(drill.force.copy())
    return drill.removed, np.array(forces), drill


def test_the_same_script_gives_the_same_removal_and_forces():
    a_removed, a_forces, _ = run_script()
    b_removed, b_forces, _ = run_script()
    assert len(a_removed["step"]) > 100
    for key in ("step", "voxel", "label"):
        assert np.array_equal(a_removed[key], b_removed[key])
    assert np.array_equal(a_forces, b_forces)
    assert np.abs(a_forces).max() > 0.1


def test_compatible_mode_removes_a_fixed_count_per_step():
    removed, _, drill = run_script("compatible")
    per_step = np.bincount(removed["step"])
    assert per_step.max() == 10, "the 6 mm burr takes 10 voxels a step"
    drill.burr = 0
    assert drill.burr_radius == pytest.approx(0.0005)


def test_critical_structures_raise_events_and_report_their_distance():
    grid = np.zeros((100, 100, 100), np.uint8)
    grid[:, :, :50] = 1
    grid[45:55, 45:55, 30:40] = 2  # a nerve 2 to 4 mm below the surface
    data = ambfplus.VolumeData(
        grid,
        voxel_size=(0.0002,) * 3,
        label_table=[ambfplus.Label(1, "Bone"), ambfplus.Label(2, "Nerve", critical=True)],
    )
    world, volume, drill = drill_world(data, burr=1, cutting_rate=2e-6, stiffness=2000.0)
    r = drill.burr_radius
    world.step()
    # Nerve voxel centres start 2.1 mm below the surface; the burr is 8 mm above it.
    start = drill.critical_distances["Nerve"]
    assert start == pytest.approx(0.010 - r + 0.0021 - 0.0001 - r, abs=0.0003) or start > 0.009
    plunge(world, drill, (0, 0, 0.01), (0, 0, r - 0.0035), seconds=1.0)
    events = drill.take_events()
    assert events and all(e["kind"] == "critical" and e["label"] == 2 for e in events)
    assert drill.critical_distances["Nerve"] < 0.0002, "the burr ends against the nerve"
    assert drill.events == []
    # World.read_state reads the same in one call (what the live view publishes); the drill,
    # off, pressed 1 mm further into the bone has a force to read.
    drill.on = False
    drill.set_waypoints([])  # the plunge's last waypoint holds the goal otherwise
    drill.goal = ambfplus.make_pose((0, 0, r - 0.0045), rotation=UP)
    world.step(20)
    camera = world.add_camera("cam", 32, 24, fov_y=0.8, near=0.001, far=1.0)
    camera.principal_point = (15.25, 13.5)
    camera.look_at((0, -0.05, 0.02), (0, 0, 0))
    read = world.read_state([volume, drill, camera])
    assert read["time"] == world.time
    bone, tool, cam = read["objects"]
    assert set(bone) == {"pose"} and set(cam) == {"pose", "intrinsics"}
    np.testing.assert_array_equal(bone["pose"], volume.pose)
    np.testing.assert_array_equal(tool["pose"], drill.pose)
    np.testing.assert_array_equal(tool["force"], drill.force)
    assert np.linalg.norm(tool["force"]) > 0, "the burr presses on the nerve's bone"
    assert tool["critical_distances"] == drill.critical_distances
    np.testing.assert_array_equal(cam["intrinsics"], camera.intrinsics)
    assert cam["intrinsics"][0, 2] == 15.25
    other = ambfplus.World()
    stranger = other.add_body("ball", "sphere", radius=0.01, mass=0.0)
    with pytest.raises(ValueError, match="'ball'.* belongs to another world"):
        world.read_state([drill, stranger])
    with pytest.raises(TypeError):
        world.read_state([drill, None])


def test_drill_moves_attached_bodies_and_reports_tick_times():
    world, volume, drill = drill_world(slab())
    burr = world.add_body("burr", "sphere", radius=drill.burr_radius)
    drill.attach(burr)
    drill.goal = ambfplus.make_pose((0.001, 0.002, 0.008), rotation=UP)
    world.step(3)
    assert np.allclose(burr.pose[:3, 3], (0.001, 0.002, 0.008))
    assert len(drill.tick_seconds) == 3 and (drill.tick_seconds > 0).all()


def test_assigning_a_drills_pose_places_it_there_at_once():
    world, volume, drill = drill_world(slab())
    r = drill.burr_radius
    world.step()
    # Deep in the bone: a goal there is only reached by drilling; a pose is taken at once.
    inside = ambfplus.make_pose((0.002, -0.001, -0.004), rotation=UP)
    drill.goal = inside
    world.step(5)
    assert drill.pose[2, 3] > r - 1e-4, "a goal in the bone stops at its surface"
    above = ambfplus.make_pose((0.003, 0.002, 0.02), rotation=UP)
    drill.pose = above
    np.testing.assert_array_equal(drill.goal, above)
    np.testing.assert_allclose(drill.cursor_proxies[0], above[:3, 3], atol=1e-12)
    np.testing.assert_allclose(drill.cursor_goals[0], above[:3, 3], atol=1e-12)
    world.step(5)
    np.testing.assert_allclose(drill.pose, above, atol=1e-9)
    assert drill.cursor_contacts == [0] * len(drill.cursor_contacts)
    with pytest.raises(ValueError, match="drill 'drill'"):
        drill.pose = np.full((4, 4), np.nan)


def test_bad_drill_arguments():
    world, volume, drill = drill_world(slab(20))
    with pytest.raises(ValueError, match="burr index"):
        drill.burr = 9
    with pytest.raises(ValueError, match="speed"):
        drill.speed = 2.0
    with pytest.raises(TypeError, match="unexpected keyword"):
        world.add_drill("d2", volume, colour="red")
    with pytest.raises(ValueError, match="cursors"):
        world.add_drill("d3", volume, cursors=0)
    with pytest.raises(ValueError, match="waypoint times"):
        drill.set_waypoints([{"time": 1.0, "pose": np.eye(4)}, {"time": 0.5, "pose": np.eye(4)}])


def test_force_limit_and_soft_start():
    world, volume, drill = drill_world(slab(), stiffness=2000.0, max_force=1.5, soft_start=0.01)
    r = drill.burr_radius
    drill.goal = ambfplus.make_pose((0, 0, r - 0.002), rotation=UP)  # 2 mm deep: 4 N unlimited
    forces = []
    for _ in range(20):
        world.step()
        forces.append(np.linalg.norm(drill.force))
    forces = np.array(forces)
    # Ramped in over 10 ms (the ramp starts when the drill is made), then capped at 1.5 N.
    assert forces[0] < 0.3 and np.all(np.diff(forces[:10]) > 0)
    assert forces[-1] == pytest.approx(1.5, rel=1e-6)
    assert np.allclose(drill.force / np.linalg.norm(drill.force), (0, 0, 1), atol=1e-3)


def test_damping_opposes_the_goal_motion_in_contact():
    world, volume, drill = drill_world(slab(), stiffness=1000.0, damping=2.0)
    r = drill.burr_radius
    drill.goal = ambfplus.make_pose((0, 0, r - 0.001), rotation=UP)
    world.step(2)  # the second step has the goal at rest
    still = drill.force.copy()
    assert still[2] == pytest.approx(1.0, rel=0.02)
    # The goal moving sideways at 1 m/s adds 2 N against the motion.
    drill.goal = ambfplus.make_pose((0.001, 0, r - 0.001), rotation=UP)
    world.step()
    assert drill.force[0] == pytest.approx(-2.0, abs=0.05)
    assert drill.force[2] == pytest.approx(still[2], rel=0.02)


def test_rigid_bodies_stop_the_drill_at_their_faces():
    # Bone below z = 0 and a steel plate (a static box body) whose top face is at z = 5 mm over
    # part of it: pushed down onto the plate, the burr rests on its face, feels the spring force
    # along its normal and cuts nothing; beside the plate it reaches the bone.
    world, volume, drill = drill_world(slab(), stiffness=800.0)
    world.add_body(
        "plate", "box", size=(0.006, 0.02, 0.002), mass=0.0, pose=ambfplus.make_pose((0, 0, 0.004))
    )
    drill.on = True
    r = drill.burr_radius
    goal_z = 0.005 + r - 0.001  # 1 mm into the plate
    drill.set_waypoints(
        [
            {"time": 0.2, "pose": ambfplus.make_pose((0, 0.001, goal_z), rotation=UP), "on": True},
            {"time": 0.4, "pose": ambfplus.make_pose((0, 0.001, goal_z), rotation=UP), "on": True},
        ]
    )
    world.step(400)
    tip = drill.cursor_proxies[0]
    assert tip[2] == pytest.approx(0.005 + r, abs=1e-5), "resting on the plate's top face"
    assert np.allclose(drill.force, 800.0 * (tip - drill.cursor_goals[0]), atol=1e-9)
    assert np.allclose(drill.force, (0, 0, 0.8), rtol=0.01, atol=1e-6), "1 mm deep at 800 N/m"
    assert np.allclose(drill.tip_normal, (0, 0, 1), atol=1e-9)
    assert len(drill.removed["voxel"]) == 0, "the plate is not bone"
    # The plate moves away (as a body pushed by physics would): the drill falls to the bone.
    world["plate"].pose = ambfplus.make_pose((0.05, 0, 0.004))
    drill.set_waypoints(
        [{"time": 0.1, "pose": ambfplus.make_pose((0, 0.001, r - 0.0005), rotation=UP), "on": True}]
    )
    world.step(200)
    assert drill.cursor_proxies[0][2] < 0.001 + r, "reached the bone"
    assert len(drill.take_removed()["voxel"]) > 0


def test_a_body_across_the_shaft_stops_the_drill():
    # A bar 6 mm up the shaft (cursor 4's height), 3 mm to the side: moving the drill sideways
    # into it, the shaft cursor meets the bar, leads, and the force pushes back along -x.
    world, volume, drill = drill_world(slab())
    tip_z = 0.008
    world.add_body(
        "bar",
        "box",
        size=(0.002, 0.02, 0.002),
        mass=0.0,
        pose=ambfplus.make_pose((0.004, 0, tip_z + 4 * 0.0015)),
    )
    drill.set_waypoints(
        [
            {"time": 0.0, "pose": ambfplus.make_pose((0, 0, tip_z), rotation=UP)},
            {"time": 0.3, "pose": ambfplus.make_pose((0.006, 0, tip_z), rotation=UP)},
        ]
    )
    world.step(300)
    lead = drill.leading_cursor
    assert 3 <= lead <= 5, "a shaft cursor near the bar leads"
    stop = 0.003 - drill.cursor_radii[lead]
    assert drill.cursor_proxies[lead][0] == pytest.approx(stop, abs=1e-4), "held at the bar"
    assert drill.force[0] < -0.5 and abs(drill.force[2]) < 0.2 * abs(drill.force[0])
    assert drill.pose[0, 3] == pytest.approx(stop, abs=1e-4), "the drill is shown where it stops"


def adf_with_drill(tmp_path, drill_block):
    """A model file with a slab volume (a slice stack) and the given drill block."""
    data = slab(20, voxel=0.001)
    data.save_slice_stack(tmp_path / "slab")
    ambfplus.write_label_table(tmp_path / "slab" / "labels.csv", data.label_table)
    path = tmp_path / "model.yaml"
    path.write_text(
        "volumes: [VOLUME slab]\n"
        "drills: [DRILL burr]\n"
        "VOLUME slab:\n"
        "  name: slab\n"
        "  dimensions: {x: 0.02, y: 0.02, z: 0.02}\n"
        "  images: {path: slab/, prefix: plane00, format: png, count: 20}\n"
        "  labels: slab/labels.csv\n" + drill_block
    )
    return path


def test_drills_declared_in_a_model_file(tmp_path, caplog):
    path = adf_with_drill(
        tmp_path,
        "DRILL burr:\n"
        "  name: mastoid drill\n"
        "  volume: VOLUME slab\n"
        "  location:\n"
        "    position: {x: 0.0, y: 0.0, z: 0.02}\n"
        "    orientation: {r: 0, p: -1.5707963, y: 0}\n"
        "  burr diameters: [0.0015, 0.003, 0.005]\n"
        "  burr: 1\n"
        "  cursors: 4\n"
        "  shaft radii: [0.0007, 0.0008, 0.0009]\n"
        "  stiffness: 400\n"
        "  removal: compatible\n"
        "  voxels per step: [2, 4, 8]\n"
        "  colour: red\n",
    )
    world = ambfplus.World()
    with caplog.at_level("WARNING", logger="ambfplus"):
        (volume,) = world.load_volumes(path)
    assert "unknown key 'colour'" in caplog.text and "line 21" in caplog.text
    (drill,) = world.drills
    assert drill.name == "mastoiddrill" and drill.volume.name == "slab"
    assert drill.burr_diameters == [0.0015, 0.003, 0.005] and drill.burr == 1
    assert drill.burr_radius == 0.0015 and drill.cursor_radii == [0.0015, 0.0007, 0.0008, 0.0009]
    assert drill.stiffness == 400 and drill.removal == "compatible"
    # The shaft (+x of the drill) points up: the pitch of -90 degrees turns x onto +z.
    assert np.allclose(drill.goal[:3, 0], (0, 0, 1), atol=1e-6)
    assert np.allclose(drill.goal[:3, 3], (0, 0, 0.02))
    drill.burr = 2
    assert drill.cursor_radii[0] == 0.0025, "a burr change at run time resizes the tip"


def test_a_drill_block_and_add_drill_share_their_keys(tmp_path):
    """A DRILL block's keys are add_drill's keywords with spaces for underscores (one table)."""
    keys = {
        "burr diameters": [0.002, 0.004],
        "burr": 1,
        "cursors": 3,
        "cursor spacing": 0.002,
        "shaft radii": [0.0006, 0.0007],
        "stiffness": 450.0,
        "max force": 4.0,
        "removal": "compatible",
        "voxels per step": [2, 5],
        "friction": {"static": 0.3, "dynamic": 0.2},
    }
    block = "DRILL burr:\n  volume: slab\n" + "".join(f"  {k}: {v}\n" for k, v in keys.items())
    from_file = ambfplus.World()
    (volume,) = from_file.load_volumes(adf_with_drill(tmp_path, block.replace("'", "")))
    (loaded,) = from_file.drills
    kwargs = {k.replace(" ", "_"): v for k, v in keys.items()}
    kwargs["spacing"] = kwargs.pop("cursor_spacing")  # Python's name; the file's is an alias
    made = from_file.add_drill("d", volume, **kwargs)
    for attribute in ("burr_diameters", "burr", "cursor_radii", "stiffness", "removal"):
        assert getattr(made, attribute) == getattr(loaded, attribute), attribute


@pytest.mark.parametrize(
    "block, message",
    [
        ("DRILL burr:\n  burr: 1\n", "needs 'volume'"),
        ("DRILL burr:\n  volume: VOLUME other\n", "not one of the file's volumes"),
        ("DRILL burr:\n  volume: slab\n  removal: fast\n", "line 10.*physical or compatible"),
        ("DRILL burr:\n  volume: slab\n  burr: [1]\n", "line 10.*'burr' must be an integer"),
        ("DRILL burr:\n  volume: slab\n  burr diameters: [0.001, -1]\n", "must be > 0"),
        ("", "lists 'DRILL burr' but the file has no block"),
    ],
)
def test_bad_drill_blocks_name_the_file_and_key(tmp_path, block, message):
    path = adf_with_drill(tmp_path, block)
    world = ambfplus.World()
    with pytest.raises(ambfplus.ConfigError, match=message) as error:
        world.load_volumes(path)
    assert error.value.filename == str(path)


def test_the_drill_logs_are_bounded_and_say_what_they_dropped():
    world = ambfplus.World()
    volume = world.add_volume("v", ambfplus.phantom(16, 0))
    drill = world.add_drill("d", volume)
    assert ambfplus.Drill.MAX_REMOVED == 262144 and ambfplus.Drill.MAX_EVENTS == 65536
    assert drill.removed_dropped == 0 and drill.events_dropped == 0
    data = volume.data
    cap = ambfplus.VolumeData.EDIT_LOG_EDITS
    for i in range(cap + 3):
        data.set_region((0, 0, 0), (1, 1, 1), 1 + i % 2)
    assert len(data.edit_log) == cap and data.edit_log_dropped == 3
    assert data.edit_log[-1]["revision"] == data.revision, "the newest edits are kept"
    assert len(data.take_edit_log()) == cap and data.edit_log == []
