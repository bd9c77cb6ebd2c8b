"""Reading recordings (the format is described in ``ambfplus.recording``): ``open_recording``
checks the head and every closed part, then gives lazy, h5py-backed access across parts."""

from __future__ import annotations

import bisect
import json
from collections import OrderedDict
from collections.abc import Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import Any

import h5py
import hdf5plugin  # noqa: F401 (registers the Blosc filter recordings use)
import numpy as np

from ..stereo import StereoFrame
from .hdf5 import (
    CheckedFile,
    check_dataset_type,
    check_variable_dataset,
    heap_type,
    open_checked,
    read_attribute,
    read_attributes,
    text_value,
)
from .schema import (
    EVENT_COLUMNS,
    FORMAT,
    FRAME_COLUMNS,
    IMAGE_PASSES,
    MINOR_VERSION_ATTR,
    REMOVED_COLUMNS,
    RIG_COLUMNS,
    STEP_REQUIRED,
    VERSION,
    VERSION_ATTR,
    GroupSummary,
    PartSummary,
    RecordingError,
    column_name,
    find_parts,
    legend_from_json,
    part_name,
    stored_name,
)

# Parts kept open at once while reading (a long session has many).
MAX_OPEN_PARTS = 32


def open_recording(path) -> Recording:
    """Opens a recording by its head file (``name.h5``; its parts sit beside it)."""
    return Recording(path)


@dataclass
class RecordedFrame:
    """One recorded camera frame; image passes that were not recorded are None."""

    stream: str
    index: int
    camera: str
    time: float
    step: int
    intrinsics: np.ndarray
    pose: np.ndarray
    rgb: np.ndarray | None = None
    depth: np.ndarray | None = None
    instance: np.ndarray | None = None
    label: np.ndarray | None = None
    voxel: np.ndarray | None = None
    points: np.ndarray | None = None
    segmentation: np.ndarray | None = None

    @property
    def height(self) -> int:
        return self._any_image().shape[0]

    @property
    def width(self) -> int:
        return self._any_image().shape[1]

    def _any_image(self) -> np.ndarray:
        return next(getattr(self, n) for n in IMAGE_PASSES if getattr(self, n) is not None)

    def __repr__(self) -> str:
        passes = [n for n in IMAGE_PASSES if getattr(self, n) is not None]
        return (
            f"RecordedFrame({self.stream}[{self.index}], camera={self.camera}, "
            f"time={self.time}, step={self.step}, {self.width}x{self.height}, passes={passes})"
        )


# What h5py raises where a file is damaged: HDF5's errors surface as any of these, depending on
# where the damage is met (metadata, chunk index, attributes, data).
DAMAGE = (OSError, RuntimeError, KeyError, ValueError, TypeError, AttributeError, IndexError)


@contextmanager
def _damage_is_an_error(path, what: str):
    """Turns what h5py raises for a damaged file into a RecordingError naming the file."""
    try:
        yield
    except RecordingError:
        raise
    except DAMAGE as error:
        raise RecordingError(
            f"{path}: damaged file: {what} failed ({type(error).__name__}: {error})"
        ) from error


