"""Cavities: what a session drilled, as a voxel grid, compared with expert cavities and measured
against the structures to skeletonise. Distances come from the engine's exact distance fields
(``ambfplus.DistanceField``), the same ones the skill metrics and the drill use.

- ``cavity_mask``: removed voxels as a bool grid.
- ``compare_cavities``: one cavity against a reference: Dice overall, in the target and per
  label; over- and under-drilled volume; over-drilling weighted by its nearness to protected
  structures; the distance between the two cavities' surfaces.
- ``exposure``: residual bone thickness over a structure's surface near the target, and the
  fraction of that surface thinned to the target thickness.
"""

from __future__ import annotations

import numpy as np

from .._core import DistanceField, Label, VolumeData

# Over-drilling closer than this to a protected structure weighs more, up to NEAR_WEIGHT times
# a voxel far from every structure (linearly from NEAR_REACH to contact).
NEAR_REACH = 0.005
NEAR_WEIGHT = 5.0


def cavity_mask(shape, removed_voxels) -> np.ndarray:
    """A bool [i, j, k] grid of `shape` that is True at each removed voxel ((M, 3) indices)."""
    mask: np.ndarray = np.zeros(tuple(int(n) for n in shape), bool)
    voxels = np.asarray(removed_voxels, dtype=np.int64).reshape(-1, 3)
    if len(voxels):
        mask[voxels[:, 0], voxels[:, 1], voxels[:, 2]] = True
    return mask


def mask_distance(mask: np.ndarray, dimensions, band: float) -> np.ndarray:
    """The exact signed distance (metres, clamped to +-band) from every voxel centre to the voxels
    where `mask` is True (negative inside), on a grid of `dimensions` metres; +band everywhere
    when the mask is empty."""
    if not mask.any():
        return np.full(mask.shape, band, np.float32)
    grid = VolumeData(
        np.asfortranarray(np.where(mask, 1, 2).astype(np.uint8)),
        dimensions=np.asarray(dimensions, float),
        label_table=[
            Label(1, "Inside", (255, 255, 255), True, False),
            Label(2, "Outside", (0, 0, 0), True, False),
        ],
    )
    return DistanceField(grid, 1, band).values()


def surface(mask: np.ndarray) -> np.ndarray:
    """Voxels of `mask` with a 6-neighbour outside it (the grid's edge counts as outside)."""
    padded = np.pad(mask, 1, constant_values=False)
    inner = np.ones_like(mask)
    for axis in range(3):
        for shift in (-1, 1):
            inner &= np.roll(padded, shift, axis=axis)[1:-1, 1:-1, 1:-1]
    return mask & ~inner


def compare_cavities(
    cavity: np.ndarray,
    reference: np.ndarray,
    labels: np.ndarray,
    voxel_volume: float,
    dimensions,
    target: np.ndarray | None = None,
    protected: np.ndarray | None = None,
    label_names: dict | None = None,
    band: float = 0.02,
) -> dict:
    """A cavity (bool grid) against a reference cavity on the same anatomy (`labels`: the label
    grid before drilling). `protected`: the distance (metres) from each voxel to the nearest
    protected structure, which weighs over-drilling. Volumes in cubic metres, distances in
    metres."""
    names = label_names or {}
    over = cavity & ~reference
    under = reference & ~cavity

    def dice(a: np.ndarray, b: np.ndarray) -> float | None:
        total = int(a.sum()) + int(b.sum())
        return 2.0 * int((a & b).sum()) / total if total else None

    regions = {}
    for label in np.unique(labels[cavity | reference]):
        if label == 0:
            continue
        inside = labels == label
        regions[names.get(int(label), str(int(label)))] = {
            "label": int(label),
            "dice": dice(cavity & inside, reference & inside),
            "over": float((over & inside).sum() * voxel_volume),
            "under": float((under & inside).sum() * voxel_volume),
        }
    weighted = float(over.sum())
    if protected is not None and over.any():
        near = np.clip(1.0 - np.asarray(protected)[over] / NEAR_REACH, 0.0, 1.0)
        weighted = float(np.sum(1.0 + (NEAR_WEIGHT - 1.0) * near))
    out = {
        "dice": dice(cavity, reference),
        "dice_in_target": dice(cavity & target, reference & target) if target is not None else None,
        "over": float(over.sum() * voxel_volume),
        "under": float(under.sum() * voxel_volume),
        "over_weighted": weighted * voxel_volume,
        "regions": regions,
    }
    out.update(_surface_distance(cavity, reference, dimensions, band))
    return out


def _surface_distance(a: np.ndarray, b: np.ndarray, dimensions, band: float) -> dict:
    """Symmetric distance between the surfaces of two cavities: mean, p95 and max (metres,
    clamped to `band`), None when either is empty."""
    if not a.any() or not b.any():
        return {"surface_mean": None, "surface_p95": None, "surface_max": None}
    # From each surface voxel of one to the nearest surface voxel of the other (0 on it).
    to_b = np.maximum(mask_distance(surface(b), dimensions, band)[surface(a)], 0.0)
    to_a = np.maximum(mask_distance(surface(a), dimensions, band)[surface(b)], 0.0)
    both = np.concatenate([to_b, to_a]).astype(float)
    return {
        "surface_mean": float(both.mean()),
        "surface_p95": float(np.percentile(both, 95)),
        "surface_max": float(both.max()),
    }


def exposure(
    final_labels: np.ndarray,
    structure: np.ndarray,
    target: np.ndarray,
    dimensions,
    thickness: float,
    reach: float,
) -> dict:
    """Residual bone over the surface of `structure` (bool grid) that lies within `reach`
    metres of the `target` region, in the anatomy after drilling (`final_labels`, 0 where
    empty): each surface voxel's thickness is the distance to the nearest empty voxel less one
    voxel. Returns the voxels considered, thickness median / p10 / min (metres) and the
    fraction of them at or under `thickness` (exposed or skeletonised)."""
    voxel = float(np.min(np.asarray(dimensions, float) / np.asarray(final_labels.shape)))
    band = max(reach, thickness) + 4 * voxel
    near = mask_distance(target, dimensions, band) <= reach
    considered = surface(structure) & near
    count = int(considered.sum())
    if count == 0:
        return {
            "surface_voxels": 0,
            "thickness_median": None,
            "thickness_p10": None,
            "thickness_min": None,
            "exposed_fraction": None,
        }
    empty = (final_labels == 0) & ~structure
    residual = np.maximum(mask_distance(empty, dimensions, band)[considered] - voxel, 0.0)
    return {
        "surface_voxels": count,
        "thickness_median": float(np.median(residual)),
        "thickness_p10": float(np.percentile(residual, 10)),
        "thickness_min": float(residual.min()),
        "exposed_fraction": float(np.mean(residual <= thickness + 1e-9)),
    }
