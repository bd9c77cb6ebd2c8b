"""Devices driving the drill (null, simulated hand, scripted, replay), the input binding
(workspace scale, clutch, camera axes, buttons), the real-time loop, and the original drilling
scene run by the drilling plugin."""

from __future__ import annotations

import threading
import time

import numpy as np
import pytest

import ambfplus

UP = ambfplus.rotation_between((1, 0, 0), (0, 0, 1))  # shaft straight up, burr at the bottom


def slab(n=80, voxel=0.0002):
    """A 16 mm cube of bone (0.2 mm voxels) below z = 0."""
    grid = np.zeros((n, n, n), np.uint8)
    grid[:, :, : n // 2] = 1
    return ambfplus.VolumeData(
        grid, voxel_size=(voxel,) * 3, label_table=[ambfplus.Label(1, "Bone")]
    )


def drill_over_slab(height=0.01, **options):
    world = ambfplus.World()
    volume = world.add_volume("bone", slab())
    drill = world.add_drill(
        "drill", volume, pose=ambfplus.make_pose((0, 0, height), rotation=UP), **options
    )
    return world, volume, drill


def test_simulated_hand_pressed_into_bone_rests_at_the_surface():
    """A hand pulling 5 mm into bone with the default stiffness: the drill stops at the surface,
    the hand comes to rest (no drift), and the energy stays bounded."""
    world, volume, drill = drill_over_slab()
    hand = ambfplus.SimulatedDevice()
    world.add_input_device("hand", hand, drill, drill_button=-1)
    r = drill.burr_radius
    # The burr touches at z = r: pull the hand 5 mm beyond that, from 10 mm above.
    hand.set_target((0.0, 0.0, r - 0.01 - 0.005))
    energy, proxy = [], []
    for _ in range(3000):
        world.step(1)
        energy.append(hand.energy)
        proxy.append(drill.cursor_proxies[0].copy())
    energy, proxy = np.array(energy), np.array(proxy)
    # The burr's centre sits one radius above the bone (voxel bumps within 0.1 mm).
    assert abs(proxy[-1, 2] - r) < 1e-4
    assert np.abs(proxy[-500:] - proxy[-1]).max() < 1e-6, "the drill drifts"
    assert np.linalg.norm(hand.velocity) < 1e-6, "the hand does not come to rest"
    # Bounded: never more than the spring held at the start, and decaying.
    assert energy.max() <= energy[0] * 1.001
    assert energy[-1] < 0.5 * energy[0]
    # At rest the wall pushes back what the hand pulls: k_hand (target - x) + force = 0.
    pull = 100.0 * ((r - 0.015) - hand.position[2])
    assert pull < 0 and drill.force[2] == pytest.approx(-pull, rel=1e-3)
    assert len(drill.removed["step"]) == 0, "the burr was off"


def test_scripted_waypoints_buttons_and_burr_changes():
    world, volume, drill = drill_over_slab(height=0.02)
    device = ambfplus.ScriptedDevice()
    device.set_waypoints(
        [
            {"time": 0.0, "position": (0, 0, 0), "buttons": 0},
            {"time": 0.1, "position": (0.002, 0, 0), "buttons": 0b1},
            {"time": 0.2, "position": (0.002, 0, 0), "buttons": 0b101},  # burr button pressed
            {"time": 0.3, "position": (0.002, 0, 0), "buttons": 0b1},
        ]
    )
    binding = world.add_input_device("dev", device, drill, workspace_scale=2.0, burr_button=2)
    start = drill.goal.copy()
    world.step(50)  # halfway to the second waypoint: 1 mm of device motion, scaled by 2
    moved = drill.goal[:3, 3] - start[:3, 3]
    assert moved[0] == pytest.approx(2.0 * 0.002 * 49 / 100, abs=1e-9)
    assert not drill.on
    world.step(100)
    assert drill.on, "button 0 turns the burr"
    burr = drill.burr
    world.step(100)
    assert drill.burr == (burr + 1) % len(drill.burr_diameters), "a press changes the burr once"
    assert binding.log["step"].tolist() == list(range(1, 251))
    assert binding.log["buttons"][-1] == 0b101


def test_the_clutch_lets_the_device_move_alone():
    world, volume, drill = drill_over_slab(height=0.02)
    device = ambfplus.ScriptedDevice()
    # Buttons hold from a waypoint to the next: the clutch (button 1) is held for the first
    # 0.2 s, while the device moves 10 mm along x.
    device.set_waypoints(
        [
            {"time": 0.0, "position": (0, 0, 0), "buttons": 0b10},
            {"time": 0.1, "position": (0.01, 0, 0), "buttons": 0b10},
            {"time": 0.2, "position": (0.01, 0, 0)},
            {"time": 0.3, "position": (0.01, 0.01, 0)},
        ]
    )
    world.add_input_device("dev", device, drill)
    x0 = drill.goal[:3, 3].copy()
    world.step(101)
    np.testing.assert_allclose(drill.goal[:3, 3], x0, atol=1e-12)  # clutched all the way
    world.step(200)
    # After release, only the later motion counts.
    np.testing.assert_allclose(drill.goal[:3, 3], x0 + (0, 0.01, 0), atol=1e-9)


def test_device_motion_follows_the_reference_cameras_axes():
    world, volume, drill = drill_over_slab(height=0.03)
    camera = world.add_camera("cam", 64, 48)
    camera.look_at((0.2, 0.0, 0.05), (0.0, 0.0, 0.05))  # looking along -x, image up = +z
    device = ambfplus.ScriptedDevice()
    device.set_waypoints(
        [{"time": 0.0, "position": (0, 0, 0)}, {"time": 0.01, "position": (0.001, 0.002, 0.003)}]
    )
    world.add_input_device("dev", device, drill, reference=camera)
    x0 = drill.goal[:3, 3].copy()
    world.step(20)
    right, up, towards_viewer = camera.pose[:3, 0], -camera.pose[:3, 1], -camera.pose[:3, 2]
    expected = 0.001 * right + 0.002 * up + 0.003 * towards_viewer
    np.testing.assert_allclose(drill.goal[:3, 3] - x0, expected, atol=1e-12)
    np.testing.assert_allclose(right, (0, 1, 0), atol=1e-12)
    np.testing.assert_allclose(up, (0, 0, 1), atol=1e-12)


def test_python_callback_is_sampled_every_n_steps_and_held():
    world, volume, drill = drill_over_slab(height=0.02)
    device = ambfplus.ScriptedDevice()
    calls = []

    def hand(t):
        calls.append(t)
        return {"position": (t * 0.01, 0.0, 0.0), "buttons": 1}

    device.set_callback(hand, every=10)
    binding = world.add_input_device("dev", device, drill)
    world.step(100)
    assert len(calls) == 10
    np.testing.assert_allclose(calls, 0.001 * (1 + 10 * np.arange(10)))
    x = binding.log["position"][:, 0]
    assert len(np.unique(x)) == 10, "held between samples"

    device.set_callback(lambda t: 1 / 0, every=5)
    index = world.step_index
    with pytest.raises(ZeroDivisionError):
        world.step(10)
    assert world.step_index == index, "a failing sampler leaves the world as it was"
    device.set_callback(lambda t: "nowhere")
    with pytest.raises(TypeError, match="callback's result"):
        world.step(1)


def drilling_session(device):
    """The 6 mm burr pushed 1 mm into the slab along a sideways path, drilling."""
    world, volume, drill = drill_over_slab(height=0.0035)
    binding = world.add_input_device("dev", device, drill)
    return world, drill, binding


def scripted_plunge():
    device = ambfplus.ScriptedDevice()
    device.set_waypoints(
        [
            {"time": 0.0, "position": (0, 0, 0), "buttons": 1},
            {"time": 0.3, "position": (0.002, 0.001, -0.0015), "buttons": 1},
            {"time": 0.6, "position": (-0.001, 0.002, -0.002), "buttons": 1},
        ]
    )
    return device


def test_a_replayed_log_gives_the_same_removal_and_forces():
    world, drill, binding = drilling_session(scripted_plunge())
    forces = []
    for _ in range(600):
        world.step(1)
        forces.append(drill.force.copy())
    removed = drill.removed
    assert len(removed["step"]) > 500
    log = binding.take_log()

    replay = ambfplus.ReplayDevice(log)
    world2, drill2, _ = drilling_session(replay)
    forces2 = []
    for _ in range(600):
        world2.step(1)
        forces2.append(drill2.force.copy())
    again = drill2.removed
    for key in ("step", "voxel", "label"):
        np.testing.assert_array_equal(removed[key], again[key])
    np.testing.assert_array_equal(np.array(forces), np.array(forces2))
    assert replay.steps_past_end == 0


def test_device_inputs_are_checked():
    world, volume, drill = drill_over_slab()
    device = ambfplus.NullDevice()
    with pytest.raises(ValueError, match="workspace scale"):
        world.add_input_device("a", device, drill, workspace_scale=0.0)
    with pytest.raises(TypeError, match="unexpected keyword argument 'scale'.*workspace_scale"):
        world.add_input_device("a", device, drill, scale=2.0)
    with pytest.raises(ValueError, match="needs 'position'"):
        ambfplus.ScriptedDevice().set_waypoints([{"time": 0.0}])
    with pytest.raises(ValueError, match="must not decrease"):
        ambfplus.ScriptedDevice().set_waypoints(
            [{"time": 1.0, "position": (0, 0, 0)}, {"time": 0.5, "position": (0, 0, 0)}]
        )
    with pytest.raises(ValueError, match="not a rotation"):
        ambfplus.SimulatedDevice().set_target((0, 0, 0), np.eye(3) * 2)
    with pytest.raises(ValueError, match="needs 'buttons'"):
        ambfplus.ReplayDevice({"step": [1], "position": [[0, 0, 0]], "orientation": [[0, 0, 0, 1]]})
    with pytest.raises(ValueError, match="not after"):
        ambfplus.ReplayDevice(
            {
                "step": [2, 2],
                "position": np.zeros((2, 3)),
                "orientation": [[0, 0, 0, 1]] * 2,
                "buttons": [0, 0],
            }
        )
    with pytest.raises(ValueError, match="one length N"):
        ambfplus.ReplayDevice(
            {
                "step": [1, 2],
                "position": np.zeros((1, 3)),
                "orientation": [[0, 0, 0, 1]] * 2,
                "buttons": [0, 0],
            }
        )


def test_real_time_session_replays_exactly_in_scripted_mode():
    """A few seconds at 1 kHz with a simulated hand drilling while a camera captures in another
    thread; its logged readings replayed in scripted mode give the same removal log."""
    hand = ambfplus.SimulatedDevice()
    world, drill, binding = drilling_session(hand)
    camera = world.add_camera("cam", 160, 120, fov_y=0.6, near=0.01, far=1.0)
    camera.look_at((0.04, -0.04, 0.05), (0.0, 0.0, 0.0))
    camera.capture()
    frames, stop = [], threading.Event()
    taken = []  # removed voxels taken in pieces while the loop drills

    def capture():
        while not stop.is_set():
            frame = camera.capture(passes=["rgb", "depth"])
            frames.append(frame.step)

    def take():
        while not stop.is_set():
            taken.append(drill.take_removed())
            drill.events, drill.critical_distances, drill.cursor_proxies  # noqa: B018
            time.sleep(0.002)

    loop = ambfplus.RealTimeLoop(world)
    threads = [threading.Thread(target=capture), threading.Thread(target=take)]
    with loop:
        assert "SCHED_" in loop.scheduling
        for thread in threads:
            thread.start()
        hand.set_target((0.0, 0.0, -0.0015), buttons=1)
        time.sleep(1.0)
        hand.set_target((0.003, 0.002, -0.002), buttons=1)
        time.sleep(1.0)
        stop.set()
        for thread in threads:
            thread.join()
    stats = loop.stats
    assert stats["steps"] > 1500
    assert stats["mean_rate"] == pytest.approx(1000, rel=0.05)
    assert len(frames) > 5 and frames == sorted(frames)
    taken.append(drill.take_removed())
    assert sum(len(t["step"]) > 0 for t in taken) > 5, "voxels were taken while the loop drilled"
    removed = {k: np.concatenate([t[k] for t in taken]) for k in ("step", "voxel", "label")}
    assert len(removed["step"]) > 100
    log = binding.take_log()
    assert log["step"].tolist() == list(range(1, stats["steps"] + 1))

    world2, drill2, _ = drilling_session(ambfplus.ReplayDevice(log))
    world2.step(stats["steps"])
    again = drill2.removed
    for key in ("step", "voxel", "label"):
        np.testing.assert_array_equal(removed[key], again[key])


def test_python_plugins_and_callbacks_run_off_the_real_time_thread():
    world, volume, drill = drill_over_slab()

    class Counter(ambfplus.Plugin):
        calls, seconds = 0, 0.0

        def physics_update(self, dt):
            Counter.calls += 1
            Counter.seconds += dt

        def mouse_move(self, x, y):
            Counter.moves.append((x, y))

    Counter.moves = []
    world.load_plugin(Counter())
    device = ambfplus.ScriptedDevice()
    samples = []
    device.set_callback(lambda t: samples.append(t) or {"position": (0, 0, 0)}, every=1)
    world.add_input_device("dev", device, drill)
    loop = ambfplus.RealTimeLoop(world, poll_rate=50.0)
    with loop:
        time.sleep(0.5)
        world.mouse_move(3.0, 4.0)  # input reaches the Python plugin while the loop steps
        time.sleep(0.5)
    steps = loop.stats["steps"]
    assert Counter.moves == [(3.0, 4.0)]
    # 50 Hz, not 1 kHz: the plugin's time adds up to the loop's.
    assert 20 <= Counter.calls <= 80
    assert 20 <= len(samples) <= 80
    assert Counter.seconds == pytest.approx(steps * world.time_step, abs=0.05)

    # world.lock() holds the loop.
    with loop:
        with world.lock():
            held = world.step_index
            time.sleep(0.1)
            assert world.step_index == held
        time.sleep(0.05)
        assert world.step_index > held
    with pytest.raises(RuntimeError, match="already"):
        loop2 = ambfplus.RealTimeLoop(world)
        with loop:
            loop2.start()


def burr_sweep_labels(volume, before, path):
    """Over the bounding box of a path of burr centres (world frame): voxel indices, their
    labels before drilling, and each voxel centre's distance to the nearest path point."""
    m = volume.world_from_voxel
    inverse = np.linalg.inv(m)
    along = path @ inverse[:3, :3].T + inverse[:3, 3]
    pad = 0.004 / np.linalg.norm(m[:3, 0])
    lo = np.maximum(np.floor(along.min(0) - pad).astype(int), 0)
    hi = np.minimum(np.ceil(along.max(0) + pad).astype(int), before.shape)
    ijk = np.stack(np.meshgrid(*[np.arange(a, b) for a, b in zip(lo, hi)], indexing="ij"), -1)
    ijk = ijk.reshape(-1, 3)
    centres = ijk @ m[:3, :3].T + m[:3, 3]
    distance = np.full(len(centres), np.inf)
    for point in path:
        np.minimum(distance, np.linalg.norm(centres - point, axis=1), out=distance)
    return ijk, before[tuple(ijk.T)], distance


@pytest.mark.slow
def test_the_original_drilling_scene_runs_with_a_scripted_device(fixtures):
    """volumetric_drilling/launch.yaml with its drills and 256^3 volume: the launch file's
    plugin (libvolumetric_drilling.so) resolves to ours, which makes the drill of the burr
    meshes; a scripted plunge into the ear removes the labels an independent sweep predicts."""
    sim = ambfplus.Simulator.from_launch(
        fixtures / "volumetric_drilling" / "launch.yaml", models=[0, 2]
    )
    assert sim.load_report.errors == []
    world = sim.world
    drill = sim.get("drill")
    volume = world.volumes[0]
    assert drill.burr_diameters == pytest.approx([0.001, 0.002, 0.004, 0.006])
    assert drill.burr == 3
    # Only the burr in use is drawn; the drill's meshes ride on it.
    camera = sim.get("main_camera")
    seen = set(np.unique(camera.capture(passes=["instance"]).instance))
    assert world["6mm"].id in seen and not {world[n].id for n in ("1mm", "2mm", "4mm")} & seen

    before = np.asarray(volume.labels).copy()
    eye, forward = camera.pose[:3, 3], camera.pose[:3, 2]
    hit = volume.raycast(eye, forward)
    into = -hit["normal"] / np.linalg.norm(hit["normal"])
    r = drill.burr_radius
    start = hit["position"] - into * (r + 0.002)
    drill.goal = ambfplus.make_pose(start, rotation=ambfplus.rotation_between((1, 0, 0), -into))
    device = ambfplus.ScriptedDevice()
    travel = tuple(into * 0.006)
    device.set_waypoints(
        [
            {"time": 0.0, "position": (0, 0, 0), "buttons": 1},
            {"time": 1.5, "position": travel, "buttons": 1},
            {"time": 2.0, "position": travel, "buttons": 1},
        ]
    )
    world.add_input_device("hand", device, drill, reference=None)
    path = []
    for _ in range(2000):
        world.step(1)
        path.append(drill.cursor_proxies[0].copy())
    removed = drill.removed
    assert np.dot(path[-1] - hit["position"], into) > -0.001, "the burr went into the bone"
    # The burr's centre along its way: at most about 600 points, micrometres apart.
    path = np.array(path)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(path, axis=0), axis=1) > 0])
    path = path[keep][:: max(1, int(keep.sum()) // 600)]
    ijk, labels, distance = burr_sweep_labels(volume, before, path)
    predicted = (distance <= r) & (labels > 0)
    got = np.zeros(before.shape, bool)
    got[tuple(removed["voxel"].T)] = True
    assert (before[tuple(removed["voxel"].T)] == removed["label"]).all()
    in_box = got[tuple(ijk.T)]
    assert in_box.sum() == len(removed["step"]), "removed outside the swept box"
    differ = in_box ^ predicted
    voxel = np.linalg.norm(volume.world_from_voxel[:3, :3], axis=0).max()
    # Differences only in the burr's boundary layer (it cuts voxels whose centres are up to
    # 0.6 voxel beyond its radius), and per label the same counts within that layer.
    assert np.abs(distance[differ] - r).max() <= 0.6 * voxel + 1e-9
    for label in np.unique(np.concatenate([labels[predicted], removed["label"]])):
        want = int(((labels == label) & predicted).sum())
        have = int((removed["label"] == label).sum())
        layer = int(((labels == label) & (np.abs(distance - r) <= 0.6 * voxel)).sum())
        assert abs(have - want) <= layer, (label, have, want)
    assert predicted.sum() > 2000


def test_options_from_an_ambf_input_device_file(fixtures):
    file = fixtures / "volumetric_drilling" / "ADF" / "input_devices" / "input_devices.yaml"
    entries = {e["identifier"]: e for e in ambfplus.read_input_devices(file)}
    world, volume, drill = drill_over_slab()
    world.add_camera("camera1", 32, 32)
    touch = ambfplus.input_device_options(entries["Geomagic Touch"], world)
    # workspace scaling 10, buttons a1: 0, a2: -1, next mode: 2, max force 2.
    assert touch == {
        "workspace_scale": 10.0,
        "drill_button": 0,
        "clutch_button": -1,
        "burr_button": 2,
        "max_force": 2.0,
    }
    mtmr = ambfplus.input_device_options(entries["MTMR"], world)
    assert mtmr["reference"].name == "camera1" and mtmr["clutch_button"] == 2
    binding = world.add_input_device("touch", ambfplus.NullDevice(), drill, **touch)
    world.step(1)
    assert binding.state["buttons"] == 0


def test_an_untaken_device_log_keeps_its_newest_readings_and_counts_the_rest():
    world, volume, drill = drill_over_slab(height=0.03)
    binding = world.add_input_device("dev", ambfplus.NullDevice(), drill)
    cap = ambfplus.InputDevice.MAX_LOG
    world.step(cap + 25)
    log = binding.log
    assert len(log["step"]) == cap and binding.log_dropped == 25
    assert log["step"][0] == 26 and log["step"][-1] == cap + 25, "the newest are kept"
    taken = binding.take_log()
    assert len(taken["step"]) == cap and len(binding.log["step"]) == 0
    world.step(10)
    assert len(binding.log["step"]) == 10 and binding.log_dropped == 25
