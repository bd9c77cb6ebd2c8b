"""Stereo training targets from rendered depth: disparity, validity and occlusion (NumPy only).

Conventions (``ambfplus.stereo``): the rig is rectified, the right camera sits ``baseline``
metres along the left camera's +x, pixel (row r, column c) is centred at x = c + 0.5, and the
disparity of a left pixel is d = x_left - x_right = f B / Z - dcx, with dcx = cx_right - cx_left
(0 for a parallel rig; an off-axis rig has zero disparity at its working distance and negative
disparities beyond it). Both cameras share their orientation, so a point has the same depth Z in
both views.
"""

from __future__ import annotations

import numpy as np

#: A left pixel counts as hidden in the right view when the surface the right camera sees where
#: it lands is nearer by more than this disparity (pixels): a slanted surface's own disparity
#: changes by well under a pixel across the half pixel that separates a point from the right
#: pixel's centre, an occluder's by far more.
OCCLUSION_TOLERANCE_PX = 1.0


def disparity_from_depth(depth, focal: float, baseline: float, dcx: float) -> np.ndarray:
    """d = f B / Z - dcx (float32 pixels) where depth > 0, else 0."""
    z = np.asarray(depth, dtype=np.float64)
    hit = z > 0
    d = np.zeros(z.shape, dtype=np.float64)
    d[hit] = focal * baseline / z[hit] - dcx
    return d.astype(np.float32)


def depth_from_disparity(disparity, focal: float, baseline: float, dcx: float) -> np.ndarray:
    """Z = f B / (d + dcx) (metres, float32) where d + dcx > 0, else 0."""
    d = np.asarray(disparity, dtype=np.float64) + dcx
    z = np.zeros(d.shape, dtype=np.float64)
    ahead = d > 0
    z[ahead] = focal * baseline / d[ahead]
    return z.astype(np.float32)


def occlusion_mask(
    left_depth,
    right_depth,
    focal: float,
    baseline: float,
    dcx: float,
    tolerance_px: float = OCCLUSION_TOLERANCE_PX,
) -> np.ndarray:
    """Left pixels whose surface point the right camera does not see (bool HxW).

    Each left pixel with a hit is carried into the right image by its disparity (x_right =
    x_left - d) and compared with what the right view's depth holds in the pixel it lands in:
    it is occluded when that pixel sees something nearer (its disparity larger by more than
    ``tolerance_px``) or when it lands outside the right image. Pixels without a hit are never
    occluded (they have no disparity; see ``valid``)."""
    left_depth = np.asarray(left_depth)
    right_depth = np.asarray(right_depth)
    if left_depth.shape != right_depth.shape or left_depth.ndim != 2:
        raise ValueError(
            f"occlusion_mask needs two depth images of the same (H, W) shape, got "
            f"{left_depth.shape} and {right_depth.shape}"
        )
    height, width = left_depth.shape
    disparity: np.ndarray = disparity_from_depth(left_depth, focal, baseline, dcx).astype(
        np.float64
    )
    hit = left_depth > 0
    x_right = np.arange(width)[None, :] + 0.5 - disparity
    column = np.floor(x_right).astype(np.int64)
    inside = (column >= 0) & (column < width)
    rows = np.broadcast_to(np.arange(height)[:, None], (height, width))
    seen_depth = right_depth[rows, np.clip(column, 0, width - 1)]
    seen_disparity: np.ndarray = disparity_from_depth(seen_depth, focal, baseline, dcx).astype(
        np.float64
    )
    nearer = (seen_depth > 0) & (seen_disparity > disparity + tolerance_px)
    return hit & (~inside | nearer)


def stereo_targets(left_depth, right_depth, focal: float, baseline: float, dcx: float) -> dict:
    """Disparity (0 where invalid), its validity (the left pixel hit something) and occlusion
    for a rectified pair, from the two views' depth."""
    left_depth = np.asarray(left_depth, dtype=np.float32)
    return {
        "disparity": disparity_from_depth(left_depth, focal, baseline, dcx),
        "valid": left_depth > 0,
        "occlusion": occlusion_mask(left_depth, right_depth, focal, baseline, dcx),
    }
