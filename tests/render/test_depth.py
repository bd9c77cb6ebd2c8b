"""Depth is metric, linear and exact; intrinsics and pose agree with what is rendered."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.rays import backproject, pixel_rays

import ambfplus


def frontal_plane_world(distance: float, near: float, far: float):
    """A camera at the origin looking along +x at an infinite plane `distance` away."""
    world = ambfplus.World()
    # The plane's normal (+z of its frame) faces back at the camera.
    facing = ambfplus.make_pose((distance, 0.0, 0.0), rpy=(0.0, -np.pi / 2, 0.0))
    world.add_body("wall", "plane", pose=facing, mass=0)
    camera = world.add_camera("cam", 320, 240, 0.9, near, far)
    camera.look_at((0, 0, 0), (1, 0, 0), (0, 0, 1))
    return world, camera


@pytest.mark.parametrize(("distance", "near", "far"), [(0.3, 0.01, 10.0), (5.0, 0.001, 100.0)])
def test_frontal_plane_has_its_distance_at_every_pixel(distance, near, far):
    _, camera = frontal_plane_world(distance, near, far)
    depth = camera.capture().depth
    assert (depth > 0).all(), "an infinite plane across the view covers every pixel"
    error = np.abs(depth.astype(np.float64) - distance).max()
    assert error <= 1e-4 * distance, f"max depth error {error:.3g} m at d = {distance} m"


def test_tilted_plane_has_analytic_depth_per_pixel():
    world = ambfplus.World()
    # Plane through (0.8, 0, 0) with its normal tilted 35 deg from the optical axis.
    normal_pose = ambfplus.make_pose((0.8, 0.0, 0.0), rpy=(0.0, -np.pi / 2 + 0.6, 0.3))
    world.add_body("slope", "plane", pose=normal_pose, mass=0)
    camera = world.add_camera("cam", 256, 192, 0.8, 0.01, 50.0)
    camera.look_at((0, 0, 0), (1, 0, 0), (0, 0, 1))
    frame = camera.capture()

    # In the camera frame the plane is n . X = c; the ray through a pixel centre is t * r with
    # r_z = 1, so its depth is c / (n . r).
    cam_from_world = np.linalg.inv(frame.pose)
    plane_in_cam = cam_from_world @ normal_pose
    n = plane_in_cam[:3, 2]
    c = float(n @ plane_in_cam[:3, 3])
    rays = pixel_rays(frame.intrinsics, frame.height, frame.width)
    expected = c / (rays @ n)
    hit = (expected > camera.near) & (expected < camera.far)
    assert hit.mean() > 0.9
    covered = frame.depth > 0
    assert np.array_equal(covered, hit)
    rel = np.abs(frame.depth[hit] - expected[hit]) / expected[hit]
    assert rel.max() < 1e-4, f"max relative depth error {rel.max():.3g}"
    assert np.ptp(expected[hit]) > 0.3, "the test plane must really be tilted"


def test_disc_centroid_lands_on_the_projection_of_its_centre():
    world = ambfplus.World()
    camera = world.add_camera("cam", 640, 480, 0.7, 0.01, 10.0)
    camera.look_at((0.1, -0.2, 0.05), (0.1, 0.8, 0.05), (0, 0, 1))
    # A thin disc parallel to the image plane, off the optical axis at a non-integer pixel.
    centre_cam = np.array([0.0317, -0.0213, 0.5])
    pose_cam = ambfplus.make_pose(centre_cam)
    disc_pose = camera.pose @ pose_cam
    world.add_body("disc", "cylinder", radius=0.04, height=1e-4, pose=disc_pose, mass=0)
    frame = camera.capture()
    rows, cols = np.nonzero(frame.depth > 0)
    centroid = np.array([cols.mean() + 0.5, rows.mean() + 0.5])

    world_centre = disc_pose[:3, 3]
    cam_from_world = np.linalg.inv(camera.pose)
    p = cam_from_world[:3, :3] @ world_centre + cam_from_world[:3, 3]
    uv = camera.intrinsics @ (p / p[2])
    error = np.abs(centroid - uv[:2]).max()
    assert rows.size > 2000
    assert error < 0.05, f"centroid {centroid} vs projection {uv[:2]} ({error:.3f} px)"


def test_backprojected_depth_lies_on_the_sphere():
    world = ambfplus.World()
    centre = np.array([0.3, 0.1, 0.2])
    radius = 0.05
    world.add_body("ball", "sphere", radius=radius, pose=ambfplus.make_pose(centre), mass=0)
    camera = world.add_camera("cam", 320, 240, 0.6, 0.01, 10.0)
    camera.look_at((0.0, -0.2, 0.35), centre, (0, 0, 1))
    points = backproject(camera.capture())
    distance = np.linalg.norm(points - centre, axis=1)
    assert points.shape[0] > 1000
    # The tessellated sphere lies within 0.5 % inside the true one.
    assert np.abs(distance - radius).max() < 0.005 * radius


def test_row_zero_is_the_top_of_the_image():
    world = ambfplus.World()
    world.add_body("high", "box", size=(0.05, 0.05, 0.05), pose=ambfplus.make_pose((1, 0, 0.2)))
    camera = world.add_camera("cam", 160, 120, 0.7, 0.01, 10.0)
    camera.look_at((0, 0, 0), (1, 0, 0), (0, 0, 1))
    rows, cols = np.nonzero(camera.capture().depth > 0)
    assert rows.max() < 60, "a box above the optical axis must appear in the upper half"
    # y down and x right: a box to the camera's right (world -y when looking along +x).
    world.add_body("right", "box", size=(0.05, 0.05, 0.05), pose=ambfplus.make_pose((1, -0.2, 0)))
    depth = camera.capture().depth
    lower = depth[60:]
    assert (lower[:, 80:] > 0).any() and not (lower[:, :80] > 0).any()


def test_objects_beyond_far_or_before_near_are_not_seen():
    world = ambfplus.World()
    world.add_body("far", "box", size=(1, 1, 1), pose=ambfplus.make_pose((0, 0, -6)))
    camera = world.add_camera("cam", 64, 48, 0.7, 0.1, 5.0)
    camera.look_at((0, 0, 0), (0, 0, -1), (0, 1, 0))
    assert (camera.capture().depth == 0).all()
    world.add_body("near", "box", size=(1, 1, 1), pose=ambfplus.make_pose((0, 0, -2)))
    depth = camera.capture().depth
    assert np.isclose(depth[24, 32], 1.5, rtol=1e-5)
