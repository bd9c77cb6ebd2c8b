"""The recording writer: ``Recorder`` buffers what a session hands it and writes it into
segment files (parts) and a head file whose virtual datasets join them; ``repair`` finishes
a recording a crash left open. The format is described in ``ambfplus.recording``."""

from __future__ import annotations

import atexit
import os
import sys
import threading
import time
import uuid
import weakref
from collections import deque
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from datetime import datetime, timezone
from pathlib import Path

import h5py
import hdf5plugin  # registers the Blosc filter with HDF5
import numpy as np

from .._core import __version__
from ..fileio import temporary_name, write_bytes
from ..labels import legend as object_legend
from .reader import (
    Recording,
    open_recording,
    scan_parts,
)
from .schema import (
    CONVENTIONS,
    EVENT_COLUMNS,
    FORMAT,
    FRAME_COLUMNS,
    IMAGE_PASSES,
    IMAGE_ROW_BYTES,
    MINOR_VERSION,
    MINOR_VERSION_ATTR,
    REMOVED_COLUMNS,
    RIG_COLUMNS,
    SMALL_CHUNK_BYTES,
    STEP_REQUIRED,
    VERSION,
    VERSION_ATTR,
    GroupSummary,
    PartSummary,
    RecordingError,
    check_text,
    find_parts,
    part_name,
    stored_name,
    text_attribute,
    text_column,
    to_json,
)
from .validation import leftover_files

MiB = 1024 * 1024
# Passes recorded when add_frame is not told which: everything a frame holds except points,
# which follow from depth and the intrinsics and would double the size.
DEFAULT_PASSES = ("rgb", "depth", "instance", "label", "voxel", "segmentation")
COMPRESSIONS = ("blosc-lz4", "lzf", "gzip", None)
# Gathered small columns are written out once they reach this size.
BUFFER_BYTES = 8 * MiB


@dataclass
class RecorderStats:
    """Counters of a recorder (a snapshot; ``Recorder.stats`` returns a fresh one)."""

    frames_queued: int = 0
    frames_written: int = 0  #: handed to HDF5 by the writer thread
    frames_flushed: int = 0  #: in closed parts: these survive a crash
    bytes_queued: int = 0  #: uncompressed bytes handed to the recorder
    bytes_written: int = 0
    seconds_blocked: float = 0.0  #: producer time spent waiting for queue space
    blocked_calls: int = 0
    pending_bytes: int = 0
    pending_high_water_bytes: int = 0
    parts: int = 0


@dataclass
class _Rows:
    """Rows appended to one group; ``frames`` counts camera frames among them."""

    group: str
    columns: dict[str, np.ndarray]
    attrs: dict = field(default_factory=dict)
    frames: int = 0
    nbytes: int = 0

    def __post_init__(self) -> None:
        self.nbytes = sum(column.nbytes for column in self.columns.values())

    @property
    def count(self) -> int:
        return len(next(iter(self.columns.values())))

    @property
    def time(self) -> float | None:
        """The latest simulation time among the rows (None without a time column)."""
        times = self.columns.get("time")
        if times is None or not len(times):
            return None
        latest = float(np.max(times))
        return latest if np.isfinite(latest) else None


def _latest_time(items) -> float | None:
    """The latest simulation time among queued items (rows, or batches of rows)."""
    found = [_latest_time(i.items) if isinstance(i, _Batch) else getattr(i, "time", None)
             for i in items]  # fmt: skip
    times = [t for t in found if t is not None]
    return max(times) if times else None


@dataclass
class _Legend:
    text: str
    nbytes: int = 0


@dataclass
class _Batch:
    """Rows that must land in the same part (a stereo pair's two views and its rig row): a part
    boundary never splits them, so a recording cut at any moment holds whole pairs."""

    items: list
    nbytes: int = 0
    frames: int = 0

    def __post_init__(self) -> None:
        self.nbytes = sum(item.nbytes for item in self.items)
        self.frames = sum(getattr(item, "frames", 0) for item in self.items)


@dataclass
class _Flush:
    done: threading.Event = field(default_factory=threading.Event)
    nbytes: int = 0


_CLOSE = object()
# The crash bound (Recorder._wait_for_durable): a part closes once it holds this fraction of the
# flush interval of simulation time, and a producer this far past the last closed part waits.
CLOSE_AFTER = 0.75
BLOCK_AFTER = 0.9