class Recording:
    """A recording opened for reading: ``cameras``, ``rigs``, ``steps``, ``removed``,
    ``events``, ``metadata``, ``legend``, ``version`` (and ``minor_version``: 0 for format
    1.0, 1 for 1.1). Arrays are read when indexed."""

    def __init__(self, path) -> None:
        self.path = Path(path)
        with _damage_is_an_error(self.path, "reading the recording's structure"):
            self._open()

    def _open(self) -> None:
        head = _read_head(self.path)
        self.version: int = head["version"]
        self.minor_version: int = head["minor_version"]
        self.recording_id: str = head["recording_id"]
        self.created: str = head["created"]
        self.software_version: str = head["software_version"]
        self.complete: bool = head["complete"]
        self.metadata: dict = head["metadata"]
        self.legend: dict = head["legend"]
        self.conventions: dict = head["conventions"]
        # The texts as stored, which repair() writes back unchanged.
        self.metadata_text: str = head["metadata_text"]
        #: whether the head holds a metadata attribute (a recorder always writes one)
        self.metadata_stored: bool = head["metadata_stored"]
        self.legend_text: str = head["legend_text"]
        self.part_summaries = scan_parts(self.path, self.recording_id)
        if self.complete:
            _check_index(self.path, head["parts"], self.part_summaries)
        self._files = _PartFiles([p.path for p in self.part_summaries])
        self._groups = _concatenate_groups(self.path, self.part_summaries)
        _check_layout(self.part_summaries, self._groups)
        self.cameras: dict[str, CameraStream] = {
            name.split("/", 1)[1]: CameraStream(self._columns(name), attrs)
            for name, (_, attrs) in self._groups.items()
            if name.startswith("cameras/")
        }
        self.rigs: dict[str, RigStream] = {
            name.split("/", 1)[1]: RigStream(
                name.split("/", 1)[1], self._columns(name), attrs, self
            )
            for name, (_, attrs) in self._groups.items()
            if name.startswith("rigs/")
        }

    @property
    def parts(self) -> list[Path]:
        return [p.path for p in self.part_summaries]

    def _columns(self, group: str) -> dict[str, Column]:
        pieces, _ = self._groups[group]
        datasets = next(g for _, g in pieces).datasets
        return {
            name: Column(self._files, group, name, dtype, trailing, pieces)
            for name, (dtype, trailing) in datasets.items()
        }

    def column_names(self, group: str) -> list[str]:
        """The names of a group's columns (none for a group the recording lacks), read from
        its first part without reading any data."""
        return list(self._columns(group)) if group in self._groups else []

    @cached_property
    def steps(self) -> dict[str, np.ndarray]:
        """Columns at the physics rate (``step``, ``time`` and the producer's), read whole."""
        if "steps" not in self._groups:
            return {}
        return {name: column[:] for name, column in self._columns("steps").items()}

    def read_columns(self, group: str, names=None) -> dict[str, np.ndarray]:
        """Some whole columns of a group (``steps``, ``removed``, ...; `names` None: all of
        them), read part by part so that each part is opened once however many parts a long
        recording has."""
        return self.read_groups({group: names})[group]

    def read_groups(self, wanted: Mapping[str, Any]) -> dict[str, dict[str, np.ndarray]]:
        """Whole columns of several groups at once, `wanted` mapping each group to its column
        names (None: all), in one pass over the parts (a long recording has a thousand: each
        opened once, not once per group). Reading every column of ``removed`` or ``events``
        also keeps them as ``removed`` and ``events`` return them."""
        columns: dict[str, dict[str, Column]] = {}
        for group, names in wanted.items():
            if group not in self._groups:
                raise KeyError(f"{self.path}: the recording has no group {group!r}")
            found = self._columns(group)
            names = list(found) if names is None else list(names)
            missing = [n for n in names if n not in found]
            if missing:
                raise KeyError(f"{self.path}: {group} has no column {missing[0]!r} (it has "
                               f"{', '.join(sorted(found))})")  # fmt: skip
            columns[group] = {n: found[n] for n in names}
        # group -> {part index: the group's piece in that part}
        pieces = {
            group: {part: piece for piece, (part, _) in enumerate(self._groups[group][0])}
            for group in columns
        }
        chunks: dict[str, dict[str, list]] = {g: {n: [] for n in c} for g, c in columns.items()}
        for part in sorted({part for p in pieces.values() for part in p}):
            for group, named in columns.items():
                piece = pieces[group].get(part)
                if piece is not None:
                    for n, column in named.items():
                        chunks[group][n].append(column.read_piece(piece))
        out = {
            group: {n: np.concatenate(c) if c else columns[group][n][:0] for n, c in named.items()}
            for group, named in chunks.items()
        }
        for group, keep in (("removed", self._removed_from), ("events", self._events_from)):
            if group in out and set(out[group]) == set(self._columns(group)):
                self.__dict__[group] = keep(out[group])
        return out

    @cached_property
    def removed(self) -> dict:
        """Removed voxels: ``step`` (M,), ``voxel`` (M, 3), ``label`` (M,) and ``volume``."""
        if "removed" not in self._groups:
            out = {n: np.empty((0,) + t, d) for n, (d, t) in REMOVED_COLUMNS.items()}
            return {**out, "volume": None}
        return self._removed_from(self.read_columns("removed"))

    def _removed_from(self, columns: dict) -> dict:
        return {**columns, "volume": self._groups["removed"][1].get("volume")}

    @cached_property
    def events(self) -> list[dict]:
        """Events as dicts: ``step``, ``kind``, ``label``, ``voxel`` (i, j, k)."""
        if "events" not in self._groups:
            return []
        return self._events_from(self.read_columns("events"))

    def _events_from(self, c: dict) -> list[dict]:
        with _damage_is_an_error(self.path, "reading events"):
            return [
                {
                    "step": int(c["step"][i]),
                    "kind": str(c["kind"][i]),
                    "label": int(c["label"][i]),
                    "voxel": tuple(int(v) for v in c["voxel"][i]),
                }
                for i in range(len(c["step"]))
            ]

    def close(self) -> None:
        self._files.close()

    def __enter__(self) -> Recording:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    def rows(self, group: str) -> int:
        """Rows of a group (``cameras/left``, ``steps``, ...) across parts, 0 if absent."""
        pieces, _ = self._groups.get(group, ([], {}))
        return sum(summary.rows for _, summary in pieces)

    def __repr__(self) -> str:
        cameras = ", ".join(f"{n}: {len(s)}" for n, s in self.cameras.items())
        return (
            f"<Recording {self.path} v{self.version}.{self.minor_version}, {len(self.parts)} "
            f"parts, cameras "
            f"{{{cameras}}}, rigs {list(self.rigs)}, {self.rows('steps')} steps, "
            f"{self.rows('removed')} removed voxels, {self.rows('events')} events"
            f"{'' if self.complete else ', not closed (interrupted)'}>"
        )


