"""Volumes: the data model, edits, and the ray-cast rendering that composites with meshes."""

from __future__ import annotations

import gc

import numpy as np
import pytest

import ambfplus


def sphere_volume(n=64, radius_vox=20.0, voxel=0.001):
    c = np.arange(n) + 0.5 - n / 2
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    labels = ((x**2 + y**2 + z**2) <= radius_vox**2).astype(np.uint8)
    return ambfplus.VolumeData(
        labels, voxel_size=(voxel,) * 3, label_table=[ambfplus.Label(1, "Bone", (230, 220, 200))]
    )


def test_labels_view_memory_contract():
    data = sphere_volume(16, 5)
    view = data.labels
    assert view.shape == (16, 16, 16) and view.dtype == np.uint8
    assert view.strides == (1, 16, 256), "i fastest in memory"
    assert not view.flags.owndata and view.flags.writeable
    view[0, 0, 0] = 1
    assert data.labels[0, 0, 0] == 1
    del data
    gc.collect()
    assert view[8, 8, 8] == 1 and view.sum() > 100


def test_phantom_is_deterministic_and_labelled():
    a, b = ambfplus.phantom(64, seed=7), ambfplus.phantom(64, seed=7)
    assert np.array_equal(np.asarray(a.labels), np.asarray(b.labels))
    c = ambfplus.phantom(64, seed=8)
    assert not np.array_equal(np.asarray(a.labels), np.asarray(c.labels))
    names = {label.name for label in a.label_table}
    # The original system's labels (its labels.csv), so tasks and scripts run on both.
    assert names == {
        "Bone", "Malleus", "Incus", "Stapes", "Bony_Labyrinth", "IAC", "Superior_Vestibular_Nerve",
        "Inferior_Vestibular_Nerve", "Cochlear_Nerve", "Facial_Nerve", "Chorda_Tympani", "ICA",
        "Sinus_+_Dura", "Vestibular_Aqueduct", "TMJ", "EAC",
    }  # fmt: skip
    counts = ambfplus.phantom(128).label_counts()
    assert (counts[1:] > 0).all(), "every structure is present at 128^3"
    assert np.allclose(a.dimensions, 0.048)
    # Critical structures are flagged for warnings.
    assert a.label("Facial_Nerve").critical and not a.label("Bone").critical


def test_remove_sphere_clears_exactly_the_voxels_inside():
    data = sphere_volume(32, 14)
    before = np.asarray(data.labels).copy()
    centre = np.array([0.003, -0.002, 0.001])
    removed = data.remove_sphere(centre, 0.004)
    c = (np.arange(32) + 0.5 - 16) * 0.001
    x, y, z = np.meshgrid(c, c, c, indexing="ij")
    inside = (x - centre[0]) ** 2 + (y - centre[1]) ** 2 + (z - centre[2]) ** 2 <= 0.004**2
    assert removed == int((before.astype(bool) & inside).sum()) > 0
    assert not np.asarray(data.labels)[inside].any()
    assert np.array_equal(np.asarray(data.labels)[~inside], before[~inside])
    (edit,) = data.edit_log
    assert edit["kind"] == "remove_sphere" and edit["changed"] == removed
    assert len(edit["voxels"]) == removed and (edit["old_labels"] == 1).all()
    i, j, k = edit["voxels"].T
    assert (before[i, j, k] == 1).all()


def test_only_removable_labels_are_drilled():
    labels = np.ones((10, 10, 10), np.uint8)
    labels[5:, :, :] = 2
    data = ambfplus.VolumeData(
        labels,
        voxel_size=(0.001,) * 3,
        label_table=[
            ambfplus.Label(1, "Bone"),
            ambfplus.Label(2, "Nerve", removable=False, critical=True),
        ],
    )
    data.remove_sphere((0, 0, 0), 0.01)
    assert (np.asarray(data.labels)[5:] == 2).all() and not np.asarray(data.labels)[:5].any()
    data.remove_sphere((0, 0, 0), 0.01, only_removable=False)
    assert not np.asarray(data.labels).any()


