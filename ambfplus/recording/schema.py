"""The recording file format's constants: names, dtypes, conventions and the part-file naming
shared by the writer (``writer``), the reader (``reader``) and the validator
(``validation``). The format itself is described in ``ambfplus.recording``."""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import ConfigError

FORMAT = "ambfplus.recording"
VERSION = 1
VERSION_ATTR = "ambfplus_recording_version"
# 1.1: text (attributes, string columns) is stored as fixed-length UTF-8 strings, never
# variable-length, so that reading needs no global heap (see ``hdf5``). Files without
# this attribute are 1.0. Readers of 1.0 read 1.1 files (fixed-length strings come back as bytes).
MINOR_VERSION = 1
MINOR_VERSION_ATTR = "ambfplus_recording_minor_version"

# Per-pixel camera outputs: dtype and trailing shape after (H, W).
IMAGE_PASSES = {
    "rgb": (np.dtype(np.uint8), (3,)),
    "depth": (np.dtype(np.float32), ()),
    "instance": (np.dtype(np.int32), ()),
    "label": (np.dtype(np.uint16), ()),
    "points": (np.dtype(np.float32), (3,)),
    "voxel": (np.dtype(np.int32), ()),
    "segmentation": (np.dtype(np.uint8), (3,)),
}
# Per-frame camera columns: dtype and trailing shape.
FRAME_COLUMNS = {
    "time": (np.dtype(np.float64), ()),
    "step": (np.dtype(np.int64), ()),
    "intrinsics": (np.dtype(np.float64), (3, 3)),
    "pose": (np.dtype(np.float64), (4, 4)),
}
RIG_COLUMNS = {
    "time": (np.dtype(np.float64), ()),
    "step": (np.dtype(np.int64), ()),
    "baseline": (np.dtype(np.float64), ()),
    "dcx": (np.dtype(np.float64), ()),
    "left_index": (np.dtype(np.int64), ()),
    "right_index": (np.dtype(np.int64), ()),
}
REMOVED_COLUMNS = {
    "step": (np.dtype(np.int64), ()),
    "voxel": (np.dtype(np.int32), (3,)),
    "label": (np.dtype(np.uint16), ()),
}
EVENT_COLUMNS = {
    "step": (np.dtype(np.int64), ()),
    "kind": (None, ()),  # UTF-8 text
    "label": (np.dtype(np.uint16), ()),
    "voxel": (np.dtype(np.int32), (3,)),
}
STEP_REQUIRED = {"step": np.dtype(np.int64), "time": np.dtype(np.float64)}

CONVENTIONS = {
    "units": "SI: metres, seconds, kilograms, newtons, radians",
    "world_frame": "right-handed, z up",
    "camera_frame": "OpenCV: x right, y down, z forward; image row 0 is the top",
    "pose": "float64 4x4 world-from-camera (camera frame as above), one per frame",
    "intrinsics": "float64 3x3 K, fx = fy = H / (2 tan(fov_y / 2)); pixel (row r, column c) is "
    "centred at (c + 0.5, r + 0.5): subtract 0.5 from cx, cy for OpenCV",
    "rgb": "uint8 (H, W, 3), RGB order",
    "depth": "float32 (H, W), metric z along the optical axis, 0 where nothing was hit",
    "points": "float32 (H, W, 3), camera frame, points = depth * K^-1 [c + 0.5, r + 0.5, 1]; "
    "0 where nothing was hit",
    "instance": "int32 (H, W) object id (0 = background), names in the legend",
    "label": "uint16 (H, W) volume label id (0 = none), names in the legend's volume labels",
    "voxel": "int32 (H, W) index of the volume voxel seen, i + nx * (j + ny * k) (i fastest); "
    "-1 where no voxel is seen",
    "segmentation": "uint8 (H, W, 3) flat RGB colours as AMBF's preprocessing shaders draw them",
    "removed_voxel": "int32 (i, j, k) global voxel indices of the named volume; never restart",
    "time": "float64 simulation seconds; step: int64 fixed-step index",
    "stereo": "baseline = |t_right - t_left| (m); dcx = cx_right - cx_left (px); "
    "Z = f B / (d + dcx)",
}

# Columns whose rows are at least this big are written one row per chunk as they arrive;
# smaller ones are gathered in memory and written in larger chunks.
IMAGE_ROW_BYTES = 64 * 1024
SMALL_CHUNK_BYTES = 64 * 1024
PART_DIGITS = 4


class RecordingError(ConfigError):
    """A file that is not a readable ambfplus recording, or a recorder that failed."""


_STORED_ESCAPES = {"25": "%", "2F": "/"}


