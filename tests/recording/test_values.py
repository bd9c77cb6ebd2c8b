"""The value rules (ambfplus.recording.values): validate fails a recording holding one bad value,
naming the frame (or step row) and the value; the exports refuse it, leaving nothing, or skip and
count it; replay refuses what it could never reproduce."""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from ambfplus.recording import Recorder, validate
from ambfplus.recording.values import Rules, pose_problem, rigid

LEGEND = {
    1: {"name": "anatomy", "kind": "volume", "shape": [10, 10, 10],
        "labels": {1: {"name": "Bone"}, 3: {"name": "Facial_Nerve"}}},
    2: {"name": "ball", "kind": "body"},
    3: {"name": "drill", "kind": "drill"},
}  # fmt: skip
STEPS = np.arange(1, 31)


def frame(step: int) -> dict:
    rng = np.random.default_rng(step)
    return {
        "camera": "cam", "time": step * 1e-3, "step": step, "pose": np.eye(4),
        "intrinsics": np.array([[6.0, 0, 4.0], [0, 6.0, 3.0], [0, 0, 1]]),
        "rgb": rng.integers(0, 256, (6, 8, 3), dtype=np.uint8),
        "depth": rng.uniform(0.2, 0.3, (6, 8)).astype(np.float32),
        "label": rng.choice(np.array([0, 1, 3], np.uint16), (6, 8)),
        "instance": rng.choice(np.array([0, 1, 2], np.int32), (6, 8)),
        "voxel": rng.integers(-1, 1000, (6, 8)).astype(np.int32),
    }  # fmt: skip


def steps() -> dict:
    poses = np.tile(np.eye(4), (len(STEPS), 1, 1))
    return {"step": STEPS, "time": STEPS * 1e-3, "drill.pose": poses,
            "drill.force": np.zeros((len(STEPS), 3))}  # fmt: skip


def record(path, damage_frame=None, damage_steps=None):
    """Three frames (steps 10, 20, 30) and a step log; `damage_frame` changes frame 1's dict,
    `damage_steps` the step log."""
    log = steps()
    if damage_steps:
        damage_steps(log)
    with Recorder(path, metadata={"scene": {"builder": "test"}}) as rec:
        rec.set_legend(LEGEND)
        for i, step in enumerate((10, 20, 30)):
            f = frame(step)
            if i == 1 and damage_frame:
                damage_frame(f)
            rec.add_frame("cam", f)
        rec.add_steps(log)
    return path


def set_pixel(name, value):
    def damage(f):
        f[name][2, 3] = value

    return damage


def set_item(name, value):
    def damage(f):
        f[name] = value

    return damage


def scaled_pose(f):
    f["pose"] = np.diag([2.0, 1.0, 1.0, 1.0])


def nan_force(log):
    log["drill.force"][4, 1] = np.nan


def sheared_pose(log):
    log["drill.pose"][6][0, 1] = 0.5


FRAME_CASES = {
    "NaN depth": (set_pixel("depth", np.nan), "depth nan at row 2, column 3"),
    "negative depth": (set_pixel("depth", -0.5), "depth -0.5 at row 2, column 3"),
    "infinite depth": (set_pixel("depth", np.inf), "depth inf at row 2, column 3"),
    "NaN time": (set_item("time", np.nan), "time nan"),
    "pose not a rotation": (scaled_pose, "a pose whose rotation is not one"),
    "zero intrinsics": (set_item("intrinsics", np.zeros((3, 3))), "no positive focal lengths"),
    "label not in the table": (set_pixel("label", 2), "label 2 at row 2, column 3 not in"),
    "instance id not in the legend": (
        set_pixel("instance", 2**31 - 1),
        "instance 2147483647 at row 2, column 3 not in the legend",
    ),
    "voxel outside the volume": (set_pixel("voxel", 1000), "voxel index 1000 at row 2, column 3"),
}


def test_an_undamaged_recording_passes_every_value_check(tmp_path):
    report = validate(record(tmp_path / "good.h5"), match_images=False)
    assert report.ok, str(report)
    assert any(c.name == "cameras/cam: frame values" and c.status == "pass" for c in report.checks)


@pytest.mark.parametrize("case", FRAME_CASES)
def test_validate_names_the_frame_and_the_value(tmp_path, case):
    damage, named = FRAME_CASES[case]
    report = validate(record(tmp_path / "bad.h5", damage_frame=damage), match_images=False)
    assert not report.ok
    failed = {c.name: c.detail for c in report.failed}
    detail = failed["cameras/cam: frame values"]
    assert detail.startswith("frame 1 (step 20): ") and named in detail, detail


