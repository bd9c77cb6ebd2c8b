"""Skill metrics of a session from its step log and removed voxels: the offline path, which
feeds the ticks to the same engine code (``ambfplus.SkillMetrics``) the live path uses.

The step log and removed voxels are what ``World.take_step_log`` and ``Drill.take_removed``
return and what a recording stores: the drill's columns ``<drill>.pose`` (4x4 world-from-drill,
the burr centre at its origin), ``.force``, ``.on`` and ``.burr`` at every step, and each removed
voxel with its step and label.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from .._core import SkillMetrics, VolumeData, burr_in_volume
from ..recording.ticks import drill_columns, removed_ticks, tick_seconds


@dataclass(frozen=True)
class Protect:
    """A structure to protect: a label name or id (or several) and a margin in metres."""

    name: str
    labels: tuple
    margin: float

    def as_dict(self) -> dict:
        return {"name": self.name, "labels": list(self.labels), "margin": self.margin}


def drill_ticks(
    steps: Mapping,
    removed: Mapping,
    drill: str,
    burr_diameters: Sequence[float],
    volume_pose: np.ndarray,
) -> dict:
    """The arguments of ``SkillMetrics.add_ticks`` for drill `drill` from a step log and its
    removed voxels, with the burr centre in the frame of the volume at `volume_pose` (4x4
    world-from-volume)."""
    c = drill_columns(steps, drill, ["pose", "force", "on", "burr"])
    pose: np.ndarray = c["pose"].astype(float).reshape(-1, 4, 4)
    force: np.ndarray = c["force"].astype(float).reshape(-1, 3)
    on: np.ndarray = c["on"].reshape(-1) > 0.5
    burr: np.ndarray = c["burr"].reshape(-1).astype(np.int64)
    diameters = np.asarray(burr_diameters, dtype=float)
    if len(burr) and (burr.min() < 0 or burr.max() >= len(diameters)):
        raise ValueError(
            f"drill '{drill}' used burr {int(burr.max())}, but {len(diameters)} burr diameters "
            "were given"
        )
    # The live metrics' own computation (not NumPy's inverse, which differs in the last bits).
    tips = burr_in_volume(
        np.asarray(volume_pose, dtype=float), np.ascontiguousarray(pose[:, :3, 3])
    )
    step = np.asarray(steps["step"], dtype=np.int64)
    times = np.asarray(steps["time"], dtype=float)
    dt = tick_seconds(times)
    index = removed_ticks(step, removed["step"])
    # A real-time session's live metrics took the protected structures' updated fields at the
    # ticks this column gives; the replay takes them at the same ticks.
    taken = steps.get(f"{drill}.metrics_fields")
    extra = {}
    if taken is not None:
        extra["fields_taken"] = np.asarray(taken, dtype=float).reshape(len(step), -1)
    return {
        **extra,
        "steps": step,
        "times": times,
        "dt": dt,
        "tips": tips,
        "forces": force,
        "burr_radii": diameters[burr] / 2.0,
        "burr_on": on,
        "removed_tick": index,
        "removed": np.asarray(removed["voxel"], dtype=np.int32).reshape(-1, 3),
        "removed_labels": np.asarray(removed["label"], dtype=np.uint16).reshape(-1),
    }


def session_metrics(
    anatomy: VolumeData,
    steps: Mapping,
    removed: Mapping,
    *,
    drill: str,
    burr_diameters: Sequence[float],
    volume_pose: np.ndarray | None = None,
    protect: Sequence[Protect] = (),
    target_labels: Sequence | None = None,
    **options,
) -> dict:
    """The skill metrics of a session, replayed onto `anatomy` (the volume as the session began;
    it is drilled as the session drilled it). `options` go to ``SkillMetrics`` (excess_force,
    stroke_gap, ...)."""
    metrics = SkillMetrics(
        anatomy,
        protect=[p.as_dict() for p in protect],
        target_labels=list(target_labels) if target_labels is not None else None,
        apply_removals=True,
        **options,
    )
    pose = np.eye(4) if volume_pose is None else volume_pose
    metrics.add_ticks(**drill_ticks(steps, removed, drill, burr_diameters, pose))
    return metrics.summary()
