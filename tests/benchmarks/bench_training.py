"""Training: how well the skill metrics tell scripted experts from novices, and what measuring a
long session costs.

    python tests/benchmarks/run.py --only training_discrimination
    python tests/benchmarks/run.py --only training_offline_metrics
    python tests/benchmarks/run.py --only assessment_discrimination
    python tests/benchmarks/run.py --only assessment_speed
    python tests/benchmarks/run.py --only live_metrics_tick

training_discrimination: 20 expert-like and 20 novice-like sessions (seeds 100.. and 200..,
none of the tests' seeds) of 20 s on the 128^3 phantom; for each metric, the ROC AUC of telling
the groups apart in the metric's expected direction (1.0: every novice worse than every expert).

training_offline_metrics: a 10-minute session at 1 kHz (a novice-like trainee plunging for 600 s
on the 128^3 phantom), then its skill metrics computed offline from its step log and removed
voxels, replayed onto a fresh phantom: CPU seconds of that computation (target for the whole
assessment: 20 s), and per tick.

assessment_discrimination: on each shipped task (cortical mastoidectomy, facial recess), 20
expert-like and 20 novice-like recorded sessions of 20 s (seeds 100.. and 200..; stereo depth at
10 Hz, 160x120), assessed against the task with completion not judged (a 20 s excerpt completes
neither the target nor the skeletonisation): the ROC AUC of the composite score, and of each
rubric item's score (the direction every item is expected to move in: an expert scores higher).

assessment_speed: a 10-minute novice-like session at 1 kHz with stereo at 20 Hz (320x240 rgb,
depth and labels) recorded on the 128^3 phantom, then assessed against the cortical
mastoidectomy task (metrics, target, exposure, burr visibility from every frame with cutting,
rubric, timeline): CPU seconds (median and worst of 3), target 20 s; and the report on top.

live_metrics_tick: what live skill metrics add to a haptic tick, measured in C++ (the thread's
CPU time around each tick's metrics, LiveMetrics.tick_cpu_seconds) over the last 16384 ticks of
a 20 s novice-like session on the cortical mastoidectomy task (three protected structures, the
target mask): median, p99 and max; target p99 <= 5 us.
"""

from __future__ import annotations

import shutil
import tempfile
import time
from pathlib import Path

import numpy as np

import ambfplus
from ambfplus.training import (
    BUILTIN_TASKS,
    Protect,
    assess,
    builtin_task,
    drill_phantom,
    expert_like,
    novice_like,
    record_trainee,
    session_metrics,
)

RESOLUTION = 128
PROTECT = (
    Protect("facial nerve", ("Facial_Nerve",), 0.001),
    Protect("sinus and dura", ("Sinus_+_Dura",), 0.0008),
    Protect("chorda tympani", ("Chorda_Tympani",), 0.0005),
)
PROTECT_LABELS = [(p.name, p.labels[0], p.margin) for p in PROTECT]


def run_session(make, seed: int, seconds: float):
    session = drill_phantom(make, seed, seconds, PROTECT_LABELS, resolution=RESOLUTION)
    return session.drill, session.steps, session.removed


def measure(drill, steps, removed) -> dict:
    return session_metrics(
        ambfplus.phantom(RESOLUTION),
        steps,
        removed,
        drill=drill.name,
        burr_diameters=drill.burr_diameters,
        volume_pose=drill.volume.pose,
        protect=PROTECT,
        target_labels=["Bone"],
    )


# Each metric with the direction in which a novice is expected to be worse (+1: larger).
METRICS = {
    "cutting_force_p95": (+1, lambda s: s["cutting_force_p95"]),
    "time_above_excess_force": (+1, lambda s: s["time_above_excess_force"]),
    "mean_stroke_length": (-1, lambda s: np.mean([k["length"] for k in s["strokes"]] or [0])),
    "mean_straightness": (-1, lambda s: np.mean([k["straightness"] for k in s["strokes"]] or [0])),
    "contacts": (+1, lambda s: sum(k["contacts"] for k in s["structures"])),
    "time_in_margins": (+1, lambda s: sum(k["time_in_margin"] for k in s["structures"])),
    "closest_approach": (-1, lambda s: min(k["closest"] for k in s["structures"])),
    "critical_voxels_removed": (+1, lambda s: sum(k["voxels_removed"] for k in s["structures"])),
}


