"""A drill's ticks in a step log: one reader of its columns and of the removed voxels' ticks,
shared by everything that replays a session from its log (the skill metrics, the drill sound)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np


def drill_columns(steps: Mapping, drill: str, names: Sequence[str]) -> dict[str, np.ndarray]:
    """Columns ``<drill>.<name>`` of a step log, as arrays; ValueError naming the missing column
    and the log's columns when one is absent."""
    try:
        return {name: np.asarray(steps[f"{drill}.{name}"]) for name in names}
    except KeyError as missing:
        raise ValueError(
            f"the step log has no column {missing} of drill '{drill}' (columns: "
            f"{', '.join(sorted(steps))})"
        ) from None


def tick_seconds(times) -> float:
    """The step log's tick (seconds): the median step between its times (1 ms for one row)."""
    times = np.asarray(times, dtype=float).reshape(-1)
    return float(np.median(np.diff(times))) if len(times) > 1 else 0.001


def removed_ticks(step, removed_step) -> np.ndarray:
    """The row of the step log (whose ``step`` column is `step`) at which each removed voxel was
    removed; ValueError when a voxel names a step the log does not hold."""
    step = np.asarray(step, dtype=np.int64).reshape(-1)
    removed_step = np.asarray(removed_step, dtype=np.int64).reshape(-1)
    index = np.asarray(np.searchsorted(step, removed_step))
    if len(removed_step) and (
        index.max() >= len(step) or not np.array_equal(step[index], removed_step)
    ):
        raise ValueError("removed voxels name steps that the step log does not hold")
    return index