def test_reset_restores_bit_for_bit_and_commit_moves_the_baseline():
    data = ambfplus.phantom(48)
    original = np.asarray(data.labels).copy()
    data.remove_sphere((0, 0, 0.012), 0.006)
    data.set_region((0, 0, 0), (5, 5, 5), 3)
    data.labels[40:44, 2:4, 10] = 9
    data.mark_dirty((40, 2, 10), (44, 4, 11))
    assert not np.array_equal(np.asarray(data.labels), original)
    data.reset()
    assert np.array_equal(np.asarray(data.labels), original)
    assert [e["kind"] for e in data.edit_log] == [
        "remove_sphere",
        "set_region",
        "mark_dirty",
        "reset",
    ]
    data.set_region((0, 0, 0), (2, 2, 2), 0)
    data.commit()
    data.reset()
    assert not np.asarray(data.labels)[:2, :2, :2].any()


def render_world(data, pose=None, size=(160, 120)):
    world = ambfplus.World()
    volume = world.add_volume("v", data, pose=np.eye(4) if pose is None else pose)
    camera = world.add_camera("cam", size[0], size[1], 0.9, 0.001, 1.0)
    camera.look_at((0.05, -0.07, 0.06), (0.0, 0.0, 0.0))
    return world, volume, camera


def test_sphere_surface_depth_matches_the_analytic_sphere():
    data = sphere_volume(64, 20.0)
    _, _, camera = render_world(data)
    frame = camera.capture()
    k, pose = frame.intrinsics, frame.pose
    rows, cols = np.nonzero(frame.depth > 0)
    assert rows.size > 1000
    sample = np.random.default_rng(1).choice(rows.size, 300, replace=False)
    # Ray-sphere intersection in the camera frame for each sampled pixel.
    centre = (np.linalg.inv(pose) @ np.array([0, 0, 0, 1.0]))[:3]
    radius = 0.020
    worst = 0.0
    for r, c in zip(rows[sample], cols[sample]):
        d = np.array([(c + 0.5 - k[0, 2]) / k[0, 0], (r + 0.5 - k[1, 2]) / k[1, 1], 1.0])
        a, b = d @ d, -2 * d @ centre
        disc = b * b - 4 * a * (centre @ centre - radius**2)
        if disc < 0:
            continue  # a silhouette pixel whose ray misses the true sphere
        t = (-b - np.sqrt(disc)) / (2 * a)
        worst = max(worst, abs(t - frame.depth[r, c]) * np.linalg.norm(d))
    assert worst < 0.001, f"surface {worst * 1000:.3f} mm from the sphere (one voxel is 1 mm)"


def test_labels_seen_agree_with_a_cpu_ray_cast():
    data = ambfplus.phantom(96, seed=3)
    pose = ambfplus.make_pose((0.01, 0.02, -0.01), rpy=(0.2, -0.1, 0.4))
    _, volume, camera = render_world(data, pose)
    frame = camera.capture()
    k, cam = frame.intrinsics, frame.pose
    rng = np.random.default_rng(0)
    hit_r, hit_c = np.nonzero(frame.depth > 0)
    pick = rng.choice(hit_r.size, 300, replace=False)
    # Pixels on the volume, and anywhere (to check misses too).
    rows = np.concatenate([hit_r[pick], rng.integers(0, frame.height, 100)])
    cols = np.concatenate([hit_c[pick], rng.integers(0, frame.width, 100)])
    agree = both = hit_mismatch = 0
    for r, c in zip(rows, cols):
        d = cam[:3, :3] @ np.array(
            [(c + 0.5 - k[0, 2]) / k[0, 0], (r + 0.5 - k[1, 2]) / k[1, 1], 1]
        )
        hit = volume.raycast(cam[:3, 3], d)
        if (hit is None) != (frame.depth[r, c] == 0):
            hit_mismatch += 1
            continue
        if hit is None:
            continue
        both += 1
        agree += hit["label"] == frame.label[r, c]
        z = (np.linalg.inv(cam) @ np.append(hit["position"], 1))[2]
        assert abs(z - frame.depth[r, c]) < 1e-5
    assert both > 100
    assert hit_mismatch <= 2 and agree >= both - 2


