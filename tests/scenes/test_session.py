"""Recorded drilling sessions and their replay: the same removal log, forces and images from the
recorded device readings, and the session re-rendered with another stereo baseline."""

from __future__ import annotations

import numpy as np
import pytest
from helpers.drilling import plunge_and_cut

from ambfplus.recording import open_recording, validate
from ambfplus.scenes import drilling_phantom, orbit_view, record_session, replay
from ambfplus.stereo import disparity_agreement


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    """1.5 s of the phantom scene at 320x240: a scripted plunge and a sideways cut, the rig
    circling; a stereo frame every 100 steps."""
    path = tmp_path_factory.mktemp("session") / "s.h5"
    scene = drilling_phantom(resolution=96, width=320, height=240)
    device = plunge_and_cut(scene)
    summary = record_session(
        scene, path, device, seconds=1.5, capture_every=100, camera_motion=orbit_view
    )
    return path, summary


def test_a_recorded_session_validates_and_holds_what_happened(session):
    path, summary = session
    assert summary["frames"] == 15 and summary["voxels_removed"] > 100
    report = validate(path)
    assert report.ok, str(report)
    # The voxel visibility check ran: removed voxels never show in later frames.
    assert any(c.name.endswith("removed voxels stay unseen") and c.status == "pass"
               for c in report.checks)  # fmt: skip
    with open_recording(path) as rec:
        steps = rec.steps
        assert steps["step"].tolist() == list(range(1, 1501))
        assert steps["hand.position"].shape == (1500, 3)
        assert steps["drill.on"].dtype == bool and steps["drill.on"][-1]
        assert len(rec.removed["step"]) == summary["voxels_removed"]
        assert rec.metadata["scene"]["builder"] == "drilling_phantom"
        left = rec.rigs["rig"][14].left
        assert left.segmentation.shape == (240, 320, 3) and (left.label > 0).any()
        # The rig moved between frames.
        first, last = rec.rigs["rig"][0].left.pose, left.pose
        assert np.linalg.norm(first[:3, 3] - last[:3, 3]) > 0.01


def test_replay_gives_the_same_removal_forces_and_images(session):
    path, summary = session
    report = replay(path)
    assert report.removal_identical and report.forces_identical, report.differences
    assert report.images_identical == report.frames == 15
    assert report.voxels_removed == summary["voxels_removed"]


def test_a_session_recorded_with_shadows_antialiasing_and_looks_replays_to_its_images(tmp_path):
    """The rig's rendering options are part of the scene's spec: the replay draws them too."""
    path = tmp_path / "looks.h5"
    options = {"shadows": True, "antialiasing": 2, "looks": True}
    scene = drilling_phantom(resolution=64, width=160, height=120, **options)
    summary = record_session(
        scene, path, plunge_and_cut(scene), seconds=0.3, capture_every=100,
        camera_motion=orbit_view,
    )  # fmt: skip
    with open_recording(path) as rec:
        params = rec.metadata["scene"]["params"]
        assert {key: params[key] for key in options} == options
        recorded = rec.rigs["rig"][0].left.rgb
    plain = drilling_phantom(resolution=64, width=160, height=120)
    plain.rig.aim(*orbit_view(0.0))
    assert (plain.rig.left.capture(passes=["rgb"]).rgb != recorded).any(axis=-1).sum() > 100
    report = replay(path)
    assert report.images_identical == report.frames == summary["frames"] == 3


def test_replay_with_another_baseline_renders_that_baseline(session, tmp_path):
    path, _ = session
    out = tmp_path / "wide.h5"
    report = replay(path, out=out, baseline=0.03, width=640, height=480)
    assert report.removal_identical and report.images_identical is None
    assert validate(out).ok
    with open_recording(out) as rec, open_recording(path) as original:
        pair = rec.rigs["rig"][7]
        assert pair.baseline == pytest.approx(0.03)
        # The rig's midpoint is where the recorded one was.
        old = original.rigs["rig"][7]
        mid = lambda p: (p.left.pose[:3, 3] + p.right.pose[:3, 3]) / 2  # noqa: E731
        np.testing.assert_allclose(mid(pair), mid(old), atol=1e-12)
        agreement = disparity_agreement(pair, step=6)
    assert agreement["points"] > 200
    # Bone is smooth in places (wrong matches there); most matches agree with depth.
    assert agreement["median_error"] <= 1.0
    # The baseline recovered from the re-rendered images: B = (d + dcx) Z / f.
    assert agreement["baseline"] == pytest.approx(0.03, rel=0.01)


def test_a_recording_without_device_readings_cannot_be_replayed(tmp_path):
    from ambfplus.recording import Recorder

    path = tmp_path / "bare.h5"
    scene = drilling_phantom(resolution=48, width=64, height=48)
    meta = {"scene": scene.spec, "device": {"name": "hand", "options": {}}}
    with Recorder(path, metadata=meta) as rec:
        rec.add_stereo("rig", scene.rig.capture(("rgb",)))
        rec.add_steps({"step": [1], "time": [0.001]})
    with pytest.raises(ValueError, match="no readings of device 'hand'"):
        replay(path)


def test_validate_catches_images_that_disagree_with_depth_and_baseline(session, tmp_path):
    """The right views replaced by the left ones: geometry and lengths still agree, but block
    matching no longer gives the disparity the depth and baseline predict."""
    import shutil

    import h5py

    path, _ = session
    for part in path.parent.glob(path.name + "*"):
        shutil.copy(part, tmp_path / part.name)
    copy = tmp_path / path.name
    for part in sorted(tmp_path.glob(path.name + ".part*")):
        with h5py.File(part, "r+") as f:
            f["cameras/rig_right/rgb"][...] = f["cameras/rig_left/rgb"][...]
    report = validate(copy)
    failed = [c.name for c in report.failed]
    assert failed == ["rigs/rig: disparity from depth and baseline matches the images"], failed


def test_replay_refuses_what_it_could_never_reproduce(session, tmp_path):
    """A NaN in the step log equals nothing a replay computes; a recording with no scene in
    its metadata has nothing to rebuild: both are RecordingErrors naming what is wrong."""
    import shutil

    import h5py

    from ambfplus.recording import RecordingError

    path, _ = session
    for part in path.parent.glob(path.name + "*"):
        shutil.copy(part, tmp_path / part.name)
    copy = tmp_path / path.name
    first = tmp_path / (path.name + ".part0001")
    with h5py.File(first, "r+") as f:
        f["steps/hand.position"][7, 2] = np.nan
    with pytest.raises(RecordingError, match=r"cannot replay steps/hand.position row 7 holds"):
        replay(copy)
    with h5py.File(copy, "r+") as f:
        f.attrs["metadata"] = np.array(b"{}", dtype=h5py.string_dtype("utf-8", 2))
    with pytest.raises(RecordingError, match="its metadata has no scene or device"):
        replay(copy)