@pytest.mark.parametrize(
    ("damage", "named"),
    [
        (nan_force, "steps/drill.force row 4 holds [ 0. nan  0.]"),
        (sheared_pose, "steps/drill.pose row 6 is a pose whose rotation is not one"),
    ],
)
def test_validate_names_the_step_row_and_the_value(tmp_path, damage, named):
    report = validate(record(tmp_path / "bad.h5", damage_steps=damage), match_images=False)
    failed = {c.name: c.detail for c in report.failed}
    assert named in failed["steps: values finite, poses rigid"], failed


def test_validate_fails_a_head_without_metadata(tmp_path):
    path = record(tmp_path / "bare.h5")
    with h5py.File(path, "r+") as f:
        del f.attrs["metadata"]
    failed = {c.name: c.detail for c in validate(path, match_images=False).failed}
    assert "no metadata attribute" in failed["metadata"]


def test_the_rigid_rule_agrees_with_pose_problem():
    rng = np.random.default_rng(3)
    poses = []
    for _ in range(50):
        q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        pose = np.eye(4)
        pose[:3, :3] = q * np.sign(np.linalg.det(q))  # a rotation
        pose[:3, 3] = rng.normal(size=3)
        poses.append(pose)
    bad = [p.copy() for p in poses[:4]]
    bad[0][:3, :3] *= 1.01  # a scale
    bad[1][:3, 0] *= -1  # a reflection
    bad[2][3, 0] = 0.1  # not affine
    bad[3][1, 2] = np.nan
    everything = np.array(poses + bad)
    assert rigid(everything).tolist() == [True] * 50 + [False] * 4
    assert [pose_problem(p) is None for p in everything] == rigid(everything).tolist()


def test_rules_read_the_legend():
    class Recording:
        legend = LEGEND
        metadata: dict = {}

    rules = Rules.of(Recording())
    assert rules.ids.tolist() == [1, 2, 3] and rules.labels.tolist() == [0, 1, 3]
    assert rules.voxels == 1000


@pytest.mark.parametrize(
    ("to", "options"),
    [("mcap", {"point_clouds": False}), ("coco", {}), ("original-h5", {})],
)
def test_exports_refuse_a_bad_frame_or_skip_and_count_it(tmp_path, to, options):
    pytest.importorskip("mcap")
    pytest.importorskip("pycocotools")
    from ambfplus.export import ExportError, export

    good = export(record(tmp_path / "good.h5"), tmp_path / "good", to, **options)
    path = record(tmp_path / "bad.h5", damage_frame=set_pixel("depth", np.nan))
    out = tmp_path / "out"
    with pytest.raises(ExportError, match=r"cameras/cam frame 1: depth nan at row 2, column 3"):
        export(path, out, to, **options)
    assert not out.exists()
    skipped = export(path, out, to, bad_frames="skip", **options)
    assert skipped.frames == good.frames - 1 == 2
    assert skipped.details["skipped_frames"] == 1 and good.details["skipped_frames"] == 0
    with pytest.raises(ExportError, match="bad_frames must be one of refuse, skip"):
        export(path, tmp_path / "x", to, bad_frames="drop", **options)


def test_an_export_refuses_a_bad_step_row_or_skips_it(tmp_path):
    pytest.importorskip("mcap")
    from ambfplus.export import ExportError, export

    path = record(tmp_path / "bad.h5", damage_steps=nan_force)
    with pytest.raises(ExportError, match=r"steps/drill.force row 4 holds \[ 0. nan  0.\]"):
        export(path, tmp_path / "out.mcap", "mcap")
    result = export(path, tmp_path / "out.mcap", "mcap", bad_frames="skip")
    assert result.details["skipped_steps"] == 1 and result.details["skipped_frames"] == 0


@pytest.mark.parametrize("episodes", ["1e12", "1000001", "-1", "2.5", "true", '"6"'])
def test_a_dataset_whose_environment_claims_absurd_episodes_fails_fast(tmp_path, episodes):
    """validate once built the set of 0..episodes-1 (1e12 exhausted memory)."""
    import resource

    from ambfplus.dataset.check import validate_dataset

    (tmp_path / "environment.json").write_text(f'{{"episodes": {episodes}}}')
    (tmp_path / "manifest.jsonl").write_text("")
    from ambfplus import ConfigError

    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(
        ConfigError, match=r"environment.json: episodes is .*, not a whole number in 0..1000000"
    ):
        validate_dataset(tmp_path)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before < 100_000  # KiB
