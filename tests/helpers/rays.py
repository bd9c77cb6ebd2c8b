"""Camera rays through pixel centres, and depth images back-projected along them."""

from __future__ import annotations

import numpy as np


def pixel_rays(intrinsics: np.ndarray, height: int, width: int) -> np.ndarray:
    """Camera-frame ray directions (z = 1) through every pixel centre, (H, W, 3)."""
    cols, rows = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    k = intrinsics
    x = (cols - k[0, 2]) / k[0, 0]
    y = (rows - k[1, 2]) / k[1, 1]
    return np.stack([x, y, np.ones_like(x)], axis=-1)


def backproject(frame) -> np.ndarray:
    """World-frame points of every pixel with a hit, (N, 3), from depth, intrinsics and pose."""
    rays = pixel_rays(frame.intrinsics, frame.height, frame.width)
    valid = frame.depth > 0
    cam = rays[valid] * frame.depth[valid][:, None].astype(np.float64)
    pose = frame.pose
    return cam @ pose[:3, :3].T + pose[:3, 3]