def auc(worse: list[float], better: list[float]) -> float:
    """P(a novice's value is worse than an expert's), ties counting half (Mann-Whitney)."""
    wins = sum((w > b) + 0.5 * (w == b) for w in worse for b in better)
    return wins / (len(worse) * len(better))


def discrimination(args):
    n = 6 if args.quick else 20
    started = time.process_time()
    groups = {
        "expert": [measure(*run_session(expert_like, 100 + k, 20.0)) for k in range(n)],
        "novice": [measure(*run_session(novice_like, 200 + k, 20.0)) for k in range(n)],
    }
    figures = {}
    for name, (sign, value) in METRICS.items():
        novice = [sign * float(value(s)) for s in groups["novice"]]
        expert = [sign * float(value(s)) for s in groups["expert"]]
        figures[name] = round(auc(novice, expert), 4)
    yield {
        "benchmark": "training_discrimination",
        "metric_auc": figures,
        "worst_metric_auc": min(figures.values()),
        "sessions_per_group": n,
        "cpu_s": round(time.process_time() - started, 2),
        "what": "ROC AUC of each skill metric telling 20 s novice-like from expert-like scripted "
        "sessions on the 128^3 phantom, in the metric's expected direction",
        "quick": args.quick,
    }


def offline_metrics(args):
    seconds = 120.0 if args.quick else 600.0
    drill, steps, removed = run_session(novice_like, 7, seconds)
    ticks = len(steps["step"])
    rounds = []
    for _ in range(3):
        started = time.process_time()
        summary = measure(drill, steps, removed)
        rounds.append(time.process_time() - started)
    worst, median = max(rounds), float(np.median(rounds))
    yield {
        "benchmark": "training_offline_metrics",
        "session_s": seconds,
        "ticks": ticks,
        "voxels_removed": int(len(removed["step"])),
        "cpu_s": round(median, 3),
        "worst_cpu_s": round(worst, 3),
        "us_per_tick": round(1e6 * median / ticks, 3),
        "strokes": len(summary["strokes"]),
        "what": "skill metrics of a 1 kHz session computed offline from its step log and "
        "removed voxels (three protected structures, replayed onto a fresh 128^3 phantom); "
        "median and worst of 3 rounds, process CPU time",
        "quick": args.quick,
    }


