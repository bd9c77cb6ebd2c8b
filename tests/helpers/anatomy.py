"""Anatomical measures of a labelled temporal bone that need no frame: structure volumes and the
distances between centroids, so that a phantom and a patient volume in different orientations
compare directly. The cochlea and the tegmen are not labels of their own; each is defined here
once and applied identically to every volume (docs/guide/volumes.md states the definitions):

- cochlea: the voxels of Bony_Labyrinth on the ICA's side of the plane through the labyrinth's
  centroid normal to the line from that centroid to the ICA's centroid;
- tegmen: the Bone voxels within 1 mm of Sinus_+_Dura (the dura's bone lining) that are nearest
  the epitympanum (the centroid of Malleus and Incus): those within 3 mm of the nearest one's
  distance. The incus and the malleus head sit in the epitympanum directly under the tegmen
  tympani, so the dura-lined bone closest to them is the tegmen.
"""

from __future__ import annotations

import numpy as np

import ambfplus

#: The structures compared, as the original system's labels.csv names them.
STRUCTURES = (
    "Bone", "Malleus", "Incus", "Stapes", "Bony_Labyrinth", "IAC", "Superior_Vestibular_Nerve",
    "Inferior_Vestibular_Nerve", "Cochlear_Nerve", "Facial_Nerve", "Chorda_Tympani", "ICA",
    "Sinus_+_Dura", "Vestibular_Aqueduct", "TMJ", "EAC",
)  # fmt: skip

#: Centroid distances compared: (structure, structure).
DISTANCES = (
    ("Facial_Nerve", "EAC"),
    ("Facial_Nerve", "Sinus_+_Dura"),
    ("Bony_Labyrinth", "EAC"),
    ("ICA", "cochlea"),
    ("tegmen", "EAC"),
)

TEGMEN_LINING_M = 0.001
TEGMEN_BAND_M = 0.003


def voxel_centres(data: ambfplus.VolumeData, index: np.ndarray) -> np.ndarray:
    """Volume-frame centres (metres) of voxels given as an (N, 3) array of (i, j, k)."""
    origin = np.asarray(data.voxel_center(0, 0, 0))
    return origin + index * np.asarray(data.voxel_size)


def measure(data: ambfplus.VolumeData) -> tuple[dict[str, float], dict[str, np.ndarray]]:
    """(volumes in mm^3 by structure, centroids in metres by structure, cochlea and tegmen
    included) of a volume labelled with the original system's label names."""
    table = {label.name: label.id for label in data.label_table}
    missing = [name for name in STRUCTURES if name not in table]
    assert not missing, f"{data.source}: no labels {missing}"
    labels = np.asarray(data.labels)
    flat = labels.ravel(order="F")
    size = int(flat.max()) + 1
    counts = np.bincount(flat, minlength=size).astype(float)
    sums = []
    for axis in range(3):
        coord = np.arange(labels.shape[axis], dtype=float)
        shape = [1, 1, 1]
        shape[axis] = -1
        grid = np.broadcast_to(coord.reshape(shape), labels.shape).ravel(order="F")
        sums.append(np.bincount(flat, weights=grid, minlength=size))
    mean_index = np.stack(sums, 1) / np.maximum(counts, 1)[:, None]
    voxel_mm3 = float(np.prod(data.voxel_size)) * 1e9
    volumes, centroids = {}, {}
    for name in STRUCTURES:
        ident = table[name]
        volumes[name] = counts[ident] * voxel_mm3 if ident < size else 0.0
        assert volumes[name] > 0, f"{data.source}: {name} is empty"
        centroids[name] = voxel_centres(data, mean_index[ident])
    centroids["cochlea"] = cochlea_centroid(data, labels, table, centroids)
    centroids["tegmen"] = tegmen_centroid(data, labels, table)
    return volumes, centroids


def cochlea_centroid(data, labels, table, centroids) -> np.ndarray:
    """Centroid of the labyrinth's part on the ICA's side of its centroid (see the module)."""
    points = voxel_centres(data, np.argwhere(labels == table["Bony_Labyrinth"]))
    towards = centroids["ICA"] - centroids["Bony_Labyrinth"]
    part = points[(points - centroids["Bony_Labyrinth"]) @ towards > 0]
    return part.mean(0)


def tegmen_centroid(data, labels, table) -> np.ndarray:
    """Centroid of the dura-lined bone nearest the epitympanum (see the module)."""
    ossicles = np.concatenate([np.argwhere(labels == table[name]) for name in ("Malleus", "Incus")])
    epitympanum = voxel_centres(data, ossicles).mean(0)
    # The bone within 20 mm of the epitympanum, and its distance to the dura.
    centre = np.argwhere(labels == table["Incus"]).mean(0).round().astype(int)
    reach = np.ceil(0.02 / np.asarray(data.voxel_size)).astype(int)
    lo = np.maximum(centre - reach, 0)
    hi = np.minimum(centre + reach + 1, labels.shape)
    box = labels[lo[0] : hi[0], lo[1] : hi[1], lo[2] : hi[2]]
    bone = voxel_centres(data, np.argwhere(box == table["Bone"]) + lo)
    field = ambfplus.DistanceField(data, "Sinus_+_Dura", band=2 * TEGMEN_LINING_M)
    distance, _ = field.sample(bone)
    lining = bone[distance <= TEGMEN_LINING_M]
    assert len(lining), f"{data.source}: no bone within 1 mm of the dura near the ossicles"
    reach_m = np.linalg.norm(lining - epitympanum, axis=1)
    return lining[reach_m <= reach_m.min() + TEGMEN_BAND_M].mean(0)


def comparison_table(phantom, fixture) -> list[tuple[str, float, float, float]]:
    """Rows (quantity, phantom, fixture, ratio): volumes (mm^3), then distances (mm)."""
    (pv, pc), (fv, fc) = phantom, fixture
    rows = [(name, pv[name], fv[name], pv[name] / fv[name]) for name in STRUCTURES]
    for a, b in DISTANCES:
        dp = 1000 * float(np.linalg.norm(pc[a] - pc[b]))
        df = 1000 * float(np.linalg.norm(fc[a] - fc[b]))
        rows.append((f"{a} to {b} (mm)", dp, df, dp / df))
    return rows
