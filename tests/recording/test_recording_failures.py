"""Recordings when things go wrong: a disk that fills during a session ends it with a
RecordingError, keeps every frame up to the last flush and leaves a process that exits cleanly,
whichever way the recorder is closed; a recording cut inside a stereo pair is flagged; files an
interrupted recorder left are reported and removed by repair; a replay reproduces the
recording's columns, forces included, and names its device."""

from __future__ import annotations

import errno
import json
import os
import shutil
import subprocess
import sys
import textwrap
import uuid
from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus.recording import (
    Recorder,
    RecordingError,
    open_recording,
    repair,
    validate,
)
from ambfplus.recording.reader import scan_parts

# Writes frames until the disk is full, then closes the recorder the way argv[2] says and
# prints what happened as JSON. With argv[3] == "engine" the frames are real captures. Frames
# come at a camera's pace (at least 2 ms apart, up to 24 MB/s), so that some parts close before
# the 5 MB disk is full: a part is written to disk as it fills, and the one a failed write
# meets is dropped whole (the recording ends at its last closed part).
FILL_DISK = textwrap.dedent("""
    import gc, json, sys, time
    import numpy as np
    import ambfplus
    from ambfplus.recording import Recorder, RecordingError

    path, order, source = sys.argv[1], sys.argv[2], sys.argv[3]
    rng = np.random.default_rng(0)
    if source == "engine":
        world = ambfplus.World()
        world.add_body("box", "box", size=(0.1, 0.1, 0.1), mass=0.0)
        camera = world.add_camera("cam", 96, 72, fov_y=0.8, near=0.01, far=5.0)
        camera.look_at((0.4, 0.2, 0.3), (0, 0, 0))
    def frame(i):
        time.sleep(0.002)
        if source == "engine":
            world.step(1)
            return camera.capture()
        return {"rgb": rng.integers(0, 255, (72, 96, 3), dtype=np.uint8),
                "depth": rng.random((72, 96), dtype=np.float32), "time": i * 0.001, "step": i,
                "intrinsics": np.eye(3), "pose": np.eye(4)}
    rec = Recorder(path, flush_interval_s=0.05, compression=None)
    error = None
    try:
        for i in range(100000):
            rec.add_frame("cam", frame(i), passes=["rgb", "depth"])
            rec.add_steps({"step": [i], "time": [i * 0.001]})
    except RecordingError as e:
        error = e
    flushed = rec.stats.frames_flushed
    again = []
    if order == "flush-close":
        for call in (rec.flush, rec.close):
            try:
                call()
            except RecordingError as e:
                again.append(type(e).__name__)
    elif order == "close-twice":
        for call in (rec.close, rec.close):
            try:
                call()
            except RecordingError as e:
                again.append(type(e).__name__)
    elif order == "del":
        del rec
        gc.collect()
    elif order == "context":
        try:
            with rec:
                pass
        except RecordingError as e:
            again.append(type(e).__name__)
    # "exit": left for the interpreter's exit
    print(json.dumps({"error": type(error).__name__ if error else None,
                      "message": str(error), "flushed": flushed, "again": again}), flush=True)
""")


@pytest.fixture
def small_disk():
    """A 5 MB tmpfs of its own (needs root), unmounted afterwards."""
    if shutil.which("mount") is None or os.geteuid() != 0:
        pytest.skip("mounting a small tmpfs needs root and mount(8)")
    folder = Path("/tmp") / f"ambfplus-small-disk-{uuid.uuid4().hex[:8]}"
    folder.mkdir()
    done = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=5m", "tmpfs", str(folder)],
        capture_output=True, text=True,
    )  # fmt: skip
    if done.returncode != 0:
        folder.rmdir()
        pytest.skip(f"cannot mount a tmpfs here: {done.stderr.strip()}")
    try:
        yield folder
    finally:
        subprocess.run(["umount", str(folder)], check=False)
        folder.rmdir()


def fill_disk(folder: Path, order: str, source: str = "recorder") -> dict:
    """Runs FILL_DISK in its own process; checks its exit and the recording it leaves."""
    path = folder / "session.h5"
    done = subprocess.run(
        [sys.executable, "-c", FILL_DISK, str(path), order, source],
        capture_output=True, text=True, timeout=300, cwd=folder,
    )  # fmt: skip
    assert done.returncode == 0, f"exit code {done.returncode}:\n{done.stdout}\n{done.stderr}"
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["error"] == "RecordingError", result
    assert "No space left on device" in result["message"] or "28" in result["message"], result
    assert result["flushed"] > 0
    # Readable up to its last flush: at least what was flushed before the error.
    with open_recording(path) as rec:
        frames = len(rec.cameras["cam"])
        assert frames >= result["flushed"]
        assert len(rec.steps["step"]) >= frames - 1  # each step row follows its frame
        assert not rec.complete
    report = validate(path, match_images=False)
    assert report.ok, str(report)
    return {**result, "frames": frames}


@pytest.mark.parametrize("order", ["flush-close", "close-twice", "context", "del", "exit"])
def test_disk_full_ends_with_an_error_and_a_clean_exit(small_disk, order):
    result = fill_disk(small_disk, order)
    if order in ("flush-close", "close-twice", "context"):
        assert result["again"] and set(result["again"]) == {"RecordingError"}


def test_disk_full_while_filming_the_engine(small_disk):
    fill_disk(small_disk, "exit", source="engine")


@pytest.mark.benchmark
def test_disk_full_ten_times(small_disk):
    """The disk-full session, repeated 10 times in fresh processes (run with -m benchmark)."""
    for run in range(10):
        for leftover in small_disk.iterdir():
            leftover.unlink()
        fill_disk(small_disk, ("exit", "close-twice")[run % 2], ("recorder", "engine")[run % 2])


