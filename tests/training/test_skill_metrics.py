"""Skill metrics from Python (ambfplus.SkillMetrics): one tick at a time and a recording's
ticks at once run the same engine code and agree; bad input is named."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus


def bone_with_nerve() -> ambfplus.VolumeData:
    labels = np.ones((40, 40, 40), dtype=np.uint8)
    labels[20:22, 20:22, :] = 2
    table = [
        ambfplus.Label(1, "Bone", (230, 230, 200)),
        ambfplus.Label(2, "Facial_Nerve", (250, 210, 40)),
    ]
    return ambfplus.VolumeData(labels, dimensions=(0.004, 0.004, 0.004), label_table=table)


def session(n: int = 400):
    """A straight stroke at 10 mm/s along x, 1 mm from the nerve, removing one bone voxel a tick."""
    steps = np.arange(n)
    times = (steps + 1) * 0.001
    tips = np.zeros((n, 3))
    tips[:, 0] = -0.002 + 0.01 * 0.001 * steps
    tips[:, 1] = 0.00105
    forces = np.tile([0.0, 0.0, 1.5], (n, 1))
    radii = np.full(n, 0.0005)
    on = np.ones(n, dtype=bool)
    removed_tick = steps[::2]
    removed = np.stack(
        [5 + removed_tick % 30, np.full_like(removed_tick, 5), removed_tick // 30], 1
    )
    return steps, times, tips, forces, radii, on, removed_tick, removed.astype(np.int32)


def test_ticks_one_by_one_equal_ticks_at_once():
    steps, times, tips, forces, radii, on, removed_tick, removed = session()
    protect = [{"name": "facial nerve", "labels": "Facial_Nerve", "margin": 0.001}]
    labels = np.ones(len(removed_tick), dtype=np.uint16)
    one = ambfplus.SkillMetrics(bone_with_nerve(), protect=protect, target_labels=["Bone"])
    for k in range(len(steps)):
        rows = removed[removed_tick == k]
        one.add(
            steps[k],
            times[k],
            0.001,
            tips[k],
            forces[k],
            radii[k],
            on[k],
            rows if len(rows) else None,
            np.ones(len(rows), np.uint16) if len(rows) else None,
        )
    many = ambfplus.SkillMetrics(bone_with_nerve(), protect=protect, target_labels=["Bone"])
    many.add_ticks(steps, times, 0.001, tips, forces, radii, on, removed_tick, removed, labels)
    a, b = one.summary(), many.summary()
    assert a == b
    # Cutting every other tick stays one stroke (gaps under 50 ms), 10 mm/s for 0.4 s.
    assert len(a["strokes"]) == 1
    assert a["strokes"][0]["length"] == pytest.approx(0.01 * 0.001 * 398, abs=1e-12)
    assert a["cutting_time"] == pytest.approx(0.2)
    assert a["removed_by_label"] == {1: 200} and a["removed_in_target"] == 200
    nerve = a["structures"][0]
    assert nerve["name"] == "facial nerve" and nerve["voxels_removed"] == 0
    # The burr's centre (y = 1.05 mm) passes 0.9 mm from the nearest nerve voxel centres
    # (y = 0.15 mm, along all of z): 0.4 mm from its surface, first where x meets their column.
    assert nerve["closest"] == pytest.approx(0.0004, abs=1e-9)
    assert tips[nerve["closest_step"], 0] == pytest.approx(0.00005, abs=0.01 * 0.001)
    assert nerve["contacts"] == 1


def test_bad_ticks_and_protect_entries_are_named():
    data = bone_with_nerve()
    with pytest.raises(ambfplus.ArgumentTypeError, match="unknown key 'margn'"):
        ambfplus.SkillMetrics(data, protect=[{"labels": 2, "margn": 0.001}])
    with pytest.raises(ambfplus.NotFound, match="'Sinus'"):
        ambfplus.SkillMetrics(data, protect=[{"labels": "Sinus"}])
    metrics = ambfplus.SkillMetrics(data)
    steps, times, tips, forces, radii, on, removed_tick, removed = session(10)
    with pytest.raises(ambfplus.ArgumentError, match="tips must have 10 rows of 3"):
        metrics.add_ticks(
            steps,
            times,
            0.001,
            tips[:5],
            forces,
            radii,
            on,
            removed_tick,
            removed,
            np.ones(len(removed_tick), np.uint16),
        )
    with pytest.raises(
        ambfplus.ArgumentError,
        match="removed_tick must be sorted indices of the ticks given \\(0..1\\), got 2 at row 1",
    ):
        metrics.add_ticks(
            steps[:2],
            times[:2],
            0.001,
            tips[:2],
            forces[:2],
            radii[:2],
            on[:2],
            removed_tick,
            removed,
            np.ones(len(removed_tick), np.uint16),
        )
    assert metrics.summary()["ticks"] == 0  # a bad batch adds nothing