class Recorder:
    """Records frames, stereo pairs, steps, removed voxels and events into ``path`` (see the
    module docstring for the layout). All HDF5 work happens on a background thread; ``add_*``
    copies its arrays and returns, or blocks while ``max_pending_bytes`` are waiting (HDF5's
    chunk cache, up to 8 MiB per image dataset, comes on top). A part closes once it holds 0.75
    of ``flush_interval_s`` of simulation time (rows' ``time``) or after ``flush_interval_s`` of
    wall-clock time, and ``add_*`` waits while what is queued runs more than 0.9 of the interval
    past the last closed part, so that a SIGKILL loses at most one interval of simulation time
    (the first part closes within it of the session's start); ``compression`` is "blosc-lz4"
    (the default), "lzf", "gzip" or None.
    ``recording_id`` and ``created`` (ISO 8601) replace the random id and the clock's time:
    with them, the same rows give the same bytes (a reproducible file)."""

    def __init__(
        self,
        path,
        metadata: dict | None = None,
        *,
        max_pending_bytes: int = 512 * MiB,
        flush_interval_s: float = 1.0,
        compression: str | None = "blosc-lz4",
        overwrite: bool = False,
        recording_id: str | None = None,
        created: str | None = None,
    ) -> None:
        if not max_pending_bytes > 0:
            raise ValueError(f"max_pending_bytes must be > 0, got {max_pending_bytes}")
        if not flush_interval_s > 0:
            raise ValueError(f"flush_interval_s must be > 0 s, got {flush_interval_s}")
        if compression not in COMPRESSIONS:
            raise ValueError(f"compression must be one of {COMPRESSIONS}, got {compression!r}")
        self.path = Path(path)
        self.max_pending_bytes = int(max_pending_bytes)
        self.flush_interval_s = float(flush_interval_s)
        self.compression = compression
        self._head = _HeadInfo(
            recording_id=check_text(str(recording_id or uuid.uuid4().hex), "recording_id"),
            created=check_text(str(created or datetime.now(timezone.utc).isoformat()), "created"),
            metadata=to_json(metadata or {}, "metadata"),
        )
        # Producer side: what each group holds, so that a mismatch fails in the caller.
        self._producer_lock = threading.RLock()
        self._schemas: dict[str, dict[str, tuple[np.dtype, tuple]]] = {}
        self._group_attrs: dict[str, dict] = {}
        self._rows_queued: dict[str, int] = {}
        # Queue shared with the writer thread.
        self._cond = threading.Condition()
        self._queue: deque = deque()
        self._stats = RecorderStats()
        self._pending = 0  # bytes queued or being written
        # Simulation time, for the crash bound (see _enqueue): the latest queued, the latest in
        # a closed part, and the first (the session's start, before any part is closed).
        self._queued_time: float | None = None
        self._durable_time: float | None = None
        self._part_time: float | None = None  # the latest written into the open part
        self._error: BaseException | None = None
        self._closing = False
        # Writer side.
        self._part: _PartFile | None = None
        self._parts: list[PartSummary] = []
        self._head_dirty = False

        _prepare_path(self.path, overwrite)
        write_head(self.path, self._head, [], complete=False)
        self._thread = threading.Thread(target=self._run, name=f"recorder {self.path.name}")
        self._thread.daemon = True
        self._thread.start()
        _OPEN_RECORDERS.add(self)

    # Producer API -----------------------------------------------------------------------

    def add_frame(self, stream_name: str, frame, *, passes=None) -> None:
        """Appends one camera frame (an ``ambfplus.Frame``, or any object or mapping with its
        attributes) to ``cameras/<stream_name>``. ``passes`` picks image passes (default: all
        the frame holds but ``points``)."""
        with self._producer_lock:
            rows = _frame_rows(stream_name, frame, passes)
            self._submit([rows])

    def add_stereo(self, rig_name: str, stereo_frame, *, passes=None) -> None:
        """Appends both views of a ``StereoFrame`` (streams named after the two cameras) and a
        row of ``rigs/<rig_name>`` (baseline, dcx and the views' row indices)."""
        left_name = _camera_name(stereo_frame.left, f"{rig_name}_left")
        right_name = _camera_name(stereo_frame.right, f"{rig_name}_right")
        if left_name == right_name:
            raise ValueError(f"rig {rig_name}: both views come from camera '{left_name}'")
        with self._producer_lock:
            left = _frame_rows(left_name, stereo_frame.left, passes)
            right = _frame_rows(right_name, stereo_frame.right, passes)
            rig = _rig_rows(
                rig_name,
                stereo_frame,
                left_name,
                right_name,
                self._rows_queued.get(left.group, 0),
                self._rows_queued.get(right.group, 0),
            )
            self._submit([left, right, rig])

    def add_steps(self, columns: Mapping) -> None:
        """Appends rows at the physics rate: equal-length columns, ``step`` and ``time``
        included. Scalars make one row. Every call must give the same columns."""
        with self._producer_lock:
            self._submit([_step_rows(columns)])

    def add_removed(self, removed: Mapping, volume: str | None = None) -> None:
        """Appends removed voxels: ``step`` (M,) or one step, ``voxel`` (M, 3) global indices,
        ``label`` (M,), as ``Drill.removed`` gives them; ``volume`` (a name or a Volume) says
        whose voxels they are."""
        volume = getattr(volume, "name", volume) or removed.get("volume")
        with self._producer_lock:
            # Later calls may leave the volume out: it stays the first call's.
            volume = volume or self._group_attrs.get("removed", {}).get("volume")
            rows = _removed_rows(removed, volume)
            if rows is not None:
                self._submit([rows])

    def add_events(self, events) -> None:
        """Appends events: dicts with ``step`` and ``kind``, optional ``label`` and ``voxel``
        (``Drill.events`` gives them)."""
        with self._producer_lock:
            rows = _event_rows(list(events))
            if rows is not None:
                self._submit([rows])

    def set_legend(self, legend) -> None:
        """Stores the id legend: a dict as ``ambfplus.labels.legend(world)`` gives it, or a
        ``World`` (then volumes also record their shape, which the voxel checks need)."""
        if hasattr(legend, "objects"):
            legend = world_legend(legend)
        self._enqueue([_Legend(to_json(legend, "legend"))])

    def flush(self) -> None:
        """Returns once everything added so far is in a closed part (safe from a crash)."""
        marker = _Flush()
        self._enqueue([marker])
        while not marker.done.wait(0.05):
            self._raise_if_failed()
        self._raise_if_failed()

    def close(self) -> None:
        """Writes what is queued, closes the last part and completes the head. Raises the
        writer thread's error, if it had one."""
        with self._cond:
            if not self._closing:
                self._closing = True
                self._queue.append(_CLOSE)
                self._cond.notify_all()
        self._thread.join()
        _OPEN_RECORDERS.discard(self)
        self._raise_if_failed()

    @property
    def stats(self) -> RecorderStats:
        with self._cond:
            return replace(self._stats, pending_bytes=self._pending)

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc_info) -> None:
        self.close()

    # Queue ---------------------------------------------------------------------------------

    def _submit(self, rows: list[_Rows]) -> None:
        """Checks rows against their groups' schemas, then queues them (caller holds the
        producer lock, so that a stereo pair's row indices stay right)."""
        for item in rows:
            self._register(item)
        self._enqueue([_Batch(rows)] if len(rows) > 1 else rows)
        for item in rows:
            self._rows_queued[item.group] = self._rows_queued.get(item.group, 0) + item.count

    def _register(self, rows: _Rows) -> None:
        schema = {name: (a.dtype, a.shape[1:]) for name, a in rows.columns.items()}
        known = self._schemas.setdefault(rows.group, schema)
        if known != schema:
            raise ValueError(f"{self.path}: {rows.group}: {_schema_difference(known, schema)}")
        attrs = self._group_attrs.setdefault(rows.group, rows.attrs)
        if attrs != rows.attrs:
            raise ValueError(
                f"{self.path}: {rows.group}: attributes {rows.attrs} differ from {attrs}"
            )

    def _enqueue(self, items: list) -> None:
        size = sum(item.nbytes for item in items)
        with self._cond:
            self._raise_if_failed()
            if self._closing:
                raise RecordingError(f"{self.path}: the recorder is closed")
            self._wait_for_space(size)
            self._queue.extend(items)
            self._pending += size
            stats = self._stats
            stats.bytes_queued += size
            stats.frames_queued += sum(getattr(item, "frames", 0) for item in items)
            stats.pending_high_water_bytes = max(stats.pending_high_water_bytes, self._pending)
            latest = _latest_time(items)
            if latest is not None:
                if self._durable_time is None:
                    self._durable_time = latest  # the session starts: nothing to lose before
                self._queued_time = max(latest, self._queued_time or latest)
            self._cond.notify_all()
            self._wait_for_durable()

    def _wait_for_durable(self) -> None:
        """The crash bound: a SIGKILL loses at most ``flush_interval_s`` of simulation time.
        The writer closes a part once it holds CLOSE_AFTER of the interval (or after the
        interval of wall-clock time); a producer whose queued rows run more than BLOCK_AFTER of
        it past the last closed part waits here until the writer catches up (under load; at
        the usual pace it never does). What a kill can lose is then under BLOCK_AFTER of the
        interval plus the producer's own batch of steps not yet handed over."""
        limit = BLOCK_AFTER * self.flush_interval_s
        start = None
        while (
            self._error is None
            and self._queued_time is not None
            and self._durable_time is not None
            and self._queued_time - self._durable_time > limit
        ):
            if start is None:
                start = time.perf_counter()
                self._stats.blocked_calls += 1
            self._cond.wait()
        if start is not None:
            self._stats.seconds_blocked += time.perf_counter() - start

    def _wait_for_space(self, size: int) -> None:
        """Backpressure: blocks while the queue is full (an item larger than the whole budget
        still goes through once the queue is empty)."""
        start = None
        while 0 < self._pending and self._pending + size > self.max_pending_bytes:
            if start is None:
                start = time.perf_counter()
                self._stats.blocked_calls += 1
            self._cond.wait()
            self._raise_if_failed()
        if start is not None:
            self._stats.seconds_blocked += time.perf_counter() - start

    def _raise_if_failed(self) -> None:
        if self._error is not None:
            raise RecordingError(
                f"{self.path}: the recording's writer thread failed ({self._error!r}); data "
                "up to its last flush is intact, nothing after it was written"
            ) from self._error

    # Writer thread -------------------------------------------------------------------------

    def _run(self) -> None:
        try:
            self._write_until_closed()
        except BaseException as error:  # surfaced in the producer
            self._abandon_part()
            with self._cond:
                self._error = error
                self._queue.clear()
                self._pending = 0
                self._cond.notify_all()

    def _write_until_closed(self) -> None:
        deadline = time.monotonic() + self.flush_interval_s
        while True:
            item = self._next_item(deadline)
            if item is _CLOSE:
                self._finish()
                return
            if item is not None:
                self._write(item)
                self._done_with(item)
            if (
                item is None
                or time.monotonic() >= deadline
                or isinstance(item, _Flush)
                or (self._part_spans(CLOSE_AFTER * self.flush_interval_s))
            ):
                self._rotate()
                if isinstance(item, _Flush):
                    item.done.set()
                deadline = time.monotonic() + self.flush_interval_s

    def _part_spans(self, span: float) -> bool:
        """Whether the open part holds rows more than `span` of simulation time past the last
        closed part (or the session's start)."""
        with self._cond:
            durable, latest = self._durable_time, self._part_time
        return durable is not None and latest is not None and latest - durable >= span

    def _next_item(self, deadline: float):
        """The next queued item, or None when the flush deadline passes first."""
        with self._cond:
            while not self._queue:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    return None
                self._cond.wait(remaining)
            return self._queue.popleft()

    def _done_with(self, item) -> None:
        with self._cond:
            self._pending -= item.nbytes
            self._stats.bytes_written += item.nbytes
            self._stats.frames_written += getattr(item, "frames", 0)
            self._cond.notify_all()

    def _write(self, item) -> None:
        """Writes one queued item (runs on the writer thread)."""
        if isinstance(item, _Batch):
            for rows in item.items:
                self._write(rows)
        elif isinstance(item, _Rows):
            if self._part is None:
                number = len(self._parts) + 1
                self._part = _PartFile(part_name(self.path, number), self._head, self.compression)
            self._part.append(item)
            self._part.raise_if_failed()
            latest = item.time
            if latest is not None:
                with self._cond:
                    self._part_time = max(latest, self._part_time or latest)
        elif isinstance(item, _Legend):
            self._head.legend = item.text
            self._head_dirty = True

    def _rotate(self) -> None:
        """Closes the current part and renames it into place; rewrites the head if needed."""
        if self._part is not None:
            summary = self._part.close()
            self._part = None
            self._parts.append(summary)
            frames = sum(
                group.rows for name, group in summary.groups.items() if name.startswith("cameras/")
            )
            with self._cond:
                self._stats.frames_flushed += frames
                self._stats.parts += 1
                if self._part_time is not None:
                    self._durable_time = self._part_time
                self._cond.notify_all()
        if self._head_dirty:
            write_head(self.path, self._head, self._parts, complete=False)
            self._head_dirty = False

    def _finish(self) -> None:
        self._rotate()
        write_head(self.path, self._head, self._parts, complete=True)

    def _abandon_part(self) -> None:
        """After a failure the part being written is dropped with its ``.tmp``: the recording
        ends at its last closed part."""
        if self._part is not None:
            try:
                self._part.discard()
            except Exception:
                pass  # the original error is the one to report
            self._part = None


