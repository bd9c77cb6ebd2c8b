"""The scene API: hierarchy, names, handles, poses, lights and the clock."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import ambfplus


def test_hierarchy_simulator_world_model_object():
    sim = ambfplus.Simulator(time_step=0.002)
    world = sim.world
    assert world.simulator is sim
    assert world.time_step == 0.002
    assert [m.name for m in world.models] == ["World"]
    arm = world.add_model("arm")
    link = arm.add_body("link", "cylinder", radius=0.01, height=0.2)
    cam = world.add_camera("cam")
    assert link.model is arm and cam.model is world.default_model
    assert [o.name for o in arm.objects] == ["link"]
    assert [o.name for o in world.objects] == ["link", "cam"]
    assert world.get("link") is link
    assert "link" in world and "nothing" not in world and len(world) == 2
    with pytest.raises(ValueError, match="model named 'arm'"):
        world.add_model("arm")


def test_kinds_and_typed_collections():
    world = ambfplus.World()
    b = world.add_body("b", "box", size=(1, 2, 3))
    c = world.add_camera("c")
    light = world.add_light("l", "spot", position=(0, 0, 1), direction=(0, 0, -1))
    assert (b.kind, c.kind, light.kind) == ("body", "camera", "light")
    assert isinstance(world["b"], ambfplus.RigidBody) and isinstance(world["c"], ambfplus.Camera)
    assert world.bodies == [b] and world.cameras == [c] and world.lights == [light]
    assert b.shape == "box" and np.allclose(b.size, (1, 2, 3))
    assert light.type == "spot" and np.allclose(light.direction, (0, 0, -1))
    assert [o.id for o in world.objects] == [1, 2, 3]


def test_handles_keep_the_world_alive():
    world = ambfplus.World()
    body = world.add_body("b", "sphere", radius=0.1)
    camera = world.add_camera("cam", 32, 24)
    camera.look_at((1, 0, 0), (0, 0, 0))
    del world
    gc.collect()
    # The camera still renders its world, and the body is still in it.
    assert (camera.capture().depth > 0).any()
    assert body.model.world.get("b") is body


def test_pose_round_trip_and_copy_semantics():
    world = ambfplus.World()
    pose = ambfplus.make_pose((0.1, -0.2, 0.3), rpy=(0.1, 0.2, 0.3))
    body = world.add_body("b", "sphere", radius=0.1, pose=pose)
    assert np.allclose(body.pose, pose, atol=1e-12)
    got = body.pose
    got[0, 3] = 99.0
    assert body.pose[0, 3] == pytest.approx(0.1), "pose is a copy; assign to change it"
    body.pose = ambfplus.make_pose((1, 2, 3))
    assert np.allclose(body.pose[:3, 3], (1, 2, 3))


def test_rpy_convention_is_fixed_axis_zyx():
    r = ambfplus.rpy_matrix((0.0, 0.0, np.pi / 2))
    assert np.allclose(r @ [1, 0, 0], [0, 1, 0])
    r = ambfplus.rpy_matrix((0.3, -0.4, 1.1))
    assert np.allclose(r @ r.T, np.eye(3)) and np.isclose(np.linalg.det(r), 1)
    # Roll is applied first (about the fixed x axis), yaw last.
    rx = ambfplus.rpy_matrix((0.3, 0, 0))
    ry = ambfplus.rpy_matrix((0, -0.4, 0))
    rz = ambfplus.rpy_matrix((0, 0, 1.1))
    assert np.allclose(r, rz @ ry @ rx)


def test_camera_pose_is_opencv_world_from_camera():
    world = ambfplus.World()
    cam = world.add_camera("cam", 640, 480, 0.7)
    cam.look_at((1, 2, 3), (1, 2, 0), up=(0, 1, 0))
    pose = cam.pose
    assert np.allclose(pose[:3, 2], (0, 0, -1))  # z forward
    assert np.allclose(pose[:3, 1], (0, -1, 0))  # y down = against up
    assert np.allclose(pose[:3, 3], (1, 2, 3))
    k = cam.intrinsics
    assert k[0, 0] == pytest.approx(480 / (2 * np.tan(0.35)))
    assert (k[0, 2], k[1, 2]) == (320, 240)


def test_frames_carry_time_step_and_geometry():
    world = ambfplus.World(time_step=0.001)
    cam = world.add_camera("cam", 32, 24)
    cam.look_at((1, 0, 0), (0, 0, 0))
    world.step(250)
    frame = cam.capture()
    assert frame.step == 250 and frame.time == pytest.approx(0.25)
    assert frame.camera == "cam" and (frame.width, frame.height) == (32, 24)
    assert np.allclose(frame.pose, cam.pose) and np.allclose(frame.intrinsics, cam.intrinsics)
    cam.look_at((0, 1, 0), (0, 0, 0))
    assert not np.allclose(frame.pose, cam.pose), "a frame keeps the pose it was taken at"


def test_each_world_keeps_its_own_clock():
    a, b = ambfplus.World(), ambfplus.World(time_step=0.01)
    a.step(3)
    b.step()
    assert (a.step_index, b.step_index) == (3, 1)
    assert (a.time, b.time) == (pytest.approx(0.003), pytest.approx(0.01))


def lit_brightness(**light) -> float:
    world = ambfplus.World()
    world.add_body("wall", "plane", mass=0, color=(1, 1, 1))
    if light:
        world.add_light("l", **light)
    cam = world.add_camera("cam", 64, 48, 0.7, 0.01, 10.0)
    cam.look_at((0, 0, 1), (0, 0, 0), up=(0, 1, 0))
    return float(cam.capture().rgb.mean())


def test_lights_shade_surfaces():
    headlight = lit_brightness()
    facing = lit_brightness(type="directional", direction=(0, 0, -1), intensity=1.0)
    behind = lit_brightness(type="directional", direction=(0, 0, 1), intensity=1.0)
    grazing = lit_brightness(type="directional", direction=(1, 0, -0.2), intensity=1.0)
    spot_away = lit_brightness(type="spot", position=(0, 0, 1), direction=(0, 1, 0))
    point = lit_brightness(type="point", position=(0, 0, 0.5), intensity=1.0)
    ambient_only = 0.15 * 255
    assert headlight > 150
    assert facing > grazing > behind
    assert behind == pytest.approx(ambient_only, abs=1.0), "a light from behind adds nothing"
    assert spot_away == pytest.approx(ambient_only, abs=1.0), "outside its cone a spot is dark"
    assert point > ambient_only + 50


def test_color_is_rendered_and_can_change():
    world = ambfplus.World()
    wall = world.add_body("wall", "plane", mass=0, color=(1.0, 0.0, 0.0), specular=0.0)
    world.add_light("sun", direction=(0, 0, -1))
    cam = world.add_camera("cam", 32, 24)
    cam.look_at((0, 0, 1), (0, 0, 0), up=(0, 1, 0))
    rgb = cam.capture().rgb
    assert rgb[..., 0].min() > 200 and rgb[..., 1:].max() < 5
    wall.color = (0.0, 0.0, 1.0)
    rgb = cam.capture().rgb
    assert rgb[..., 2].min() > 200 and rgb[..., :2].max() < 5
    assert np.allclose(wall.color, (0, 0, 1, 1))


def test_background_colour_fills_empty_pixels():
    world = ambfplus.World()
    cam = world.add_camera("cam", 16, 12, background=(0.2, 0.4, 0.6))
    frame = cam.capture()
    assert np.array_equal(frame.rgb[0, 0], [51, 102, 153])
    assert (frame.depth == 0).all()