class Column(Sequence):
    """One dataset read lazily across parts: ``len``, ``shape``, indexing by int, slice or a
    list of ints, ``np.asarray``."""

    def __init__(self, files, group, name, dtype, trailing, pieces) -> None:
        self._files = files
        self.path = f"{group}/{stored_name(name)}"
        self.is_text = np.dtype(dtype).kind == "O"
        self.dtype = np.dtype(object) if self.is_text else np.dtype(dtype)
        self._trailing = tuple(trailing)
        self._parts = [part_index for part_index, _ in pieces]
        self._starts = [0]
        for _, group_summary in pieces:
            self._starts.append(self._starts[-1] + group_summary.rows)

    def __len__(self) -> int:
        return self._starts[-1]

    @property
    def shape(self) -> tuple[int, ...]:
        return (len(self),) + self._trailing

    def __getitem__(self, key):
        if isinstance(key, tuple):
            return self[key[0]][key[1:]]
        if isinstance(key, slice):
            start, stop, stride = key.indices(len(self))
            if stride == 1:
                return self._read_range(start, max(start, stop))
            return self._read_rows(range(start, stop, stride))
        if isinstance(key, (int, np.integer)):
            return self._read_row(self._normalise(int(key)))
        return self._read_rows([self._normalise(int(i)) for i in np.asarray(key).ravel()])

    def __array__(self, dtype=None, copy=None):
        array = self[:]
        return array if dtype is None else array.astype(dtype)

    def _normalise(self, index: int) -> int:
        if not -len(self) <= index < len(self):
            raise IndexError(f"{self.path}: index {index} out of range for {len(self)} rows")
        return index % len(self)

    def _dataset(self, piece: int):
        dataset = self._files.dataset(self._parts[piece], self.path)
        return dataset.asstr() if self.is_text else dataset

    def _read_row(self, index: int):
        piece = bisect.bisect_right(self._starts, index) - 1
        with _damage_is_an_error(self._files.path(self._parts[piece]), f"reading {self.path}"):
            return self._dataset(piece)[index - self._starts[piece]]

    def _read_rows(self, indices) -> np.ndarray:
        rows = [self._read_row(i) for i in indices]
        return np.array(rows, dtype=self.dtype) if rows else self._empty()

    def read_piece(self, piece: int) -> np.ndarray:
        """The rows this column holds in one part (piece `piece` of its parts)."""
        with _damage_is_an_error(self._files.path(self._parts[piece]), f"reading {self.path}"):
            return np.asarray(self._dataset(piece)[:])

    def _read_range(self, start: int, stop: int) -> np.ndarray:
        chunks = []
        for piece in range(len(self._parts)):
            lo, hi = max(start, self._starts[piece]), min(stop, self._starts[piece + 1])
            if lo < hi:
                offset = self._starts[piece]
                part = self._files.path(self._parts[piece])
                with _damage_is_an_error(part, f"reading {self.path}"):
                    chunks.append(np.asarray(self._dataset(piece)[lo - offset : hi - offset]))
        return np.concatenate(chunks) if chunks else self._empty()

    def _empty(self) -> np.ndarray:
        return np.empty((0,) + self._trailing, dtype=self.dtype)