# Recorders a script forgot to close still finish their files when the interpreter exits (the
# writer is a daemon thread, so that it never keeps a process alive by itself).
_OPEN_RECORDERS: weakref.WeakSet = weakref.WeakSet()


@atexit.register
def _close_open_recorders() -> None:
    for recorder in list(_OPEN_RECORDERS):
        try:
            recorder.close()
        except Exception as error:  # at exit there is no caller left to raise to
            print(f"ambfplus: {error}", file=sys.stderr)


# Rows from frames, steps, removals and events ----------------------------------------------


def _camera_name(frame, default: str) -> str:
    name = frame.get("camera") if isinstance(frame, Mapping) else getattr(frame, "camera", None)
    return check_text(str(name), "camera name") if name else default


def _field(frame, name: str):
    return frame.get(name) if isinstance(frame, Mapping) else getattr(frame, name, None)


def _frame_rows(stream: str, frame, passes) -> _Rows:
    """One frame as a row of ``cameras/<stream>``, every array copied (frames are views of
    engine buffers that the next capture overwrites)."""
    _check_name(stream, "stream")
    group = f"cameras/{stream}"
    wanted = DEFAULT_PASSES if passes is None else tuple(passes)
    unknown = set(wanted) - set(IMAGE_PASSES)
    if unknown:
        raise ValueError(
            f"{group}: unknown passes {sorted(unknown)}: expected {list(IMAGE_PASSES)}"
        )
    columns = {}
    for name in wanted:
        image = _field(frame, name)
        if image is None:
            if passes is not None:
                raise ValueError(f"{group}: the frame has no '{name}' image")
            continue
        dtype, trailing = IMAGE_PASSES[name]
        _check_image(np.asarray(image), trailing, f"{group}/{name}")
        columns[name] = _copy_as(image, dtype, f"{group}/{name}")[None]
    if not columns:
        raise ValueError(f"{group}: the frame holds none of the passes {list(wanted)}")
    _check_same_size(columns, group)
    for name, (dtype, trailing) in FRAME_COLUMNS.items():
        value = _field(frame, name)
        if value is None:
            raise ValueError(f"{group}: the frame has no '{name}'")
        columns[name] = _copy_as(value, dtype, f"{group}/{name}")[None]
        _check_row(columns[name][0], trailing, f"{group}/{name}")
    return _Rows(group, columns, {"camera": _camera_name(frame, stream)}, frames=1)