def test_empty_space_skipping_changes_nothing_but_the_cost():
    data = ambfplus.phantom(96, seed=4)
    _, volume, camera = render_world(data, size=(200, 150))
    fast = camera.capture()
    volume.empty_space_skipping = False
    naive = camera.capture()
    assert np.array_equal(fast.depth, naive.depth)
    assert np.array_equal(fast.label, naive.label)
    assert np.array_equal(fast.rgb, naive.rgb)


def test_dirty_box_upload_equals_a_full_upload():
    data = ambfplus.phantom(96)
    world, volume, camera = render_world(data)
    camera.capture()
    removed = volume.remove_sphere((0.0, 0.0, 0.012), 0.005)
    assert removed > 100
    edited = camera.capture()
    upload = volume.last_upload
    assert not upload["full"] and 0 < upload["voxels"] < 0.02 * 96**3
    # A second world sharing the data uploads it whole.
    _, fresh_volume, fresh_camera = render_world(data)
    full = fresh_camera.capture()
    assert fresh_volume.last_upload["full"]
    for name in ("rgb", "depth", "label"):
        assert np.array_equal(getattr(edited, name), getattr(full, name)), name


def test_many_scattered_edits_upload_as_a_full_upload_would():
    # Sixty small removals between two captures, near each other and far apart (more edits than
    # a capture copies boxes, so the renderer merges them): the result is the full upload's.
    data = ambfplus.phantom(96)
    world, volume, camera = render_world(data)
    camera.capture()
    rng = np.random.default_rng(7)
    near = rng.uniform(-0.003, 0.003, (50, 3)) + (0.0, 0.0, 0.012)
    far = rng.uniform(-0.02, 0.02, (10, 3))
    removed = sum(volume.remove_sphere(tuple(c), 0.0008) for c in np.vstack([near, far]))
    assert removed > 100
    edited = camera.capture()
    assert not volume.last_upload["full"]
    _, fresh_volume, fresh_camera = render_world(data)
    full = fresh_camera.capture()
    assert fresh_volume.last_upload["full"]
    for name in ("rgb", "depth", "label"):
        assert np.array_equal(getattr(edited, name), getattr(full, name)), name


def test_more_edits_than_the_history_keeps_upload_little_and_render_as_a_full_upload():
    # Over 4500 small removals between two captures, more than a volume lists: the renderer copies
    # the union of the edits no longer listed, not the grid, and draws what a full upload draws.
    data = ambfplus.phantom(96)
    world, volume, camera = render_world(data)
    camera.capture()
    rng = np.random.default_rng(11)
    start, removed = data.revision, 0
    for centre in rng.uniform(-0.006, 0.006, (60000, 3)) + (0.0, 0.0, 0.012):
        removed += volume.remove_sphere(tuple(centre), 0.0003)
        if data.revision - start > 4500:
            break
    assert removed > 100 and data.revision - start > 4500, data.revision - start
    edited = camera.capture()
    upload = volume.last_upload
    assert not upload["full"] and 0 < upload["voxels"] < 0.1 * 96**3, upload
    _, fresh_volume, fresh_camera = render_world(data)
    full = fresh_camera.capture()
    assert fresh_volume.last_upload["full"]
    for name in ("rgb", "depth", "label"):
        assert np.array_equal(getattr(edited, name), getattr(full, name)), name


