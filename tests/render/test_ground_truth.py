"""Ground truth in one call: depth and point clouds against analytic geometry, stereo disparity
against block matching of the rendered images, instance ids against the geometry each pixel's
ray hits, labels and voxels against a CPU ray cast, and the conversions a dataset needs."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.drilling import plunge_and_cut
from helpers.rays import pixel_rays

import ambfplus
from ambfplus.labels import legend, segmentation
from ambfplus.scenes import drilling_phantom, orbit_view
from ambfplus.stereo import (
    StereoRig,
    ambf_to_opencv,
    depth_to_disparity,
    disparity_agreement,
    disparity_to_depth,
    opencv_to_ambf,
)

FOCAL = 1135.0  # the paper's rig: 640x480, f about 1135 px, 65 mm baseline, about 250 mm away
FOV_Y = 2 * np.arctan(240 / FOCAL)


def test_tilted_plane_depth_and_point_cloud():
    world = ambfplus.World()
    rotation = ambfplus.rpy_matrix((0.35, -0.25, 0.4))
    centre = np.array([0.02, -0.01, 0.0])
    pose = ambfplus.make_pose(centre, rotation=rotation)
    world.add_body("plate", "box", size=(2.0, 2.0, 0.02), pose=pose, mass=0.0)
    camera = world.add_camera("cam", 640, 480, fov_y=0.6, near=0.05, far=5.0)
    camera.look_at((0.3, -0.2, 0.8), (0.0, 0.0, 0.0), up=(0, 0, 1))
    frame = camera.capture(passes=["depth", "instance"])
    assert frame.rgb is None and frame.label is None  # only what was asked for
    normal = rotation[:, 2]
    top = centre + 0.01 * normal
    hit = frame.instance == world.get("plate").id
    assert hit.all()
    # Analytic depth: the pixel's ray meets the plane n . (x - top) = 0.
    rays = pixel_rays(frame.intrinsics, 480, 640)  # camera frame, z = 1
    r_wc, eye = frame.pose[:3, :3], frame.pose[:3, 3]
    t = (normal @ (top - eye)) / (rays @ (r_wc.T @ normal))
    assert np.max(np.abs(frame.depth - t) / t) <= 1e-4
    # The organised cloud lies on the plane.
    points = frame.points.reshape(-1, 3).astype(np.float64) @ r_wc.T + eye
    rms = np.sqrt(np.mean(((points - top) @ normal) ** 2))
    assert rms <= 1e-4
    assert frame.points.shape == (480, 640, 3) and frame.points.dtype == np.float32


def textured_world(tilt: float, seed: int = 0) -> ambfplus.World:
    """A plane textured by 1 mm voxels of random colours, 250 mm in front of the rig."""
    rng = np.random.default_rng(seed)
    world = ambfplus.World()
    labels = rng.integers(1, 17, size=(300, 225, 4)).astype(np.uint8)
    table = [
        ambfplus.Label(i, f"t{i}", tuple(int(v) for v in rng.integers(20, 235, 3)))
        for i in range(1, 17)
    ]
    data = ambfplus.VolumeData(labels, dimensions=(0.3, 0.225, 0.01), label_table=table)
    world.add_volume("plane", data, pose=ambfplus.make_pose((0, 0, 0), rpy=(0, tilt, 0)))
    return world


@pytest.mark.parametrize("working_distance", [None, 0.25], ids=["parallel", "off-axis"])
def test_stereo_disparity_from_depth_matches_the_images(working_distance):
    world = textured_world(tilt=0.3)
    rig = StereoRig(
        world, "rig", baseline=0.065, fov_y=FOV_Y, near=0.01, far=2.0,
        working_distance=working_distance,
    )  # fmt: skip
    rig.look_at((-0.0325, 0, 0.25), (-0.0325, 0, 0), up=(0, 1, 0))
    frames = rig.capture()
    left, right = frames.left, frames.right
    assert left.time == right.time and left.step == right.step
    assert frames.baseline == pytest.approx(0.065, rel=1e-9)
    focal = frames.focal
    if working_distance is None:
        assert frames.dcx == 0
    else:
        assert frames.dcx == pytest.approx(focal * 0.065 / 0.25)
        assert right.intrinsics[0, 2] - left.intrinsics[0, 2] == pytest.approx(frames.dcx)
    # Block matching on the non-occluded pixels (the match inside the right image).
    agreement = disparity_agreement(frames, step=12)
    assert agreement["points"] > 500
    assert agreement["median_error"] <= 0.25
    assert agreement["p95_error"] <= 1.0
    # The baseline recovered from the images: B = (d + dcx) Z / f.
    baseline = agreement["baseline"]
    assert baseline == pytest.approx(0.065, rel=0.01)


def test_instance_ids_name_the_geometry_each_ray_hits():
    world = ambfplus.World()
    # Ids past 65,535 do not wrap: cameras are cheap objects that take ids.
    for i in range(65_540):
        world.add_camera(f"filler{i}", 8, 8)
    boxes = {
        "near": ((0.0, 0.0, 0.05), (0.04, 0.05, 0.03)),
        "far": ((0.05, 0.03, -0.02), (0.06, 0.04, 0.05)),
    }
    for name, (position, size) in boxes.items():
        pose = ambfplus.make_pose(position, rpy=(0.3, 0.2, 0.5))
        world.add_body(name, "box", size=size, pose=pose, mass=0.0)
    volume = world.add_volume("ear", ambfplus.phantom(48), pose=ambfplus.make_pose((-0.06, 0, 0)))
    assert min(world.get(n).id for n in boxes) > 65_536
    camera = world.add_camera("cam", 320, 240, fov_y=0.8, near=0.01, far=2.0)
    camera.look_at((0.05, -0.25, 0.15), (0.0, 0.0, 0.0))
    frame = camera.capture(passes=["depth", "instance", "label", "voxel"])
    ids = frame.instance
    assert ids.dtype == np.int32
    rays = pixel_rays(frame.intrinsics, 240, 320)
    points = (rays * frame.depth[..., None]) @ frame.pose[:3, :3].T + frame.pose[:3, 3]
    for name, (_, size) in boxes.items():
        body = world.get(name)
        mask = ids == body.id
        assert mask.sum() > 200, name
        local = (points[mask] - body.pose[:3, 3]) @ body.pose[:3, :3]
        # On the box's surface: its largest normalised coordinate is 1.
        outside = np.max(np.abs(local) - np.asarray(size) / 2, axis=1)
        assert np.max(np.abs(outside)) < 1e-4, name
    on_volume = ids == volume.id
    assert on_volume.sum() > 200
    assert np.all(frame.label[on_volume] > 0) and np.all(frame.voxel[on_volume] >= 0)
    nothing = ids == 0
    assert nothing.sum() > 1000
    assert np.all(frame.depth[nothing] == 0) and np.all(frame.voxel[nothing] == -1)
    # Stable across frames.
    world.step(5)
    assert np.array_equal(camera.capture(passes=["instance"]).instance, ids)


def test_label_and_voxel_equal_a_cpu_ray_cast():
    world = ambfplus.World()
    volume = world.add_volume("ear", ambfplus.phantom(96, seed=3))
    camera = world.add_camera("cam", 256, 192, fov_y=0.7, near=0.01, far=1.0)
    camera.look_at((0.06, -0.09, 0.05), (0.0, 0.0, 0.0))
    frame = camera.capture(passes=["depth", "label", "voxel"])
    rng = np.random.default_rng(1)
    rows, cols = rng.integers(0, 192, 1500), rng.integers(0, 256, 1500)
    rays = pixel_rays(frame.intrinsics, 192, 256)[rows, cols] @ frame.pose[:3, :3].T
    same_label = same_voxel = 0
    for k in range(len(rows)):
        hit = volume.raycast(frame.pose[:3, 3], rays[k])
        label = hit["label"] if hit else 0
        voxel = hit["voxel"] if hit else -1
        same_label += frame.label[rows[k], cols[k]] == label
        same_voxel += frame.voxel[rows[k], cols[k]] == voxel
    assert same_label / len(rows) >= 0.995
    assert same_voxel / len(rows) >= 0.995
    # The voxel index names a voxel of that label.
    hits = frame.voxel >= 0
    flat = np.asarray(volume.labels).reshape(-1, order="F")
    assert np.array_equal(flat[frame.voxel[hits]], frame.label[hits])


def test_every_pass_agrees_while_the_phantom_is_drilled():
    # The demo's scene and size: a plunge and a sideways cut while the rig circles. Where the
    # smoothed surface bridges a concave corner, no voxel at the hit is solid; such pixels
    # must still name the solid voxel that made the surface, never the volume with no label.
    scene = drilling_phantom(resolution=128, width=640, height=480)
    volume, drill = scene.drill.volume, scene.drill
    device = plunge_and_cut(scene)
    scene.world.add_input_device(scene.device_name, device, drill, **scene.device_options)
    passes = ["depth", "instance", "label", "voxel"]
    removed = 0
    for _ in range(7):
        scene.world.step(200)
        removed += len(drill.take_removed()["step"])
        scene.rig.aim(*orbit_view(scene.world.time))
        pair = scene.rig.capture(passes)
        labels = np.asarray(volume.labels).reshape(-1, order="F")
        for frame in (pair.left, pair.right):
            on_volume = frame.instance == volume.id
            assert on_volume.mean() > 0.05 and np.all(frame.depth[on_volume] > 0)
            where = f"{frame.camera} at step {frame.step}"
            assert np.count_nonzero(on_volume != (frame.label > 0)) == 0, where
            assert np.count_nonzero(on_volume != (frame.voxel >= 0)) == 0, where
            # Each pixel's voxel is solid now (not removed) and holds the pixel's label.
            assert np.array_equal(labels[frame.voxel[on_volume]], frame.label[on_volume]), where
    assert removed > 100


def test_the_cpu_ray_cast_names_a_solid_voxel_wherever_it_hits():
    # VolumeData.raycast, the shader's algorithm on the CPU, at every volume pixel of the
    # demo's first view: where the smoothed surface rounds a concave corner over eight empty
    # voxels it falls back to the nearest solid voxel, as the shader does (10 hits of this view
    # had label 0 and voxel -1 before).
    scene = drilling_phantom(resolution=128, width=640, height=480)
    volume = scene.drill.volume
    scene.rig.aim(*orbit_view(0.0))
    frame = scene.rig.capture(["instance", "label", "voxel"]).left
    pixels = np.argwhere(frame.instance == volume.id)
    rays = pixel_rays(frame.intrinsics, 480, 640) @ frame.pose[:3, :3].T
    labels = np.asarray(volume.labels).reshape(-1, order="F")
    unlabelled = []
    for r, c in pixels:
        hit = volume.raycast(frame.pose[:3, 3], rays[r, c])
        if hit and (hit["label"] == 0 or hit["voxel"] < 0 or labels[hit["voxel"]] != hit["label"]):
            unlabelled.append((r, c))
    assert len(pixels) > 10000 and unlabelled == []


def test_segmentation_colours_and_legend():
    world = ambfplus.World()
    world.add_body("cube", "box", size=(0.05, 0.05, 0.05), mass=0.0, color=(1.0, 0.0, 0.5))
    world.add_volume("ear", ambfplus.phantom(32), pose=ambfplus.make_pose((0.0, 0.08, 0.0)))
    camera = world.add_camera("cam", 160, 120, fov_y=1.0, near=0.01, far=2.0)
    camera.look_at((0.0, -0.25, 0.1), (0.0, 0.04, 0.0))
    frame = camera.capture(passes=["rgb", "instance", "label"], poses=["cube"])
    assert frame.poses["cube"] == pytest.approx(world.get("cube").pose)
    entries = legend(world)
    cube = world.get("cube")
    assert entries[cube.id]["name"] == "cube" and entries[cube.id]["color"] == (255, 0, 128)
    image = segmentation(frame, world)
    assert np.all(image[frame.instance == cube.id] == (255, 0, 128))
    ear = world.get("ear")
    on_ear = frame.instance == ear.id
    assert on_ear.any()
    colours = {label.id: tuple(label.color) for label in ear.data.label_table}
    for r, c in zip(*np.nonzero(on_ear)):
        assert tuple(image[r, c]) == colours[frame.label[r, c]]
    assert np.all(image[frame.instance == 0] == 0)


def test_conversions():
    depth = np.array([[0.25, 0.5], [0.0, 1.0]])
    d = depth_to_disparity(depth, FOCAL, 0.065, dcx=295.1)
    assert np.isnan(d[1, 0])
    back = disparity_to_depth(d, FOCAL, 0.065, dcx=295.1)
    assert back[~np.isnan(back)] == pytest.approx(depth[depth > 0])
    points = np.random.default_rng(0).normal(size=(10, 3))
    ambf = opencv_to_ambf(points)
    assert ambf[:, 0] == pytest.approx(-points[:, 2])  # x = -depth
    assert ambf[:, 1] == pytest.approx(points[:, 0])  # y right
    assert ambf[:, 2] == pytest.approx(-points[:, 1])  # z up
    assert ambf_to_opencv(ambf) == pytest.approx(points)


def test_pass_selection_and_bad_names():
    world = ambfplus.World()
    world.add_body("cube", "box", size=(0.1, 0.1, 0.1), mass=0.0)
    camera = world.add_camera("cam", 64, 48)
    camera.look_at((0.5, 0.0, 0.0), (0.0, 0.0, 0.0))
    assert camera.passes == ["rgb", "depth", "label"]
    camera.passes = ["instance"]
    frame = camera.capture()
    assert frame.rgb is None and frame.depth is None and frame.instance is not None
    refilled = camera.capture(out=frame)
    assert refilled is frame and frame.rgb is None
    with pytest.raises(ValueError, match="unknown pass 'colour'"):
        camera.capture(passes=["colour"])
    with pytest.raises(ValueError, match="passes goes with a new frame"):
        camera.capture(out=frame, passes=["rgb"])
    out = {"instance": np.zeros((48, 64), np.int32), "voxel": np.zeros((48, 64), np.int32)}
    frame = camera.capture(out=out)
    assert np.all(out["voxel"] == -1) and np.all(out["instance"][24, 32] == world.get("cube").id)


@pytest.mark.slow
def test_fixture_stereo_pair_renders_the_ear_with_its_baseline(fixtures):
    # The original's stereoL/stereoR (children of main_camera, 25 mm apart) looking at the ear.
    launch = fixtures / "volumetric_drilling" / "launch.yaml"
    sim = ambfplus.Simulator.from_launch(launch, models=[0, 2, 5])
    rig = StereoRig.from_cameras(sim.get("stereoL"), sim.get("stereoR"))
    assert rig.baseline == pytest.approx(0.025)
    frames = rig.capture()
    agreement = disparity_agreement(frames, step=8)
    assert agreement["points"] > 500
    # Bone is smooth in places (wrong matches there); most matches agree with depth.
    assert agreement["median_error"] <= 1.0
    baseline = agreement["baseline"]
    assert baseline == pytest.approx(0.025, rel=0.01)


def test_adf_stereo_camera_makes_two_converging_eyes(fixtures):
    # single_stereo_camera.yaml: stereoLR with stereo {eye separation: 0.005, focal length: 0.5}.
    launch = fixtures / "volumetric_drilling" / "launch.yaml"
    sim = ambfplus.Simulator.from_launch(launch, models=[6])
    centre, left, right = (sim.get(n) for n in ("stereoLR", "stereoLR_left", "stereoLR_right"))
    rig = StereoRig.from_cameras(left, right)
    assert rig.baseline == pytest.approx(0.005)
    mid = (left.pose[:3, 3] + right.pose[:3, 3]) / 2
    assert mid == pytest.approx(centre.pose[:3, 3])
    f = centre.intrinsics[0, 0]
    assert rig.dcx == pytest.approx(f * 0.005 / 0.5)  # zero disparity at the focal length
    assert centre.publish["image"] is False  # commented out in that file
    main = sim.get("main_camera").publish  # the world file's: an interval, no image flag
    assert (
        main["image_interval"] == 5 and main["depth_interval"] == 10 and main["depth_noise"] is None
    )
