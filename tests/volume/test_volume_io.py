"""Anatomy volumes from every source land in the same place with the same labels."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest
from helpers.volume_files import nrrd_bytes, segment_keys, write_slices
from PIL import Image

import ambfplus
from ambfplus.cli import main as cli

EAR = "volumetric_drilling"


def read_labels_csv(path: Path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return [(r["name"], (int(r["r"]), int(r["g"]), int(r["b"]))) for r in rows]


def independent_counts(folder: Path, table) -> np.ndarray:
    """Per-label voxel counts by decoding the PNGs with Pillow: alpha >= 128 is solid and each
    colour goes to the nearest table colour."""
    colours = np.array([c for _, c in table], float)
    counts = np.zeros(len(table) + 1, np.int64)
    files = sorted(folder.glob("plane00*.png"), key=lambda p: int(p.stem[len("plane00") :]))
    for path in files:
        px = np.asarray(Image.open(path).convert("RGBA")).reshape(-1, 4)
        solid = px[px[:, 3] >= 128, :3].astype(float)
        counts[0] += (px[:, 3] < 128).sum()
        if len(solid):
            nearest = np.argmin(((solid[:, None, :] - colours[None]) ** 2).sum(-1), axis=1)
            counts[1:] += np.bincount(nearest, minlength=len(table))
    return counts


@pytest.mark.parametrize(
    ("name", "slices", "size"), [("ear3_171", 169, 171), ("ear3_256", 253, 256)]
)
@pytest.mark.slow
def test_fixture_ears_load_with_exact_label_counts(fixtures, name, slices, size):
    root = fixtures / EAR
    table = read_labels_csv(root / "labels.csv")
    folder = root / "resources" / "volumes" / name
    data = ambfplus.load_slice_stack(
        folder, "plane00", count=512, dimensions=(0.049, 0.049, 0.048), labels=root / "labels.csv"
    )
    assert data.shape == (size, size, slices)
    assert [label.name for label in data.label_table] == [n for n, _ in table]
    assert len(data.label_table) == 16
    counts = data.label_counts()
    expected = independent_counts(folder, table)
    counts = np.pad(counts, (0, len(expected) - len(counts)))
    assert np.array_equal(counts, expected)


def test_fixture_adf_loads_the_ear_where_the_adf_puts_it(fixtures):
    root = fixtures / EAR
    world = ambfplus.World()
    (volume,) = world.load_volumes(root / "ADF" / "volume_256.yaml", labels=root / "labels.csv")
    assert volume.name == "mastoidectomy_volume_low"
    assert volume.data.shape == (256, 256, 253)
    assert np.allclose(volume.data.dimensions, (0.0492027, 0.0492027, 0.048485))
    expected = ambfplus.make_pose((-0.3, 0.0, 0.0), rpy=(1.57079, 1.4, 0.0))
    assert np.allclose(volume.pose, expected, atol=1e-12)
    # The grid's centre is at the volume's position.
    centre = volume.voxel_to_world((127.5, 127.5, 126.0))
    assert np.allclose(centre, (-0.3, 0.0, 0.0), atol=1e-12)


def marker_volume(n=(12, 10, 8)):
    """Bone everywhere in the lower half of k, and a one-voxel marker at a corner, so every axis
    and its direction matter."""
    labels = np.zeros(n, np.uint8)
    labels[:, :, : n[2] // 2] = 1
    labels[n[0] - 2, 1, n[2] - 2] = 2
    return labels


TABLE = [("Bone", (240, 230, 200)), ("Marker", (250, 20, 30))]


def as_rgba(labels):
    colours = np.zeros((3, 4), np.uint8)
    for i, (_, rgb) in enumerate(TABLE, start=1):
        colours[i] = (*rgb, 255)
    return colours[labels]


def test_orientation_is_the_same_through_every_loader(tmp_path):
    labels = marker_volume()
    dims = np.array([0.012, 0.010, 0.008])  # 1 mm voxels
    marker = np.argwhere(labels == 2)[0]

    write_slices(tmp_path / "stack", as_rgba(labels))
    (tmp_path / "labels.csv").write_text(
        "name,r,g,b\n" + "".join(f"{n},{r},{g},{b}\n" for n, (r, g, b) in TABLE)
    )
    (tmp_path / "plain.nrrd").write_bytes(nrrd_bytes(labels, "uint8"))
    seg = np.stack([(labels == 1).astype(np.uint8), (labels == 2).astype(np.uint8)])
    (tmp_path / "layers.seg.nrrd").write_bytes(
        nrrd_bytes(
            seg,
            "uint8",
            kinds="list domain domain domain",
            extra=segment_keys([("Bone", TABLE[0][1], 1, 0), ("Marker", TABLE[1][1], 1, 1)]),
        )
    )
    (tmp_path / "volume.yaml").write_text(
        "volumes: [VOLUME m]\nVOLUME m:\n  name: m\n"
        "  location:\n"
        "    position: {x: 0.1, y: -0.2, z: 0.3}\n"
        "    orientation: {r: 0.3, p: -0.2, y: 1.0}\n"
        "  dimensions: {x: 0.012, y: 0.010, z: 0.008}\n"
        "  images: {path: stack/, prefix: plane00, format: png, count: 100}\n"
        "  labels: labels.csv\n"
    )

    loaded = {
        "stack": ambfplus.load_slice_stack(
            tmp_path / "stack", dimensions=dims, labels=tmp_path / "labels.csv"
        ),
        "nrrd": ambfplus.load_nrrd(tmp_path / "plain.nrrd"),
        "segmentation": ambfplus.load_nrrd(tmp_path / "layers.seg.nrrd"),
    }
    pose = ambfplus.make_pose((0.1, -0.2, 0.3), rpy=(0.3, -0.2, 1.0))
    world = ambfplus.World()
    (adf_volume,) = world.load_volumes(tmp_path / "volume.yaml")
    expected_world = pose[:3, :3] @ ((marker + 0.5) * 0.001 - dims / 2) + pose[:3, 3]
    for name, data in loaded.items():
        # A plain label map has no names: its marker is id 2.
        marker_id = 2 if name == "nrrd" else data.label("Marker").id
        assert np.argwhere(np.asarray(data.labels) == marker_id).tolist() == [marker.tolist()], name
        assert np.allclose(data.dimensions, dims), name
        volume = world.add_volume(name, data, pose=pose)
        assert np.allclose(volume.voxel_to_world(marker), expected_world, atol=1e-12), name
    adf_marker = np.argwhere(np.asarray(adf_volume.labels) == 2)[0]
    assert np.allclose(adf_volume.voxel_to_world(adf_marker), expected_world, atol=1e-12)


def test_marker_renders_on_the_expected_side():
    labels = np.zeros((16, 16, 16), np.uint8)
    labels[:, :, :4] = 1  # a floor of bone (low k = low z)
    labels[12:15, 12:15, 4:7] = 2  # a marker at high i (+x) and high j (+y)
    data = ambfplus.VolumeData(
        labels,
        voxel_size=(0.001,) * 3,
        label_table=[ambfplus.Label(1, "Bone"), ambfplus.Label(2, "Marker")],
    )
    world = ambfplus.World()
    world.add_volume("v", data)
    camera = world.add_camera("cam", 64, 64, 0.8, 0.001, 1.0)
    # Looking down -z with image up = +y: +x is to the right, +y is up (low rows).
    camera.look_at((0.0, 0.0, 0.05), (0.0, 0.0, 0.0), up=(0, 1, 0))
    rows, cols = np.nonzero(camera.capture().label == 2)
    assert rows.size > 0
    assert cols.min() > 32 and rows.max() < 32


def test_slice_stack_to_nrrd_and_back_is_lossless(tmp_path):
    data = ambfplus.phantom(48, seed=3)
    data.save_slice_stack(tmp_path / "stack")
    ambfplus.write_label_table(tmp_path / "labels.csv", data.label_table)
    stack = ambfplus.load_slice_stack(
        tmp_path / "stack", dimensions=data.dimensions, labels=tmp_path / "labels.csv"
    )
    assert np.array_equal(np.asarray(stack.labels), np.asarray(data.labels))
    stack.save_nrrd(tmp_path / "v.nrrd")
    back = ambfplus.load_nrrd(tmp_path / "v.nrrd")
    assert np.array_equal(np.asarray(back.labels), np.asarray(data.labels))
    assert back.label_table == data.label_table[:0] + [
        ambfplus.Label(label.id, label.name, label.color) for label in data.label_table
    ]
    assert np.allclose(back.dimensions, data.dimensions)
    raw = tmp_path / "raw.nrrd"
    stack.save_nrrd(raw, gzip=False)
    assert np.array_equal(np.asarray(ambfplus.load_nrrd(raw).labels), np.asarray(data.labels))


def test_slicer_segmentation_keeps_names_and_colours(tmp_path):
    labels = marker_volume()
    segments = [("Temporal bone", (230, 220, 190), 1, 0), ("Facial nerve", (255, 200, 0), 2, 0)]
    path = tmp_path / "ear.seg.nrrd"
    path.write_bytes(
        nrrd_bytes(
            labels,
            "uint8",
            spacing_mm=(0.5, 0.5, 0.5),
            origin_mm=(10.0, -20.0, 30.0),
            extra=segment_keys(segments),
        )
    )
    data = ambfplus.load_nrrd(path)
    assert [(label.id, label.name, label.color) for label in data.label_table] == [
        (1, "Temporal bone", (230, 220, 190)),
        (2, "Facial nerve", (255, 200, 0)),
    ]
    assert np.array_equal(np.asarray(data.labels), labels)
    assert np.allclose(data.voxel_size, 0.0005)
    # The first voxel's centre sits at the NRRD origin in patient space.
    first = data.patient_from_volume @ np.append(data.voxel_center(0, 0, 0), 1)
    assert np.allclose(first[:3], (0.010, -0.020, 0.030))


def test_nrrd_geometry_honours_directions_and_flips(tmp_path):
    labels = marker_volume()
    # A left-handed grid (k runs towards -z) with an origin.
    directions = np.diag([1.0, 1.0, -2.0])
    path = tmp_path / "flip.nrrd"
    path.write_bytes(nrrd_bytes(labels, "uint8", directions=directions, origin_mm=(5.0, 6.0, 7.0)))
    data = ambfplus.load_nrrd(path)
    assert np.allclose(data.dimensions, (0.012, 0.010, 0.016))
    p = data.patient_from_volume
    assert np.isclose(np.linalg.det(p[:3, :3]), 1.0)
    # Every voxel lands at origin + directions @ (i, j, k) whatever the grid was flipped to.
    marker_in_file = np.argwhere(labels == 2)[0]
    expected = (np.array([5.0, 6.0, 7.0]) + directions @ marker_in_file) / 1000
    ((i, j, k),) = np.argwhere(np.asarray(data.labels) == 2)
    got = p @ np.append(data.voxel_center(int(i), int(j), int(k)), 1)
    assert np.allclose(got[:3], expected)


def test_intensity_nrrd_needs_a_threshold(tmp_path):
    ct = np.full((8, 8, 8), -1000, np.int16)
    ct[2:6, 2:6, 2:6] = 1200
    path = tmp_path / "ct.nrrd"
    path.write_bytes(nrrd_bytes(ct, "short"))
    with pytest.raises(ambfplus.ConfigError, match="threshold"):
        ambfplus.load_nrrd(path)
    data = ambfplus.load_nrrd(path, threshold=300)
    assert data.label_counts()[1] == 64
    assert np.array_equal(np.asarray(data.intensity), ct)


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (
            b"NRRD0004\ntype: complex\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n" + bytes(8),
            "unsupported type 'complex'",
        ),
        (
            b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: raw\n\n" + bytes(10),
            "holds 10 bytes but the header needs 64",
        ),
        (
            b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 4 4 4\nencoding: gzip\n\nnot gzip",
            "gzip data is corrupt",
        ),
        (
            b"NRRD0004\ntype: uint8\nsizes: 4 4 4\n\n" + bytes(64),
            "missing required field 'dimension'",
        ),
        (b"P6\n4 4\n255\n", "not an NRRD file"),
        (b"NRRD0004\ntype: uint8\ndimension: 2\nsizes: 4 4\n\n" + bytes(16), "expected 3"),
    ],
)
def test_bad_nrrd_files_name_the_problem(tmp_path, content, message):
    path = tmp_path / "bad.nrrd"
    path.write_bytes(content)
    with pytest.raises(ambfplus.ConfigError, match=message) as info:
        ambfplus.load_nrrd(path)
    assert str(path) in str(info.value)


def test_missing_slice_is_named(tmp_path):
    write_slices(tmp_path, as_rgba(marker_volume()))
    (tmp_path / "plane003.png").unlink()
    with pytest.raises(ambfplus.ConfigError, match="slice 3 is missing but slice 4") as info:
        ambfplus.load_slice_stack(tmp_path, dimensions=(1, 1, 1))
    assert "plane003.png" in str(info.value)


def test_count_beyond_the_files_is_fine_and_a_smaller_count_stops_early(tmp_path):
    write_slices(tmp_path, as_rgba(marker_volume()))
    assert ambfplus.load_slice_stack(tmp_path, count=500, dimensions=(1, 1, 1)).shape[2] == 8
    assert ambfplus.load_slice_stack(tmp_path, count=3, dimensions=(1, 1, 1)).shape[2] == 4


def test_mixed_slice_sizes_and_corrupt_images_are_named(tmp_path):
    write_slices(tmp_path, as_rgba(marker_volume()))
    Image.fromarray(np.zeros((5, 5, 4), np.uint8), "RGBA").save(tmp_path / "plane002.png")
    with pytest.raises(ambfplus.ConfigError, match="5x5 but slice 0 is 12x10") as info:
        ambfplus.load_slice_stack(tmp_path, dimensions=(1, 1, 1))
    assert "plane002.png" in str(info.value)
    (tmp_path / "plane002.png").write_bytes(b"\x89PNG\r\n\x1a\nbroken")
    with pytest.raises(ambfplus.ConfigError, match="cannot decode") as info:
        ambfplus.load_slice_stack(tmp_path, dimensions=(1, 1, 1))
    assert "plane002.png" in str(info.value)


def test_missing_stack_and_missing_first_slice(tmp_path):
    with pytest.raises(ambfplus.AssetNotFound):
        ambfplus.load_slice_stack(tmp_path / "nowhere", dimensions=(1, 1, 1))
    with pytest.raises(ambfplus.AssetNotFound, match="plane000.png"):
        ambfplus.load_slice_stack(tmp_path, dimensions=(1, 1, 1))


def test_off_palette_colours_snap_to_the_nearest_label(tmp_path):
    rgba = as_rgba(marker_volume())
    rgba[0, 0, 0, :3] = (235, 228, 205)  # near Bone's colour, not equal to it
    write_slices(tmp_path / "s", rgba)
    (tmp_path / "t.csv").write_text("name,r,g,b\nBone,240,230,200\nMarker,250,20,30\n")
    data = ambfplus.load_slice_stack(
        tmp_path / "s", dimensions=(1, 1, 1), labels=tmp_path / "t.csv"
    )
    assert np.asarray(data.labels)[0, 0, 0] == 1
    # Without a table, every colour found becomes a label, most frequent first.
    built = ambfplus.load_slice_stack(tmp_path / "s", dimensions=(1, 1, 1))
    assert built.label_table[0].color == (240, 230, 200)
    assert {label.color for label in built.label_table[1:]} == {(250, 20, 30), (235, 228, 205)}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("label,red\nA,1\n", "header with columns name,r,g,b"),
        ("name,r,g,b\nA,1,2,300\n", "line 2: r must be|line 2: b must be"),
        ("name,r,g,b\nA,1,2,3\nA,4,5,6\n", "line 3: label name 'A' is used twice"),
    ],
)
def test_bad_label_tables_name_the_line(tmp_path, text, message):
    path = tmp_path / "labels.csv"
    path.write_text(text)
    with pytest.raises(ambfplus.ConfigError, match=message):
        ambfplus.read_label_table(path)


def test_yaml_label_table(tmp_path):
    path = tmp_path / "labels.yaml"
    path.write_text(
        "labels:\n  - {id: 3, name: Nerve, color: [250, 220, 40], critical: true}\n"
        "  - {id: 7, name: Bone, color: [240, 230, 200], removable: true}\n"
    )
    table = ambfplus.read_label_table(path)
    assert [(x.id, x.name, x.critical) for x in table] == [(3, "Nerve", True), (7, "Bone", False)]


def test_bad_adf_volume_blocks(tmp_path):
    world = ambfplus.World()
    path = tmp_path / "v.yaml"
    path.write_text("volumes: [VOLUME a]\n")
    with pytest.raises(ambfplus.ConfigError, match="no block of that name"):
        world.load_volumes(path)
    path.write_text("volumes: [VOLUME a]\nVOLUME a:\n  name: a\n")
    with pytest.raises(ambfplus.ConfigError, match="needs images"):
        world.load_volumes(path)
    path.write_text("volumes: [VOLUME a\n")
    with pytest.raises(ambfplus.ConfigError, match="line"):
        world.load_volumes(path)
    path.write_text("volumes: [VOLUME a]\nVOLUME a:\n  images: {path: nowhere/}\n")
    with pytest.raises(ambfplus.AssetNotFound, match="nowhere"):
        world.load_volumes(path)


def test_convert_round_trip_through_the_command_line(tmp_path, capsys):
    data = ambfplus.phantom(40, seed=1)
    data.save_nrrd(tmp_path / "in.nrrd")
    assert cli(["convert", str(tmp_path / "in.nrrd"), str(tmp_path / "stack")]) == 0
    assert (tmp_path / "stack" / "volume.yaml").exists()
    world = ambfplus.World()
    (volume,) = world.load_volumes(tmp_path / "stack" / "volume.yaml")
    assert np.array_equal(np.asarray(volume.labels), np.asarray(data.labels))
    assert [x.name for x in volume.data.label_table] == [x.name for x in data.label_table]
    assert (
        cli(["convert", str(tmp_path / "stack" / "volume.yaml"), str(tmp_path / "out.nrrd")]) == 0
    )
    again = ambfplus.load_nrrd(tmp_path / "out.nrrd")
    assert np.array_equal(np.asarray(again.labels), np.asarray(data.labels))
    assert (
        cli(["convert", str(tmp_path / "out.nrrd"), str(tmp_path / "bone.ply"), "--label", "1"])
        == 0
    )
    assert "triangles" in capsys.readouterr().out
