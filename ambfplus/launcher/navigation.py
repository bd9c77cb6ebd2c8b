"""Mouse navigation of the shown camera: orbiting, panning and zooming about where it looks."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# GLFW's mouse buttons.
MOUSE_LEFT, MOUSE_RIGHT = 0, 1


@dataclass
class Orbit:
    """Mouse navigation of a camera about the point it looks at."""

    target: np.ndarray
    rotate: float = 0.005  # rad per pixel
    pan: float = 0.0005  # metres per pixel per metre of distance
    zoom: float = 0.1  # fraction of the distance per wheel step
    last: tuple | None = None
    dragging: int | None = None

    def drag(self, pose: np.ndarray, dx: float, dy: float, button: int) -> dict:
        """What a drag of (dx, dy) pixels does to a camera at `pose`: {'look_at': (eye, target,
        up)} to turn about the target (left button), else {'pose': the new pose} to pan (the
        target moves with it). Computed off the world's lock; applying it is one engine call."""
        pose = np.array(pose, dtype=float)
        eye = pose[:3, 3]
        if button == MOUSE_LEFT:
            # Turn the eye about the target: yaw about world z, pitch about the camera's x.
            offset = eye - self.target
            yaw, pitch = -dx * self.rotate, -dy * self.rotate
            offset = _rotate(offset, np.array([0.0, 0.0, 1.0]), yaw)
            offset = _rotate(offset, pose[:3, 0], pitch)
            return {"look_at": (self.target + offset, self.target, -pose[:3, 1])}
        distance = np.linalg.norm(eye - self.target)
        shift = (-dx * pose[:3, 0] - dy * pose[:3, 1]) * self.pan * distance
        self.target = self.target + shift
        pose[:3, 3] = eye + shift
        return {"pose": pose}

    def scroll(self, pose: np.ndarray, steps: float) -> np.ndarray:
        """The pose of a camera at `pose` after `steps` wheel steps towards the target."""
        pose = np.array(pose, dtype=float)
        eye = pose[:3, 3]
        pose[:3, 3] = self.target + (eye - self.target) * (1.0 - self.zoom) ** steps
        return pose


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    axis = axis / np.linalg.norm(axis)
    return (
        v * math.cos(angle)
        + np.cross(axis, v) * math.sin(angle)
        + axis * np.dot(axis, v) * (1 - math.cos(angle))
    )