class CameraStream(Sequence):
    """One camera stream: ``len``, ``stream[i]`` -> RecordedFrame, and lazy columns ``rgb``,
    ``depth``, ``instance``, ``label``, ``voxel``, ``points`` (None when not recorded),
    ``time``, ``step``, ``intrinsics``, ``pose``."""

    def __init__(self, columns: dict[str, Column], attrs: dict) -> None:
        self.columns = columns
        self.name = next(iter(columns.values())).path.split("/")[1]
        self.camera = attrs.get("camera", self.name)
        self.passes = [name for name in IMAGE_PASSES if name in columns]

    def __len__(self) -> int:
        return len(self.columns["time"])

    def __getitem__(self, index):
        if isinstance(index, slice):
            return [self[i] for i in range(*index.indices(len(self)))]
        index = self.columns["time"]._normalise(int(index))
        images = {name: self.columns[name][index] for name in self.passes}
        return RecordedFrame(
            stream=self.name,
            index=index,
            camera=self.camera,
            time=float(self.columns["time"][index]),
            step=int(self.columns["step"][index]),
            intrinsics=self.columns["intrinsics"][index],
            pose=self.columns["pose"][index],
            **images,
        )

    def __getattr__(self, name: str):
        if name in IMAGE_PASSES:
            return self.columns.get(name)
        if name in ("time", "step", "intrinsics", "pose"):
            return self.columns[name]
        raise AttributeError(name)

    def __repr__(self) -> str:
        return f"<CameraStream {self.name} ({self.camera}): {len(self)} frames, {self.passes}>"


class RigStream(Sequence):
    """A stereo rig's pairs: ``rig[i]`` -> ``ambfplus.stereo.StereoFrame`` of RecordedFrames;
    columns ``baseline``, ``dcx``, ``time``, ``step``, ``left_index``, ``right_index``."""

    def __init__(self, name: str, columns: dict[str, Column], attrs: dict, recording) -> None:
        self.name = name
        self.columns = columns
        self._path = recording.path
        try:
            self.left = recording.cameras[attrs["left"]]
            self.right = recording.cameras[attrs["right"]]
        except KeyError as missing:
            raise RecordingError(
                f"{recording.path}: rigs/{name} names stream {missing}, which is not recorded"
            ) from None

    def __len__(self) -> int:
        return len(self.columns["baseline"])

    def __getitem__(self, index):
        index = self.columns["baseline"]._normalise(int(index))
        return StereoFrame(
            left=self._view(self.left, "left_index", index),
            right=self._view(self.right, "right_index", index),
            baseline=float(self.columns["baseline"][index]),
            dcx=float(self.columns["dcx"][index]),
        )

    def _view(self, stream: CameraStream, column: str, index: int) -> RecordedFrame:
        row = int(self.columns[column][index])
        if not 0 <= row < len(stream):
            raise RecordingError(
                f"{self._path}: rigs/{self.name}/{column}[{index}] is {row}, but stream "
                f"{stream.name} has {len(stream)} frames"
            )
        return stream[row]

    def __getattr__(self, name: str):
        if name in ("columns", "left", "right", "name"):
            raise AttributeError(name)
        try:
            return self.columns[name]
        except KeyError:
            raise AttributeError(name) from None


class _PartFiles:
    """Part files opened on demand, the least recently used closed beyond MAX_OPEN_PARTS."""

    def __init__(self, paths: list[Path]) -> None:
        self._paths = paths
        self._open: OrderedDict[int, CheckedFile] = OrderedDict()
        # The datasets looked up in each open part (a lookup costs more than a small read).
        self._datasets: dict[int, dict[str, h5py.Dataset]] = {}

    def path(self, index: int) -> Path:
        return self._paths[index]

    def get(self, index: int) -> h5py.File:
        f = self._open.get(index)
        if f is None:
            f = self._open[index] = open_checked(self._paths[index])
            self._datasets[index] = {}
            if len(self._open) > MAX_OPEN_PARTS:
                closed, oldest = self._open.popitem(last=False)
                del self._datasets[closed]
                oldest.close()
        self._open.move_to_end(index)
        return f.file

    def dataset(self, index: int, path: str) -> h5py.Dataset:
        """Dataset `path` of part `index`."""
        file = self.get(index)
        found = self._datasets[index].get(path)
        if found is None:
            found = self._datasets[index][path] = file[path]
        return found

    def close(self) -> None:
        self._datasets.clear()
        while self._open:
            self._open.popitem()[1].close()