def _rig_rows(rig, stereo, left: str, right: str, left_index: int, right_index: int) -> _Rows:
    _check_name(rig, "rig")
    values = {
        "time": _field(stereo.left, "time"),
        "step": _field(stereo.left, "step"),
        "baseline": stereo.baseline,
        "dcx": stereo.dcx,
        "left_index": left_index,
        "right_index": right_index,
    }
    columns = {
        name: _copy_as(values[name], dtype, f"rigs/{rig}/{name}")[None]
        for name, (dtype, _) in RIG_COLUMNS.items()
    }
    return _Rows(f"rigs/{rig}", columns, {"left": left, "right": right})


def _step_rows(columns: Mapping) -> _Rows:
    missing = [name for name in STEP_REQUIRED if name not in columns]
    if missing:
        raise ValueError(f"steps: columns {missing} are required (got {sorted(columns)})")
    one_row = np.ndim(columns["step"]) == 0
    out = {}
    for name, value in columns.items():
        _check_name(name, "steps column", slash=True)
        array = np.asarray(value)
        array = array[None] if one_row else array
        if name in STEP_REQUIRED:
            out[name] = _copy_as(array, STEP_REQUIRED[name], f"steps/{name}")
        else:
            out[name] = _copy_column(array, f"steps/{name}")
    _check_lengths(out, "steps")
    return _Rows("steps", out)


