"""The capture area: one pass table, points as a pass (also into the caller's array), and poses
taken with the images from the same copy of the world, also while a real-time loop steps it."""

from __future__ import annotations

import threading

import numpy as np
import pytest

import ambfplus
from ambfplus import _core

SPEED = 0.5  # m/s of the ball along x


def test_the_pass_table_names_every_pass_once_with_its_array_type():
    table = _core.capture_passes()
    names = [p["name"] for p in table]
    assert names == ["rgb", "depth", "label", "instance", "voxel", "segmentation", "points"]
    world = ambfplus.World()
    world.add_body("wall", "box", size=(1, 1, 0.01), mass=0.0)
    camera = world.add_camera("cam", 64, 48, fov_y=0.8, near=0.01, far=5.0)
    camera.look_at((0, 0, 1.0), (0, 0, 0), up=(0, 1, 0))
    frame = camera.capture(passes=names)
    for p in table:
        image = getattr(frame, p["name"])
        assert image.dtype == np.dtype(p["dtype"]), p["name"]
        assert image.shape == ((48, 64) if p["channels"] == 1 else (48, 64, p["channels"]))
    assert [p["name"] for p in table if p["default"]] == camera.passes
    with pytest.raises(ValueError, match="expected one of rgb, depth"):
        camera.capture(passes=["rgb", "normals"])


def test_points_pass_is_depth_through_the_intrinsics_also_into_a_callers_array():
    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.3, mass=0.0)
    camera = world.add_camera("cam", 80, 60, fov_y=0.9, near=0.01, far=5.0)
    camera.principal_point = (37.25, 33.5)  # off-axis: the shift must reach the points
    camera.look_at((0.1, -0.2, 1.0), (0, 0, 0))
    alone = camera.capture(passes=["points"])
    assert alone.depth is None and alone.rgb is None
    with_depth = camera.capture(passes=["depth"])
    k = with_depth.intrinsics
    rows, cols = np.mgrid[0:60, 0:80]
    z = with_depth.depth.astype(np.float64)
    expected = np.stack(
        [(cols + 0.5 - k[0, 2]) / k[0, 0] * z, (rows + 0.5 - k[1, 2]) / k[1, 1] * z, z], axis=-1
    )
    assert (z > 0).sum() > 500 and (z == 0).sum() > 500
    np.testing.assert_allclose(alone.points, expected, atol=1e-6)
    np.testing.assert_allclose(with_depth.points, expected, atol=1e-6)
    # Into preallocated memory: the caller's array is filled and the frame views it.
    out = {"points": np.full((60, 80, 3), np.nan, np.float32)}
    frame = camera.capture(out=out)
    np.testing.assert_allclose(out["points"], expected, atol=1e-6)
    assert np.shares_memory(frame.points, out["points"])


def test_refilling_a_frame_without_asking_for_poses_leaves_none_behind():
    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.1, mass=0.0)
    camera = world.add_camera("cam", 32, 24, fov_y=0.8, near=0.01, far=5.0)
    camera.look_at((0, -1, 0), (0, 0, 0))
    frame = camera.capture(poses=["ball"])
    assert set(frame.poses) == {"ball"}
    camera.capture(out=frame)
    assert frame.poses is None
    assert set(camera.capture(poses=True).poses) == {"ball", "cam"}
    with pytest.raises(ValueError, match="no object named 'nothing'"):
        camera.capture(poses=["nothing"])


def test_read_state_under_a_real_time_loop_is_one_step_of_the_world():
    world, ball, camera = moving_ball_world()
    offset = np.eye(4)
    offset[:3, 3] = (0.0, -0.5, 0.0)
    camera.attach_to(ball, offset)
    dt = world.time_step
    reads = []

    def read():
        while len(reads) < 200 or (len({r["time"] for r in reads}) <= 10 and len(reads) < 20000):
            reads.append(world.read_state([ball, camera]))

    with ambfplus.RealTimeLoop(world):
        thread = threading.Thread(target=read)
        thread.start()
        thread.join()
    assert len({r["time"] for r in reads}) > 10, "the loop stepped while the thread read"
    for r in reads:
        (b, c) = r["objects"]
        # Same step as the time: one step away is SPEED * dt = 0.5 mm.
        assert b["pose"][0, 3] == pytest.approx(SPEED * r["time"], abs=2e-5), r["time"]
        np.testing.assert_allclose(c["pose"], b["pose"] @ offset, atol=1e-12)
        assert r["time"] / dt == pytest.approx(round(r["time"] / dt))


def test_the_state_lock_excludes_other_threads_and_is_reentrant():
    world = ambfplus.World()
    events = []

    def other():
        with world.lock():
            events.append("other")

    with world.lock():
        with world.lock():  # the same thread again
            thread = threading.Thread(target=other)
            thread.start()
            thread.join(0.2)
            assert thread.is_alive(), "the other thread waits for the lock"
            events.append("main")
    thread.join(10)
    assert events == ["main", "other"]


def moving_ball_world():
    """A ball gliding along x at SPEED with nothing to slow it, and a camera riding on it: at step
    n its pose and the camera's are known exactly."""
    world = ambfplus.World()
    world.gravity = (0.0, 0.0, 0.0)
    ball = world.add_body(
        "ball", "sphere", radius=0.01, mass=1.0, linear_damping=0.0, angular_damping=0.0
    )
    ball.linear_velocity = (SPEED, 0.0, 0.0)
    camera = world.add_camera("cam", 32, 24, fov_y=0.8, near=0.01, far=5.0)
    camera.look_at((0, -0.5, 0), (0, 0, 0))
    return world, ball, camera


def test_poses_under_a_real_time_loop_belong_to_the_frames_step():
    world, ball, camera = moving_ball_world()
    camera.capture()  # programs and buffers before the clock starts
    dt = world.time_step
    frames = []

    def capture():
        # At least 40 captures, over more than 10 steps (a fast machine captures 40 within 10).
        while len(frames) < 40 or (len({f.step for f in frames}) <= 10 and len(frames) < 4000):
            frames.append(camera.capture(passes=["depth"], poses=["ball"]))

    with ambfplus.RealTimeLoop(world):
        thread = threading.Thread(target=capture)
        thread.start()
        thread.join()
    steps = [f.step for f in frames]
    assert len(set(steps)) > 10, "the loop stepped while the thread captured"
    for frame in frames:
        x = frame.poses["ball"][0, 3]
        # One step away is SPEED * dt = 0.5 mm; Bullet integrates in single precision.
        assert x == pytest.approx(SPEED * dt * frame.step, abs=2e-5), frame.step
        assert frame.time == pytest.approx(frame.step * dt)
