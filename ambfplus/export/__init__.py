"""Recordings and datasets into the field's tools: ``export(source, out, to=FORMAT)``.

Formats (``FORMATS``):

- ``mcap``: one MCAP file of ROS 2 messages (CDR), which ROS 2 tools and Foxglove read: images
  per camera and pass (raw, or as lossless PNG/TIFF CompressedImage with ``image_topics``,
  ``ambfplus.export.images``), CameraInfo, point clouds, TF, the drill's wrench, the removal
  log and the critical-structure events (``ambfplus.export.ros`` lists the topics).
- ``rosbag2``: the same messages as a rosbag2 folder (``metadata.yaml`` and ``<name>_0.mcap``).
- ``original-h5``: the original system's HDF5 layout (volumetric_drilling data_record v3,
  ``ambfplus.export.original_h5``).
- ``coco``: COCO instance annotations (RLE masks) per camera, with the RGB frames as PNG
  (``ambfplus.export.coco``).

A source is a recording (its head file) or a dataset folder (a ``manifest.jsonl`` listing
shards): each shard whose SHA-256 matches its manifest line is exported to ``OUT`` under the
same relative name, with ``OUT/index.jsonl`` saying what became of each. An output is written
under a temporary name and renamed into place when complete: a failed export leaves nothing,
and an existing output is replaced only with ``force=True``. Every output states the units,
frames, conventions and the ambfplus version in its own metadata. The exports need the extra
``ambfplus[export]``; the live view (``ambfplus.export.live``) needs ``ambfplus[foxglove]``.
"""

from __future__ import annotations

import hashlib
import json
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from ..fileio import refuse_writing_over, written_whole
from ..recording import RecordingError, open_recording
from ..recording.schema import recording_files
from ._common import ExportError, MissingExtra, check_output, progress_bar

FORMATS = ("mcap", "rosbag2", "original-h5", "coco")
# What each format's output is called beside the shard or recording it comes from.
SUFFIXES = {"mcap": ".mcap", "rosbag2": "", "original-h5": "", "coco": ""}
MANIFEST = "manifest.jsonl"
INDEX = "index.jsonl"
MANIFEST_KEYS = ("episode", "file", "sha256")
# The options each format takes (keyword arguments of export()).
OPTIONS = {
    "mcap": (
        "point_clouds",
        "compression",
        "image_topics",
        "rgb_codec",
        "jpeg_quality",
        "depth_no_hit",
        "stamp",
        "bad_frames",
    ),
    "rosbag2": (
        "point_clouds",
        "image_topics",
        "rgb_codec",
        "jpeg_quality",
        "depth_no_hit",
        "stamp",
        "bad_frames",
    ),
    "original-h5": ("chunk_size", "names", "bad_frames"),
    "coco": ("images", "bad_frames"),
}


@dataclass
class ExportResult:
    """What an export wrote: the output, the format, frames exported, seconds taken, bytes of
    the output, and details from the format (topics and message counts, files, warnings)."""

    source: Path
    output: Path
    format: str
    frames: int
    seconds: float
    bytes: int
    details: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {"source": str(self.source), "output": str(self.output), "format": self.format,
                "frames": self.frames, "seconds": round(self.seconds, 3), "bytes": self.bytes,
                **self.details}  # fmt: skip


def _writer(to: str) -> Callable:
    from .coco import write_coco
    from .original_h5 import write_original
    from .ros import write_ros

    writers: dict[str, Callable] = {
        "mcap": lambda rec, out, bar, **o: write_ros(rec, out, "mcap", bar, **o),
        "rosbag2": lambda rec, out, bar, **o: write_ros(rec, out, "rosbag2", bar, **o),
        "original-h5": write_original,
        "coco": write_coco,
    }
    return writers[to]


def check_format(to: str, options: dict | None = None) -> str:
    """The format name, or an ExportError listing the known ones (or naming an option the
    format does not take)."""
    if to not in FORMATS:
        raise ExportError(f"unknown export format {to!r}; known: {', '.join(FORMATS)}")
    unknown = sorted(set(options or {}) - set(OPTIONS[to]))
    if unknown:
        raise ExportError(f"the {to} export takes no option {', '.join(unknown)} (its options: "
                          f"{', '.join(OPTIONS[to])})")  # fmt: skip
    return to


def _size(path: Path) -> int:
    if path.is_file():
        return path.stat().st_size
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file())


def export(source, out, to: str, *, force: bool = False, progress: bool | None = None,
           **options) -> ExportResult | list[ExportResult]:  # fmt: skip
    """Exports a recording (or every shard of a dataset folder) to ``out`` in format ``to``
    (one of FORMATS). ``force`` replaces an existing output; ``progress`` shows a bar (None:
    only on a terminal). Options go to the format (``OPTIONS``): ``point_clouds``,
    ``image_topics`` ("raw", "compressed" or "both"), ``rgb_codec`` ("png" or "jpeg"),
    ``jpeg_quality``, ``depth_no_hit`` ("nan" or "zero"), ``stamp`` ("sim" or "wall") (mcap,
    rosbag2), ``compression`` (mcap), ``chunk_size``, ``names``
    (original-h5), ``images`` (coco); and ``bad_frames`` (every format): "refuse" (default: an
    ExportError naming the first frame whose values break ``ambfplus.recording.values``' rules;
    nothing is left) or "skip" (such frames are left out and counted in the details). A source
    is a recording's head file (a dataset's shard) or a dataset folder, which gives one result
    per shard."""
    check_format(to, options)
    source, out = Path(source), Path(out)
    if source.is_dir():
        return export_dataset(source, out, to, force=force, progress=progress, **options)
    if source.name == MANIFEST:
        raise ExportError(f"{source} is a dataset's manifest: export its folder "
                          f"{source.parent} (every shard) or one shard's head file")  # fmt: skip
    refuse_writing_over(out, recording_files(source), "export", ExportError)
    check_output(out, force)
    _writer(to)  # the extra's modules are imported before anything is opened
    with open_recording(source) as recording, written_whole(out) as temporary:
        return _export_one(recording, temporary, out, to, progress, options)