def _removed_rows(removed: Mapping, volume: str | None) -> _Rows | None:
    voxel = np.asarray(removed["voxel"])
    if voxel.size == 0:
        return None
    step = np.asarray(removed["step"])
    count = len(voxel)
    columns = {
        "step": np.broadcast_to(step, (count,)) if step.ndim == 0 else step,
        "voxel": voxel,
        "label": np.asarray(removed["label"]),
    }
    for name, (dtype, trailing) in REMOVED_COLUMNS.items():
        columns[name] = _copy_as(columns[name], dtype, f"removed/{name}")
        if columns[name].ndim != 1 + len(trailing):
            raise ValueError(f"removed/{name}: expected shape (M,) + {trailing}")
        _check_row(columns[name][0], trailing, f"removed/{name}")
    _check_lengths(columns, "removed")
    attrs = {"volume": check_text(str(volume), "removed volume name")} if volume else {}
    return _Rows("removed", columns, attrs)


def _event_rows(events: list) -> _Rows | None:
    if not events:
        return None
    allowed = set(EVENT_COLUMNS)
    for event in events:
        unknown = set(event) - allowed
        if unknown or "step" not in event or "kind" not in event:
            raise ValueError(
                f"events: each event needs 'step' and 'kind' and may have 'label' and 'voxel'; "
                f"got keys {sorted(event)}"
            )
    columns = {
        "step": np.array([e["step"] for e in events]),
        "kind": np.array([check_text(str(e["kind"]), "events/kind") for e in events], dtype=object),
        "label": np.array([e.get("label", 0) for e in events]),
        "voxel": np.array([tuple(e.get("voxel", (-1, -1, -1))) for e in events]).reshape(-1, 3),
    }
    for name, (dtype, _) in EVENT_COLUMNS.items():
        if dtype is not None:
            columns[name] = _copy_as(columns[name], dtype, f"events/{name}")
    return _Rows("events", columns)


def _copy_as(value, dtype: np.dtype, where: str) -> np.ndarray:
    """A C-contiguous copy in ``dtype``, refusing conversions that would lose information."""
    array = np.asarray(value)
    if array.dtype == dtype or np.can_cast(array.dtype, dtype, casting="safe"):
        return np.array(array, dtype=dtype, order="C", copy=True)
    if array.dtype.kind in "iub" and dtype.kind in "iu":
        info = np.iinfo(dtype)
        if array.size == 0 or (array.min() >= info.min and array.max() <= info.max):
            return np.array(array, dtype=dtype, order="C", copy=True)
    raise ValueError(f"{where}: cannot store {array.dtype} as {dtype} without loss")


def _copy_column(array: np.ndarray, where: str) -> np.ndarray:
    """A producer's step column: numbers and booleans as they are, text as UTF-8 strings."""
    if array.dtype.kind == "U" or (
        array.dtype.kind == "O" and all(isinstance(v, str) for v in array.ravel())
    ):
        for value in array.ravel():
            check_text(str(value), where)
        return np.array(array.tolist(), dtype=object)
    if array.dtype.kind not in "biufcS":
        raise ValueError(f"{where}: cannot record values of dtype {array.dtype}")
    if array.ndim == 0:
        raise ValueError(f"{where}: expected one value per step, got a scalar")
    return np.array(array, order="C", copy=True)


def _check_image(image: np.ndarray, trailing: tuple, where: str) -> None:
    if image.ndim != 2 + len(trailing) or image.shape[2:] != trailing:
        expected = ("H", "W") + trailing
        raise ValueError(f"{where}: expected an image of shape {expected}, got {image.shape}")


def _check_row(row: np.ndarray, trailing: tuple, where: str) -> None:
    if row.shape != trailing:
        raise ValueError(f"{where}: expected rows of shape {trailing}, got {row.shape}")


def _check_same_size(columns: dict, group: str) -> None:
    sizes = {name: a.shape[1:3] for name, a in columns.items()}
    if len(set(sizes.values())) > 1:
        raise ValueError(f"{group}: images of different sizes {sizes}")


def _check_lengths(columns: dict, group: str) -> None:
    lengths = {name: len(a) for name, a in columns.items()}
    if len(set(lengths.values())) > 1:
        raise ValueError(f"{group}: columns of different lengths {lengths}")


def _check_name(name: str, what: str, *, slash: bool = False) -> None:
    """Stream and rig names become HDF5 groups: no '/'. Step-log columns may hold one (a
    namespaced object's, ``psm1/link.pose``: stored as ``stored_name`` gives it)."""
    if not name or ("/" in name and not slash) or "\0" in name or name in (".", ".."):
        allowed = "" if slash else ", no '/'"
        raise ValueError(f"invalid {what} name {name!r} (non-empty{allowed}, no NUL)")


def _schema_difference(known: dict, got: dict) -> str:
    if set(known) != set(got):
        return f"datasets {sorted(got)} differ from the first rows' {sorted(known)}"
    for name in known:
        if known[name] != got[name]:
            return f"{name}: {got[name]} differs from the first rows' {known[name]}"
    return "schema differs"


# Files -------------------------------------------------------------------------------------


@dataclass
class _HeadInfo:
    recording_id: str
    created: str
    metadata: str
    legend: str = "{}"


