"""Bad input, one small case each: every reader checks what it reads and every Python-reachable
volume method checks its arguments, with an ``ambfplus`` error naming the file (or argument),
the key or line, and what was expected; never a crash, a hang or a half-loaded file.

Meshes that crash or hang Debian's assimp are loaded in their own process, with a timeout."""

from __future__ import annotations

import contextlib
import gzip
import os
import struct
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest
from helpers.volume_files import nrrd_bytes, segment_keys, write_slices

import ambfplus

LABELS = np.zeros((8, 8, 8), dtype=np.uint8)
LABELS[2:6, 2:6, 2:6] = 1
RAW = np.asfortranarray(LABELS).tobytes(order="F")  # 512 bytes

HEADER = "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nendian: little\n"


def nrrd(tmp_path: Path, header: str, payload: bytes, name: str = "bad.nrrd") -> Path:
    path = tmp_path / name
    path.write_bytes(header.encode() + b"\n" + payload)
    return path


def expect_config_error(path: Path, *words: str, error=None):
    """load_nrrd fails with a ConfigError naming the file and every word given."""
    with pytest.raises(error or ambfplus.ConfigError) as info:
        ambfplus.load_nrrd(path)
    message = str(info.value)
    assert str(path) in message
    for word in words:
        assert word in message, message
    return message


# NRRD payloads: exactly the bytes the header promises -------------------------------------


def test_nrrd_gzip_cut_to_20_bytes_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: gzip\n", gzip.compress(RAW)[:20])
    expect_config_error(path, "gzip data is corrupt or cut short")


def test_nrrd_valid_gzip_of_too_few_bytes_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: gzip\n", gzip.compress(RAW[:100]))
    expect_config_error(path, "decodes to 100 bytes", "needs 512")


def test_nrrd_gzip_of_too_many_bytes_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: gzip\n", gzip.compress(RAW + bytes(100)))
    expect_config_error(path, "decodes to more than", "needs 512")


def test_nrrd_bytes_after_the_gzip_stream_are_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: gzip\n", gzip.compress(RAW) + b"junk")
    expect_config_error(path, "4 bytes follow the end of the gzip data")


def test_nrrd_gzip_in_two_members_loads(tmp_path):
    path = nrrd(
        tmp_path, HEADER + "encoding: gzip\n", gzip.compress(RAW[:200]) + gzip.compress(RAW[200:])
    )
    assert np.array_equal(np.asarray(ambfplus.load_nrrd(path).labels), LABELS)


def test_nrrd_short_raw_payload_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: raw\n", RAW[:300])
    expect_config_error(path, "raw data holds 300 bytes", "needs 512")


def test_nrrd_long_raw_payload_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: raw\n", RAW + bytes(7))
    expect_config_error(path, "raw data holds 519 bytes", "needs 512")


@pytest.mark.parametrize("skip", ["1000000000", "1e9", "-7", "many"])
def test_nrrd_byte_skip_out_of_range_is_an_error(tmp_path, skip):
    path = nrrd(tmp_path, HEADER + f"encoding: raw\nbyte skip: {skip}\n", RAW)
    expect_config_error(path, "field 'byte skip' (line 7)")


@pytest.mark.parametrize("skip", ["1000000000", "-1", "1e9"])
def test_nrrd_line_skip_out_of_range_is_an_error(tmp_path, skip):
    path = nrrd(tmp_path, HEADER + f"encoding: raw\nline skip: {skip}\n", RAW)
    expect_config_error(path, "field 'line skip' (line 7)")


def test_nrrd_skips_that_fit_are_honoured(tmp_path):
    # byte skip -1: the data is the file's last bytes; line skip passes text lines; with gzip the
    # byte skip applies to the decoded data.
    path = nrrd(tmp_path, HEADER + "encoding: raw\nbyte skip: -1\n", b"junk\n" + RAW, "a.nrrd")
    assert np.array_equal(np.asarray(ambfplus.load_nrrd(path).labels), LABELS)
    path = nrrd(tmp_path, HEADER + "encoding: raw\nline skip: 2\n", b"a\nb\n" + RAW, "b.nrrd")
    assert np.array_equal(np.asarray(ambfplus.load_nrrd(path).labels), LABELS)
    header = HEADER + "encoding: gzip\nbyte skip: 3\n"
    path = nrrd(tmp_path, header, gzip.compress(b"xyz" + RAW), "c.nrrd")
    assert np.array_equal(np.asarray(ambfplus.load_nrrd(path).labels), LABELS)