def stored_name(name: str) -> str:
    """A column's name as its HDF5 dataset is named: a namespaced object's step-log column
    (``psm1/link.pose``) holds '/', which HDF5 reads as a path, so '%' and '/' are stored as
    ``%25`` and ``%2F`` (``psm1%2Flink.pose``); every other name is stored as it is."""
    return name.replace("%", "%25").replace("/", "%2F")


def column_name(stored: str) -> str:
    """The column name a dataset name stands for (``stored_name`` undone)."""
    if "%" not in stored:
        return stored
    return re.sub(r"%(25|2F)", lambda m: _STORED_ESCAPES[m[1]], stored)


def text_dtype(length: int | None):
    """h5py's dtype for UTF-8 text: fixed-length (`length` bytes), or variable-length for None
    (format 1.0 only)."""
    import h5py

    return h5py.string_dtype("utf-8", length)


def text_attribute(text: str, where: str) -> np.ndarray:
    """A fixed-length UTF-8 string value for an HDF5 attribute (at least 1 byte long)."""
    encoded = check_text(text, where).encode("utf-8")
    return np.array(encoded, dtype=text_dtype(max(1, len(encoded))))


def text_column(values: np.ndarray) -> np.ndarray:
    """Text rows (an object array of str) as fixed-length UTF-8 strings, as wide as the
    longest (at least 1 byte)."""
    encoded = [value.encode("utf-8") for value in values.ravel()]
    width = max([1] + [len(e) for e in encoded])
    return np.array(encoded, dtype=text_dtype(width)).reshape(values.shape)


def check_text(text: str, where: str) -> str:
    """Text HDF5 can store: fixed-length strings drop trailing NULs, variable-length ones
    refuse any."""
    if "\0" in text:
        raise ValueError(f"{where}: text may not contain NUL characters, got {text!r}")
    return text


def part_name(head: Path, number: int) -> Path:
    """``name.h5`` -> ``name.h5.part0001`` (the n-th closed segment)."""
    return head.with_name(f"{head.name}.part{number:0{PART_DIGITS}d}")


def part_number(head: Path, candidate: Path) -> int | None:
    """The segment number of ``candidate`` if it is one of ``head``'s parts, else None."""
    pattern = re.escape(head.name) + r"\.part(\d{" + str(PART_DIGITS) + ",})"
    match = re.fullmatch(pattern, candidate.name)
    return int(match.group(1)) if match else None


def recording_files(head: Path) -> list[Path]:
    """A recording's files on disk: its head and its closed parts."""
    return [Path(head)] + [path for _, path in find_parts(Path(head))]


def find_parts(head: Path) -> list[tuple[int, Path]]:
    """Closed segments on disk, sorted by number (temporary files excluded)."""
    found = []
    for candidate in head.parent.glob(glob_escape(head.name) + ".part*"):
        number = part_number(head, candidate)
        if number is not None:
            found.append((number, candidate))
    return sorted(found)


def glob_escape(name: str) -> str:
    return re.sub(r"([*?\[])", r"[\1]", name)


@dataclass
class GroupSummary:
    """One group of one part: its row count, datasets (dtype, trailing shape; text is dtype
    object), attributes, and how each text dataset is stored: (encoding, length in bytes, None
    for variable-length)."""

    rows: int
    datasets: dict[str, tuple[np.dtype, tuple[int, ...]]] = field(default_factory=dict)
    attrs: dict[str, object] = field(default_factory=dict)
    strings: dict[str, tuple[str, int | None]] = field(default_factory=dict)


@dataclass
class PartSummary:
    """What a closed segment holds, keyed by group path (``cameras/left``, ``steps``, ...)."""

    path: Path
    groups: dict[str, GroupSummary] = field(default_factory=dict)


def to_json(value, what: str) -> str:
    """JSON text of user metadata or a legend (NumPy scalars, arrays and tuples allowed)."""
    try:
        return json.dumps(value, default=_json_default, sort_keys=True)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{what} must be JSON-serialisable: {error}") from None


def _json_default(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"{type(value).__name__} is not JSON-serialisable")


def legend_from_json(text: str) -> dict:
    """Inverse of the legend's JSON: integer ids as keys again, colours and shapes as tuples."""
    raw = json.loads(text)
    return {_maybe_int(key): _restore_entry(entry) for key, entry in raw.items()}


def _restore_entry(entry):
    if not isinstance(entry, dict):
        return entry
    out = {}
    for key, value in entry.items():
        if key == "labels" and isinstance(value, dict):
            value = {_maybe_int(k): _restore_entry(v) for k, v in value.items()}
        elif key in ("color", "shape") and isinstance(value, list):
            value = tuple(value)
        out[key] = value
    return out


def _maybe_int(key: str):
    return int(key) if key.lstrip("-").isdigit() else key
