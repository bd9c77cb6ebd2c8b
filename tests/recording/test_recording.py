"""Recordings: exact round trips of real captures, backpressure, writer errors, survival of
SIGKILL, validation and its failures, and clear errors for files that are not recordings."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import h5py
import numpy as np
import pytest

import ambfplus
import ambfplus.labels
from ambfplus.cli import main as cli_main
from ambfplus.recording import (
    Recorder,
    RecordingError,
    open_recording,
    repair,
    validate,
    world_legend,
)
from ambfplus.stereo import StereoRig

PASSES = ["rgb", "depth", "instance", "label", "voxel"]
ALL_PASSES = PASSES + ["points"]


def ear_scene():
    """The phantom ear seen by a small off-axis stereo rig."""
    world = ambfplus.World()
    volume = world.add_volume("ear", ambfplus.phantom(64))
    rig = StereoRig(world, "rig", baseline=0.01, width=64, height=48, working_distance=0.1)
    rig.look_at((0.05, -0.08, 0.05), (0.0, 0.0, 0.0))
    return world, volume, rig


def snapshot(frame) -> dict:
    """Copies of everything a recorded frame must give back."""
    out = {name: np.array(getattr(frame, name)) for name in ALL_PASSES}
    out.update(
        time=frame.time, step=frame.step, intrinsics=frame.intrinsics.copy(), pose=frame.pose.copy()
    )
    return out


def assert_frame_equal(recorded, expected: dict, passes=ALL_PASSES) -> None:
    for name in passes:
        got = getattr(recorded, name)
        assert got.dtype == expected[name].dtype, name
        assert np.array_equal(got, expected[name]), name
    assert recorded.time == expected["time"] and recorded.step == expected["step"]
    assert np.array_equal(recorded.intrinsics, expected["intrinsics"])
    assert np.array_equal(recorded.pose, expected["pose"])


def synthetic_frame(i: int, height: int = 24, width: int = 32) -> dict:
    """A frame whose every value follows from its index (a subprocess and the test agree)."""
    rng = np.random.default_rng(i)
    pose = np.eye(4)
    pose[:3, 3] = rng.normal(size=3)
    return {
        "camera": "cam",
        "rgb": rng.integers(0, 256, (height, width, 3), dtype=np.uint8),
        "depth": rng.random((height, width), dtype=np.float32),
        "label": rng.integers(0, 11, (height, width)).astype(np.uint16),
        "time": 0.001 * (10 * i + 10),
        "step": 10 * i + 10,
        "intrinsics": np.array([[40.0 + i, 0, 16], [0, 40.0 + i, 12], [0, 0, 1]]),
        "pose": pose,
    }


def synthetic_frame_bytes() -> int:
    """What a recorder queues for one synthetic frame: its arrays plus time and step."""
    frame = synthetic_frame(0)
    return 16 + sum(frame[n].nbytes for n in ("rgb", "depth", "label", "intrinsics", "pose"))


def assert_synthetic(recorded, i: int) -> None:
    expected = synthetic_frame(i)
    for name in ("rgb", "depth", "label"):
        assert np.array_equal(getattr(recorded, name), expected[name]), (i, name)
    assert recorded.step == expected["step"] and recorded.time == expected["time"]
    assert np.array_equal(recorded.pose, expected["pose"])


@pytest.fixture
def drilled_recording(tmp_path):
    """A real session: stereo frames of the ear, a sphere removed where the left camera looks
    (logged as removed voxels), steps, events; returns (path, world, snapshots, removed)."""
    world, volume, rig = ear_scene()
    path = tmp_path / "session.h5"
    snapshots, removed = [], {}
    with Recorder(path, metadata={"scene": "phantom(64)", "seed": 0}) as rec:
        rec.set_legend(world)
        for i in range(4):
            world.step(5)
            pair = rig.capture(passes=PASSES)
            snapshots.append((snapshot(pair.left), snapshot(pair.right), pair.baseline, pair.dcx))
            rec.add_stereo("rig", pair, passes=ALL_PASSES)
            rec.add_steps(
                {
                    "step": np.arange(world.step_index - 4, world.step_index + 1),
                    "time": np.arange(world.step_index - 4, world.step_index + 1) * 1e-3,
                    "force": np.full((5, 3), float(i)),
                }
            )
            if i == 1:
                removed = remove_visible_sphere(world, volume, pair.left)
                rec.add_removed(removed, volume="ear")
                rec.add_events([{"step": world.step_index, "kind": "critical", "label": 3}])
            rec.flush()  # several parts: reading must join them
    return path, world, snapshots, removed


def remove_visible_sphere(world, volume, frame) -> dict:
    """Removes a 2 mm sphere around the voxel the frame's centre pixel shows; the removal log
    as a drill gives it."""
    seen = frame.voxel[frame.voxel >= 0]
    centre = int(np.median(seen))
    nx, ny, _ = volume.data.shape
    ijk = (centre % nx, (centre // nx) % ny, centre // (nx * ny))
    volume.remove_sphere(volume.voxel_to_world(ijk), 0.002, only_removable=False)
    (edit,) = volume.data.take_edit_log()
    count = len(edit["voxels"])
    assert count > 0
    return {
        "step": np.full(count, world.step_index),
        "voxel": edit["voxels"],
        "label": edit["old_labels"],
    }


def test_round_trip_of_real_stereo_captures_is_exact(drilled_recording):
    path, world, snapshots, removed = drilled_recording
    with open_recording(path) as rec:
        assert rec.version == 1 and rec.complete and len(rec.parts) == 4
        assert rec.software_version == ambfplus.__version__
        assert rec.metadata == {"scene": "phantom(64)", "seed": 0}
        assert rec.legend == world_legend(world)
        assert "OpenCV" in rec.conventions["camera_frame"]
        assert "c + 0.5" in rec.conventions["intrinsics"]
        left, right = rec.cameras["rig_left"], rec.cameras["rig_right"]
        assert len(left) == len(right) == 4 and sorted(left.passes) == sorted(ALL_PASSES)
        for i, (want_left, want_right, baseline, dcx) in enumerate(snapshots):
            assert_frame_equal(left[i], want_left)
            assert_frame_equal(right[i], want_right)
            pair = rec.rigs["rig"][i]
            assert pair.baseline == baseline and pair.dcx == dcx
            assert_frame_equal(pair.left, want_left)
        # Lazy columns read across parts.
        assert left.depth.shape == (4, 48, 64) and left.depth.dtype == np.float32
        assert np.array_equal(left.rgb[1:3], np.stack([s[0]["rgb"] for s in snapshots[1:3]]))
        assert np.array_equal(left.step[[3, 0]], [snapshots[3][0]["step"], snapshots[0][0]["step"]])
        assert np.array_equal(rec.steps["step"], np.arange(1, 21))
        assert rec.steps["force"].shape == (20, 3) and rec.steps["force"][7, 2] == 1.0
        assert rec.removed["volume"] == "ear"
        for name in ("step", "voxel", "label"):
            assert np.array_equal(rec.removed[name], removed[name]), name
        assert rec.removed["voxel"].dtype == np.int32 and rec.removed["label"].dtype == np.uint16
        assert rec.events == [{"step": 10, "kind": "critical", "label": 3, "voxel": (-1, -1, -1)}]
        assert rec.rows("steps") == 20 and rec.rows("removed") == len(removed["step"])
        assert "cameras {rig_left: 4, rig_right: 4}" in repr(rec)


def test_read_groups_reads_several_groups_in_one_pass(drilled_recording):
    """Recording.read_groups: whole columns of several groups in one pass over the parts, equal
    to each column read on its own; reading all of removed and events keeps them as the
    properties give them; a missing group or column is a KeyError naming it."""
    path, _, _, removed = drilled_recording
    with open_recording(path) as rec:
        alone = {name: column[:] for name, column in rec.cameras["rig_left"].columns.items()}
        got = rec.read_groups({"steps": ["step", "force"], "cameras/rig_left": ["step", "pose"],
                               "removed": None, "events": None})  # fmt: skip
        assert sorted(got) == ["cameras/rig_left", "events", "removed", "steps"]
        assert np.array_equal(got["steps"]["step"], np.arange(1, 21))
        assert got["steps"]["force"].shape == (20, 3) and got["steps"]["force"][7, 2] == 1.0
        for name in ("step", "pose"):
            assert np.array_equal(got["cameras/rig_left"][name], alone[name]), name
        for name in ("step", "voxel", "label"):
            assert np.array_equal(got["removed"][name], removed[name]), name
        kept_removed, kept_events = rec.removed, rec.events  # kept by the pass, not read again
        assert kept_removed["volume"] == "ear" and kept_removed["voxel"].dtype == np.int32
        assert kept_events == [{"step": 10, "kind": "critical", "label": 3, "voxel": (-1, -1, -1)}]
        with pytest.raises(KeyError, match="no group 'nothing'"):
            rec.read_groups({"nothing": None})
        with pytest.raises(KeyError, match="steps has no column 'nothing'"):
            rec.read_columns("steps", ["step", "nothing"])
    with open_recording(path) as fresh:  # the properties read alone give the same
        assert fresh.events == kept_events
        for name in ("step", "voxel", "label"):
            assert np.array_equal(fresh.removed[name], kept_removed[name]), name


def test_plain_h5py_reads_the_closed_head_as_one_file(drilled_recording, tmp_path, monkeypatch):
    path, _, snapshots, _ = drilled_recording
    monkeypatch.chdir(tmp_path.parent)  # parts are found beside the head, not in the cwd
    with h5py.File(path, "r") as f:
        # Text attributes are fixed-length UTF-8 strings, which h5py gives as bytes.
        assert f.attrs["format"] == b"ambfplus.recording"
        assert f.attrs["ambfplus_recording_version"] == 1
        assert f.attrs["ambfplus_recording_minor_version"] == 1
        depth = f["cameras/rig_left/depth"]
        assert depth.is_virtual and depth.shape == (4, 48, 64)
        for i, (want, _, baseline, _) in enumerate(snapshots):
            assert np.array_equal(depth[i], want["depth"])
            assert np.array_equal(f["cameras/rig_left/pose"][i], want["pose"])
            assert f["rigs/rig/baseline"][i] == baseline
        assert f["rigs/rig"].attrs["left"].decode() == "rig_left"
        assert json.loads(f.attrs["metadata"])["seed"] == 0
        assert f["events/kind"].asstr()[0] == "critical"


def test_frames_are_copied_before_the_engine_reuses_their_buffers(tmp_path):
    world = ambfplus.World()
    world.add_volume("ear", ambfplus.phantom(64))
    camera = world.add_camera("cam", 64, 48, fov_y=0.7)
    camera.look_at((0.05, -0.08, 0.05), (0.0, 0.0, 0.0))
    frame = camera.capture(passes=["rgb", "depth", "label"])
    first = snapshot_of(frame, ["rgb", "depth", "label"])
    with SlowRecorder(tmp_path / "r.h5", delay=0.2) as rec:
        rec.add_frame("cam", frame)
        camera.look_at((0.0, -0.09, 0.02), (0.0, 0.0, 0.0))
        world.step(1)
        camera.capture(out=frame)  # overwrites the buffers the first frame's arrays view
        assert not np.array_equal(frame.depth, first["depth"])
        rec.add_frame("cam", frame)
    with open_recording(tmp_path / "r.h5") as rec:
        assert rec.cameras["cam"].passes == ["rgb", "depth", "label"]
        for name in ("rgb", "depth", "label"):
            assert np.array_equal(getattr(rec.cameras["cam"][0], name), first[name])
        assert np.array_equal(rec.cameras["cam"][1].depth, frame.depth)


def snapshot_of(frame, names) -> dict:
    return {name: np.array(getattr(frame, name)) for name in names}


class SlowRecorder(Recorder):
    """A recorder whose writer takes ``delay`` seconds per item (a slow disk)."""

    def __init__(self, *args, delay: float, **kwargs) -> None:
        self.delay = delay
        super().__init__(*args, **kwargs)

    def _write(self, item) -> None:
        time.sleep(self.delay)
        super()._write(item)


class FailingRecorder(Recorder):
    """A recorder whose writer fails on its ``fail_at``-th camera frame, after ``delay`` s."""

    def __init__(self, *args, fail_at: int, delay: float = 0.0, **kwargs) -> None:
        self.fail_at, self.delay, self.seen = fail_at, delay, 0
        super().__init__(*args, **kwargs)

    def _write(self, item) -> None:
        if getattr(item, "frames", 0):
            self.seen += 1
            if self.seen == self.fail_at:
                time.sleep(self.delay)
                raise OSError(28, "No space left on device (injected)")
        super()._write(item)


def test_backpressure_blocks_the_producer_and_loses_nothing(tmp_path):
    frame_bytes = synthetic_frame_bytes()
    budget = int(2.5 * frame_bytes)  # two frames fit, the third waits
    delay, count = 0.05, 12
    rec = SlowRecorder(tmp_path / "b.h5", delay=delay, max_pending_bytes=budget)
    start = time.perf_counter()
    for i in range(count):
        rec.add_frame("cam", synthetic_frame(i))
    producer_seconds = time.perf_counter() - start
    rec.close()
    stats = rec.stats
    # The producer had to wait for the writer: about (count - 2) writes of `delay` each.
    assert producer_seconds >= (count - 3) * delay
    assert stats.seconds_blocked >= (count - 3) * delay
    assert stats.blocked_calls >= count - 3
    assert 2 * frame_bytes <= stats.pending_high_water_bytes <= budget
    assert stats.frames_queued == stats.frames_written == stats.frames_flushed == count
    assert stats.bytes_written == stats.bytes_queued == count * frame_bytes
    with open_recording(tmp_path / "b.h5") as read:
        assert len(read.cameras["cam"]) == count
        for i in range(count):
            assert_synthetic(read.cameras["cam"][i], i)


def test_an_item_larger_than_the_whole_budget_still_goes_through(tmp_path):
    with SlowRecorder(tmp_path / "big.h5", delay=0.02, max_pending_bytes=1000) as rec:
        for i in range(3):
            rec.add_frame("cam", synthetic_frame(i))
    assert rec.stats.frames_written == 3
    assert rec.stats.blocked_calls >= 1  # each waited for the previous one to be written


def test_a_writer_error_surfaces_in_the_producer_and_on_close(tmp_path):
    path = tmp_path / "e.h5"
    rec = FailingRecorder(path, fail_at=3)
    rec.add_frame("cam", synthetic_frame(0))
    rec.add_frame("cam", synthetic_frame(1))
    rec.flush()
    rec.add_frame("cam", synthetic_frame(2))  # the writer fails on this one
    with pytest.raises(RecordingError, match="writer thread failed") as error:
        for i in range(3, 100):
            rec.add_frame("cam", synthetic_frame(i))
            time.sleep(0.01)
    assert isinstance(error.value.__cause__, OSError)
    assert str(path) in str(error.value)
    with pytest.raises(RecordingError, match="No space left") as error:
        rec.close()
    assert isinstance(error.value.__cause__, OSError)
    # What was flushed before the failure is intact.
    with open_recording(path) as read:
        assert not read.complete and len(read.cameras["cam"]) == 2
        assert_synthetic(read.cameras["cam"][1], 1)


def test_a_writer_error_wakes_a_blocked_producer(tmp_path):
    budget = int(2.5 * synthetic_frame_bytes())  # two frames fit, the third waits
    rec = FailingRecorder(tmp_path / "w.h5", fail_at=1, delay=0.3, max_pending_bytes=budget)
    outcome = []

    def produce():
        try:
            for i in range(50):
                rec.add_frame("cam", synthetic_frame(i))
        except RecordingError as error:
            outcome.append(error)

    thread = threading.Thread(target=produce)
    thread.start()
    thread.join(timeout=10)
    assert not thread.is_alive(), "the producer stayed blocked after the writer died"
    assert outcome and isinstance(outcome[0].__cause__, OSError)
    assert rec.stats.blocked_calls == 1  # it was waiting for space when the writer died
    with pytest.raises(RecordingError):
        rec.close()


KILLED_WRITER = """
import sys, time
sys.path.insert(0, {tests!r})
from test_recording import synthetic_frame
from ambfplus.recording import Recorder
rec = Recorder({path!r}, metadata={{"run": "sigkill"}}, flush_interval_s=0.05)
reported, i = 0, 0
while True:
    rec.add_frame("cam", synthetic_frame(i))
    rec.add_steps({{"step": 10 * i + 10, "time": 0.001 * (10 * i + 10)}})
    i += 1
    time.sleep(0.002)  # about 25 frames per flush interval
    flushed = rec.stats.frames_flushed
    if flushed != reported:
        reported = flushed
        print(flushed, flush=True)