@pytest.mark.parametrize("spacings", ["-1 1 1", "0 1 1", "nan 1 1", "inf 1 1", "1 1"])
def test_nrrd_bad_spacings_are_errors(tmp_path, spacings):
    path = nrrd(tmp_path, HEADER + f"encoding: raw\nspacings: {spacings}\n", RAW)
    expect_config_error(path, "field 'spacings' (line 7)")


@pytest.mark.parametrize(
    "directions",
    ["(0,0,0) (0,1,0) (0,0,1)", "(nan,0,0) (0,1,0) (0,0,1)", "(1,0,0) (2,0,0) (0,0,1)",
     "(1,0,0) (0,1,0)", "(1,0,0) (0,1) (0,0,1)"],
)  # fmt: skip
def test_nrrd_bad_space_directions_are_errors(tmp_path, directions):
    path = nrrd(tmp_path, HEADER + f"encoding: raw\nspace directions: {directions}\n", RAW)
    expect_config_error(path, "field 'space directions' (line 7)")


@pytest.mark.parametrize(
    ("field", "value"),
    [("dimension", "3abc"), ("sizes", "8 8 8x"), ("sizes", "8 8 99999"), ("endian", "middle"),
     ("space units", '"furlong" "mm" "mm"'), ("encoding", "bzip2")],
)  # fmt: skip
def test_nrrd_bad_field_values_name_the_field(tmp_path, field, value):
    lines = [line for line in HEADER.splitlines() if not line.startswith(field + ":")]
    if field != "encoding":
        lines.append("encoding: raw")
    path = nrrd(tmp_path, "\n".join(lines + [f"{field}: {value}"]) + "\n", RAW)
    expect_config_error(path, f"field '{field}'")


def test_nrrd_field_given_twice_is_an_error(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: raw\ntype: uint16\n", RAW)
    expect_config_error(path, "line 7", "field 'type' is given twice (first on line 2)")


def test_nrrd_header_that_never_ends_holds_no_data(tmp_path):
    path = tmp_path / "open.nrrd"
    path.write_bytes((HEADER + "encoding: raw").encode())
    expect_config_error(path, "does not end with a blank line")


def test_nrrd_non_utf8_header_is_a_config_error_naming_the_line(tmp_path):
    path = nrrd(tmp_path, HEADER + "encoding: raw\n# caf\xe9\n", RAW)
    path.write_bytes(path.read_bytes().replace("caf\xe9".encode(), b"caf\xe9"))
    message = expect_config_error(path, "line 7", "0xe9", "not UTF-8")
    message.encode("utf-8")  # the message itself is text


def test_nrrd_non_utf8_segment_name_is_a_config_error(tmp_path):
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0)])
    data = nrrd_bytes(LABELS, "uint8", extra=keys).replace(b"_Name:=Bone", b"_Name:=B\xffne")
    path = tmp_path / "seg.seg.nrrd"
    path.write_bytes(data)
    expect_config_error(path, "0xff", "not UTF-8")


def test_nrrd_folder_says_it_is_a_folder(tmp_path):
    folder = tmp_path / "volume.nrrd"
    folder.mkdir()
    expect_config_error(folder, "not a regular file but a folder")


def test_nrrd_detached_data_file_missing_is_asset_not_found(tmp_path):
    path = tmp_path / "head.nhdr"
    path.write_text(HEADER + "encoding: raw\ndata file: gone.raw\n")
    with pytest.raises(ambfplus.AssetNotFound, match="gone.raw"):
        ambfplus.load_nrrd(path)