def _memory_file(path: Path, **options) -> h5py.File:
    """An HDF5 file built in memory (HDF5's core driver, nothing on disk), for the small head:
    HDF5 itself then never meets a failing disk, whose errors leave its open objects in a state
    that crashes the process when they are freed (at interpreter exit at the latest). Parts,
    which are large, go to disk as they are written, through a ``_GuardedFile``."""
    return h5py.File(path, "w", driver="core", backing_store=False, block_size=4 * MiB, **options)


def _store(file: h5py.File, path: Path) -> None:
    """Closes an in-memory file and writes its bytes to ``path`` atomically: as ``<path>.tmp``,
    renamed into place. A failed write (disk full, I/O error) removes the partial ``.tmp`` and
    raises the OSError."""
    file.flush()
    image = file.id.get_file_image()
    file.close()
    write_bytes(path, image)


class _GuardedFile:
    """The file HDF5 writes a part through (h5py's "fileobj" driver): the part's ``.tmp`` on
    disk, written in place, until a write or truncation fails (disk full, I/O error). From then
    on the file lives in memory and every call succeeds, so that HDF5 never meets the failure;
    ``error`` holds it for the recorder to raise once HDF5 is done with the file."""

    def __init__(self, path: Path) -> None:
        self.error: OSError | None = None
        self._fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_TRUNC, 0o644)
        self._memory: bytearray | None = None
        self._position = 0
        self._size = 0

    def seek(self, offset: int, whence: int = os.SEEK_SET) -> int:
        if whence == os.SEEK_SET:
            self._position = offset
        elif whence == os.SEEK_CUR:
            self._position += offset
        elif whence == os.SEEK_END:
            self._position = self._size + offset
        else:
            raise ValueError(f"seek: whence must be 0, 1 or 2, not {whence}")
        return self._position

    def tell(self) -> int:
        return self._position

    def write(self, data) -> int:
        view = memoryview(data).cast("B")
        end = self._position + len(view)
        if self._memory is None:
            try:
                done = 0
                while done < len(view):
                    written = os.pwrite(self._fd, view[done:], self._position + done)
                    if written == 0:
                        raise OSError(28, os.strerror(28))
                    done += written
            except OSError as error:
                self._fail(error)
        if self._memory is not None:
            if end > len(self._memory):
                self._memory.extend(bytes(end - len(self._memory)))
            self._memory[self._position : end] = view
        self._position, self._size = end, max(self._size, end)
        return len(view)

    def readinto(self, buffer) -> int:
        """Reads at the position; bytes past the end read as zeros (as HDF5's own drivers do)."""
        view = memoryview(buffer).cast("B")
        if self._memory is not None:
            got = self._memory[self._position : self._position + len(view)]
            view[: len(got)] = got
            count = len(got)
        else:
            try:
                count = os.preadv(self._fd, [view], self._position)
            except OSError as error:
                self._fail(error)
                return self.readinto(buffer)
        view[count:] = bytes(len(view) - count)
        self._position += len(view)
        return len(view)

    def read(self, size: int = -1) -> bytes:
        size = self._size - self._position if size < 0 else size
        buffer = bytearray(max(size, 0))
        self.readinto(buffer)
        return bytes(buffer)

    def truncate(self, size: int | None = None) -> int:
        size = self._position if size is None else size
        if self._memory is None:
            try:
                os.ftruncate(self._fd, size)
            except OSError as error:
                self._fail(error)
        if self._memory is not None:
            del self._memory[size:]
            self._memory.extend(bytes(size - len(self._memory)))
        self._size = size
        return size

    def flush(self) -> None:
        pass  # unbuffered; fsync is not promised (see the module docstring)

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def _fail(self, error: OSError) -> None:
        """From the first failure on, the file lives in memory: what reached the disk is read
        back into it (zeros where even that fails), the rest is kept there."""
        self.error = self.error or error
        self._memory = bytearray(self._size)
        try:
            os.preadv(self._fd, [self._memory], 0)
        except OSError:
            pass