# Cut recordings ---------------------------------------------------------------------------------


def frame(camera: str, step: int, x: float) -> dict:
    pose = np.eye(4)
    pose[0, 3] = x
    return {
        "camera": camera, "time": step * 0.001, "step": step,
        "rgb": np.zeros((4, 6, 3), np.uint8), "depth": np.ones((4, 6), np.float32),
        "intrinsics": np.array([[5.0, 0, 3], [0, 5, 2], [0, 0, 1]]), "pose": pose,
    }  # fmt: skip


class Pair:
    def __init__(self, step: int):
        self.left, self.right = frame("left", step, 0.0), frame("right", step, 0.065)
        self.baseline, self.dcx, self.time, self.step = 0.065, 0.0, step * 0.001, step


def test_validate_flags_a_stereo_pair_cut_in_half(tmp_path):
    path = tmp_path / "cut.h5"
    with Recorder(path) as rec:
        for step in range(1, 6):
            rec.add_stereo("rig", Pair(step))
        rec.add_frame("left", frame("left", 6, 0.0))  # a left view whose right half was lost
    report = validate(path, match_images=False)
    failed = [check.name for check in report.failed]
    assert failed == ["rigs/rig: both views of every pair recorded"], str(report)
    assert "has 6 frames and right 5" in str(report)


def test_a_part_boundary_never_splits_a_stereo_pair(tmp_path):
    path = tmp_path / "pairs.h5"
    with Recorder(path, flush_interval_s=1e-6) as rec:  # a new part after nearly every item
        for step in range(1, 40):
            rec.add_stereo("rig", Pair(step))
    with open_recording(path) as recording:
        parts = scan_parts(path, recording.recording_id)
    assert len(parts) > 5
    for part in parts:
        rows = {name: group.rows for name, group in part.groups.items()}
        assert rows.get("cameras/left") == rows.get("cameras/right") == rows.get("rigs/rig")
    assert validate(path, match_images=False).ok


@pytest.mark.parametrize("code", [errno.ENOSPC, errno.EIO])
def test_a_failed_write_ends_the_recording_at_its_last_closed_part(tmp_path, monkeypatch, code):
    """Writes to disk that fail in the middle of a part (a short write, then an error) end the
    recording with a RecordingError at its last closed part, with no .tmp left; HDF5 never sees
    the error (the part's writes go on in memory). Needs no root, unlike the full tmpfs above."""
    budget = {"bytes": None}
    pwrite = os.pwrite

    def failing_pwrite(fd, data, offset):
        if budget["bytes"] is None:
            return pwrite(fd, data, offset)
        if budget["bytes"] <= 0:
            raise OSError(code, os.strerror(code))
        written = pwrite(fd, memoryview(data)[: budget["bytes"]], offset)
        budget["bytes"] -= written
        return written

    monkeypatch.setattr(os, "pwrite", failing_pwrite)
    path = tmp_path / "failing.h5"
    rec = Recorder(path, flush_interval_s=100.0, compression=None)
    for step in range(1, 6):
        rec.add_stereo("rig", Pair(step))
    rec.flush()
    budget["bytes"] = 3000
    with pytest.raises(RecordingError, match=os.strerror(code)):
        for step in range(6, 100):
            rec.add_stereo("rig", Pair(step))
            rec.flush()
    for _ in range(2):
        with pytest.raises(RecordingError):
            rec.close()
    monkeypatch.undo()
    assert not list(tmp_path.glob("*.tmp"))
    with open_recording(path) as recording:
        assert len(recording.rigs["rig"]) == 5 and not recording.complete
    assert validate(path, match_images=False).ok


def test_leftover_temporary_files_are_reported_and_repair_removes_them(tmp_path):
    path = tmp_path / "killed.h5"
    with Recorder(path) as rec:
        rec.add_stereo("rig", Pair(1))
    leftover = tmp_path / "killed.h5.part0002.tmp"
    leftover.write_bytes(b"half a part")
    report = validate(path, match_images=False)
    check = next(c for c in report.checks if c.name == "no unfinished files")
    assert check.status == "warn" and "killed.h5.part0002.tmp" in check.detail
    assert report.ok
    repair(path)
    assert not leftover.exists()
    check = next(
        c for c in validate(path, match_images=False).checks if c.name == "no unfinished files"
    )
    assert check.status == "pass"


# Replay ----------------------------------------------------------------------------------------


def test_replay_reproduces_every_step_column_and_names_its_device(tmp_path):
    from ambfplus.scenes import drilling_phantom, record_session, replay

    scene = drilling_phantom(resolution=40, width=64, height=48)
    hand = ambfplus.SimulatedDevice()
    hand.set_target((0.0, 0.0, -0.03), buttons=1)
    original = tmp_path / "original.h5"
    record_session(scene, original, hand, seconds=0.4, capture_every=100)
    copy = tmp_path / "replayed.h5"
    report = replay(original, out=copy)
    assert report.removal_identical and report.forces_identical
    with open_recording(original) as a, open_recording(copy) as b:
        force = [k for k in a.steps if k.endswith(".force")]
        assert len(force) >= 2  # the drill's and the device's
        assert np.count_nonzero(a.steps[f"{scene.device_name}.force"]) > 0
        for column in a.steps:
            assert np.array_equal(a.steps[column], b.steps[column]), column
        assert b.metadata["device"]["kind"] == "ReplayDevice"
        assert b.metadata["device"]["replays"]["kind"] == "SimulatedDevice"
        assert b.metadata["replay_of"] == str(original)
