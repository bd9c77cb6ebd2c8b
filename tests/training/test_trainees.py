"""Scripted trainees drill the built-in phantom like an expert or like a novice, and the skill
metrics of their sessions (computed offline from the step log, by the engine) tell them apart."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus
from ambfplus.training import Protect, drill_phantom, expert_like, novice_like, session_metrics

RESOLUTION = 96
PROTECT = (
    Protect("facial nerve", ("Facial_Nerve",), 0.001),
    Protect("sinus and dura", ("Sinus_+_Dura",), 0.0008),
    Protect("chorda tympani", ("Chorda_Tympani",), 0.0005),
)


def drill_session(make, seed: int, seconds: float = 12.0) -> dict:
    protect = [(p.name, p.labels[0], p.margin) for p in PROTECT]
    session = drill_phantom(make, seed, seconds, protect, resolution=RESOLUTION)
    drill = session.drill
    return session_metrics(
        ambfplus.phantom(RESOLUTION),
        session.steps,
        session.removed,
        drill=drill.name,
        burr_diameters=drill.burr_diameters,
        volume_pose=drill.volume.pose,
        protect=PROTECT,
        target_labels=["Bone"],
    )


def stroke_mean(summary: dict, key: str) -> float:
    return float(np.mean([s[key] for s in summary["strokes"]]))


@pytest.fixture(scope="module")
def sessions():
    return {
        "expert": [drill_session(expert_like, seed) for seed in (1, 2)],
        "novice": [drill_session(novice_like, seed) for seed in (1, 2)],
    }


@pytest.mark.slow
def test_every_session_drills_and_is_measured(sessions):
    for group in sessions.values():
        for summary in group:
            assert summary["removed_in_target"] > 200
            assert summary["strokes"] and summary["cutting_time"] > 0.5
            assert len(summary["structures"]) == 3


def test_experts_press_lighter_stroke_longer_and_straighter_and_keep_their_margins(sessions):
    expert, novice = sessions["expert"], sessions["novice"]
    # Each expert session against each novice session, metric by metric.
    for e in expert:
        for n in novice:
            assert e["cutting_force_p95"] < n["cutting_force_p95"]
            assert stroke_mean(e, "length") > stroke_mean(n, "length")
            assert stroke_mean(e, "straightness") > stroke_mean(n, "straightness")
    for e in expert:
        for structure in e["structures"]:
            assert structure["contacts"] == 0 and structure["voxels_removed"] == 0
            assert structure["closest"] > structure["margin"]
