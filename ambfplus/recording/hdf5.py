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
  modification time stay the same). libhdf5 also allocates, and fills, the length each
  variable-length value claims before it looks for the value, so the lengths are read from the
  file's bytes first (an attribute's from its attribute message, a dataset's from its storage):
  one claiming more than the file holds is a ``RecordingError``.
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

from ..fileio import require_regular_file
from .schema import MINOR_VERSION_ATTR, RecordingError

# A global heap collection starts with this signature and its version (1, the only one).
GLOBAL_HEAP_START = b"GCOL\x01"
# Files whose global heaps passed the check, by (device, inode, size, mtime): collections found.
_HEAPS_CHECKED: OrderedDict[tuple, int] = OrderedDict()
_HEAPS_CHECKED_LIMIT = 4096
# What attribute messages of a name claim, by file (as above) and name: _attribute_claims.
_CLAIMS: OrderedDict[tuple, list] = OrderedDict()


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
    require_regular_file(path, "recording file", RecordingError)
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
    if problem:
        _check_variable_attribute(checked, where, name, problem)
    return obj.attrs[name]


# A variable-length value on disk (HDF5 file format, "Variable-length" data and "Global Heap
# ID"): its length (4 bytes), then where its data is, the heap collection's address and the
# object's index (4 bytes). libhdf5 allocates, and fills, the length a value claims before it
# finds the heap object holding it, so a damaged length (4 GB in 16 bytes) is read here first.


def _check_variable_attribute(checked: CheckedFile, where: str, name: str, problem: str) -> None:
    """Refuses a format 1.0 attribute of variable length whose stored value claims more than
    the file holds, or whose stored form cannot be found to check it."""
    if problem not in ("a variable-length string", "a variable-length sequence"):
        raise RecordingError(
            f"{checked.path}: attribute '{where}' is {problem}; format 1.0 keeps only text on "
            "the global heap, so the file is damaged"
        )
    claims = _attribute_claims(checked, name)
    if not claims:
        raise RecordingError(
            f"{checked.path}: attribute '{where}' is {problem}, but no attribute message named "
            f"'{name}' holding one is in the file to check its length: the file is damaged"
        )
    for lengths in claims:
        _check_lengths(checked, f"attribute '{where}'", lengths)


def check_variable_dataset(checked: CheckedFile, name: str, dataset) -> None:
    """Refuses a format 1.0 dataset of variable length (a low-level h5py DatasetID) whose
    stored values claim more than the file holds, before any is read: its raw values are
    read from its contiguous storage or unfiltered chunks (what the format 1.0 writer made)."""
    plist = dataset.get_create_plist()
    layout = plist.get_layout()
    element = 8 + checked.file.id.get_create_plist().get_sizes()[0]
    spans: list[tuple[int, int]] = []
    if layout == h5py.h5d.CONTIGUOUS:
        if dataset.get_storage_size():
            spans.append((dataset.get_offset(), dataset.get_storage_size()))
    elif layout == h5py.h5d.CHUNKED:
        if plist.get_nfilters():
            raise RecordingError(
                f"{checked.path}: dataset {name} holds variable-length values through filters, "
                "which format 1.0 never wrote: the file is damaged"
            )
        for i in range(dataset.get_num_chunks()):
            info = dataset.get_chunk_info(i)
            spans.append((info.byte_offset, info.size))
    else:
        return  # compact values fit the object's header; a virtual dataset's are in its sources
    size = checked.path.stat().st_size
    with open(checked.path, "rb") as raw:
        for offset, length in spans:
            if offset is None or offset + length > size:
                raise RecordingError(
                    f"{checked.path}: dataset {name} keeps its values past the end of the file"
                )
            raw.seek(offset)
            data = raw.read(length)
            lengths = [_unsigned(data, at, 4) for at in range(0, len(data) - element + 1, element)]
            _check_lengths(checked, f"dataset {name}", lengths)


def _check_lengths(checked: CheckedFile, what: str, lengths: list[int] | None) -> None:
    size = checked.file.id.get_filesize()
    if lengths is None:
        raise RecordingError(f"{checked.path}: {what} keeps its values past the end of the file")
    for length in lengths:
        if length > size:
            raise RecordingError(
                f"{checked.path}: {what} holds a variable-length value claiming {length} bytes, "
                f"more than the file's {size}: the file is damaged"
            )


def _attribute_claims(checked: CheckedFile, name: str) -> list[list[int] | None]:
    """The lengths each attribute message named `name` in the file claims for its variable-
    length values (None for one whose values run past the file), found in the file's bytes:
    compact attributes in object headers and dense ones in fractal heaps alike. Layout (HDF5
    file format, "Attribute Message"): version 1 (name, datatype and dataspace each padded to 8
    bytes), 2 or 3 (unpadded; 3 adds the name's encoding), flags, the three sizes; the name with
    its NUL; datatype; dataspace; the values."""
    stat = checked.path.stat()
    key = (stat.st_dev, stat.st_ino, stat.st_size, stat.st_mtime_ns, name)
    if key in _CLAIMS:
        return _CLAIMS[key]
    size_addr, size_len = checked.file.id.get_create_plist().get_sizes()
    element = 8 + size_addr
    wanted = name.encode() + b"\0"
    n = len(wanted)
    found: list[list[int] | None] = []
    with open(checked.path, "rb") as raw:
        if not stat.st_size:
            return found
        with mmap.mmap(raw.fileno(), 0, access=mmap.ACCESS_READ) as data:
            at = data.find(wanted)
            while at >= 0:
                for version, prefix in ((1, 8), (2, 8), (3, 9)):
                    start = at - prefix
                    if start < 0 or data[start] != version or _unsigned(data, start + 2, 2) != n:
                        continue
                    flags = data[start + 1]
                    dt_size, ds_size = _unsigned(data, start + 4, 2), _unsigned(data, start + 6, 2)
                    if version == 1:
                        if flags:
                            continue
                        dt = at + _pad8(n)
                        ds = dt + _pad8(dt_size)
                        value = ds + _pad8(ds_size)
                    else:
                        if flags & 0x3 or (version == 3 and data[start + 8] > 1):
                            continue  # a shared datatype or dataspace: not one written here
                        dt, ds = at + n, at + n + dt_size
                        value = ds + ds_size
                    if value > len(data) or dt_size < 8 or data[dt] & 0x0F != 9:
                        continue  # not a message of a variable-length type
                    count = _dataspace_points(data, ds, ds_size, size_len)
                    if count is None:
                        continue
                    end = value + count * element
                    found.append(
                        None
                        if end > len(data)
                        else [_unsigned(data, v, 4) for v in range(value, end, element)]
                    )
                    break
                at = data.find(wanted, at + 1)
    _CLAIMS[key] = found
    while len(_CLAIMS) > _HEAPS_CHECKED_LIMIT:
        _CLAIMS.popitem(last=False)
    return found


def _dataspace_points(data, at: int, size: int, size_len: int) -> int | None:
    """The points of the dataspace message at `at` (version 1 or 2), or None if it is not
    one."""
    if size < 4 or at + size > len(data):
        return None
    version, rank = data[at], data[at + 1]
    if version == 1:
        dims = at + 8
    elif version == 2:
        kind = data[at + 3]
        if kind == 2:
            return 0
        if kind > 2:
            return None
        dims = at + 4
    else:
        return None
    if dims + rank * size_len > at + size:
        return None
    points = 1
    for d in range(rank):
        points *= _unsigned(data, dims + d * size_len, size_len)
    return points


def _pad8(n: int) -> int:
    return (n + 7) // 8 * 8


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