def assessment_discrimination(args):
    n = 6 if args.quick else 20
    folder = Path(tempfile.mkdtemp(prefix="ambfplus-assess-"))
    try:
        for name in BUILTIN_TASKS:
            # Completion (of the target, of skeletonisation) is not judged on 20 s excerpts.
            task = builtin_task(name).with_thresholds(
                min_target_fraction=0.0, min_exposed_fraction=0.0
            )
            started = time.process_time()
            results = {"expert": [], "novice": []}
            for group, make, base in (("expert", expert_like, 100), ("novice", novice_like, 200)):
                for k in range(n):
                    path = folder / f"{name}_{group}_{k}.h5"
                    record_trainee(make, base + k, 20.0, path, task, capture_every=100,
                                   passes=("depth", "label"), width=160, height=120)  # fmt: skip
                    results[group].append(assess(path, task).data)
            items = {}
            for key in [i["key"] for i in results["expert"][0]["rubric"]]:

                def score(d, key=key):
                    item = next(i for i in d["rubric"] if i["key"] == key)
                    return item["score"] if item["score"] is not None else 0.5

                items[key] = round(auc([score(d) for d in results["expert"]],
                                       [score(d) for d in results["novice"]]), 4)  # fmt: skip
            composite = auc([d["score"] for d in results["expert"]],
                            [d["score"] for d in results["novice"]])  # fmt: skip
            scores = {g: [round(d["score"], 1) for d in results[g]] for g in results}
            yield {
                "benchmark": "assessment_discrimination",
                "task": name,
                "composite_auc": round(composite, 4),
                "target": 0.95,
                "item_auc": items,
                "items_against_direction": sorted(k for k, v in items.items() if v < 0.5),
                "expert_score_median": float(np.median(scores["expert"])),
                "expert_score_min": min(scores["expert"]),
                "novice_score_median": float(np.median(scores["novice"])),
                "novice_score_max": max(scores["novice"]),
                "sessions_per_group": n,
                "cpu_s": round(time.process_time() - started, 2),
                "what": "ROC AUC of the composite score (and of each rubric item's score) telling "
                "20 s expert-like from novice-like recorded sessions on a shipped task; 0.5 is "
                "chance, items at 0.5 do not vary between the groups",
                "quick": args.quick,
            }
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def assessment_speed(args):
    seconds = 120.0 if args.quick else 600.0
    folder = Path(tempfile.mkdtemp(prefix="ambfplus-assess-"))
    try:
        task = builtin_task("cortical_mastoidectomy")
        path = folder / "long.h5"
        started = time.process_time()
        summary = record_trainee(
            novice_like, 7, seconds, path, task, capture_every=50,
            passes=("rgb", "depth", "label"), width=320, height=240,
        )  # fmt: skip
        record_cpu = time.process_time() - started
        rounds, report = [], []
        for _ in range(3):
            started = time.process_time()
            result = assess(path, task)
            rounds.append(time.process_time() - started)
            started = time.process_time()
            result.write_report(folder / "report.html")
            report.append(time.process_time() - started)
        yield {
            "benchmark": "assessment_speed",
            "session_s": seconds,
            "frames": summary["frames"],
            "voxels_removed": summary["voxels_removed"],
            "cpu_s": round(float(np.median(rounds)), 3),
            "worst_cpu_s": round(max(rounds), 3),
            "target_cpu_s": 20.0,
            "report_cpu_s": round(float(np.median(report)), 3),
            "report_worst_cpu_s": round(max(report), 3),
            "visibility_frames": result.data["visibility"]["frames"],
            "record_cpu_s": round(record_cpu, 1),
            "what": "assessing a 1 kHz session with 20 Hz stereo (320x240 rgb, depth, labels) on "
            "the 128^3 phantom against the cortical mastoidectomy task; median and worst of 3, "
            "process CPU time; the report (renders of the cavity) on top",
            "quick": args.quick,
        }
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def live_metrics_tick(args):
    from ambfplus.training import NOVICE, task_setup
    from ambfplus.training.trainees import _trainee_on_phantom

    seconds = 8.0 if args.quick else 20.0
    task = builtin_task("cortical_mastoidectomy")
    setup = task_setup(task, NOVICE)
    scene, device = _trainee_on_phantom(novice_like, 11, seconds, setup["protect"],
                                        setup["resolution"], setup["region"], 0.03,
                                        setup["burr"], 160, 120)  # fmt: skip
    world, drill = scene.world, scene.drill
    data = drill.volume.data
    live = ambfplus.live_metrics(drill, protect=task.protect_config(data),
                                 target_mask=task.target_mask(data),
                                 excess_force=task.excess_force)  # fmt: skip
    world.add_input_device(scene.device_name, device, drill, **scene.device_options)
    world.step(int(round(seconds / world.time_step)))
    costs = np.asarray(live.tick_cpu_seconds) * 1e6
    drill_costs = np.asarray(drill.tick_cpu_seconds)[-len(costs) :] * 1e6
    yield {
        "benchmark": "live_metrics_tick",
        "ticks": int(len(costs)),
        "us_median": round(float(np.median(costs)), 3),
        "us_p99": round(float(np.percentile(costs, 99)), 3),
        "us_max": round(float(costs.max()), 3),
        "target_us_p99": 5.0,
        "drill_tick_us_median": round(float(np.median(drill_costs)), 3),
        "drill_tick_us_p99": round(float(np.percentile(drill_costs, 99)), 3),
        "voxels_removed": int(sum(live.summary()["removed_by_label"].values())),
        "what": "CPU time live skill metrics add to each haptic tick (C++, thread CPU clock), "
        "last 16384 ticks of a novice-like session on the cortical mastoidectomy task; the "
        "drill's own tick beside it",
        "quick": args.quick,
    }


BENCHMARKS = {
    "live_metrics_tick": live_metrics_tick,
    "training_discrimination": discrimination,
    "training_offline_metrics": offline_metrics,
    "assessment_discrimination": assessment_discrimination,
    "assessment_speed": assessment_speed,
}