"""


def test_sigkill_leaves_every_flushed_frame(tmp_path):
    path = tmp_path / "killed.h5"
    code = KILLED_WRITER.format(tests=str(Path(__file__).parent), path=str(path))
    # Run from elsewhere: the source folder (the cwd) holds no compiled engine.
    child = subprocess.Popen(
        [sys.executable, "-c", code], stdout=subprocess.PIPE, text=True, cwd=tmp_path
    )
    try:
        reports = []
        deadline = time.monotonic() + 60
        while len(reports) < 4 and time.monotonic() < deadline:
            line = child.stdout.readline()
            assert line, f"the recording process ended early (code {child.poll()})"
            reports.append(int(line))
        os.kill(child.pid, signal.SIGKILL)  # mid-session, probably mid-write
        child.wait(timeout=10)
    finally:
        if child.poll() is None:
            child.kill()
    assert child.returncode == -signal.SIGKILL
    flushed = reports[-1]
    assert flushed > 0
    with open_recording(path) as rec:
        assert not rec.complete and rec.metadata == {"run": "sigkill"}
        stream = rec.cameras["cam"]
        assert len(stream) >= flushed
        for i in range(len(stream)):
            assert_synthetic(stream[i], i)
        assert len(rec.steps["step"]) >= flushed - 1  # a frame's step row may be in the next part
        assert np.array_equal(rec.steps["step"], 10 * np.arange(len(rec.steps["step"])) + 10)
    report = validate(path)
    assert report.ok and report.checks[0].status == "warn", str(report)
    # repair() writes the virtual datasets, so that plain h5py reads the session too.
    repair(path).close()
    with h5py.File(path, "r") as f:
        assert f.attrs["complete"] and f["cameras/cam/rgb"].shape[0] == len(stream)
        assert np.array_equal(
            f["cameras/cam/rgb"][flushed - 1], synthetic_frame(flushed - 1)["rgb"]
        )


def test_validate_passes_on_a_good_recording(drilled_recording, capsys):
    path = drilled_recording[0]
    report = validate(path)
    assert report.ok, str(report)
    statuses = {check.name: check.status for check in report.checks}
    for name in (
        "cameras/rig_left: points agree with depth",
        "rigs/rig: baseline = distance between poses",
        "rigs/rig: dcx = cx_right - cx_left",
        "removed/label: ids in the volume's label table",
        "cameras/rig_left: removed voxels stay unseen",
        "steps/time increases strictly",
    ):
        assert statuses[name] == "pass", name
    # The check had something to find: the removed voxels were in view before their removal.
    with open_recording(path) as rec:
        nx, ny, _ = rec.legend[1]["shape"]
        v = rec.removed["voxel"].astype(np.int64)
        removed = v[:, 0] + nx * (v[:, 1] + ny * v[:, 2])
        assert np.isin(rec.cameras["rig_left"][1].voxel, removed).sum() > 10
    assert cli_main(["validate", str(path)]) == 0
    assert "OK:" in capsys.readouterr().out


def corrupt(path: Path, part: int, dataset: str, change) -> None:
    """Edits one dataset of a closed part in place."""
    with h5py.File(f"{path}.part{part:04d}", "r+") as f:
        data = f[dataset][...]
        change(data)
        f[dataset][...] = data


@pytest.mark.parametrize(
    "part, dataset, change, failing",
    [
        (3, "cameras/rig_left/time", lambda t: t.fill(0.0), "cameras/rig_left/time increases"),
        (2, "rigs/rig/baseline", lambda b: b.__iadd__(1e-5), "rigs/rig: baseline"),
        (1, "rigs/rig/dcx", lambda d: d.__iadd__(0.5), "rigs/rig: dcx"),
        (4, "cameras/rig_right/points", lambda p: p.__imul__(1.001), "cameras/rig_right: points"),
        (2, "removed/label", lambda label: label.fill(99), "removed/label: ids"),
        (2, "steps/step", lambda s: s.fill(3), "steps/step increases"),
    ],
    ids=["time", "baseline", "dcx", "points", "removed-label", "steps"],
)
def test_validate_names_the_check_a_corruption_breaks(
    drilled_recording, capsys, part, dataset, change, failing
):
    path = drilled_recording[0]
    corrupt(path, part, dataset, change)
    report = validate(path)
    assert not report.ok
    assert [c.name for c in report.failed if c.name.startswith(failing)], str(report)
    assert all(c.name.startswith(failing) for c in report.failed), str(report)
    assert cli_main(["validate", str(path)]) == 1
    out = capsys.readouterr().out
    assert f"FAIL  {failing}" in out and "FAILED" in out


def test_validate_sees_a_removed_voxel_that_is_still_visible(drilled_recording):
    path = drilled_recording[0]
    with open_recording(path) as rec:
        last = rec.cameras["rig_left"][3]
        nx, ny, _ = rec.legend[1]["shape"]
    visible = np.unique(last.voxel[(last.voxel >= 0) & (last.label > 0)])[:5]
    ijk = np.stack([visible % nx, (visible // nx) % ny, visible // (nx * ny)], axis=1)
    with h5py.File(f"{path}.part0002", "r+") as f:  # claim they were removed at step 10
        removed = f["removed"]
        start = removed["step"].shape[0]
        for name in ("step", "voxel", "label"):
            removed[name].resize(start + len(visible), axis=0)
        removed["step"][start:] = 10
        removed["voxel"][start:] = ijk
        removed["label"][start:] = 1
    report = validate(path)
    failed = {c.name: c for c in report.failed}
    assert set(failed) <= {
        f"cameras/rig_{s}: removed voxels stay unseen" for s in ("left", "right")
    }
    detail = failed["cameras/rig_left: removed voxels stay unseen"].detail
    assert "first in frame 2" in detail or "first in frame 3" in detail


def test_a_recording_without_volume_shapes_skips_the_visibility_check(tmp_path):
    world, volume, rig = ear_scene()
    path = tmp_path / "s.h5"
    with Recorder(path) as rec:
        rec.set_legend(ambfplus.labels.legend(world))  # no shapes
        world.step(1)
        pair = rig.capture(passes=PASSES)
        rec.add_frame("left", pair.left)
        rec.add_removed(remove_visible_sphere(world, volume, pair.left), volume="ear")
    checks = {c.name: c for c in validate(path).checks}
    assert checks["cameras/left: removed voxels stay unseen"].status == "skip"
    assert "shape" in checks["cameras/left: removed voxels stay unseen"].detail
    assert checks["removed/label: ids in the volume's label table"].status == "pass"


def write_plain_hdf5(path: Path, **attrs) -> None:
    with h5py.File(path, "w") as f:
        f.create_dataset("x", data=np.arange(3))
        f.attrs.update(attrs)


def test_reader_refuses_files_that_are_not_recordings(tmp_path):
    plain = tmp_path / "plain.h5"
    write_plain_hdf5(plain)
    with pytest.raises(RecordingError, match=r"plain\.h5: not an ambfplus recording.*'format'"):
        open_recording(plain)
    future = tmp_path / "future.h5"
    write_plain_hdf5(future, format="ambfplus.recording", ambfplus_recording_version=7)
    with pytest.raises(RecordingError, match=r"future\.h5: recording version 7 .* version 1"):
        open_recording(future)
    garbage = tmp_path / "garbage.h5"
    garbage.write_bytes(os.urandom(4096))
    with pytest.raises(RecordingError, match=r"garbage\.h5: not a readable HDF5 file"):
        open_recording(garbage)
    with pytest.raises(ValueError):  # RecordingError is a ConfigError, a ValueError
        open_recording(garbage)
    assert isinstance(RecordingError("x"), ambfplus.ConfigError)
    report = validate(garbage)
    assert not report.ok and report.checks[0].name == "open"


def small_recording(path: Path, frames: int = 3) -> None:
    with Recorder(path) as rec:
        for i in range(frames):
            rec.add_frame("cam", synthetic_frame(i))
            rec.flush()


def test_reader_names_a_truncated_part(tmp_path):
    path = tmp_path / "t.h5"
    small_recording(path)
    part = Path(f"{path}.part0002")
    data = part.read_bytes()
    part.write_bytes(data[: len(data) // 2])
    with pytest.raises(RecordingError, match=r"t\.h5\.part0002: not a readable HDF5 file"):
        open_recording(path)
    assert cli_main(["validate", str(path)]) == 1


def test_reader_names_a_missing_part(tmp_path):
    path = tmp_path / "m.h5"
    small_recording(path)
    Path(f"{path}.part0002").unlink()
    with pytest.raises(RecordingError, match=r"m\.h5\.part0002: missing"):
        open_recording(path)
    Path(f"{path}.part0003").unlink()  # now only the index says parts are missing
    with pytest.raises(RecordingError, match=r"lists 3 parts but 1 are on disk"):
        open_recording(path)


def test_reader_names_a_dataset_of_inconsistent_length(tmp_path):
    path = tmp_path / "l.h5"
    small_recording(path)
    with h5py.File(f"{path}.part0002", "r+") as f:
        f["cameras/cam/time"].resize(2, axis=0)
    with pytest.raises(RecordingError, match=r"l\.h5\.part0002: inconsistent lengths.*cam/time"):
        open_recording(path)
    (check,) = validate(path).checks
    assert check.status == "fail" and "cameras/cam/time" in check.detail


def test_reader_refuses_a_part_opened_as_a_head(tmp_path):
    path = tmp_path / "p.h5"
    small_recording(path, frames=1)
    with pytest.raises(RecordingError, match="one part of a recording"):
        open_recording(f"{path}.part0001")


def test_a_stream_keeps_its_passes_shapes_and_dtypes(tmp_path):
    with Recorder(tmp_path / "s.h5") as rec:
        rec.add_frame("cam", synthetic_frame(0))
        other = synthetic_frame(1)
        del other["label"]
        with pytest.raises(ValueError, match=r"cameras/cam: datasets .* differ"):
            rec.add_frame("cam", other)
        with pytest.raises(ValueError, match=r"cameras/cam: rgb: .* differs"):
            rec.add_frame("cam", synthetic_frame(2, height=12))
        lossy = synthetic_frame(3)
        lossy["depth"] = lossy["depth"].astype(np.float64)
        with pytest.raises(ValueError, match=r"cameras/cam/depth: cannot store float64"):
            rec.add_frame("cam", lossy)
        with pytest.raises(ValueError, match=r"has no 'voxel'"):
            rec.add_frame("cam", synthetic_frame(4), passes=["rgb", "voxel"])
    with open_recording(tmp_path / "s.h5") as read:
        assert len(read.cameras["cam"]) == 1


def test_steps_events_and_removed_inputs_are_checked(tmp_path):
    with Recorder(tmp_path / "s.h5") as rec:
        with pytest.raises(ValueError, match=r"'time'"):
            rec.add_steps({"step": [1, 2]})
        rec.add_steps({"step": [1, 2], "time": [0.001, 0.002], "mode": ["a", "b"]})
        with pytest.raises(ValueError, match="different lengths"):
            rec.add_steps({"step": [3, 4], "time": [0.003], "mode": ["c", "d"]})
        with pytest.raises(ValueError, match=r"steps: datasets"):
            rec.add_steps({"step": [3], "time": [0.003]})
        rec.add_steps({"step": 3, "time": 0.003, "mode": "c"})  # scalars: one row
        with pytest.raises(ValueError, match="'step' and 'kind'"):
            rec.add_events([{"step": 1, "kind": "x", "force": 3.0}])
        with pytest.raises(ValueError, match=r"removed/voxel: cannot store"):
            rec.add_removed({"step": 1, "voxel": np.full((2, 3), 2**40), "label": [1, 1]})
        rec.add_removed({"step": 4, "voxel": np.ones((2, 3), np.int64), "label": [1, 2]})
        rec.add_events([{"step": 4, "kind": "burr", "voxel": (1, 2, 3)}])
    with open_recording(tmp_path / "s.h5") as read:
        assert list(read.steps["mode"]) == ["a", "b", "c"]
        assert np.array_equal(read.steps["step"], [1, 2, 3])
        assert np.array_equal(read.removed["step"], [4, 4]) and read.removed["volume"] is None
        assert read.events == [{"step": 4, "kind": "burr", "label": 0, "voxel": (1, 2, 3)}]


def test_stereo_pairs_of_mappings_and_rig_indices_after_single_frames(tmp_path):
    path = tmp_path / "pairs.h5"
    with Recorder(path) as rec:
        rec.add_frame("left", synthetic_frame(0) | {"camera": "left"})  # an unpaired frame first
        for i in (1, 2):
            left = synthetic_frame(i) | {"camera": "left"}
            right = synthetic_frame(i + 10) | {"camera": "right", "step": left["step"]}
            right["time"] = left["time"]
            rec.add_stereo("rig", ambfplus.stereo.StereoFrame(left, right, 0.01, 2.5))
    with open_recording(path) as read:
        rig = read.rigs["rig"]
        assert len(rig) == 2 and len(read.cameras["left"]) == 3
        assert np.array_equal(rig.left_index[:], [1, 2]) and np.array_equal(
            rig.right_index[:], [0, 1]
        )
        assert_synthetic(rig[1].left, 2)
        assert np.array_equal(rig[1].right.rgb, synthetic_frame(12)["rgb"])
        assert rig[0].baseline == 0.01 and rig[0].dcx == 2.5


@pytest.mark.parametrize("compression", ["blosc-lz4", "lzf", "gzip", None])
def test_layout_chunks_one_frame_and_compresses_as_asked(tmp_path, compression):
    path = tmp_path / "c.h5"
    frame = synthetic_frame(0) | {"depth": np.full((24, 32), 0.25, np.float32)}
    with Recorder(path, compression=compression) as rec:
        for _ in range(2):
            rec.add_frame("cam", frame)
        rec.add_steps({"step": np.arange(3), "time": np.arange(3) * 1e-3})
    with h5py.File(f"{path}.part0001", "r") as f:
        depth, rgb, time_ = (f[f"cameras/cam/{n}"] for n in ("depth", "rgb", "time"))
        assert depth.chunks == (1, 24, 32) and rgb.chunks == (1, 24, 32, 3)
        assert depth.maxshape == (None, 24, 32) and time_.maxshape == (None,)
        assert f["steps/step"].maxshape == (None,) and f["steps/step"].chunks == (3,)
        if compression == "blosc-lz4":
            # HDF5 filter 32001 (Blosc): LZ4 (codec 1), byte shuffle (1) only for multi-byte types.
            for dataset, shuffle in ((depth, 1), (rgb, 0), (time_, 1)):
                blosc = dataset._filters["32001"]
                assert blosc[5:7] == (shuffle, 1), blosc
        else:
            assert depth.compression == rgb.compression == time_.compression == compression
            assert depth.shuffle == (compression is not None) and not rgb.shuffle
        if compression:
            assert depth.id.get_storage_size() < depth.size * 4 / 10  # a constant compresses
        assert np.array_equal(depth[1], frame["depth"]) and np.array_equal(rgb[1], frame["rgb"])
    with pytest.raises(ValueError, match="compression must be one of"):
        Recorder(tmp_path / "x.h5", compression="zstd")


def test_an_existing_recording_is_not_overwritten_unless_asked(tmp_path):
    path = tmp_path / "o.h5"
    small_recording(path)
    with pytest.raises(FileExistsError, match="o.h5"):
        Recorder(path)
    with Recorder(path, overwrite=True) as rec:
        rec.add_frame("cam", synthetic_frame(7))
    with open_recording(path) as read:
        assert len(read.parts) == 1 and len(read.cameras["cam"]) == 1
        assert_synthetic(read.cameras["cam"][0], 7)


def test_a_recorder_left_open_is_completed_when_the_interpreter_exits(tmp_path):
    path = tmp_path / "open.h5"
    code = (
        "import numpy as np\n"
        "from ambfplus.recording import Recorder\n"
        f"rec = Recorder({str(path)!r}, flush_interval_s=100)\n"
        "rec.add_steps({'step': np.arange(5), 'time': np.arange(5) * 1e-3})\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tmp_path, timeout=60)
    with open_recording(path) as rec:
        assert rec.complete and np.array_equal(rec.steps["step"], np.arange(5))


@pytest.mark.parametrize("slow_writer_s", [0.0, 0.05])
def test_a_sigkill_loses_at_most_one_flush_interval_of_simulation_time(tmp_path, slow_writer_s):
    """A drilling session that simulates faster than real time, its writer fast or starved (50
    ms per append: the queue outgrew it before, and a kill lost everything queued), killed once
    it reached 1.6 s: what its recording holds reaches within one flush interval (0.5 s) of
    where the simulation was. The first part closed within the interval of the start."""
    import sys

    sys.path.insert(0, str(Path(__file__).parents[1]))
    from helpers.killed_session import kill_session

    result = kill_session(tmp_path, 1.6, flush=0.5, slow_writer_s=slow_writer_s)
    assert result["reached"] >= 1.6 and result["recorded"] > 0, result
    assert result["loss"] <= 0.5, result


def test_the_recorder_keeps_queued_rows_within_the_crash_bound(tmp_path, monkeypatch):
    """Whatever the writer's pace, a producer never gets more than 0.9 of the flush interval of
    simulation time past the last closed part: add_* waits for the writer."""
    import ambfplus.recording.writer as writer

    append = writer._PartFile.append

    def slow_append(self, rows):
        time.sleep(0.01)
        return append(self, rows)

    monkeypatch.setattr(writer._PartFile, "append", slow_append)
    with Recorder(tmp_path / "bound.h5", flush_interval_s=0.2) as rec:
        for i in range(120):  # 1.2 s of simulation in 10 ms rows, far faster than the writer
            rec.add_steps({"step": [i + 1], "time": [0.01 * (i + 1)]})
            assert rec._queued_time - rec._durable_time <= writer.BLOCK_AFTER * 0.2 + 1e-12
        assert rec.stats.blocked_calls > 0  # the bound held because add_steps waited
    with open_recording(tmp_path / "bound.h5") as done:
        assert len(done.parts) >= 6 and len(done.steps["step"]) == 120


def test_step_columns_of_namespaced_objects_round_trip(tmp_path):
    # A namespaced object's column holds '/', which HDF5 reads as a path: stored escaped
    # ('%2F', and '%' as '%25'), read back as written, in the head and in every part.
    path = tmp_path / "ns.h5"
    names = ["psm1/link.pose", "odd%2Fname.v", "plain.v"]
    rows = {"step": np.arange(6, dtype=np.int64), "time": np.arange(6) * 0.001}
    rows.update({name: np.arange(6, dtype=float) * (i + 1) for i, name in enumerate(names)})
    with Recorder(path, flush_interval_s=0.001) as rec:
        for start in range(0, 6, 2):
            rec.add_steps({k: v[start : start + 2] for k, v in rows.items()})
    with open_recording(path) as rec:
        assert len(rec.parts) >= 2
        assert set(rec.steps) == {"step", "time", *names}
        for name in names:
            np.testing.assert_array_equal(rec.steps[name], rows[name])
        assert set(rec.read_columns("steps", names)) == set(names)
    with h5py.File(path) as f:
        assert set(f["steps"]) == {"step", "time", "psm1%2Flink.pose", "odd%252Fname.v", "plain.v"}
        np.testing.assert_array_equal(f["steps/psm1%2Flink.pose"][()], rows["psm1/link.pose"])
    assert validate(path).ok
