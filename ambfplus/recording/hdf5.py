"""HDF5 access for the recording reader that cannot hang on a damaged file.

libhdf5 keeps variable-length data (strings, sequences, region references) and the mappings of
virtual datasets in *global heap collections*, and loops forever when it loads a damaged one:
its collection parser (``H5HG__cache_heap_deserialize``, HDF5 2.0) steps from object to object
by each object's size, and a free-space object of size 0 never moves it on. So:

- Files of format 1.1 (``ambfplus_recording_minor_version`` >= 1, every file this ambfplus
  writes) hold no variable-length data: every text is a fixed-length UTF-8 string. Before any
  attribute is read, its type is inspected through the low-level API without reading its data,
  and a variable-length type (or a reference) in such a file is a ``RecordingError`` naming the
  file and the attribute; each dataset's type is checked the same way when a part is listed.
  A part then holds no global heap at all.
- Files of format 1.0 (written before) store text as variable-length strings. Each is read only
  after every global heap collection in it has been walked the way libhdf5 walks it: a walk that
  would not end exactly at the collection's end is a ``RecordingError`` naming the file and the
  collection's byte offset. This reads the whole file once (then not again while its size and
  modification time stay the same).
- Heads of either format are checked that way too (they are small, and their virtual datasets'
  mappings live in a global heap), before any attribute is read.

What is left: a part of format 1.1 whose dataset header was rewritten into a virtual dataset
pointing at a crafted, looping collection. Random damage does not make one (such a part holds
no collection to point at); ``validate`` checks every file's global heaps before it opens the
recording, so it also refuses that.

No timeouts: every guard is structural."""

from __future__ import annotations

import mmap
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

import h5py
import numpy as np

from .schema import MINOR_VERSION_ATTR, RecordingError

# A global heap collection starts with this signature and its version (1, the only one).
GLOBAL_HEAP_START = b"GCOL\x01"
# Files whose global heaps passed the check, by (device, inode, size, mtime): collections found.
_HEAPS_CHECKED: OrderedDict[tuple, int] = OrderedDict()
_HEAPS_CHECKED_LIMIT = 4096


@dataclass
class CheckedFile:
    """An HDF5 file of a recording, opened for reading; ``fixed_text`` is True for format 1.1
    and later (no variable-length data allowed)."""

    path: Path
    file: h5py.File
    fixed_text: bool

    def close(self) -> None:
        self.file.close()


def open_checked(path: Path, heaps: str = "if_variable") -> CheckedFile:
    """Opens one file of a recording. Its global heaps are checked first when `heaps` is
    "always" (heads, which keep their virtual datasets' mappings there), or "if_variable" and
    the file is of format 1.0 (whose text is variable-length)."""
    file = open_hdf5(path)
    try:
        checked = CheckedFile(path, file, fixed_text=False)
        minor = read_attribute(checked, file, MINOR_VERSION_ATTR, expect="integer")
        checked.fixed_text = minor is not None and int(minor) >= 1
        if heaps == "always" or not checked.fixed_text:
            check_global_heaps(path, file)
        return checked
    except BaseException:
        file.close()
        raise


def open_hdf5(path: Path) -> h5py.File:
    """h5py.File(path, "r"), with a RecordingError naming the file if it cannot be opened."""
    if not path.is_file():
        raise RecordingError(f"{path}: no such file")
    try:
        return h5py.File(path, "r")
    except OSError as error:
        raise RecordingError(f"{path}: not a readable HDF5 file ({error})") from None


def read_attribute(checked: CheckedFile, obj, name: str, expect: str | None = None):
    """The value of attribute `name` of `obj` (None if absent), read only once its type and
    size are known to be safe; `expect` = "integer" refuses any other type."""
    where = _attribute_name(obj, name)
    try:
        attribute = h5py.h5a.open(obj.id, name.encode())
    except KeyError:
        return None
    type_id = attribute.get_type()
    problem = heap_type(type_id)
    if problem and checked.fixed_text:
        raise RecordingError(
            f"{checked.path}: attribute '{where}' is {problem}; a format 1.1 recording stores "
            "text as fixed-length strings, so the file is damaged"
        )
    if expect == "integer" and type_id.get_class() != h5py.h5t.INTEGER:
        raise RecordingError(f"{checked.path}: attribute '{where}' is not an integer")
    space = attribute.get_space()
    if space.get_simple_extent_type() == h5py.h5s.NULL:
        raise RecordingError(f"{checked.path}: attribute '{where}' holds no value")
    points = space.get_simple_extent_npoints()
    # Data kept in the file cannot be larger than the file (a damaged size would be allocated).
    if points * type_id.get_size() > checked.file.id.get_filesize():
        raise RecordingError(
            f"{checked.path}: attribute '{where}' claims {points} values of "
            f"{type_id.get_size()} bytes, more than the file holds"
        )
    return obj.attrs[name]