def _read_head(path: Path) -> dict:
    """The head's attributes, checked: format, version, JSON metadata and legend."""
    checked = open_checked(path, heaps="always")
    with checked.file as f:
        attrs = read_attributes(checked, f)
        found = text_value(attrs.get("format"))
        if found != FORMAT:
            raise RecordingError(
                f"{path}: not an ambfplus recording (root attribute 'format' is {found!r}, "
                f"expected '{FORMAT}')"
            )
        if "part" in attrs:
            raise RecordingError(
                f"{path}: this is one part of a recording; open its head file instead"
            )
        version = read_attribute(checked, f, VERSION_ATTR, expect="integer")
        if version is None or int(version) != VERSION:
            version = version.item() if isinstance(version, np.generic) else version
            raise RecordingError(
                f"{path}: recording version {version!r} (attribute '{VERSION_ATTR}') is not "
                f"supported; this ambfplus reads version {VERSION}"
            )
        try:
            metadata = text_value(attrs.get("metadata")) or "{}"
            legend = text_value(attrs.get("legend")) or "{}"
            return {
                "version": int(version),
                "minor_version": int(attrs.get(MINOR_VERSION_ATTR, 0)),
                "recording_id": text_value(attrs["recording_id"]),
                "created": text_value(attrs.get("created")),
                "software_version": text_value(attrs.get("software_version")),
                "complete": bool(attrs.get("complete", False)),
                "metadata": json.loads(metadata),
                "metadata_text": metadata,
                "metadata_stored": "metadata" in attrs,
                "legend": legend_from_json(legend),
                "legend_text": legend,
                "parts": json.loads(text_value(attrs.get("parts")) or "[]"),
                "conventions": {
                    k: text_value(v) for k, v in read_attributes(checked, f["conventions"]).items()
                }
                if "conventions" in f
                else {},
            }
        except (KeyError, ValueError) as error:
            raise RecordingError(
                f"{path}: a root attribute is missing or invalid: {error}"
            ) from None


def scan_parts(head: Path, recording_id: str) -> list[PartSummary]:
    """Every closed part on disk, checked: numbered 1..n without gaps, of this recording, each
    group's datasets of equal length."""
    summaries = []
    for expected, (number, path) in enumerate(find_parts(head), start=1):
        if number != expected:
            raise RecordingError(
                f"{part_name(head, expected)}: missing, but later parts exist: the recording "
                "lost data"
            )
        summaries.append(_summarise_part(path, recording_id, number))
    return summaries


def _summarise_part(path: Path, recording_id: str, number: int) -> PartSummary:
    checked = open_checked(path)
    with checked.file as f:
        found_id = text_value(read_attribute(checked, f, "recording_id"))
        found_number = read_attribute(checked, f, "part", expect="integer")
        if found_id != recording_id or found_number != number:
            raise RecordingError(
                f"{path}: not part {number} of recording {recording_id} (attributes "
                f"'recording_id', 'part' say {found_id}, {found_number})"
            )
        summary = PartSummary(path)
        # Through the low-level API (the same library calls as h5py's visititems: a visit of
        # the names, then each object opened): a long recording has a thousand parts of some
        # fifty datasets, and each high-level object costs more than reading its header.
        names: list[bytes] = []
        h5py.h5o.visit(f.id, names.append)
        for name in names:
            found = h5py.h5o.open(f.id, name)
            if isinstance(found, h5py.h5d.DatasetID):
                _summarise_dataset(checked, summary, name.decode("utf-8", "replace"), found)
        return summary


def _summarise_dataset(checked: CheckedFile, summary: PartSummary, name: str, dataset) -> None:
    """Adds one dataset (a low-level h5py DatasetID) to its group's summary, checked: no
    variable-length type in a format 1.1 part, as many rows as the group's other datasets."""
    path = checked.path
    type_id = dataset.get_type()
    check_dataset_type(checked, name, type_id)
    if heap_type(type_id):
        check_variable_dataset(checked, name, dataset)
    group, column = name.rsplit("/", 1) if "/" in name else ("", name)
    column = column_name(column)
    shape = dataset.shape
    entry = summary.groups.get(group)
    if entry is None:
        parent = checked.file[group] if group else checked.file
        attrs: dict[str, object] = {
            k: text_value(v) for k, v in read_attributes(checked, parent).items()
        }
        entry = summary.groups[group] = GroupSummary(shape[0] if shape else 0, {}, attrs)
    if not shape or shape[0] != entry.rows:
        other = next(iter(entry.datasets), None)
        raise RecordingError(
            f"{path}: inconsistent lengths: dataset {name} has shape {shape}, but "
            f"{group}/{other} has {entry.rows} rows"
        )
    dtype = dataset.dtype
    string = h5py.check_string_dtype(dtype)
    if string:
        entry.strings[column] = (string.encoding, string.length)
    entry.datasets[column] = (np.dtype(object) if string else dtype, shape[1:])


