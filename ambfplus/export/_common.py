"""What every export shares: errors, the extras they need, output checks, poses as
quaternions, the simulation clock of a recording and a progress bar."""

from __future__ import annotations

import importlib
from pathlib import Path

import numpy as np

from .. import __version__


class ExportError(ValueError):
    """An export that cannot be made: an unknown format, an output that exists, or a recording
    holding something the format cannot represent. The message says which and why."""


class MissingExtra(ImportError):
    """An optional dependency of an export or of the live view is not installed."""


def require(extra: str, *modules: str):
    """Imports the modules an extra provides, or raises MissingExtra naming what to install."""
    loaded = []
    for name in modules:
        try:
            loaded.append(importlib.import_module(name))
        except ImportError as error:
            raise MissingExtra(
                f"this needs the Python module '{name}' ({error}); install it with "
                f'pip install "ambfplus[{extra}]"'
            ) from None
    return loaded[0] if len(loaded) == 1 else loaded


def check_output(out: Path, force: bool) -> None:
    """Refuses an output path that exists unless force is given (checked before any work)."""
    if (out.exists() or out.is_symlink()) and not force:
        raise ExportError(f"{out} exists; pass --force (force=True) to replace it")
    if not out.parent.is_dir():
        raise ExportError(f"{out}: the folder {out.parent} does not exist")


def quaternion_xyzw(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion (x, y, z, w) of a 3x3 rotation, w >= 0 (Shepperd's method, which
    divides by the largest of the four candidates, so it is exact to rounding everywhere)."""
    m = np.asarray(rotation, dtype=np.float64)
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    candidates = (trace, m[0, 0], m[1, 1], m[2, 2])
    k = int(np.argmax(candidates))
    if k == 0:
        s = 2.0 * np.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    elif k == 1:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif k == 2:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s)
    q = np.array(q)
    q /= np.linalg.norm(q)
    return -q if q[3] < 0 else q


def pose_vector(pose: np.ndarray) -> np.ndarray:
    """A 4x4 pose as [x, y, z, qx, qy, qz, qw]."""
    pose = np.asarray(pose, dtype=np.float64)
    return np.concatenate([pose[:3, 3], quaternion_xyzw(pose[:3, :3])])


def nanoseconds(seconds: float) -> int:
    """Simulation seconds as integer nanoseconds (the time stamps of ROS and MCAP)."""
    return int(round(float(seconds) * 1e9))


class StepClock:
    """Simulation time of a step: from the recording's step log where it has the step, else
    from its fixed step (found in the log or the frames)."""

    def __init__(self, recording) -> None:
        steps = recording.steps
        self._steps = np.asarray(steps.get("step", np.empty(0, np.int64)))
        self._times = np.asarray(steps.get("time", np.empty(0)))
        self.time_step = self._fixed_step(recording)

    def _fixed_step(self, recording) -> float:
        pairs = [(self._steps, self._times)]
        pairs += [(s.step[:], s.time[:]) for s in recording.cameras.values()]
        for steps, times in pairs:
            usable = steps > 0
            if usable.any():
                return float(np.median(times[usable] / steps[usable]))
        return 0.001

    def __call__(self, steps) -> np.ndarray:
        steps = np.asarray(steps, dtype=np.int64)
        out = steps * self.time_step
        if len(self._steps):
            where = np.clip(np.searchsorted(self._steps, steps), 0, len(self._steps) - 1)
            known = self._steps[where] == steps
            out = np.where(known, self._times[where], out)
        return out


def progress_bar(total: int, description: str, enabled: bool | None, unit: str = "frame"):
    """A tqdm bar on stderr (enabled None: only on a terminal); a no-op without tqdm when not
    asked for explicitly."""
    if enabled is False:
        return _NoBar()
    try:
        from tqdm.auto import tqdm
    except ImportError:
        if enabled:
            require("export", "tqdm")
        return _NoBar()
    return tqdm(
        total=total, desc=description, unit=unit, disable=None if enabled is None else False
    )


class _NoBar:
    def update(self, n: int = 1) -> None:
        pass

    def set_postfix_str(self, text: str) -> None:
        pass

    def close(self) -> None:
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc_info) -> None:
        pass


def export_conventions(recording) -> dict:
    """What every export states about itself: software, source and units."""
    return {
        "ambfplus_version": __version__,
        "source": str(recording.path),
        "source_recording_id": recording.recording_id,
        "source_software_version": recording.software_version or "",
        "units": "SI: metres, seconds, newtons, radians",
        "world_frame": "right-handed, z up",
        "time": "simulation time in seconds since the session started (step 0 at 0 s), not "
        "wall-clock or Unix time",
    }


# The optical frame (OpenCV axes: x right, y down, z forward) in the camera's body frame
# (REP 103: x forward, y left, z up): its columns are the optical axes in body coordinates.
LINK_FROM_OPTICAL = np.array(
    [[0.0, 0.0, 1.0, 0.0], [-1.0, 0.0, 0.0, 0.0], [0.0, -1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)


def tf_frame(name: str, namespace: str = "") -> str:
    """The TF frame id of an object: its own name, under its namespace where it has one
    (``/ambf/env/`` + ``drill`` -> ``ambf/env/drill``), without a leading slash (tf2 refuses
    frame ids that start with one)."""
    space = namespace.strip("/")
    return f"{space}/{name}" if space else name


def camera_frames(name: str, namespace: str = "") -> tuple[str, str]:
    """A camera's two TF frames: its body frame ``<camera>_link`` (REP 103 axes) and, its
    child by ``LINK_FROM_OPTICAL``, the optical frame ``<camera>_optical_frame`` (OpenCV
    axes) that images, camera_info and point clouds are stamped with."""
    base = tf_frame(name, namespace)
    return f"{base}_link", f"{base}_optical_frame"


def link_pose(world_from_optical: np.ndarray) -> np.ndarray:
    """world-from-link of a camera from its recorded world-from-optical pose."""
    return np.asarray(world_from_optical, dtype=np.float64) @ np.linalg.inv(LINK_FROM_OPTICAL)


def frame_name(name: str, kind: str, namespace: str = "") -> str:
    """The TF frame that stamps an object's data: a camera's optical frame, any other object's
    own frame (``tf_frame``). The live view and the ROS exports share this rule."""
    if kind == "camera":
        return camera_frames(name, namespace)[1]
    return tf_frame(name, namespace)
