"""Training: skill metrics, scripted trainees and (to come) tasks, assessment and reports.

The metrics themselves are computed by the engine (``ambfplus.SkillMetrics``), live in the
haptic loop and offline from a recording through the same code; the structures they watch are
``ambfplus.DistanceField`` objects that follow the drilling.
"""

from .metrics import Protect, drill_ticks, session_metrics
from .trainees import (
    EXPERT,
    NOVICE,
    ProtectedField,
    ScriptedTrainee,
    TraineeSession,
    TraineeStyle,
    TrainingRegion,
    drill_phantom,
    expert_like,
    novice_like,
)

__all__ = [
    "Protect",
    "drill_ticks",
    "session_metrics",
    "EXPERT",
    "NOVICE",
    "ProtectedField",
    "ScriptedTrainee",
    "TraineeStyle",
    "TraineeSession",
    "TrainingRegion",
    "drill_phantom",
    "expert_like",
    "novice_like",
]
