"""Loading anatomy volumes from any supported source, and converting between formats."""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ._core import VolumeData, World, load_nrrd, load_slice_stack, write_label_table
from .fileio import refuse_writing_over


def load_volume(
    source: str | os.PathLike,
    *,
    prefix: str = "plane00",
    labels: str | os.PathLike | None = None,
    dimensions: Sequence[float] | None = None,
    voxel_size: Sequence[float] | None = None,
    threshold: float | None = None,
) -> VolumeData:
    """Loads volume data from an NRRD file (label map, intensities segmented at `threshold`, or a
    3D Slicer .seg.nrrd), a volume ADF (its first volume) or a folder of slices (which needs
    `dimensions` or `voxel_size`)."""
    path = Path(source)
    if path.is_dir():
        return load_slice_stack(
            path, prefix, labels=labels, dimensions=dimensions, voxel_size=voxel_size
        )
    suffix = "".join(path.suffixes[-2:]).lower()
    if path.suffix.lower() in (".nrrd", ".nhdr") or suffix == ".seg.nrrd":
        return load_nrrd(path, threshold=threshold)
    if path.suffix.lower() in (".yaml", ".yml"):
        volumes = World().load_volumes(path, labels=labels)
        if not volumes:
            raise ValueError(f"{path}: the file lists no volumes")
        return volumes[0].data
    if not path.exists():
        raise FileNotFoundError(2, "no such volume file or folder", str(path))
    raise ValueError(f"{path}: expected .nrrd, .seg.nrrd, a volume ADF (.yaml) or a slice folder")


def write_volume_adf(
    path: str | os.PathLike, data: VolumeData, name: str, prefix: str, count: int
) -> None:
    """Writes an AMBF volume ADF for a slice stack in the same folder (with the label table, an
    ambfplus extension that AMBF ignores)."""
    x, y, z = (float(v) for v in data.dimensions)
    Path(path).write_text(
        "# AMBF volume written by ambfplus convert\n"
        "bodies: []\njoints: []\n"
        f"volumes: [VOLUME {name}]\n\n"
        f"VOLUME {name}:\n"
        f"  name: {name}\n"
        "  location:\n"
        "    position: {x: 0.0, y: 0.0, z: 0.0}\n"
        "    orientation: {r: 0.0, p: 0.0, y: 0.0}\n"
        "  scale: 1.0\n"
        f"  dimensions: {{x: {x!r}, y: {y!r}, z: {z!r}}}\n"
        f"  images: {{path: ./, prefix: {prefix}, format: png, count: {count}}}\n"
        "  labels: labels.csv\n"
    )


def volume_sources(source: str | os.PathLike) -> list[Path]:
    """The files and folders a volume is read from: the source, and for a volume ADF the slice
    folders its volumes' ``images`` name (relative to the ADF)."""
    path = Path(source)
    found = [path]
    if path.suffix.lower() in (".yaml", ".yml") and path.is_file():
        import yaml

        try:
            blocks = yaml.safe_load(path.read_text())
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            return found  # the loader names what is wrong with it
        for value in blocks.values() if isinstance(blocks, dict) else ():
            images = value.get("images") if isinstance(value, dict) else None
            if isinstance(images, dict) and isinstance(images.get("path"), str):
                found.append(path.parent / images["path"])
    return found


def convert_volume(
    source: str | os.PathLike,
    output: str | os.PathLike,
    *,
    prefix: str = "plane00",
    labels: str | os.PathLike | None = None,
    dimensions: Sequence[float] | None = None,
    voxel_size: Sequence[float] | None = None,
    threshold: float | None = None,
    label: int = 0,
) -> str:
    """Converts a volume (see load_volume for sources) to a slice stack with its ADF and label
    table (output is a folder), an NRRD label map (.nrrd) or a surface mesh (.stl, .ply).
    Returns a one-line summary. An output that is the source, lies inside it or holds it (or
    the slice folder a volume ADF names) is refused before anything is read or written."""
    refuse_writing_over(output, volume_sources(source), "convert")
    data = load_volume(
        source,
        prefix=prefix,
        labels=labels,
        dimensions=dimensions,
        voxel_size=voxel_size,
        threshold=threshold,
    )
    out = Path(output)
    kind = out.suffix.lower()
    if kind:
        out.parent.mkdir(parents=True, exist_ok=True)
    if kind in (".stl", ".ply"):
        triangles = data.save_mesh(out, label=label)
        return f"{source} -> {out}: {triangles} triangles"
    if kind == ".nrrd":
        data.save_nrrd(out)
        return f"{source} -> {out}: {'x'.join(map(str, data.shape))} {data.label_type} labels"
    if kind:
        raise ValueError(f"{out}: expected a folder, .nrrd, .stl or .ply")
    out.mkdir(parents=True, exist_ok=True)
    data.save_slice_stack(out, prefix)
    write_label_table(out / "labels.csv", data.label_table)
    name = Path(source).name.split(".")[0] or "volume"
    write_volume_adf(out / "volume.yaml", data, name, prefix, data.shape[2])
    return f"{source} -> {out}: {data.shape[2]} slices, volume.yaml, labels.csv"
