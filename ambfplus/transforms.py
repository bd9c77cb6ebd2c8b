"""Small helpers for building poses (4x4 rigid transforms, float64)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np


def rpy_matrix(rpy: Sequence[float]) -> np.ndarray:
    """Rotation from fixed-axis roll, pitch, yaw (radians), as AMBF files give them.

    R = Rz(yaw) @ Ry(pitch) @ Rx(roll).
    """
    r, p, y = (float(v) for v in rpy)
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def make_pose(
    position: Sequence[float] = (0.0, 0.0, 0.0),
    rpy: Sequence[float] | None = None,
    rotation: np.ndarray | None = None,
) -> np.ndarray:
    """A 4x4 pose from a position and either fixed-axis roll-pitch-yaw or a 3x3 rotation."""
    if rpy is not None and rotation is not None:
        raise ValueError("give rpy or rotation, not both")
    pose = np.eye(4)
    if rpy is not None:
        pose[:3, :3] = rpy_matrix(rpy)
    elif rotation is not None:
        pose[:3, :3] = np.asarray(rotation, dtype=float).reshape(3, 3)
    pose[:3, 3] = np.asarray(position, dtype=float).reshape(3)
    return pose