def test_nrrd_non_finite_intensity_is_an_error(tmp_path):
    ct = np.full((4, 4, 4), 100.0, dtype=np.float32)
    ct[1, 2, 3] = np.nan
    path = tmp_path / "ct.nrrd"
    path.write_bytes(nrrd_bytes(ct, "float"))
    with pytest.raises(ambfplus.ConfigError, match=r"voxel \(1, 2, 3\)") as info:
        ambfplus.load_nrrd(path, threshold=50)
    assert str(path) in str(info.value)


# Slicer segmentations: label values checked against the label type --------------------------


def segmentation(tmp_path: Path, data: np.ndarray, nrrd_type: str, keys: dict) -> Path:
    path = tmp_path / "seg.seg.nrrd"
    path.write_bytes(nrrd_bytes(data, nrrd_type, extra=keys))
    return path


@pytest.mark.parametrize(
    ("nrrd_type", "dtype", "value", "expected"),
    [("uint16", np.uint16, "70000", "1..65535"), ("int", np.int32, "2147483648", "1..2147483647"),
     ("uchar", np.uint8, "0", "1..255"), ("short", np.int16, "-5", "1..32767")],
)  # fmt: skip
def test_segment_label_value_outside_the_type_names_the_key(
    tmp_path, nrrd_type, dtype, value, expected
):
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0), ("Nerve", (250, 200, 0), 2, 0)])
    keys["Segment1_LabelValue"] = value
    path = segmentation(tmp_path, LABELS.astype(dtype), nrrd_type, keys)
    expect_config_error(path, "key 'Segment1_LabelValue'", value, expected)


def test_segment_number_too_large_names_the_key(tmp_path):
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0)])
    keys["Segment2147483648_LabelValue"] = "1"
    path = segmentation(tmp_path, LABELS, "uchar", keys)
    expect_config_error(path, "key 'Segment2147483648_LabelValue'", "segment number")


@pytest.mark.parametrize(
    ("key", "value"), [("Segment0_Color", "nan 0 0"), ("Segment0_Color", "red"),
                       ("Segment0_Layer", "3"), ("Segment0_LabelValue", "one")]
)  # fmt: skip
def test_segment_bad_values_name_the_key(tmp_path, key, value):
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0)])
    keys[key] = value
    path = segmentation(tmp_path, LABELS, "uchar", keys)
    expect_config_error(path, f"key '{key}'")


# Label tables ---------------------------------------------------------------------------------


def test_labels_csv_non_utf8_is_a_config_error_naming_file_and_line(tmp_path):
    path = tmp_path / "labels.csv"
    path.write_bytes(b"name,r,g,b\nBone,200,200,200\nN\xe9rf,255,200,0\n")
    with pytest.raises(ambfplus.ConfigError, match="line 3") as info:
        ambfplus.read_label_table(path)
    assert str(path) in str(info.value) and "0xe9" in str(info.value)


def test_labels_csv_with_a_byte_order_mark_loads(tmp_path):
    path = tmp_path / "labels.csv"
    path.write_bytes(b"\xef\xbb\xbfname,r,g,b\nBone,200,200,200\n")
    assert [label.name for label in ambfplus.read_label_table(path)] == ["Bone"]


# Slice stacks ---------------------------------------------------------------------------------


def stack(tmp_path: Path) -> Path:
    rgba = np.zeros((6, 6, 4, 4), dtype=np.uint8)
    rgba[1:5, 1:5, :, :] = (200, 200, 200, 255)
    write_slices(tmp_path / "slices", rgba)
    return tmp_path / "slices"


BAD_STACK_OPTIONS = [("count", 0), ("count", -2), ("alpha_threshold", 300), ("alpha_threshold", -1)]


@pytest.mark.parametrize(("option", "value"), BAD_STACK_OPTIONS)
def test_slice_stack_bad_options_are_argument_errors(tmp_path, option, value):
    folder = stack(tmp_path)
    with pytest.raises(ambfplus.ArgumentError, match=option) as info:
        ambfplus.load_slice_stack(folder, dimensions=(0.01, 0.01, 0.01), **{option: value})
    assert str(folder) in str(info.value)


