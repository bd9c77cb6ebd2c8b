"""Live skill metrics: the engine feeds them at every step, and they equal the offline
assessment of the session's recording (the same code, fed from the recording)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import ambfplus
from ambfplus.scenes import record_session
from ambfplus.training import NOVICE, assess, load_task, novice_like, task_setup
from ambfplus.training.trainees import _trainee_on_phantom

TASK = {
    "version": 1,
    "name": "Live",
    "anatomy": {"phantom": {"resolution": 128, "seed": 0}},
    "target": {"labels": ["Bone"], "box": {"min": [-10, -8, 7.5], "max": [1, 8, 13]}},
    "protect": [
        {"structure": "Facial_Nerve", "margin": 1.0},
        {"structure": "EAC", "margin": 2.0},
    ],
}


def same(live, offline, path="summary"):
    """Equal, floats to 1e-9 relative (sums of the same terms may round differently)."""
    if isinstance(live, dict):
        assert live.keys() == offline.keys(), path
        for key in live:
            same(live[key], offline[key], f"{path}.{key}")
    elif isinstance(live, list):
        assert len(live) == len(offline), path
        for i, (a, b) in enumerate(zip(live, offline)):
            same(a, b, f"{path}[{i}]")
    elif isinstance(live, float) and not (math.isinf(live) or offline is None):
        assert live == pytest.approx(offline, rel=1e-9, abs=1e-12), path
    else:
        assert live == offline, path


def test_live_metrics_equal_the_offline_assessment(tmp_path):
    task = load_task(TASK)
    setup = task_setup(task, NOVICE)
    scene, device = _trainee_on_phantom(novice_like, 4, 6.0, setup["protect"], 128,
                                        setup["region"], 0.03, setup["burr"], 160, 120)  # fmt: skip
    data = scene.drill.volume.data
    live = ambfplus.live_metrics(scene.drill, protect=task.protect_config(data),
                                 target_mask=task.target_mask(data),
                                 excess_force=task.excess_force)  # fmt: skip
    path = tmp_path / "live.h5"
    record_session(scene, path, device, 6.0, capture_every=200, passes=("depth",))
    summary = live.summary()
    assert summary["ticks"] == 6000 and sum(summary["removed_by_label"].values()) > 100
    assert any(s["contacts"] for s in summary["structures"])  # the novice came near the canal
    offline = assess(path, task).data["metrics"]
    offline.pop("removed_by_name")
    same(summary, offline)
    # The fields followed the drilling on the offline schedule, waited for when late.
    waits = live.field_waits
    assert waits["count"] >= 0 and (waits["seconds"] > 0) == (waits["count"] > 0), waits
    costs = live.tick_cpu_seconds
    assert len(costs) == 6000 and np.all(costs >= 0)


def test_the_replay_takes_the_burr_centres_the_live_metrics_took_bit_for_bit():
    """With the volume turned, NumPy's inverse of its pose differs from the engine's in the last
    bits; the replay takes the burr centres from the live metrics' own computation, so that a
    clearance, and a near tie between two ticks' clearances, falls the same live and offline."""
    from ambfplus.training.metrics import burr_in_volume, drill_ticks
    from ambfplus.transforms import make_pose

    scene = ambfplus.scenes.drilling_phantom(resolution=32, width=64, height=48)
    drill, volume = scene.drill, scene.drill.volume
    volume.pose = make_pose((0.003, -0.002, 0.001), rpy=(0.31, -0.27, 0.93))
    protect = [{"labels": "Facial_Nerve", "margin": 0.001}]
    live = ambfplus.live_metrics(drill, protect=protect)
    poses = []
    for _ in range(5):
        scene.world.step(1)
        poses.append(np.asarray(drill.pose, float).copy())
    n = len(poses)
    steps = {"step": np.arange(n), "time": np.arange(n) * 0.001,
             f"{drill.key}.pose": np.stack(poses).reshape(n, 16),
             f"{drill.key}.force": np.zeros((n, 3)), f"{drill.key}.on": np.zeros((n, 1)),
             f"{drill.key}.burr": np.full((n, 1), drill.burr)}  # fmt: skip
    removed = {"step": np.zeros(0, np.int64), "voxel": np.zeros((0, 3), np.int32),
               "label": np.zeros(0, np.uint16)}  # fmt: skip
    pose = np.asarray(volume.pose, float)
    tips = drill_ticks(steps, removed, drill.key, drill.burr_diameters, pose)["tips"]
    centres = np.stack(poses)[:, :3, 3]
    np.testing.assert_array_equal(tips, burr_in_volume(pose, centres))
    inverse = np.linalg.inv(pose)
    assert np.any(centres @ inverse[:3, :3].T + inverse[:3, 3] != tips), "the bits do differ"
    # The same centre and the same field: the same clearance, to the last bit.
    offline = ambfplus.SkillMetrics(volume.data, protect=protect)
    distance = live.clearances()[0]["distance"]
    assert distance == offline.clearance(0, tips[-1], drill.burr_radius)


