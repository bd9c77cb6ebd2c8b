"""The drill's sound offline: the signal a ``DrillSound`` plays live, rendered from a recording
(or any step log with its removed voxels) to samples or a WAV file. One synthesiser serves both
(``render_drill_sound``), so what is rendered here is what a trainee heard, sample for sample,
for the same ticks.

Per tick the sound needs the burr's state (``<drill>.on``, and ``<drill>.speed`` where the log
has it, else full speed), its load (the norm of ``<drill>.force``), the tissue removed at that
step (from the removed voxels: count x voxel volume / step, and the mean hardness of their
labels), and for warnings the distance to each structure, which a step log does not hold: pass
them as ``distances`` with ``warnings``.
"""

from __future__ import annotations

import io
import wave
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .._core import DRILL_SOUND_MAX_WARNINGS, render_drill_sound
from ..fileio import write_bytes
from ..labels import legend_index, object_key
from ..recording.ticks import drill_columns, removed_ticks, tick_seconds

__all__ = ["drill_ticks", "render_session", "render_wav", "write_wav"]


# Where a DrillSound's default proximity beep starts (metres from a critical structure).
DEFAULT_WARNING_START = 0.001


def drill_ticks(
    steps: Mapping,
    removed: Mapping,
    drill: str,
    voxel_size,
    hardness: Mapping[int, float] | None = None,
) -> dict:
    """The sound's input per tick for drill `drill`: ``on``, ``speed``, ``load`` (N),
    ``removal_rate`` (m^3/s), ``hardness`` and ``tick_seconds``, from a step log and its removed
    voxels. `voxel_size` (metres, 3 values) sizes a voxel; `hardness` maps label ids to the
    tissue's hardness relative to bone (1 for labels it leaves out)."""
    c = drill_columns(steps, drill, ["on", "force"])
    on: np.ndarray = c["on"].astype(float).reshape(-1) > 0.5
    force: np.ndarray = c["force"].astype(float).reshape(-1, 3)
    n = len(on)
    speed_column = steps.get(f"{drill}.speed")
    speed = np.ones(n) if speed_column is None else np.asarray(speed_column, float).reshape(-1)
    step = np.asarray(steps["step"], dtype=np.int64).reshape(-1)
    dt = tick_seconds(steps["time"])
    size = np.asarray(voxel_size, dtype=float).reshape(3)
    voxel_volume = float(size[0] * size[1] * size[2])

    labels = np.asarray(removed["label"], dtype=np.int64).reshape(-1)
    index = removed_ticks(step, removed["step"])
    count = np.bincount(index, minlength=n).astype(float)
    table = np.ones(int(labels.max(initial=0)) + 1)
    for label, value in (hardness or {}).items():
        if 0 <= int(label) < len(table):
            table[int(label)] = float(value)
    hard_sum = np.bincount(index, weights=table[labels], minlength=n)
    mean_hardness = np.divide(hard_sum, count, out=np.ones(n), where=count > 0)
    return {
        "on": on,
        "speed": speed,
        # As the engine computes them live, so that both give the same float32 values.
        "load": np.sqrt((force * force).sum(axis=1)),
        "removal_rate": count * voxel_volume / dt,
        "hardness": mean_hardness,
        "tick_seconds": dt,
    }


def render_session(
    steps: Mapping,
    removed: Mapping,
    drill: str,
    voxel_size,
    *,
    hardness: Mapping[int, float] | None = None,
    warnings: Mapping | None = None,
    distances=None,
    sample_rate: int = 48000,
    seed: int = 0x5EED,
) -> np.ndarray:
    """The drill sound of a session (float32 samples at `sample_rate`); see ``drill_ticks``
    and ``render_drill_sound`` for the arguments."""
    ticks = drill_ticks(steps, removed, drill, voxel_size, hardness)
    return render_drill_sound(
        ticks["on"],
        ticks["load"],
        ticks["removal_rate"],
        speed=ticks["speed"],
        hardness=ticks["hardness"],
        warnings=warnings,
        distances=distances,
        sample_rate=sample_rate,
        tick_seconds=ticks["tick_seconds"],
        seed=seed,
    )


def write_wav(path, samples: np.ndarray, sample_rate: int = 48000) -> Path:
    """Writes mono samples in [-1, 1] as a 16-bit PCM WAV file, whole."""
    pcm = np.round(np.clip(np.asarray(samples, dtype=float), -1.0, 1.0) * 32767).astype("<i2")
    buffer = io.BytesIO()
    with wave.open(buffer, "wb") as out:
        out.setnchannels(1)
        out.setsampwidth(2)
        out.setframerate(int(sample_rate))
        out.writeframes(pcm.tobytes())
    path = Path(path)
    write_bytes(path, buffer.getvalue())
    return path


def render_wav(
    recording,
    path,
    *,
    drill: str | None = None,
    hardness: Mapping[int, float] | None = None,
    warnings: Mapping | None = None,
    distances=None,
    sample_rate: int = 48000,
    seed: int = 0x5EED,
) -> Path:
    """Renders the drill sound of a recording (a path or an open ``Recording``) to a WAV file.
    `drill` names the drill (default: the recording's only drill); its volume's voxel size
    comes from the legend (the volume its removed voxels belong to). Without `warnings` and
    `distances`, the proximity beeps are those a ``DrillSound`` plays by default (each critical
    structure from 1 mm), from the step log's ``<drill>.critical_distance`` column where the
    recording has it."""
    from ..recording import open_recording

    rec = recording if hasattr(recording, "steps") else open_recording(recording)
    # By the names step-log columns use: keys (a drill under a namespace: 'psm1/drill').
    legend = legend_index(rec.legend)
    if drill is None:
        drills = sorted(
            {object_key(legend, n) for n, e in legend.items() if e.get("kind") == "drill"}
        )
        if len(drills) != 1:
            raise ValueError(f"{rec.path}: name the drill to render (drills: {drills})")
        drill = drills[0]
    drill = object_key(legend, drill)
    volume = rec.removed.get("volume") or next(
        (name for name, entry in legend.items() if entry.get("kind") == "volume"), None
    )
    if volume is None or "voxel_size" not in legend.get(volume, {}):
        raise ValueError(f"{rec.path}: no volume with a voxel size in the legend")
    if warnings is None and distances is None:
        column = rec.steps.get(f"{drill}.critical_distance")
        names = legend.get(drill, {}).get("critical")
        if (
            column is not None
            and names
            and np.asarray(column).reshape(len(column), -1).shape[1] == len(names)
        ):
            # As a DrillSound's default: the first DRILL_SOUND_MAX_WARNINGS critical labels.
            kept = names[:DRILL_SOUND_MAX_WARNINGS]
            warnings = {name: DEFAULT_WARNING_START for name in kept}
            distances = np.asarray(column, dtype=float).reshape(len(column), -1)[:, : len(kept)]
    samples = render_session(
        rec.steps,
        rec.removed,
        drill,
        legend[volume]["voxel_size"],
        hardness=hardness,
        warnings=warnings,
        distances=distances,
        sample_rate=sample_rate,
        seed=seed,
    )
    return write_wav(path, samples, sample_rate)
