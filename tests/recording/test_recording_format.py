"""Recording format 1.1: text stored as fixed-length strings (no variable-length data, so no
global heap to read), recordings of format 1.0 still read, and damaged files that made libhdf5
loop forever are RecordingErrors naming the file (and the attribute)."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest
from helpers import TESTS

import ambfplus.recording.writer as writer_module
from ambfplus.recording import Recorder, RecordingError, open_recording, repair, validate
from ambfplus.recording.hdf5 import collection_problem

CORPUS = TESTS / "fuzz" / "corpus" / "recording"
# A recording written by the format 1.0 writer (variable-length strings), kept as a fuzz seed.
FORMAT_1_0 = CORPUS / "seed-complete-v1.0"
# A format 1.0 head whose global heap a fuzzer damaged: libhdf5 looped forever reading it.
HANGING_HEAD = CORPUS / "found-hdf5-hang-fe1ea829"
SEPARATOR = b"\n--8<--\n"
LONG_KIND = "drilled through the tegmen, " * 4 + "é"


def unpack(corpus_input: Path, folder: Path) -> Path:
    """Writes a recording fuzz input (head and parts cut at the separator) as files; returns
    the head."""
    head, *parts = corpus_input.read_bytes().split(SEPARATOR)
    (folder / "session.h5").write_bytes(head)
    for number, part in enumerate(parts, start=1):
        (folder / f"session.h5.part{number:04d}").write_bytes(part)
    return folder / "session.h5"


def frame(camera: str, i: int) -> dict:
    rng = np.random.default_rng(i)
    return {
        "camera": camera, "time": i * 0.01, "step": i * 10,
        "rgb": rng.integers(0, 255, (4, 6, 3), dtype=np.uint8),
        "depth": rng.random((4, 6), dtype=np.float32),
        "intrinsics": np.array([[5.0, 0, 3], [0, 5, 2], [0, 0, 1]]), "pose": np.eye(4),
    }  # fmt: skip


def write_recording(path: Path) -> None:
    """Two parts with every kind of text the format has: attributes, conventions, camera and
    volume names, events and a text step column whose longest text grows from part to part."""
    legend = {1: {"name": "oreille", "kind": "volume", "labels": {1: {"name": "Os é"}}}}
    with Recorder(path, metadata={"scene": "é" * 40000}) as rec:  # a large attribute
        rec.set_legend(legend)
        for i in range(2):
            rec.add_frame("cam", frame("caméra", i))
            rec.add_steps({"step": [i], "time": [i * 0.01], "note": ["x" * (5 + 10 * i)]})
            rec.add_events([{"step": i, "kind": "contact"}])
            rec.flush()
        rec.add_events([{"step": 3, "kind": LONG_KIND}])
        rec.add_removed({"step": 3, "voxel": [[1, 2, 3]], "label": [1]}, volume="oreille")


def variable_length_in(path: Path) -> list[str]:
    """Every attribute and dataset of the file whose type is variable-length, found through the
    low-level API without reading any data."""

    def variable(type_id) -> bool:
        kind = type_id.get_class()
        return kind == h5py.h5t.VLEN or (kind == h5py.h5t.STRING and type_id.is_variable_str())

    found = []
    with h5py.File(path, "r") as f:
        objects = [("/", f)]
        f.visititems(lambda name, obj: objects.append((name, obj)))
        for name, obj in objects:
            for attribute in obj.attrs:
                if variable(h5py.h5a.open(obj.id, attribute.encode()).get_type()):
                    found.append(f"{name} attribute {attribute}")
            if isinstance(obj, h5py.Dataset) and variable(obj.id.get_type()):
                found.append(f"{name} dataset")
    return found


def test_a_recording_written_now_holds_no_variable_length_data(tmp_path):
    path = tmp_path / "session.h5"
    write_recording(path)
    files = [path, *sorted(tmp_path.glob("session.h5.part*"))]
    assert len(files) == 4  # two flushes and the close
    for file in files:
        assert variable_length_in(file) == [], file
        with h5py.File(file, "r") as f:
            assert f.attrs["ambfplus_recording_minor_version"] == 1
    for part in files[1:]:  # no global heap collection at all
        assert b"GCOL" not in part.read_bytes(), part
    with open_recording(path) as rec:
        assert (rec.version, rec.minor_version) == (1, 1)
        assert rec.metadata == {"scene": "é" * 40000}
        assert rec.legend[1]["labels"][1]["name"] == "Os é"
        assert rec.cameras["cam"].camera == "caméra"
        assert [e["kind"] for e in rec.events] == ["contact", "contact", LONG_KIND]
        assert list(rec.steps["note"]) == ["x" * 5, "x" * 15]
        assert rec.removed["volume"] == "oreille"
    assert validate(path, match_images=False).ok
    with h5py.File(path, "r") as f:  # the head's virtual datasets are as wide as the widest part
        assert list(f["events/kind"].asstr()[:]) == ["contact", "contact", LONG_KIND]


def test_longer_text_widens_a_text_column_within_a_part(tmp_path, monkeypatch):
    monkeypatch.setattr(writer_module, "BUFFER_BYTES", 1)  # every row written at once
    path = tmp_path / "w.h5"
    with Recorder(path) as rec:
        for kind in ("a", LONG_KIND, "bb"):
            rec.add_events([{"step": 1, "kind": kind}])
    (part,) = tmp_path.glob("w.h5.part*")
    with h5py.File(part, "r") as f:
        assert f["events/kind"].dtype.itemsize == len(LONG_KIND.encode())
    with open_recording(path) as rec:
        assert [e["kind"] for e in rec.events] == ["a", LONG_KIND, "bb"]


def test_text_with_nul_is_refused_where_it_is_given(tmp_path):
    with Recorder(tmp_path / "n.h5") as rec:
        with pytest.raises(ValueError, match=r"events/kind: text may not contain NUL"):
            rec.add_events([{"step": 1, "kind": "a\0b"}])
        with pytest.raises(ValueError, match=r"steps/note: text may not contain NUL"):
            rec.add_steps({"step": [1], "time": [0.0], "note": ["a\0b"]})
    with pytest.raises(ValueError, match="recording_id: text may not contain NUL"):
        Recorder(tmp_path / "m.h5", recording_id="a\0")


def test_a_format_1_0_recording_still_reads_and_repairs(tmp_path):
    head = unpack(FORMAT_1_0, tmp_path)
    with h5py.File(head, "r") as f:  # really the old format: variable-length text
        assert "ambfplus_recording_minor_version" not in f.attrs
        assert "/ attribute legend" in variable_length_in(head)
    with open_recording(head) as rec:
        assert (rec.version, rec.minor_version) == (1, 0)
        assert rec.metadata == {"scene": "seed"}
        assert rec.legend[1]["name"] == "ear" and rec.legend[1]["labels"][1]["name"] == "Bone"
        assert len(rec.rigs["rig"]) == 2 and rec.rigs["rig"][1].baseline == 0.065
        assert rec.events == [{"step": 5, "kind": "contact", "label": 1, "voxel": (-1, -1, -1)}]
        assert np.array_equal(rec.steps["force"], [[0.0, 0, 1], [0.0, 0, 1]])
        assert rec.cameras["left"].camera == "left"
    assert validate(head, match_images=False).ok
    with repair(head) as rec:  # a new head (format 1.1) over the old parts
        assert rec.minor_version == 1 and rec.events[0]["kind"] == "contact"
    assert variable_length_in(head) == ["events/kind dataset"]  # a view of the old parts
    with h5py.File(head, "r") as f:
        assert f["events/kind"].asstr()[0] == "contact"


def open_in_a_subprocess(head: Path) -> subprocess.CompletedProcess:
    """open_recording in its own process, so that a regression fails this test instead of
    hanging the test run."""
    script = textwrap.dedent(
        f"""
        from ambfplus.recording import RecordingError, open_recording
        try:
            with open_recording({str(head)!r}) as rec:
                rec.events
        except RecordingError as error:
            print("RecordingError:", error)
        # This process's own peak (VmHWM): ru_maxrss would report the parent's peak before
        # exec (Linux keeps the larger of the two), a test runner's gigabytes.
        status = open("/proc/self/status").read()
        print("peak MB:", int(status.split("VmHWM:")[1].split()[0]) // 1024)
        """
    )
    return subprocess.run(
        [sys.executable, "-P", "-c", script], capture_output=True, text=True, timeout=120
    )


def test_a_damaged_global_heap_is_an_error_not_a_hang(tmp_path):
    head = unpack(HANGING_HEAD, tmp_path)
    done = open_in_a_subprocess(head)
    assert done.returncode == 0, done.stderr
    assert f"RecordingError: {head}: damaged global heap collection at byte 2048" in done.stdout
    assert "free-space object at byte 4768 has size 0" in done.stdout


def test_a_damaged_global_heap_in_a_format_1_0_part_names_the_part(tmp_path):
    head = unpack(FORMAT_1_0, tmp_path)
    part = tmp_path / "session.h5.part0001"
    data = bytearray(part.read_bytes())
    start = data.find(b"GCOL\x01")
    offset = start + 16  # walk to the free-space object (index 0) and make its size 0
    while int.from_bytes(data[offset : offset + 2], "little") != 0:
        offset += 16 + (int.from_bytes(data[offset + 8 : offset + 16], "little") + 7) // 8 * 8
    data[offset + 8 : offset + 16] = bytes(8)
    part.write_bytes(bytes(data))
    done = open_in_a_subprocess(head)
    assert done.returncode == 0, done.stderr
    assert f"RecordingError: {part}: damaged global heap collection at byte {start}" in done.stdout


def peak_mb(done) -> int:
    return int(done.stdout.rsplit("peak MB:", 1)[1])


@pytest.mark.parametrize(
    ("file", "name", "length", "refusal"),
    [
        ("session.h5.part0001", "recording_id", 32, "attribute 'recording_id' holds a "
         "variable-length value claiming 4294967264 bytes, more than the file's {size}: the "
         "file is damaged"),
        # Dense attributes (the head's eleven, in a fractal heap) have checksums libhdf5 checks.
        ("session.h5", "legend", 95, "damaged file: reading the "),
    ],
)  # fmt: skip
def test_a_format_1_0_attribute_claiming_more_than_its_file_is_refused(
    tmp_path, file, name, length, refusal
):
    """libhdf5 allocates and fills the length a variable-length value claims before it finds
    the value: a fuzzer's 16 damaged bytes in a part's header cost 4 GB."""
    head = unpack(FORMAT_1_0, tmp_path)
    intact = open_in_a_subprocess(head)
    assert "RecordingError" not in intact.stdout, intact.stdout
    path = tmp_path / file
    data = bytearray(path.read_bytes())
    # The value's length field: the first 4-byte `length` after the attribute's name (its last
    # occurrence: the head's conventions text says "legend" too).
    at = data.rfind(name.encode() + b"\0")
    at = data.find(length.to_bytes(4, "little"), at, at + 80)
    assert at > 0
    data[at : at + 4] = (0xFFFFFFE0).to_bytes(4, "little")
    path.write_bytes(bytes(data))
    done = open_in_a_subprocess(head)
    assert done.returncode == 0, done.stderr
    assert f"RecordingError: {path}: {refusal.format(size=len(data))}" in done.stdout
    assert peak_mb(done) < 1024, done.stdout


def test_a_format_1_0_dataset_claiming_more_than_its_file_is_refused(tmp_path):
    head = unpack(FORMAT_1_0, tmp_path)
    part = tmp_path / "session.h5.part0001"
    with h5py.File(part, "r") as f:
        chunk = f["events/kind"].id.get_chunk_info(0)
        assert f["events/kind"].asstr()[0] == "contact"
    data = bytearray(part.read_bytes())
    assert data[chunk.byte_offset : chunk.byte_offset + 4] == len("contact").to_bytes(4, "little")
    data[chunk.byte_offset : chunk.byte_offset + 4] = (0xFFFFFFF0).to_bytes(4, "little")
    part.write_bytes(bytes(data))
    done = open_in_a_subprocess(head)
    assert done.returncode == 0, done.stderr
    assert (
        f"RecordingError: {part}: dataset events/kind holds a variable-length value claiming "
        "4294967280 bytes"
    ) in done.stdout
    assert peak_mb(done) < 1024, done.stdout


@pytest.mark.parametrize(
    ("file", "obj", "attribute", "named"),
    [
        ("session.h5", "/", "legend", "'legend'"),
        ("session.h5", "conventions", "units", "'conventions/units'"),
        ("session.h5.part0001", "/", "recording_id", "'recording_id'"),
        ("session.h5.part0001", "cameras/cam", "camera", "'cameras/cam/camera'"),
    ],
)
def test_a_variable_length_attribute_in_a_format_1_1_file_is_refused(
    tmp_path, file, obj, attribute, named
):
    write_recording(tmp_path / "session.h5")
    with h5py.File(tmp_path / file, "r+") as f:
        value = f[obj].attrs[attribute].decode()
        f[obj].attrs.create(attribute, value, dtype=h5py.string_dtype())
    message = rf"{tmp_path / file}: attribute {named} is a variable-length string"
    with pytest.raises(RecordingError, match=message):
        open_recording(tmp_path / "session.h5")
    report = validate(tmp_path / "session.h5")
    assert not report.ok and "variable-length string" in report.checks[0].detail


def test_a_variable_length_dataset_in_a_format_1_1_part_is_refused(tmp_path):
    write_recording(tmp_path / "session.h5")
    part = tmp_path / "session.h5.part0002"
    with h5py.File(part, "r+") as f:
        kinds = f["events/kind"].asstr()[:]
        del f["events/kind"]
        f["events"].create_dataset("kind", data=kinds.astype(object), dtype=h5py.string_dtype())
    with pytest.raises(RecordingError, match=rf"{part}: dataset events/kind is a variable-length"):
        open_recording(tmp_path / "session.h5")


def collection(objects: list[tuple[int, int]], size: int = 4096) -> bytearray:
    """A global heap collection (8-byte lengths) holding objects (index, data length), then a
    free-space object over the rest."""
    data = bytearray(b"GCOL\x01\0\0\0" + size.to_bytes(8, "little"))
    for index, length in objects:
        data += index.to_bytes(2, "little") + bytes(6) + length.to_bytes(8, "little")
        data += bytes((length + 7) // 8 * 8)
    free = size - len(data)
    data += bytes(8) + free.to_bytes(8, "little") + bytes(free - 16)
    return data


def test_a_global_heap_walk_must_end_at_the_collections_end():
    good = collection([(1, 18), (2, 5)])
    assert collection_problem(bytes(good), 0, 8) is None
    free = 16 + (16 + 24) + (16 + 8)  # after the header and the two objects
    stuck = bytearray(good)
    stuck[free + 8 : free + 16] = bytes(8)  # the free-space object's size: 0
    assert "has size 0" in collection_problem(bytes(stuck), 0, 8)
    overrun = bytearray(good)
    overrun[16 + 8 : 16 + 16] = (5000).to_bytes(8, "little")  # object 1 longer than the rest
    assert "object 1 at byte 16 runs past" in collection_problem(bytes(overrun), 0, 8)
    assert "does not fit the file" in collection_problem(bytes(good[:2048]), 0, 8)
    assert "cut off" in collection_problem(b"GCOL\x01\0\0\0\x10", 0, 8)


def test_a_group_without_its_layouts_columns_is_refused(tmp_path):
    path = tmp_path / "session.h5"
    with Recorder(path) as rec:
        rec.add_frame("cam", frame("cam", 0))
        rec.add_events([{"step": 1, "kind": "contact"}])
    (part,) = tmp_path.glob("session.h5.part*")
    with h5py.File(part, "r+") as f:
        f.move("events/kind", "events/kinds")
    with pytest.raises(RecordingError, match=rf"{part}: events has no dataset 'kind'"):
        open_recording(path)
    with h5py.File(part, "r+") as f:
        f.move("events/kinds", "events/kind")
        pose = f["cameras/cam/pose"][()]
        del f["cameras/cam/pose"]
        f["cameras/cam"].create_dataset("pose", data=pose[:, :3], maxshape=(None, 3, 4))
    with pytest.raises(RecordingError, match=r"cameras/cam/pose is float64 \(3, 4\) per row, exp"):
        open_recording(path)


def test_a_rig_row_naming_a_missing_frame_is_an_error(tmp_path):
    path = tmp_path / "session.h5"

    class Pair:
        left, right = frame("left", 0), frame("right", 0)
        baseline, dcx = 0.065, 0.0

    with Recorder(path) as rec:
        rec.add_stereo("rig", Pair())
    (part,) = tmp_path.glob("session.h5.part*")
    with h5py.File(part, "r+") as f:
        f["rigs/rig/right_index"][0] = 7
    with open_recording(path) as rec:
        with pytest.raises(RecordingError, match=r"rigs/rig/right_index\[0\] is 7, but stream"):
            rec.rigs["rig"][0]


def test_validate_checks_the_global_heaps_of_every_file(tmp_path):
    path = tmp_path / "session.h5"
    write_recording(path)
    report = validate(path, match_images=False)
    (heaps,) = [check for check in report.checks if check.name == "global heaps"]
    assert heaps.status == "pass" and heaps.numbers["files"] == 4
    assert heaps.numbers["collections"] >= 1  # the head's virtual dataset mappings
    # A looping collection nothing points to yet: open_recording does not read a format 1.1
    # part's every byte, validate does.
    part = tmp_path / "session.h5.part0002"
    size = part.stat().st_size
    stuck = collection([(1, 8)])
    stuck[16 + 24 + 8 : 16 + 24 + 16] = bytes(8)
    with open(part, "ab") as out:
        out.write(stuck)
    with open_recording(path) as rec:
        assert len(rec.cameras["cam"]) == 2
    (check,) = validate(path).checks
    assert check.name == "open" and check.status == "fail"
    assert f"{part}: damaged global heap collection at byte {size}" in check.detail