def _concatenate_groups(head: Path, parts: list[PartSummary]) -> dict:
    """group -> ([(part index, GroupSummary), ...], attrs), checking that a group has the same
    datasets in every part."""
    groups: dict[str, tuple[list, dict]] = {}
    for index, part in enumerate(parts):
        for name, group in part.groups.items():
            pieces, attrs = groups.setdefault(name, ([], group.attrs))
            if pieces and pieces[0][1].datasets != group.datasets:
                first = parts[pieces[0][0]].path
                raise RecordingError(
                    f"{part.path}: group {name} holds {_describe(group.datasets)}, but in "
                    f"{first} it holds {_describe(pieces[0][1].datasets)}"
                )
            pieces.append((index, group))
    return groups


# Columns every group of a kind must have: name -> (dtype, trailing shape); None = text.
_REQUIRED: dict[str, Mapping[str, tuple[Any, tuple[Any, ...]]]] = {
    "cameras/": FRAME_COLUMNS,
    "rigs/": RIG_COLUMNS,
    "removed": REMOVED_COLUMNS,
    "events": EVENT_COLUMNS,
    "steps": {name: (dtype, ()) for name, dtype in STEP_REQUIRED.items()},
}


def _check_layout(parts: list[PartSummary], groups: dict) -> None:
    """Every group has its kind's columns with their types and shapes, and a camera stream at
    least one image pass of its type (else a damaged file fails later, outside the reader)."""
    for name, (pieces, _) in groups.items():
        kind = name.split("/", 1)[0] + "/" if "/" in name else name
        if kind not in _REQUIRED:
            continue
        path, datasets = parts[pieces[0][0]].path, pieces[0][1].datasets
        expected = dict(_REQUIRED[kind])
        if kind == "cameras/":
            if not any(p in datasets for p in IMAGE_PASSES):
                raise RecordingError(f"{path}: {name} holds no image pass of {list(IMAGE_PASSES)}")
            expected.update({p: (d, (None, None) + t) for p, (d, t) in IMAGE_PASSES.items()})
        for column, (dtype, trailing) in expected.items():
            found = datasets.get(column)
            if found is None and (kind != "cameras/" or column not in IMAGE_PASSES):
                raise RecordingError(f"{path}: {name} has no dataset '{column}'")
            if found is not None and not _same_layout(found, dtype, trailing):
                want = "text" if dtype is None else f"{dtype} {_shape_text(trailing)}"
                raise RecordingError(
                    f"{path}: {name}/{column} is {found[0]} {tuple(found[1])} per row, "
                    f"expected {want}"
                )


def _same_layout(found: tuple, dtype, trailing: tuple) -> bool:
    """A dataset's (dtype, shape of a row) against the layout's (None in a shape: any size,
    None as dtype: text). Byte order does not matter."""
    found_dtype, found_trailing = np.dtype(found[0]), tuple(found[1])
    if dtype is None:
        return found_dtype.kind == "O" and found_trailing == tuple(trailing)
    dtype = np.dtype(dtype)
    if (found_dtype.kind, found_dtype.itemsize) != (dtype.kind, dtype.itemsize):
        return False
    return len(found_trailing) == len(trailing) and all(
        want is None or want == got for want, got in zip(trailing, found_trailing)
    )


def _shape_text(trailing: tuple) -> str:
    names = iter("HW")
    return "(" + ", ".join(next(names) if n is None else str(n) for n in trailing) + ")"


def _describe(datasets: dict) -> str:
    return ", ".join(f"{n} {d} {tuple(t)}" for n, (d, t) in sorted(datasets.items()))


def _check_index(head: Path, listed: list[str], parts: list[PartSummary]) -> None:
    """A closed recording lists its parts: every one must be there, and no other."""
    found = [p.path.name for p in parts]
    if found != listed:
        missing = sorted(set(listed) - set(found))
        extra = sorted(set(found) - set(listed))
        raise RecordingError(
            f"{head}: the head lists {len(listed)} parts but {len(found)} are on disk "
            f"(missing: {missing or 'none'}; not listed: {extra or 'none'})"
        )


__all__ = ["CameraStream", "Column", "RecordedFrame", "Recording", "RigStream", "open_recording"]