def _export_one(recording, temporary: Path, out: Path, to: str, progress, options):
    started = time.perf_counter()
    frames = _frames_to_write(recording, to)
    if to == "rosbag2":  # its data file is named after the folder it will have
        options = {**options, "bag_name": out.name}
    with progress_bar(frames, f"{recording.path.name} -> {to}", progress) as bar:
        details = _writer(to)(recording, temporary, bar, **options)
    return ExportResult(recording.path, out, to, details.pop("frames", frames),
                        time.perf_counter() - started, _size(temporary), details)  # fmt: skip


def _frames_to_write(recording, to: str) -> int:
    if to == "original-h5":
        rig = next(iter(recording.rigs.values()), None)
        if rig is not None:
            return len(rig)
        return len(next(iter(recording.cameras.values()))) if recording.cameras else 0
    return sum(len(s) for s in recording.cameras.values())


def read_manifest(folder: Path) -> list[dict]:
    """The dataset's manifest lines, checked: JSON objects with episode, file and sha256."""
    path = folder / MANIFEST
    if not path.is_file():
        hint = ""
        if (folder.parent / MANIFEST).is_file():
            hint = f"; it is inside the dataset folder {folder.parent}: export that folder"
        elif any(folder.glob("*.h5")):
            hint = "; export one of its recordings (name.h5) or a dataset folder"
        raise ExportError(f"{folder}: not a recording and not a dataset folder (no "
                          f"{MANIFEST}){hint}")  # fmt: skip
    entries = []
    for number, line in enumerate(path.read_text().splitlines(), start=1):
        if not line.strip():
            continue
        try:
            entry = json.loads(line)
        except json.JSONDecodeError as error:
            raise ExportError(f"{path}, line {number}: not JSON ({error})") from None
        missing = [k for k in MANIFEST_KEYS if not isinstance(entry, dict) or k not in entry]
        if missing:
            raise ExportError(f"{path}, line {number}: missing {', '.join(missing)} (a shard "
                              f"line holds at least {', '.join(MANIFEST_KEYS)})")  # fmt: skip
        file = Path(entry["file"])
        if file.is_absolute() or ".." in file.parts:
            raise ExportError(f"{path}, line {number}: file {entry['file']!r} must be a path "
                              "inside the dataset folder")  # fmt: skip
        entries.append(entry)
    if not entries:
        raise ExportError(f"{path}: lists no shard")
    return entries


def shard_digests(head: Path) -> set[str]:
    """SHA-256 of a shard as a manifest may state it: of its head file, and of the head
    followed by its parts in order (the same when it has no parts)."""
    from ..recording.schema import find_parts

    whole, alone = hashlib.sha256(), hashlib.sha256()
    with open(head, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            whole.update(block)
            alone.update(block)
    for _, part in find_parts(head):
        with open(part, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                whole.update(block)
    return {alone.hexdigest(), whole.hexdigest()}


def verify_shards(folder: Path, entries: list[dict]) -> None:
    """Every shard exists and matches its manifest checksum, or an ExportError naming it."""
    for entry in entries:
        head = folder / entry["file"]
        if not head.is_file():
            raise ExportError(f"{folder / MANIFEST}: shard {entry['file']} (episode "
                              f"{entry['episode']}) is missing")  # fmt: skip
        if str(entry["sha256"]).lower() not in shard_digests(head):
            raise ExportError(
                f"{head}: its SHA-256 does not match the manifest's (episode "
                f"{entry['episode']}): the shard changed or is damaged; nothing was exported"
            )


def export_dataset(folder: Path, out: Path, to: str, *, force: bool = False,
                   progress: bool | None = None, **options) -> list[ExportResult]:  # fmt: skip
    """Exports every shard of a dataset folder into the folder ``out``, mirroring the shards'
    names, with ``index.jsonl`` (one line per shard: its manifest fields, the output and
    counts). Checksums are verified first; a mismatch exports nothing."""
    check_format(to, options)
    refuse_writing_over(out, [folder], "export", ExportError)
    check_output(out, force)
    entries = read_manifest(folder)
    verify_shards(folder, entries)
    _writer(to)
    results = []
    with written_whole(out) as temporary:
        temporary.mkdir()
        for extra in ("spec.yaml", "environment.json"):
            if (folder / extra).is_file():
                (temporary / extra).write_bytes((folder / extra).read_bytes())
        index = []
        for entry in entries:
            relative = Path(entry["file"])
            target = relative.with_name(relative.name.removesuffix(".h5") + SUFFIXES[to])
            (temporary / target).parent.mkdir(parents=True, exist_ok=True)
            with open_recording(folder / relative) as recording:
                result = _export_one(recording, temporary / target, out / target, to,
                                     progress, options)  # fmt: skip
            results.append(result)
            index.append({**entry, "source_file": entry["file"], "file": str(target),
                          "format": to, "frames": result.frames, "bytes": result.bytes,
                          "source_sha256": entry["sha256"]})  # fmt: skip
            index[-1].pop("sha256")
        (temporary / INDEX).write_text("".join(json.dumps(line) + "\n" for line in index))
    return results


__all__ = [
    "FORMATS",
    "ExportError",
    "ExportResult",
    "MissingExtra",
    "RecordingError",
    "export",
    "export_dataset",
    "read_manifest",
    "verify_shards",
]