def test_edit_through_numpy_changes_the_next_render_and_reset_restores_it():
    data = ambfplus.phantom(64)
    _, volume, camera = render_world(data)
    before = camera.capture()
    centre = np.argwhere(before.label > 0)[len(np.argwhere(before.label > 0)) // 2]
    labels = volume.labels
    labels[:, :, 40:] = 0  # shave the lateral part off through the view
    volume.mark_dirty((0, 0, 40), (64, 64, 64))
    after = camera.capture()
    assert not np.array_equal(after.depth, before.depth)
    assert after.depth[tuple(centre)] != before.depth[tuple(centre)]
    volume.reset()
    restored = camera.capture()
    assert np.array_equal(restored.rgb, before.rgb)
    assert np.array_equal(restored.depth, before.depth)


def test_volume_and_meshes_occlude_each_other_by_depth():
    data = sphere_volume(48, 16)
    world, volume, camera = render_world(data)
    camera.look_at((0.0, 0.0, 0.08), (0.0, 0.0, 0.0), up=(0, 1, 0))
    alone = camera.capture()
    # A box in front of the sphere hides it where it covers; a box behind it does not show.
    world.add_body("front", "box", size=(0.01, 0.01, 0.002), pose=ambfplus.make_pose((0, 0, 0.03)))
    world.add_body("back", "box", size=(0.3, 0.3, 0.002), pose=ambfplus.make_pose((0, 0, -0.03)))
    both = camera.capture()
    r, c = both.height // 2, both.width // 2
    assert both.depth[r, c] == pytest.approx(0.08 - 0.031, abs=1e-5) and both.label[r, c] == 0
    assert alone.label[r, c] == 1
    # Around the small box the sphere is still seen, in front of the big box behind it.
    ring = (alone.label == 1) & (both.label == 1)
    assert ring.sum() > 0.5 * (alone.label == 1).sum()
    assert np.array_equal(both.depth[ring], alone.depth[ring])
    corner = both.depth[5, 5]
    assert corner == pytest.approx(0.08 + 0.029, abs=1e-5), "the back box fills the rest"


def test_world_voxel_transforms_round_trip():
    data = ambfplus.phantom(32)
    pose = ambfplus.make_pose((0.1, 0.2, 0.3), rpy=(0.5, 0.1, -0.3))
    world = ambfplus.World()
    volume = world.add_volume("v", data, pose=pose)
    ijk = np.array([3.0, 17.0, 30.0])
    p = volume.voxel_to_world(ijk)
    assert np.allclose(volume.world_to_voxel(p), ijk)
    assert np.allclose(volume.world_from_voxel @ np.append(ijk, 1), np.append(p, 1))
    assert np.allclose(data.voxel_center(3, 17, 30), np.linalg.inv(pose)[:3] @ np.append(p, 1))


def test_surface_mesh_export_matches_the_volume(tmp_path):
    data = sphere_volume(40, 12)
    path = tmp_path / "sphere.stl"
    triangles = data.save_mesh(path)
    assert triangles > 500
    world = ambfplus.World()
    world.add_body("mesh", mesh=str(path))
    camera = world.add_camera("cam", 120, 120, 0.9, 0.001, 1.0)
    camera.look_at((0.0, 0.0, 0.05), (0.0, 0.0, 0.0), up=(0, 1, 0))
    mesh_depth = camera.capture().depth
    _, _, vcam = render_world(data, size=(120, 120))
    vcam.look_at((0.0, 0.0, 0.05), (0.0, 0.0, 0.0), up=(0, 1, 0))
    volume_depth = vcam.capture().depth
    both = (mesh_depth > 0) & (volume_depth > 0)
    assert both.sum() > 0.95 * (volume_depth > 0).sum()
    # Away from the silhouette (where depth changes steeply with position) the surfaces agree
    # within half a voxel.
    inner = both.copy()
    for axis in (0, 1):
        for shift in (-2, 2):
            inner &= np.roll(both, shift, axis=axis)
    assert inner.sum() > 0.7 * both.sum()
    assert np.abs(mesh_depth[inner] - volume_depth[inner]).max() < 0.0005
    ply = tmp_path / "sphere.ply"
    assert data.save_mesh(ply) == triangles


def test_bad_volume_arguments():
    with pytest.raises(ValueError, match="dimensions"):
        ambfplus.VolumeData(np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(TypeError, match="uint8 or uint16"):
        ambfplus.VolumeData(np.zeros((4, 4, 4), np.float32), voxel_size=(1, 1, 1))
    with pytest.raises(ValueError, match="iso"):
        ambfplus.World().add_volume("v", sphere_volume(8, 2), iso=1.5)
    with pytest.raises(ValueError, match="does not fit a uint8"):
        ambfplus.VolumeData(
            np.zeros((4, 4, 4), np.uint8),
            voxel_size=(1, 1, 1),
            label_table=[ambfplus.Label(300, "Big")],
        )
