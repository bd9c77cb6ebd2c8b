"""Stereo evaluation (NumPy only): disparity and depth errors against rendered ground truth, and
the row filling that makes a sparse matcher's output dense for a full-density comparison."""

from __future__ import annotations

import numpy as np

from .targets import depth_from_disparity


def disparity_metrics(
    predicted, truth, mask, focal: float, baseline: float, dcx: float
) -> dict[str, float]:
    """Errors over the pixels of `mask`: ``epe`` (mean |d - d_true|, px), ``bad1`` (share of
    pixels off by more than 1 px), ``depth_l1_mm`` (mean |Z - Z_true| in mm, Z = f B / (d +
    dcx); a disparity with no depth, d + dcx <= 0, counts as 1 m) and ``pixels``. Sums
    (``*_sum``) are included so that sequences can be pooled (``pool``)."""
    predicted = np.asarray(predicted, dtype=np.float64)
    truth = np.asarray(truth, dtype=np.float64)
    mask = np.asarray(mask, dtype=bool)
    if predicted.shape != truth.shape or truth.shape != mask.shape:
        raise ValueError(
            f"shapes differ: predicted {predicted.shape}, truth {truth.shape}, mask {mask.shape}"
        )
    error = np.abs(predicted[mask] - truth[mask])
    z_true: np.ndarray = depth_from_disparity(truth[mask], focal, baseline, dcx).astype(np.float64)
    z: np.ndarray = depth_from_disparity(predicted[mask], focal, baseline, dcx).astype(np.float64)
    # A disparity at or beyond infinity (d + dcx <= 0) has no depth: count it at 1 m, far
    # beyond the anatomy, rather than dropping it.
    z[z <= 0] = 1.0
    depth_error = np.abs(z - z_true) * 1000.0
    n = int(mask.sum())
    out = {
        "pixels": n,
        "epe_sum": float(error.sum()),
        "bad1_sum": float((error > 1.0).sum()),
        "depth_l1_mm_sum": float(depth_error.sum()),
    }
    return {**out, **summarise(out)}


def summarise(sums: dict) -> dict[str, float]:
    """Means from (pooled) sums."""
    n = max(sums["pixels"], 1)
    return {
        "epe": sums["epe_sum"] / n,
        "bad1": sums["bad1_sum"] / n,
        "depth_l1_mm": sums["depth_l1_mm_sum"] / n,
    }


def pool(metrics: list[dict]) -> dict[str, float]:
    """Pixel-weighted means over many frames' ``disparity_metrics``."""
    keys = ("pixels", "epe_sum", "bad1_sum", "depth_l1_mm_sum")
    sums = {k: sum(m[k] for m in metrics) for k in keys}
    return {**sums, **summarise(sums)}


def fill_invalid_along_rows(disparity, invalid) -> np.ndarray:
    """Fills each run of invalid pixels in a row from its nearest valid neighbours in that row,
    taking the smaller (farther) of the two, since holes in a matcher's output are mostly
    occlusions, which belong to the background; runs at a row's end take the one neighbour
    they have. Rows without any valid pixel are left as they are."""
    disparity = np.array(disparity, dtype=np.float32)
    invalid = np.asarray(invalid, dtype=bool)
    height, width = disparity.shape
    columns = np.broadcast_to(np.arange(width), (height, width))
    valid = ~invalid
    left = np.maximum.accumulate(np.where(valid, columns, -1), axis=1)
    right = np.minimum.accumulate(np.where(valid, columns, width)[:, ::-1], axis=1)[:, ::-1]
    rows = np.broadcast_to(np.arange(height)[:, None], (height, width))
    from_left = np.where(left >= 0, disparity[rows, np.clip(left, 0, width - 1)], np.inf)
    from_right = np.where(right < width, disparity[rows, np.clip(right, 0, width - 1)], np.inf)
    filled = np.minimum(from_left, from_right)
    return np.where(invalid & np.isfinite(filled), filled, disparity).astype(np.float32)
