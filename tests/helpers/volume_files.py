"""Writers of volume files in their public formats, independent of the engine, for tests."""

from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
from PIL import Image


def write_slices(folder: Path, rgba: np.ndarray, prefix: str = "plane00") -> None:
    """Writes an (nx, ny, nz, 4) grid as AMBF slices: pixel (row r, column c) of slice k holds
    voxel (c, ny - 1 - r, k)."""
    folder.mkdir(parents=True, exist_ok=True)
    for k in range(rgba.shape[2]):
        image = np.ascontiguousarray(rgba[:, ::-1, k, :].transpose(1, 0, 2))
        Image.fromarray(image, "RGBA").save(folder / f"{prefix}{k}.png")


def nrrd_bytes(
    data: np.ndarray,
    nrrd_type: str,
    spacing_mm=(1.0, 1.0, 1.0),
    origin_mm=(0.0, 0.0, 0.0),
    encoding: str = "gzip",
    extra: dict[str, str] | None = None,
    directions=None,
    kinds: str = "domain domain domain",
) -> bytes:
    """An NRRD file holding `data` ((nx, ny, nz) or (layers, nx, ny, nz)), first axis fastest."""
    dims = data.ndim
    if directions is None:
        directions = np.diag(spacing_mm)
    dir_text = " ".join(
        "(" + ",".join(repr(float(v)) for v in col) + ")" for col in np.asarray(directions).T
    )
    if dims == 4:
        dir_text = "none " + dir_text
    header = [
        "NRRD0004",
        f"type: {nrrd_type}",
        f"dimension: {dims}",
        "space: left-posterior-superior",
        "sizes: " + " ".join(str(s) for s in data.shape),
        f"space directions: {dir_text}",
        f"kinds: {kinds}",
        "endian: little",
        f"encoding: {encoding}",
        "space origin: (" + ",".join(repr(float(v)) for v in origin_mm) + ")",
    ]
    for key, value in (extra or {}).items():
        header.append(f"{key}:={value}")
    raw = np.asfortranarray(data).tobytes(order="F")
    if encoding == "gzip":
        raw = gzip.compress(raw)
    return ("\n".join(header) + "\n\n").encode() + raw


def segment_keys(segments: list[tuple[str, tuple[int, int, int], int, int]]) -> dict[str, str]:
    """3D Slicer's per-segment keys for (name, rgb 0..255, label value, layer) tuples."""
    keys = {}
    for n, (name, rgb, value, layer) in enumerate(segments):
        keys[f"Segment{n}_ID"] = f"Segment_{n + 1}"
        keys[f"Segment{n}_Name"] = name
        keys[f"Segment{n}_Color"] = " ".join(f"{c / 255:.6f}" for c in rgb)
        keys[f"Segment{n}_LabelValue"] = str(value)
        keys[f"Segment{n}_Layer"] = str(layer)
    return keys