BAD_SIZES = [(0.0, 0.01, 0.01), (0.01, float("nan"), 0.01), (0.01, 0.01, -0.01),
             (0.01, 0.01, float("inf"))]  # fmt: skip


@pytest.mark.parametrize("argument", ["dimensions", "voxel_size"])
@pytest.mark.parametrize("sizes", BAD_SIZES)
def test_slice_stack_bad_sizes_name_the_argument_and_folder(tmp_path, argument, sizes):
    folder = stack(tmp_path)
    with pytest.raises(ambfplus.ArgumentError) as info:
        ambfplus.load_slice_stack(folder, **{argument: sizes})
    message = str(info.value)
    assert f"{argument} must be three positive finite metres" in message, message
    assert str(folder) in message, message


@pytest.mark.parametrize("argument", ["dimensions", "voxel_size"])
@pytest.mark.parametrize("sizes", BAD_SIZES)
def test_volume_data_bad_sizes_name_the_argument(argument, sizes):
    with pytest.raises(ambfplus.ArgumentError) as info:
        ambfplus.VolumeData(LABELS.copy(), **{argument: sizes})
    assert f"VolumeData: {argument} must be three positive finite metres" in str(info.value)


@pytest.mark.parametrize("sizes", BAD_SIZES)
def test_volume_data_dimensions_setter_refuses_bad_sizes(volume, sizes):
    with pytest.raises(ambfplus.ArgumentError, match=r"VolumeData\.dimensions must be three"):
        volume.dimensions = sizes
    assert np.allclose(volume.dimensions, (0.008, 0.008, 0.008))


def test_slice_stack_corrupt_image_names_the_file(tmp_path):
    folder = stack(tmp_path)
    (folder / "plane002.png").write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(40))
    with pytest.raises(ambfplus.ConfigError, match="cannot decode") as info:
        ambfplus.load_slice_stack(folder, dimensions=(0.01, 0.01, 0.01))
    assert "plane002.png" in str(info.value)


def volume_adf(tmp_path: Path, folder: Path, dimensions: str, count: int = 4) -> Path:
    path = tmp_path / "volume.yaml"
    path.write_text(
        textwrap.dedent(f"""\
        volumes: [VOLUME ear]
        VOLUME ear:
          name: ear
          dimensions: {dimensions}
          images: {{path: {folder}, prefix: plane00, format: png, count: {count}}}
        """)
    )
    return path


@pytest.mark.parametrize(
    ("dimensions", "count", "key"),
    [("{x: 0.01, y: 0.01}", 4, "dimensions.z"), ("{x: 0.01, y: 0.01, z: 0}", 4, "dimensions.z"),
     ("{x: .nan, y: 0.01, z: 0.01}", 4, "dimensions.x"), ("{x: 0.01, y: 0.01, z: 0.01}", 0,
      "images.count")],
)  # fmt: skip
def test_volume_adf_bad_sizes_name_file_and_key(tmp_path, dimensions, count, key):
    path = volume_adf(tmp_path, stack(tmp_path), dimensions, count)
    with pytest.raises(ambfplus.ConfigError, match=key.replace(".", r"\.")) as info:
        ambfplus.World().load_volumes(path)
    assert str(path) in str(info.value)


# Volume methods reachable from Python -------------------------------------------------------


@pytest.fixture
def volume():
    return ambfplus.VolumeData(LABELS.copy(), dimensions=(0.008, 0.008, 0.008))


@pytest.mark.parametrize("method", ["mark_dirty", "set_region"])
@pytest.mark.parametrize(
    ("lo", "hi", "error", "words"),
    [((0, 0, 0), (9, 8, 8), ambfplus.OutOfRange, "outside the grid"),
     ((-1, 0, 0), (2, 2, 2), ambfplus.OutOfRange, "outside the grid"),
     ((4, 0, 0), (2, 2, 2), ambfplus.ArgumentError, "lo (4, 0, 0) is above hi")],
)  # fmt: skip
def test_box_edits_outside_the_grid_or_inverted_are_errors(volume, method, lo, hi, error, words):
    before = np.asarray(volume.labels).copy()
    revision = volume.revision
    args = (lo, hi, 1) if method == "set_region" else (lo, hi)
    with pytest.raises(error, match=method) as info:
        getattr(volume, method)(*args)
    assert words in str(info.value)
    assert volume.revision == revision and np.array_equal(np.asarray(volume.labels), before)


