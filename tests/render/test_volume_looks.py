"""Volume looks of the rgb pass (Camera.looks): ambient occlusion darkens a pit's floor and not
open ground, the bone texture is fixed to the volume (two views see the same factor at the same
point), and every ground-truth pass is bit-identical with the looks on or off."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import map_coordinates

import ambfplus
from ambfplus.stereo import StereoRig

W, H = 320, 240
VOXEL = 0.001  # metres
BONE = (150, 140, 130)


def slab(pit: bool) -> ambfplus.VolumeData:
    """48 x 48 x 24 voxels of 1 mm, solid below z = +8 mm (the volume is centred on the
    origin); with a pit 10 mm square and 12 mm deep (x, y in [-5, 5] mm, floor at z = -4 mm)."""
    labels = np.zeros((48, 48, 24), np.uint8)
    labels[:, :, :20] = 1
    if pit:
        labels[19:29, 19:29, 8:20] = 0
    table = [ambfplus.Label(1, "bone", BONE)]
    return ambfplus.VolumeData(labels, dimensions=(0.048, 0.048, 0.024), label_table=table)


def world_over(data: ambfplus.VolumeData) -> ambfplus.World:
    """The volume without specular light under a dim light straight down: the rgb is its albedo
    times one factor everywhere the surface faces up, so ratios of images are albedo ratios."""
    world = ambfplus.World()
    world.add_volume("bone", data, specular=0.0)
    world.add_light("sun", direction=(0.0, 0.0, -1.0), intensity=0.6)
    return world


def world_points(frame) -> np.ndarray:
    """World points of every pixel centre, from depth and the intrinsics (H x W x 3)."""
    k = frame.intrinsics
    rows, cols = np.mgrid[0 : frame.height, 0 : frame.width]
    z = frame.depth.astype(np.float64)
    cam = np.stack([(cols + 0.5 - k[0, 2]) / k[0, 0] * z, (rows + 0.5 - k[1, 2]) / k[1, 1] * z, z])
    pose = frame.pose
    return np.einsum("ij,jhw->hwi", pose[:3, :3], cam) + pose[:3, 3]


def capture_both(camera, passes=("rgb", "depth")):
    camera.looks = False
    plain = camera.capture(passes=list(passes))
    camera.looks = True
    looks = camera.capture(passes=list(passes))
    return plain, looks


def brightness(frame) -> np.ndarray:
    return frame.rgb.astype(np.float64).sum(-1)


def test_ambient_occlusion_darkens_a_pits_floor_and_leaves_open_ground():
    world = world_over(slab(pit=True))
    camera = world.add_camera("cam", W, H, fov_y=0.5, near=0.01, far=1.0)
    camera.look_at((0.0, 0.0, 0.13), (0.0, 0.0, 0.0), up=(0, 1, 0))
    plain, looks = capture_both(camera)
    p = world_points(plain)
    hit = plain.depth > 0
    floor = hit & (np.abs(p[..., 0]) < 0.002) & (np.abs(p[..., 1]) < 0.002)
    floor &= np.abs(p[..., 2] + 0.004) < 0.0005
    ground = hit & (p[..., 0] > 0.013) & (p[..., 0] < 0.019) & (np.abs(p[..., 1]) < 0.003)
    ground &= np.abs(p[..., 2] - 0.008) < 0.0005
    assert floor.sum() > 100 and ground.sum() > 200
    # Without the looks the floor, lit straight down, is as bright as the open ground.
    a, b = brightness(plain), brightness(looks)
    assert abs(a[floor].mean() / a[ground].mean() - 1) < 0.02
    floor_ratio = b[floor].mean() / a[floor].mean()
    ground_ratio = b[ground].mean() / a[ground].mean()
    assert abs(ground_ratio - 1) < 0.06, "open ground keeps its light (the texture averages out)"
    assert floor_ratio < 0.85 and floor_ratio < ground_ratio - 0.12, (floor_ratio, ground_ratio)


def test_drilling_updates_the_occlusion_as_a_fresh_volume_has_it():
    """The occlusion field is updated in boxes as voxels go: after a hole is drilled into open
    ground, the image is bit for bit that of a volume built with the hole, and the hole's floor
    has darkened while the ground around keeps its light."""
    hole = ((0.0, 0.0, 0.008), 0.005)  # a 5 mm sphere centred on the top surface

    def view(world):
        camera = world.add_camera("cam", W, H, fov_y=0.5, near=0.01, far=1.0, looks=True)
        camera.look_at((0.0, 0.0, 0.13), (0.0, 0.0, 0.0), up=(0, 1, 0))
        return camera

    drilled = world_over(slab(pit=False))
    camera = view(drilled)
    before = camera.capture(passes=["rgb", "depth"])
    assert drilled.volumes[0].remove_sphere(*hole) > 0
    after = camera.capture(passes=["rgb", "depth"])
    built = slab(pit=False)
    built.remove_sphere(*hole)
    fresh = view(world_over(built)).capture(passes=["rgb", "depth"])
    np.testing.assert_array_equal(after.rgb, fresh.rgb)
    np.testing.assert_array_equal(after.depth, fresh.depth)
    camera.looks = False
    plain = camera.capture(passes=["rgb", "depth"])
    p = world_points(after)
    floor = (np.hypot(p[..., 0], p[..., 1]) < 0.0015) & (p[..., 2] < 0.004)
    ground = (np.hypot(p[..., 0], p[..., 1]) > 0.011) & (np.abs(p[..., 2] - 0.008) < 0.0005)
    assert floor.sum() > 50 and ground.sum() > 1000
    ratio = brightness(after) / np.maximum(brightness(plain), 1)
    floor_ratio, ground_ratio = ratio[floor].mean(), ratio[ground].mean()
    assert floor_ratio < ground_ratio - 0.15, (floor_ratio, ground_ratio)
    assert abs(ground_ratio - 1) < 0.06
    # Before the hole, the same floor pixels showed flat ground at the top.
    assert np.abs(before.depth[floor] - after.depth[floor]).min() > 0.003


def test_bone_texture_varies_the_albedo_and_is_fixed_to_the_volume():
    world = world_over(slab(pit=False))
    cameras = [world.add_camera(f"cam{i}", W, H, fov_y=0.5, near=0.01, far=1.0) for i in (0, 1)]
    # Two views of the flat top (z = +8 mm) 30 mm apart, like a stereo pair's eyes.
    cameras[0].look_at((-0.015, 0.0, 0.12), (0.0, 0.0, 0.0), up=(0, 1, 0))
    cameras[1].look_at((0.015, 0.002, 0.12), (0.0, 0.0, 0.0), up=(0, 1, 0))
    (plain0, looks0), (plain1, looks1) = capture_both(cameras[0]), capture_both(cameras[1])
    p = world_points(plain0)
    top = (plain0.depth > 0) & (np.abs(p[..., 0]) < 0.012) & (np.abs(p[..., 1]) < 0.012)
    assert top.sum() > 5000
    # More spatial variance with the texture, within the stated +-13% of the albedo.
    a0, b0 = brightness(plain0), brightness(looks0)
    assert a0[top].std() < 1.0, "flat and evenly lit without the looks"
    factor0 = b0 / np.maximum(a0, 1)
    assert b0[top].std() > 5.0 + 4 * a0[top].std()
    assert 0.84 < factor0[top].min() and factor0[top].max() < 1.16
    # The second view sees the same factor at the same world points.
    factor1 = brightness(looks1) / np.maximum(brightness(plain1), 1)
    k, pose = plain1.intrinsics, plain1.pose
    cam = np.einsum("ji,hwj->hwi", pose[:3, :3], p - pose[:3, 3])  # R^T (p - t)
    cols = cam[..., 0] / cam[..., 2] * k[0, 0] + k[0, 2] - 0.5
    rows = cam[..., 1] / cam[..., 2] * k[1, 1] + k[1, 2] - 0.5
    inside = top & (cols > 2) & (cols < W - 3) & (rows > 2) & (rows < H - 3)
    assert inside.sum() > 5000
    seen = map_coordinates(factor1, [rows[inside], cols[inside]], order=1)
    here = factor0[inside]
    assert np.corrcoef(here, seen)[0, 1] > 0.9
    assert np.abs(here - seen).mean() < 0.015
    # A texture fixed to the image, or one sampled 3 mm off, would not match.
    off = map_coordinates(factor1, [rows[inside], cols[inside] + 0.003 * k[0, 0] / 0.112], order=1)
    assert abs(np.corrcoef(here, off)[0, 1]) < 0.5


def test_only_bone_takes_the_bone_texture():
    """Soft tissue keeps its even colour: of two halves of the flat top with the same colour, the
    one labelled Bone is mottled, the one labelled Facial_Nerve is not."""
    labels = np.zeros((48, 48, 24), np.uint8)
    labels[:24, :, :20] = 1
    labels[24:, :, :20] = 2
    table = [ambfplus.Label(1, "Bone", BONE), ambfplus.Label(2, "Facial_Nerve", BONE)]
    data = ambfplus.VolumeData(labels, dimensions=(0.048, 0.048, 0.024), label_table=table)
    camera = world_over(data).add_camera("cam", W, H, fov_y=0.5, near=0.01, far=1.0)
    camera.look_at((0.0, 0.0, 0.12), (0.0, 0.0, 0.0), up=(0, 1, 0))
    plain, looks = capture_both(camera, ("rgb", "depth", "label"))
    p = world_points(plain)
    top = (plain.depth > 0) & (np.abs(p[..., 1]) < 0.012) & (np.abs(p[..., 2] - 0.008) < 0.0005)
    bone = top & (p[..., 0] < -0.004) & (p[..., 0] > -0.016) & (plain.label == 1)
    nerve = top & (p[..., 0] > 0.004) & (p[..., 0] < 0.016) & (plain.label == 2)
    assert bone.sum() > 2000 and nerve.sum() > 2000
    factor = brightness(looks) / np.maximum(brightness(plain), 1)
    assert factor[bone].std() > 0.03, factor[bone].std()
    assert factor[nerve].std() < 0.01, factor[nerve].std()
    assert abs(np.median(factor[nerve]) - 1) < 0.06


def striped_ct(tmp_path) -> ambfplus.VolumeData:
    """CT of the slab, loaded from an NRRD file: bone in 4 mm stripes along x of 400 and
    1000 HU under air (-1000 HU), segmented at 300 HU."""
    ct = np.full((48, 48, 24), -1000, np.int16)
    ct[:, :, :20] = np.where((np.arange(48) // 4) % 2 == 1, 1000, 400)[:, None, None]
    path = tmp_path / "ct.nrrd"
    header = "NRRD0004\ntype: short\ndimension: 3\nsizes: 48 48 24\nspacings: 1 1 1\n"
    header += "encoding: raw\nendian: little\n\n"
    path.write_bytes(header.encode() + ct.tobytes(order="F"))
    return ambfplus.load_nrrd(path, kind="intensity", threshold=300)


def test_a_ct_intensity_grid_replaces_the_procedural_texture(tmp_path):
    data = striped_ct(tmp_path)
    assert data.intensity is not None and data.shape == (48, 48, 24)
    world = world_over(data)
    camera = world.add_camera("cam", W, H, fov_y=0.5, near=0.01, far=1.0)
    camera.look_at((0.0, 0.0, 0.13), (0.0, 0.0, 0.0), up=(0, 1, 0))
    plain, looks = capture_both(camera)
    p = world_points(plain)
    top = (plain.depth > 0) & (np.abs(p[..., 0]) < 0.016) & (np.abs(p[..., 1]) < 0.016)
    factor = brightness(looks) / np.maximum(brightness(plain), 1)
    # Where a stripe is, 1 mm clear of its edges (the intensity is filtered linearly).
    stripe, within = np.divmod((p[..., 0] + 0.024) * 1000, 4)
    clear = top & (within > 1) & (within < 3)
    dense, light = clear & (stripe % 2 == 1), clear & (stripe % 2 == 0)
    assert dense.sum() > 1000 and light.sum() > 1000
    # 1000 HU is the 98th percentile (factor 1.13), 400 HU the 2nd (0.87); nothing else varies.
    assert abs(np.median(factor[dense]) - 1.13) < 0.02 and factor[dense].std() < 0.02
    assert abs(np.median(factor[light]) - 0.87) < 0.02 and factor[light].std() < 0.02


def test_a_changed_intensity_grid_is_drawn_after_mark_intensity_changed(tmp_path):
    """The intensity grid is read again when it is declared changed: the stripes, inverted
    through the NumPy view after a first render, are drawn inverted; an undeclared write is not
    seen."""
    data = striped_ct(tmp_path)
    camera = world_over(data).add_camera("cam", W, H, fov_y=0.5, near=0.01, far=1.0, looks=True)
    camera.look_at((0.0, 0.0, 0.13), (0.0, 0.0, 0.0), up=(0, 1, 0))
    first = camera.capture(passes=["rgb", "depth"])
    p = world_points(first)
    stripe, within = np.divmod((p[..., 0] + 0.024) * 1000, 4)
    clear = (first.depth > 0) & (np.abs(p[..., 1]) < 0.016) & (within > 1) & (within < 3)
    clear &= np.abs(p[..., 0]) < 0.016
    dense, light = clear & (stripe % 2 == 1), clear & (stripe % 2 == 0)
    b = brightness(first)
    assert b[dense].mean() > 1.2 * b[light].mean()
    grid = data.intensity
    solid = grid[:, :, :20].copy()
    grid[:, :, :20] = np.where(solid == 1000, 400, 1000)  # the stripes swapped
    np.testing.assert_array_equal(brightness(camera.capture(passes=["rgb"])), b)  # not declared
    data.mark_intensity_changed()
    after = brightness(camera.capture(passes=["rgb"]))
    assert after[light].mean() > 1.2 * after[dense].mean()
    np.testing.assert_allclose(after[light].mean(), b[dense].mean(), rtol=0.02)


GROUND_TRUTH = ["depth", "label", "instance", "voxel", "segmentation", "points"]


def test_ground_truth_is_bit_identical_with_the_looks_on_or_off():
    world = ambfplus.World()
    volume = world.add_volume("bone", ambfplus.phantom(64))
    world.add_light("sun", direction=(0.3, 0.4, -1.0), shadow_quality=3)
    camera = world.add_camera("cam", W, H, fov_y=0.8, near=0.01, far=2.0, shadows=True)
    camera.look_at((0.03, -0.075, 0.075), (0, 0, 0.005))
    frames = {}
    for looks, k in ((False, 1), (True, 1), (True, 2)):
        camera.looks, camera.antialiasing = looks, k
        frames[looks, k] = camera.capture(passes=["rgb", *GROUND_TRUTH])
    base = frames[False, 1]
    assert (base.instance == volume.id).sum() > 5000 and len(np.unique(base.label)) > 2
    for key, frame in frames.items():
        for name in GROUND_TRUTH:
            a, b = getattr(frame, name), getattr(base, name)
            assert a.tobytes() == b.tobytes(), f"{name} differs with looks, k = {key}"
    assert (frames[True, 1].rgb != base.rgb).any(axis=-1).sum() > 2000, "the looks change rgb"


def test_looks_are_off_by_default_and_chosen_per_camera():
    world = ambfplus.World()
    camera = world.add_camera("cam", 32, 24)
    assert camera.looks is False, "the library's default"
    assert world.add_camera("wet", 32, 24, looks=True).looks is True
    rig = StereoRig(world, "rig", looks=True)
    assert rig.left.looks and rig.right.looks


ADF = """
cameras: [CAMERA main]
CAMERA main:
  name: main
  location: {x: 1, y: 0, z: 0}
  look at: {x: 0, y: 0, z: 0}
  looks: %s
"""


def test_the_adf_key_looks_chooses_a_cameras_looks(tmp_path):
    path = tmp_path / "world.yaml"
    path.write_text(ADF % "true")
    world = ambfplus.World()
    world.load_adf(path)
    assert world.get("main").looks is True
    path.write_text(ADF % "shiny")
    with pytest.raises(ambfplus.ConfigError, match=r"world.yaml.*looks"):
        ambfplus.World().load_adf(path)