class _PartFile:
    """The segment being written, as ``<part>.tmp`` (through a ``_GuardedFile``) until ``close``
    renames it into place."""

    def __init__(self, path: Path, head: _HeadInfo, compression: str | None) -> None:
        self.path = path
        self.compression = compression
        self.tmp = temporary_name(path)
        self.disk = _GuardedFile(self.tmp)
        self.file: h5py.File | None = None
        self.summary = PartSummary(path)
        self._buffers: dict[tuple[str, str], list[np.ndarray]] = {}
        self._buffered_bytes: dict[tuple[str, str], int] = {}
        # Open datasets stay open: reopening one per write costs as much as compressing it.
        self._datasets: dict[tuple[str, str], h5py.Dataset] = {}
        try:
            self.file = h5py.File(self.disk, "w")
            _set_attributes(
                self.file,
                {
                    "format": FORMAT,
                    VERSION_ATTR: VERSION,
                    MINOR_VERSION_ATTR: MINOR_VERSION,
                    "recording_id": head.recording_id,
                    "part": _number_of(path),
                },
            )
        except BaseException:
            self.discard()
            raise

    def append(self, rows: _Rows) -> None:
        group = self.summary.groups.get(rows.group)
        if group is None:
            group = self.summary.groups[rows.group] = _new_group_summary(rows)
            assert self.file is not None, "open from __init__ on"
            _set_attributes(self.file.require_group(rows.group), rows.attrs)
        is_camera = rows.group.startswith("cameras/")
        for name, data in rows.columns.items():
            if (is_camera and name in IMAGE_PASSES) or data.nbytes // len(data) >= IMAGE_ROW_BYTES:
                self._append(rows.group, name, data, chunk_rows=1)
            else:
                self._buffer(rows.group, name, data)
        group.rows += len(next(iter(rows.columns.values())))

    def _buffer(self, group: str, name: str, data: np.ndarray) -> None:
        key = (group, name)
        self._buffers.setdefault(key, []).append(data)
        self._buffered_bytes[key] = self._buffered_bytes.get(key, 0) + data.nbytes
        if self._buffered_bytes[key] >= BUFFER_BYTES:
            self._write_buffer(group, name)

    def _write_buffer(self, group: str, name: str) -> None:
        self._buffered_bytes.pop((group, name), None)
        pieces = self._buffers.pop((group, name), [])
        if pieces:
            data = np.concatenate(pieces)
            row_bytes = max(data.nbytes // len(data), 1)
            chunk_rows = max(1, min(len(data), SMALL_CHUNK_BYTES // row_bytes))
            self._append(group, name, data, chunk_rows)

    def _append(self, group: str, name: str, data: np.ndarray, chunk_rows: int) -> None:
        """Appends rows to a chunked dataset resizable along axis 0, creating it if needed.
        Text is stored as fixed-length UTF-8 strings, widened when longer text comes."""
        if data.dtype.kind == "O":
            data = text_column(data)
        dataset = self._datasets.get((group, name))
        if dataset is None:
            assert self.file is not None, "open from __init__ on"
            dataset = _create(
                self.file[group], stored_name(name), data, chunk_rows, self.compression
            )
        else:
            if data.dtype.kind == "S" and data.dtype.itemsize > dataset.dtype.itemsize:
                dataset = self._widen(group, name, dataset, data.dtype)
            start = dataset.shape[0]
            dataset.resize(start + len(data), axis=0)
            dataset[start:] = data
        self._datasets[group, name] = dataset
        string = h5py.check_string_dtype(dataset.dtype)
        if string:
            self.summary.groups[group].strings[name] = (string.encoding, string.length)

    def _widen(self, group: str, name: str, dataset: h5py.Dataset, dtype) -> h5py.Dataset:
        """The text dataset rewritten with wider fixed-length strings (text columns are small, and
        HDF5 reuses the space it frees while the part is open)."""
        rows, chunk_rows = dataset[()], dataset.chunks[0]
        assert self.file is not None, "open from __init__ on"
        del self.file[group][stored_name(name)]
        return _create(
            self.file[group], stored_name(name), rows.astype(dtype), chunk_rows, self.compression
        )

    def close(self) -> PartSummary:
        """Writes what is buffered, closes the file and renames it into place; a failed write
        removes the ``.tmp`` and raises its OSError."""
        for group, name in list(self._buffers):
            self._write_buffer(group, name)
        self._datasets.clear()
        assert self.file is not None, "open from __init__ on"
        self.file.close()
        self.disk.close()
        if self.disk.error is not None:
            self.tmp.unlink(missing_ok=True)
            raise self.disk.error
        os.replace(self.tmp, self.path)
        return self.summary

    def raise_if_failed(self) -> None:
        """A failed write surfaces at the next item, not only when the part closes."""
        if self.disk.error is not None:
            raise self.disk.error

    def discard(self) -> None:
        """Drops the part (after a failure): HDF5 closes it (into memory if a write failed),
        and its ``.tmp`` is removed."""
        try:
            self._datasets.clear()
            if self.file is not None:
                self.file.close()
        finally:
            self.disk.close()
            self.tmp.unlink(missing_ok=True)


def _new_group_summary(rows: _Rows) -> GroupSummary:
    datasets = {name: (a.dtype, a.shape[1:]) for name, a in rows.columns.items()}
    return GroupSummary(0, datasets, dict(rows.attrs))


def _create(
    group: h5py.Group, name: str, data: np.ndarray, chunk_rows: int, compression: str | None
) -> h5py.Dataset:
    return group.create_dataset(
        name,
        data=data,
        dtype=data.dtype,
        maxshape=(None,) + data.shape[1:],
        chunks=(chunk_rows,) + data.shape[1:],
        **_filters(compression, data.dtype),
    )


def _set_attributes(obj, values: Mapping) -> None:
    """Sets attributes, text as fixed-length UTF-8 strings (never variable-length: reading
    those needs HDF5's global heap, which libhdf5 loops on when it is damaged)."""
    for key, value in values.items():
        if isinstance(value, str):
            value = text_attribute(value, f"attribute '{key}'")
        obj.attrs[key] = value


def _filters(compression: str | None, dtype: np.dtype) -> dict:
    """create_dataset's filter arguments. Grouping the bytes of multi-byte values by
    significance (shuffling) makes depth compress twice as well."""
    if compression == "blosc-lz4":
        shuffle = hdf5plugin.Blosc.SHUFFLE if dtype.itemsize > 1 else hdf5plugin.Blosc.NOSHUFFLE
        return dict(hdf5plugin.Blosc(cname="lz4", clevel=5, shuffle=shuffle))
    return {"compression": compression, "shuffle": bool(compression) and dtype.kind == "f"}


def _number_of(path: Path) -> int:
    return int(path.name.rsplit(".part", 1)[1])


def _prepare_path(path: Path, overwrite: bool) -> None:
    """Refuses to mix a new recording into an old one unless told to replace it."""
    path.parent.mkdir(parents=True, exist_ok=True)
    old = [p for _, p in find_parts(path)]
    old += [p for p in [path, temporary_name(path)] if p.exists()]
    old += list(path.parent.glob(path.name + ".part*.tmp"))
    if old and not overwrite:
        raise FileExistsError(f"{path}: a recording is already there (pass overwrite=True)")
    for stale in old:
        stale.unlink()


def write_head(path: Path, head: _HeadInfo, parts: list[PartSummary], complete: bool) -> None:
    """Writes the head file atomically: description, and when complete, virtual datasets that
    concatenate the parts."""
    f = _memory_file(path, libver=("v110", "latest"))
    try:
        _set_attributes(
            f,
            {
                "format": FORMAT,
                VERSION_ATTR: VERSION,
                MINOR_VERSION_ATTR: MINOR_VERSION,
                "recording_id": head.recording_id,
                "created": head.created,
                "software_version": __version__,
                "h5py_version": h5py.version.version,
                "hdf5_version": h5py.version.hdf5_version,
                "metadata": head.metadata,
                "legend": head.legend,
                "complete": complete,
                "parts": to_json([p.path.name for p in parts], "parts"),
            },
        )
        _set_attributes(f.create_group("conventions"), CONVENTIONS)
        if complete:
            _write_virtual_datasets(f, parts)
    except BaseException:
        f.close()
        raise
    _store(f, path)


def _write_virtual_datasets(f: h5py.File, parts: list[PartSummary]) -> None:
    groups: dict[str, list[tuple[PartSummary, GroupSummary]]] = {}
    for part in parts:
        for name, group in part.groups.items():
            groups.setdefault(name, []).append((part, group))
    for name, pieces in groups.items():
        first = pieces[0][1]
        _set_attributes(f.require_group(name), first.attrs)
        total = sum(group.rows for _, group in pieces)
        for column, (dtype, trailing) in first.datasets.items():
            if column in first.strings:
                dtype = _text_union([group.strings.get(column) for _, group in pieces])
            sources = [(part.path.name, group.rows) for part, group in pieces]
            _virtual_dataset(
                f[name], stored_name(column), dtype, (total,) + tuple(trailing), sources
            )


def _virtual_dataset(group: h5py.Group, name: str, dtype, shape: tuple, sources: list) -> None:
    """A virtual dataset concatenating the same-named dataset of each (file, rows) source along
    axis 0. Without HDF5's object timestamps (h5py's VirtualLayout keeps them), so that the same
    parts always give the same head, byte for byte."""
    dcpl = h5py.h5p.create(h5py.h5p.DATASET_CREATE)
    dcpl.set_obj_track_times(False)
    # HDF5 reads '%' in a source's file and dataset names as a format specifier: '%%' is one.
    path = f"{group.name}/{name}".lstrip("/").replace("%", "%%").encode()
    start = 0
    for file_name, rows in sources:
        if rows == 0:
            continue
        block = (rows,) + tuple(shape[1:])
        selection = h5py.h5s.create_simple(shape)
        selection.select_hyperslab((start,) + (0,) * (len(shape) - 1), (1,) * len(shape),
                                   block=block)  # fmt: skip
        source = file_name.replace("%", "%%").encode()
        dcpl.set_virtual(selection, source, path, h5py.h5s.create_simple(block))
        start += rows
    space = h5py.h5s.create_simple(shape)
    h5py.h5d.create(group.id, name.encode(), h5py.h5t.py_create(np.dtype(dtype), logical=1),
                    space, dcpl=dcpl)  # fmt: skip


def _text_union(stored: list) -> np.dtype:
    """The string type a virtual dataset over text parts needs: as wide as the widest part,
    variable-length only over format 1.0 parts that were (repair of an old recording)."""
    encoding = stored[0][0] if stored[0] else "utf-8"
    lengths = [entry[1] for entry in stored if entry and entry[1] is not None]
    if len(lengths) < len(stored):  # a part without an entry, or variable-length
        return h5py.string_dtype(encoding)
    return h5py.string_dtype(encoding, max(lengths))


def repair(path) -> Recording:
    """Completes the head of a recording whose recorder did not close (a crash): virtual
    datasets over every closed part, so that plain h5py reads it as one file, and removes the
    unfinished files it left (its last part's ``.tmp``). Returns it opened."""
    path = Path(path)
    for leftover in leftover_files(path):
        leftover.unlink()
    with open_recording(path) as recording:
        parts = scan_parts(path, recording.recording_id)
        head = _HeadInfo(
            recording.recording_id,
            recording.created,
            recording.metadata_text,
            recording.legend_text,
        )
    write_head(path, head, parts, complete=True)
    return open_recording(path)


def world_legend(world) -> dict:
    """``ambfplus.labels.legend(world)`` plus each volume's grid shape, dimensions and voxel
    size, which map a ``voxel`` image's index to (i, j, k), and its pose (world-from-volume,
    as the recording starts), which places removed voxels in the world; drills add their burr
    diameters (m), which give the ``burr`` index of the step log a size."""
    out = object_legend(world)
    for volume in world.volumes:
        data = volume.data
        out[volume.id].update(
            shape=tuple(int(n) for n in data.shape),
            dimensions=[float(d) for d in data.dimensions],
            voxel_size=[float(d) for d in data.voxel_size],
            pose=np.asarray(volume.pose, dtype=np.float64).tolist(),
        )
    for drill in world.drills:
        out[drill.id]["burr_diameters"] = [float(d) for d in drill.burr_diameters]
    return out