def test_live_metrics_check_their_config_and_count_every_step():
    scene = ambfplus.scenes.drilling_phantom(resolution=32, width=64, height=48)
    with pytest.raises(ambfplus.NotFound, match="Facial nerve"):
        ambfplus.live_metrics(scene.drill, protect=[{"labels": "Facial nerve", "margin": 0.001}])
    live = ambfplus.live_metrics(scene.drill, protect=[{"labels": "Facial_Nerve"}])
    scene.world.step(5)
    later = ambfplus.live_metrics(scene.drill, excess_force=1.0)
    scene.world.step(7)
    assert live.active and live.summary()["ticks"] == 12 and later.summary()["ticks"] == 7
    assert live.summary()["total_time"] == pytest.approx(0.012)


def test_the_replay_takes_each_updated_field_at_the_step_the_live_metrics_took_it(tmp_path):
    # The live metrics log the steps at which they took a protected structure's updated field
    # ("<drill>.metrics_fields"); in a real-time loop those follow the background work, and the
    # replay takes each field at the logged step, whatever the schedule would say.
    from ambfplus.recording import open_recording
    from ambfplus.training.metrics import drill_ticks

    task = load_task({**TASK, "protect": [{"structure": "Bone", "margin": 1.0}]})
    setup = task_setup(task, NOVICE)

    def scene_and_device():
        return _trainee_on_phantom(novice_like, 4, 2.0, setup["protect"], 128,
                                   setup["region"], 0.03, setup["burr"], 160, 120)  # fmt: skip

    scene, device = scene_and_device()
    drill = scene.drill
    live = ambfplus.live_metrics(drill, protect=task.protect_config(drill.volume.data))
    path = tmp_path / "live.h5"
    record_session(scene, path, device, 2.0, capture_every=500, passes=("depth",))
    with open_recording(path) as rec:
        steps, removed = dict(rec.steps), rec.removed
    taken = np.asarray(steps[f"{drill.name}.metrics_fields"]).reshape(2000, -1)
    assert taken.shape == (2000, 1) and int((taken > 0).sum()) >= 5  # drilling bone: updates
    ticks = drill_ticks(steps, removed, drill.name, drill.burr_diameters, drill.volume.pose)
    np.testing.assert_array_equal(ticks["fields_taken"], taken)

    def replay(fields_taken):
        anatomy = scene_and_device()[0].drill.volume.data  # the anatomy as it began
        metrics = ambfplus.SkillMetrics(anatomy, protect=task.protect_config(anatomy),
                                        apply_removals=True)  # fmt: skip
        metrics.add_ticks(**{**ticks, "fields_taken": fields_taken})
        return metrics.summary()

    same(live.summary(), replay(taken))
    # The first field taken 30 steps later than logged (as a slower machine would): the replay
    # follows, and measures otherwise. (The later updates start as the first was taken, so they
    # are still under way at their logged steps.)
    first = int(np.flatnonzero(taken[:, 0])[0])
    late = taken.copy()
    late[first + 30], late[first] = taken[first], 0.0
    delayed = replay(late)["structures"][0]
    assert delayed != live.summary()["structures"][0]
    # A schedule naming a structure the metrics lack is refused.
    with pytest.raises(ambfplus.ArgumentError, match="protected structure 1"):
        replay(np.where(taken > 0, 2.0, 0.0))
