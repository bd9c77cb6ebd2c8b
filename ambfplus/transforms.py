"""Small helpers for building poses (4x4 rigid transforms, float64)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ._core import ArgumentError


def rpy_matrix(rpy: Sequence[float] | np.ndarray) -> np.ndarray:
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
    """A 4x4 pose from a position and either fixed-axis roll-pitch-yaw or a 3x3 rotation.

    Raises ``ArgumentError`` for non-finite values or a 3x3 that is not a rotation."""
    if rpy is not None and rotation is not None:
        raise ArgumentError("make_pose: give rpy or rotation, not both")
    pose = np.eye(4)
    if rpy is not None:
        pose[:3, :3] = rpy_matrix(_finite("rpy", rpy, (3,)))
    elif rotation is not None:
        r = _finite("rotation", rotation, (3, 3))
        if not np.allclose(r.T @ r, np.eye(3), atol=1e-6) or np.linalg.det(r) < 0:
            raise ArgumentError(
                "make_pose: rotation must be a rotation matrix (orthonormal, det +1)"
            )
        pose[:3, :3] = r
    pose[:3, 3] = _finite("position", position, (3,))
    return pose


def _finite(name: str, value, shape: tuple[int, ...]) -> np.ndarray:
    """value as a float array of the given shape, or ArgumentError naming make_pose's argument."""
    try:
        array = np.asarray(value, dtype=float).reshape(shape)
    except (TypeError, ValueError):
        raise ArgumentError(
            f"make_pose: {name} must be {' x '.join(map(str, shape))} numbers, got {value!r}"
        ) from None
    if not np.isfinite(array).all():
        raise ArgumentError(f"make_pose: {name} must be finite, got {array.tolist()}")
    return array


def rotation_between(a: Sequence[float], b: Sequence[float]) -> np.ndarray:
    """The smallest rotation taking direction a to direction b (3x3)."""
    u = np.asarray(a, float) / np.linalg.norm(a)
    v = np.asarray(b, float) / np.linalg.norm(b)
    axis = np.cross(u, v)
    s, c = np.linalg.norm(axis), float(u @ v)
    if s < 1e-12:
        if c > 0:
            return np.eye(3)
        # Opposite: half a turn about any axis perpendicular to u.
        p = np.cross(u, [1.0, 0.0, 0.0] if abs(u[0]) < 0.9 else [0.0, 1.0, 0.0])
        p /= np.linalg.norm(p)
        return 2 * np.outer(p, p) - np.eye(3)
    k = axis / s
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + s * kx + (1 - c) * (kx @ kx)