def test_box_edits_inside_the_grid_still_work(volume):
    assert volume.set_region((0, 0, 0), (8, 8, 1), 1) == 64
    volume.mark_dirty((0, 0, 0), (8, 8, 8))
    volume.mark_dirty((3, 3, 3), (3, 3, 3))  # empty: nothing to do, not an error


@pytest.mark.parametrize("ijk", [(8, 0, 0), (0, -1, 0), (0, 0, 100000)])
def test_voxel_center_outside_the_grid_is_out_of_range(volume, ijk):
    with pytest.raises(ambfplus.OutOfRange, match=r"voxel_center: voxel \(") as info:
        volume.voxel_center(*ijk)
    assert "8x8x8" in str(info.value)


@pytest.mark.parametrize("radius", [float("inf"), float("nan"), -0.001])
def test_remove_sphere_needs_a_finite_radius(volume, radius):
    with pytest.raises(ambfplus.ArgumentError, match="remove_sphere"):
        volume.remove_sphere((0, 0, 0), radius)
    assert np.array_equal(np.asarray(volume.labels), LABELS)


def test_remove_sphere_with_a_huge_radius_clears_everything(volume):
    assert volume.remove_sphere((0, 0, 0), 1e300, only_removable=False) == int(LABELS.sum())


# Meshes: each in its own process, since these crashed or hung Debian's assimp ---------------

PLY_HEAD = (
    "ply\nformat ascii 1.0\nelement vertex {n}\nproperty float x\nproperty float y\n"
    "property float z\nelement face {f}\nproperty list uchar int vertex_indices\n"
)
LOAD_MESH = """
import sys, ambfplus
try:
    ambfplus.Simulator().world.add_body("b", mesh=sys.argv[1])
except ambfplus.Error as error:
    print(type(error).__name__ + ": " + str(error))
    sys.exit(3)
print("loaded")
"""


def load_mesh_in_a_process(path: Path) -> tuple[int, str]:
    try:
        done = subprocess.run(
            [sys.executable, "-c", LOAD_MESH, str(path)],
            capture_output=True,
            text=True,
            timeout=60,
            cwd=path.parent,
        )
    except subprocess.TimeoutExpired:
        pytest.fail(f"loading {path.name} hung (no answer in 60 s)")
    return done.returncode, done.stdout + done.stderr


def expect_mesh_error(path: Path, *words: str) -> None:
    code, output = load_mesh_in_a_process(path)
    assert code == 3, f"expected a typed error, got exit code {code}:\n{output}"
    assert output.startswith("ConfigError: ") and str(path) in output, output
    for word in words:
        assert word in output, output


