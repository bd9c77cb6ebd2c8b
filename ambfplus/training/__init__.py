"""Training: tasks, skill metrics, assessment against a task and expert references, debrief
reports, and scripted trainees.

The metrics themselves are computed by the engine (``ambfplus.SkillMetrics``), live in the
haptic loop and offline from a recording through the same code; the structures they watch are
``ambfplus.DistanceField`` objects that follow the drilling. ``assess`` reads any recording the
package makes, against a ``Task`` (``load_task``; two ship with the package, ``BUILTIN_TASKS``).
"""

from .assess import Assessment, SessionData, assess, default_task, load_session
from .cavity import cavity_mask, compare_cavities, exposure
from .metrics import Protect, drill_ticks, session_metrics
from .rubric import RubricItem, composite, rubric
from .task import BUILTIN_TASKS, RUBRIC_DEFAULTS, Task, TaskError, builtin_task, load_task
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
    record_trainee,
    task_setup,
)
from .visibility import burr_visible, visibility

__all__ = [
    "Assessment",
    "SessionData",
    "assess",
    "default_task",
    "load_session",
    "cavity_mask",
    "compare_cavities",
    "exposure",
    "Protect",
    "drill_ticks",
    "session_metrics",
    "RubricItem",
    "composite",
    "rubric",
    "BUILTIN_TASKS",
    "RUBRIC_DEFAULTS",
    "Task",
    "TaskError",
    "builtin_task",
    "load_task",
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
    "record_trainee",
    "task_setup",
    "burr_visible",
    "visibility",
]
