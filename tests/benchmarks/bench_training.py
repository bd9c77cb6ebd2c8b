"""Training: how well the skill metrics tell scripted experts from novices, and what measuring a
long session costs.

    python tests/benchmarks/run.py --only training_discrimination
    python tests/benchmarks/run.py --only training_offline_metrics

training_discrimination: 20 expert-like and 20 novice-like sessions (seeds 100.. and 200..,
none of the tests' seeds) of 20 s on the 128^3 phantom; for each metric, the ROC AUC of telling
the groups apart in the metric's expected direction (1.0: every novice worse than every expert).

training_offline_metrics: a 10-minute session at 1 kHz (a novice-like trainee plunging for 600 s
on the 128^3 phantom), then its skill metrics computed offline from its step log and removed
voxels, replayed onto a fresh phantom: CPU seconds of that computation (target for the whole
assessment: 20 s), and per tick.
"""

from __future__ import annotations

import time

import numpy as np

import ambfplus
from ambfplus.training import Protect, drill_phantom, expert_like, novice_like, session_metrics

RESOLUTION = 128
PROTECT = (
    Protect("facial nerve", ("Facial_Nerve",), 0.001),
    Protect("sinus and dura", ("Sinus_Dura",), 0.0008),
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


BENCHMARKS = {
    "training_discrimination": discrimination,
    "training_offline_metrics": offline_metrics,
}