def test_ply_without_end_header_is_an_error_not_a_hang(tmp_path):
    path = tmp_path / "noend.ply"
    path.write_text(PLY_HEAD.format(n=3, f=1) + "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    expect_mesh_error(path, "line 9", "'end_header' line missing")


def test_ply_with_a_stray_line_before_its_faces_is_an_error_not_an_abort(tmp_path):
    path = tmp_path / "stray.ply"
    body = "0 0 0\n1 0 0\n0 1 0\n1 1 0\nvt 0.9 0.9\n3 0 1 2\n3 1 3 2\n"
    path.write_text(PLY_HEAD.format(n=4, f=2) + "end_header\n" + body)
    expect_mesh_error(path, "line 14", "'vt'")


def test_ply_face_naming_a_missing_vertex_is_an_error_not_a_segfault(tmp_path):
    path = tmp_path / "index.ply"
    path.write_text(PLY_HEAD.format(n=3, f=1) + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
    expect_mesh_error(path, "names vertex 7 but there are 3 vertices")


def binary_ply(vertices: np.ndarray, faces: list[list[int]], cut: int = 0) -> bytes:
    head = PLY_HEAD.format(n=len(vertices), f=len(faces)).replace("ascii", "binary_little_endian")
    body = vertices.astype("<f4").tobytes()
    for face in faces:
        body += struct.pack("<B", len(face)) + np.asarray(face, dtype="<i4").tobytes()
    return (head + "end_header\n").encode() + body[: len(body) - cut]


def test_binary_ply_cut_short_is_an_error(tmp_path):
    path = tmp_path / "cut.ply"
    path.write_bytes(binary_ply(np.eye(3), [[0, 1, 2]], cut=5))
    expect_mesh_error(path, "ends inside row 0", "element 'face'")


def test_binary_ply_face_naming_a_missing_vertex_is_an_error(tmp_path):
    path = tmp_path / "index.ply"
    path.write_bytes(binary_ply(np.eye(3), [[0, 1, 2], [0, 2, 1000000]]))
    expect_mesh_error(path, "names vertex 1000000")


def test_ply_with_more_rows_than_declared_is_an_error(tmp_path):
    path = tmp_path / "more.ply"
    path.write_text(
        PLY_HEAD.format(n=3, f=1) + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 2 1\n"
    )
    expect_mesh_error(path, "more data after the rows the header declares")


def test_good_ply_files_still_load(tmp_path):
    ascii_path = tmp_path / "good.ply"
    ascii_path.write_text(PLY_HEAD.format(n=3, f=1) + "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    binary_path = tmp_path / "good_binary.ply"
    binary_path.write_bytes(binary_ply(np.eye(3), [[0, 1, 2]]))
    for path in (ascii_path, binary_path):
        code, output = load_mesh_in_a_process(path)
        assert code == 0 and "loaded" in output, output


def test_ply_header_cut_before_end_header_is_an_error(tmp_path):
    path = tmp_path / "header_only.ply"
    path.write_text(PLY_HEAD.format(n=3, f=1))
    expect_mesh_error(path, "no 'end_header' line")


OBJ_TRIANGLE = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def test_obj_with_a_nan_vertex_is_an_error(tmp_path):
    path = tmp_path / "nan.obj"
    path.write_text(OBJ_TRIANGLE + "v nan 0 0\nf 1 2 3\nf 1 2 4\n")
    expect_mesh_error(path, "is (nan, 0, 0); expected finite coordinates")


def test_obj_with_a_nan_vertex_in_its_second_object_is_an_error_not_half_a_mesh(tmp_path):
    # Two materials make two meshes; assimp's invalid-data step dropped the second one (its NaN
    # vertex) and the first loaded alone, silently.
    (tmp_path / "two.mtl").write_text("newmtl a\nKd 1 0 0\nnewmtl b\nKd 0 1 0\n")
    path = tmp_path / "half.obj"
    second = "v 0 0 1\nv 1 0 1\nv 0 nan 1\nusemtl b\nf 4 5 6\n"
    path.write_text(f"mtllib two.mtl\no good\n{OBJ_TRIANGLE}usemtl a\nf 1 2 3\no bad\n{second}")
    expect_mesh_error(path, "is (0, nan, 1); expected finite coordinates")


@pytest.mark.parametrize(
    ("face", "words"),
    [("f 1 2 9", "vertex index out of range"), ("f 1 2 -9", "vertex index out of range"),
     ("f 1 2 0", "Invalid face index")],
)  # fmt: skip
def test_obj_face_naming_a_missing_vertex_is_an_error(tmp_path, face, words):
    path = tmp_path / "index.obj"
    path.write_text(OBJ_TRIANGLE + face + "\n")
    expect_mesh_error(path, words)


def binary_stl(triangles: np.ndarray, header: bytes = b"", cut: int = 0) -> bytes:
    """A binary STL of (n, 3, 3) triangles, cut short by `cut` bytes."""
    data = header.ljust(80, b" ") + struct.pack("<I", len(triangles))
    for triangle in triangles:
        data += np.zeros(3, "<f4").tobytes() + np.asarray(triangle, "<f4").tobytes() + bytes(2)
    return data[: len(data) - cut]


TWO_TRIANGLES = np.array([np.eye(3), np.eye(3)[::-1] + 1.0])


@pytest.mark.parametrize("header", [b"binary", b"solid but binary"])
@pytest.mark.parametrize("cut", [1, 30, 50, 100])
def test_binary_stl_cut_short_is_an_error(tmp_path, header, cut):
    path = tmp_path / "cut.stl"
    path.write_bytes(binary_stl(TWO_TRIANGLES, header, cut))
    expect_mesh_error(path, "promises 2 triangles", "= 184 bytes", f"has {184 - cut} (cut short)")


def test_binary_stl_with_bytes_left_over_is_an_error(tmp_path):
    path = tmp_path / "long.stl"
    path.write_bytes(binary_stl(TWO_TRIANGLES, b"binary") + bytes(7))
    expect_mesh_error(path, "has 191 (bytes left over)")


def test_binary_stl_shorter_than_its_header_is_an_error(tmp_path):
    path = tmp_path / "header.stl"
    path.write_bytes(binary_stl(TWO_TRIANGLES)[:60])
    expect_mesh_error(path, "60 bytes is shorter than its 84-byte header")


@pytest.mark.parametrize("value", [np.nan, np.inf, -np.inf])
def test_binary_stl_with_a_non_finite_vertex_is_an_error(tmp_path, value):
    triangles = TWO_TRIANGLES.copy()
    triangles[1, 2, 0] = value
    path = tmp_path / "nan.stl"
    path.write_bytes(binary_stl(triangles, b"binary"))
    expect_mesh_error(path, "vertex 5 of mesh 0", "expected finite coordinates")


def test_ascii_stl_with_a_nan_vertex_is_an_error(tmp_path):
    path = tmp_path / "nan_ascii.stl"
    path.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
        "vertex 0 nan 0\nendloop\nendfacet\nendsolid t\n"
    )
    expect_mesh_error(path, "vertex 2 of mesh 0", "expected finite coordinates")


OFF_TRIANGLE = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n"


@pytest.mark.parametrize(
    "counts",
    ["3 44444444444444444444 0", "4000000000 1 0", "3 9 0", "3 444444444z44 0", "3\n# c\n9 0"],
)
def test_off_counts_beyond_its_lines_are_an_error_not_gigabytes(tmp_path, counts):
    # A fuzzer's finding: Debian's assimp allocated 3 GB for the faces a 100-byte file promised.
    path = tmp_path / "huge.off"
    path.write_text(f"OFF\n# a comment\n{counts}\n" + OFF_TRIANGLE)
    expect_mesh_error(path, "OFF header promises", "but only 5 lines follow the counts")


@pytest.mark.parametrize("edges", ["444444444", "444444444z444444"])
def test_an_off_edge_count_beyond_the_file_is_an_error_not_gigabytes(tmp_path, edges):
    # A fuzzer's finding in CI: Debian's assimp took 7 GB for the edges a 66-byte file promised.
    path = tmp_path / "edges.off"
    path.write_text(f"OFF\n3 1 {edges}\n" + OFF_TRIANGLE)
    expect_mesh_error(path, "OFF header promises 444444444 edges", "can hold")


def test_good_obj_stl_and_off_files_still_load(tmp_path):
    obj = tmp_path / "good.obj"
    obj.write_text(OBJ_TRIANGLE + "f 1 2 3\n")
    stl = tmp_path / "good.stl"
    stl.write_bytes(binary_stl(TWO_TRIANGLES, b"binary"))
    off = tmp_path / "good.off"
    off.write_text("OFF\n3 1 0\n" + OFF_TRIANGLE)
    for path in (obj, stl, off):
        code, output = load_mesh_in_a_process(path)
        assert code == 0 and "loaded" in output, output


# ADF files (the YAML layer every loader reads through).
def adf_file(tmp_path: Path, data: bytes) -> Path:
    path = tmp_path / "model.yaml"
    path.write_bytes(data)
    return path


def test_adf_with_a_non_utf8_name_is_a_config_error_naming_file_and_line(tmp_path):
    path = adf_file(tmp_path, b"bodies: [BODY a]\nBODY a:\n  name: ab\xff\n  mass: 1\n")
    with pytest.raises(ambfplus.ConfigError) as caught:
        ambfplus.World().load_adf(path)
    message = str(caught.value)
    assert str(path) in message and "line 3" in message and "0xff" in message


def test_adf_with_two_yaml_documents_is_a_config_error(tmp_path):
    text = b"bodies: [BODY a]\nBODY a:\n  name: a\n---\nbodies: [BODY b]\nBODY b:\n  name: b\n"
    path = adf_file(tmp_path, text)
    with pytest.raises(ambfplus.ConfigError, match="line 4: .*second YAML document"):
        ambfplus.World().load_adf(path)


def test_adf_of_a_lone_comma_is_a_config_error_not_endless_memory(tmp_path):
    # A fuzzer's finding: yaml-cpp's LoadAll allocates without end on this input.
    with pytest.raises(ambfplus.ConfigError):
        ambfplus.World().load_adf(adf_file(tmp_path, b","))


# Files that are not regular files -----------------------------------------------------------


@contextlib.contextmanager
def fifo(path: Path):
    """A FIFO at `path`, checked never to have been opened for reading. Should a reader block
    on it (the defect these tests guard against), a writer opens and closes it after 5 s, which
    releases the reader and marks the FIFO opened: the test fails instead of hanging."""
    os.mkfifo(path)
    done, opened = threading.Event(), threading.Event()

    def release() -> None:
        if done.wait(5.0):
            return
        while not done.is_set():
            try:
                os.close(os.open(path, os.O_WRONLY | os.O_NONBLOCK))
                opened.set()
            except OSError:  # no reader
                time.sleep(0.05)

    thread = threading.Thread(target=release, daemon=True)
    thread.start()
    try:
        yield path
    finally:
        done.set()
        thread.join()
    assert not opened.is_set(), f"{path} was opened for reading"


TRIANGLE_UV = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3\n"


def test_a_fifo_is_refused_as_what_it_is_and_never_read(tmp_path):
    """A FIFO given as a mesh, NRRD, label table, model file or slice is a ConfigError saying it
    is a FIFO (not "file not found"); one named by an OBJ's mtllib or an MTL's map_Kd is
    skipped as a missing one is (the mesh loads, as in AMBF). None is ever opened."""
    world = ambfplus.World()
    checks = [
        ("mesh.obj", lambda p: world.add_body("fifo", mesh=str(p))),
        ("ear.nrrd", ambfplus.load_nrrd),
        ("labels.csv", ambfplus.read_label_table),
        ("model.yaml", lambda p: ambfplus.World().load_adf(p)),
    ]
    for name, load in checks:
        with fifo(tmp_path / name) as path:
            with pytest.raises(ambfplus.ConfigError, match="not a regular file but a FIFO"):
                load(path)
    rgba = np.full((4, 4, 3, 4), 255, dtype=np.uint8)
    write_slices(tmp_path / "slices", rgba)
    slice_file = sorted((tmp_path / "slices").glob("*.png"))[1]
    slice_file.unlink()
    with fifo(slice_file), pytest.raises(ambfplus.ConfigError, match="a FIFO") as info:
        ambfplus.load_slice_stack(tmp_path / "slices", dimensions=(0.01, 0.01, 0.01))
    assert slice_file.name in str(info.value)
    (tmp_path / "a.obj").write_text("mtllib fifo.mtl\n" + TRIANGLE_UV)
    (tmp_path / "b.mtl").write_text("newmtl red\nKd 1 0 0\nmap_Kd fifo.png\n")
    (tmp_path / "b.obj").write_text("mtllib b.mtl\n" + TRIANGLE_UV)
    with fifo(tmp_path / "fifo.mtl"), fifo(tmp_path / "fifo.png"):
        assert world.add_body("a", mesh=str(tmp_path / "a.obj")).name == "a"
        assert world.add_body("b", mesh=str(tmp_path / "b.obj")).name == "b"