def read_attributes(checked: CheckedFile, obj) -> dict:
    """Every attribute of `obj`, each checked as ``read_attribute`` does."""
    return {name: read_attribute(checked, obj, name) for name in obj.attrs.keys()}


def check_dataset_type(checked: CheckedFile, name: str, type_id) -> None:
    """Refuses a variable-length or reference dataset (its HDF5 type, ``dataset.id.get_type()``)
    in a format 1.1 file, before its data is read."""
    problem = heap_type(type_id)
    if problem and checked.fixed_text:
        raise RecordingError(
            f"{checked.path}: dataset {name} is {problem}; a format 1.1 recording stores text "
            "as fixed-length strings, so the file is damaged"
        )


def heap_type(type_id) -> str | None:
    """What in an HDF5 type keeps its data in the global heap ("a variable-length string",
    ...), or None; looks into compound members and array elements."""
    kind = type_id.get_class()
    if kind == h5py.h5t.STRING:
        return "a variable-length string" if type_id.is_variable_str() else None
    if kind == h5py.h5t.VLEN:
        return "a variable-length sequence"
    if kind == h5py.h5t.REFERENCE:
        return "a reference"
    if kind == h5py.h5t.COMPOUND:
        for i in range(type_id.get_nmembers()):
            inner = heap_type(type_id.get_member_type(i))
            if inner:
                return f"a compound with {inner}"
    if kind == h5py.h5t.ARRAY:
        inner = heap_type(type_id.get_super())
        return f"an array of {inner}" if inner else None
    return None


def check_global_heaps(path: Path, file: h5py.File | None = None) -> int:
    """Walks every global heap collection in the file as libhdf5 would, refusing one whose
    walk would loop or run past its end; returns how many there are. Reads the whole file
    (once: a file checked before is not read again while its size and time stay the same)."""
    stat = path.stat()
    key = (stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns)
    if key in _HEAPS_CHECKED:
        return _HEAPS_CHECKED[key]
    if file is None:
        with open_hdf5(path) as opened:
            return check_global_heaps(path, opened)
    _, size_bytes = file.id.get_create_plist().get_sizes()
    collections = 0
    with open(path, "rb") as raw:
        if stat.st_size:
            with mmap.mmap(raw.fileno(), 0, access=mmap.ACCESS_READ) as data:
                start = data.find(GLOBAL_HEAP_START)
                while start >= 0:
                    problem = collection_problem(data, start, size_bytes)
                    if problem:
                        raise RecordingError(
                            f"{path}: damaged global heap collection at byte {start} (where "
                            "HDF5 keeps variable-length data and virtual dataset mappings): "
                            f"{problem}"
                        )
                    collections += 1
                    start = data.find(GLOBAL_HEAP_START, start + 1)
    _HEAPS_CHECKED[key] = collections
    while len(_HEAPS_CHECKED) > _HEAPS_CHECKED_LIMIT:
        _HEAPS_CHECKED.popitem(last=False)
    return collections


def collection_problem(data, start: int, size_bytes: int) -> str | None:
    """Why libhdf5's walk over the collection at `start` would loop or overrun, or None. The
    layout (HDF5 file format, "Global Heap"): signature, version, 3 reserved bytes, the
    collection's size; then objects, each a 2-byte index, 2-byte reference count, 4 reserved
    bytes, a size and its data padded to 8 bytes; index 0 is the free space, whose size
    includes its header and is not padded. A tail too short for an object header is free."""
    header = 8 + size_bytes
    object_header = 8 + size_bytes
    if start + header > len(data):
        return "it is cut off by the end of the file"
    size = _unsigned(data, start + 8, size_bytes)
    if size < header or start + size > len(data):
        return f"its size {size} does not fit the file ({len(data) - start} bytes from it)"
    offset = header
    while offset < size:
        if offset + object_header > size:
            break  # free space too small for an object header
        index = _unsigned(data, start + offset, 2)
        length = _unsigned(data, start + offset + 8, size_bytes)
        step = length if index == 0 else object_header + (length + 7) // 8 * 8
        if step == 0:
            return f"its free-space object at byte {start + offset} has size 0 (libhdf5 loops)"
        if offset + step > size:
            return f"object {index} at byte {start + offset} runs past the collection's end"
        offset += step
    return None


def _unsigned(data, at: int, size: int) -> int:
    return int.from_bytes(data[at : at + size], "little")


def _attribute_name(obj, name: str) -> str:
    group = obj.name if isinstance(obj.name, str) else ""
    return name if group in ("/", "") else f"{group.lstrip('/')}/{name}"


def text_value(value) -> str | None:
    """An attribute's text as str (fixed-length strings come back from h5py as bytes)."""
    if value is None:
        return None
    if isinstance(value, np.ndarray) and value.shape == ():
        value = value[()]
    return value.decode() if isinstance(value, bytes) else str(value)
