"""A dataset folder's manifest (``manifest.jsonl``): one JSON object per line per complete shard.

Only the process driving a generation writes it: one ``write`` of a whole line per shard, opened
for appending, so that a killed driver leaves at most a torn last line, which readers ignore (and
the next run drops). A run that ends, and a run that resumes, rewrite it sorted by episode under
a temporary name renamed into place.

Fields of a record: ``episode``, ``seed`` (the episode's own seed), ``anatomy``, ``scenario``,
``frames`` (stereo pairs), ``bytes`` and ``sha256`` (over the shard's head and then its parts,
in order), ``file`` (the head, relative to the folder), ``parts``, ``version`` (ambfplus),
``renderer``, ``label_pixels`` (label name -> pixels over both views), and the fields that say
how a run went, which differ between runs of the same spec (``RUN_FIELDS``).
"""

from __future__ import annotations

import hashlib
import json
import os
from functools import partial
from pathlib import Path, PurePosixPath

from ..fileio import write_text

MANIFEST = "manifest.jsonl"
# Fields that depend on the run (time, place, retries), not on the spec and the episode.
RUN_FIELDS = ("seconds", "cpu_seconds", "worker", "attempt")
REQUIRED_FIELDS = (
    "episode",
    "seed",
    "anatomy",
    "scenario",
    "frames",
    "bytes",
    "sha256",
    "file",
    "parts",
    "version",
)


def shard_checksum(files) -> tuple[str, int]:
    """(SHA-256 hex digest, bytes) of a shard's files read in order: head, then parts."""
    digest, size = hashlib.sha256(), 0
    for file in files:
        with open(file, "rb") as f:
            for block in iter(partial(f.read, 1 << 20), b""):
                digest.update(block)
                size += len(block)
    return digest.hexdigest(), size


def without_run_fields(record: dict) -> dict:
    """A record without the fields that vary between runs (to compare two datasets)."""
    return {k: v for k, v in record.items() if k not in RUN_FIELDS}


def read_manifest(folder) -> tuple[list[dict], list[str]]:
    """The manifest's records in file order, and a list of problems (lines that are not JSON
    objects with every required field, each of the type the writer gives it: ``record_problem``).
    A missing manifest has no records."""
    path = Path(folder) / MANIFEST
    if not path.is_file():
        return [], []
    records, problems = [], []
    lines = path.read_bytes().split(b"\n")
    for number, line in enumerate(lines, start=1):
        if not line.strip():
            continue
        try:
            record = json.loads(line)
        except (ValueError, RecursionError):  # RecursionError: nested too deeply
            torn = number == len(lines)  # no newline after it: the writer was stopped
            problems.append(f"{path}: line {number} is not JSON" + (" (torn)" if torn else ""))
            continue
        missing = [k for k in REQUIRED_FIELDS if not isinstance(record, dict) or k not in record]
        if missing:
            problems.append(f"{path}: line {number} lacks {', '.join(missing)}")
            continue
        problem = record_problem(record)
        if problem:
            problems.append(f"{path}: line {number}: {problem}")
            continue
        records.append(record)
    return records, problems


def _count(value) -> bool:
    return isinstance(value, int) and not isinstance(value, bool) and value >= 0


def _relative(value) -> bool:
    """A path inside the dataset folder, as the writer gives it (``shards/name.h5``)."""
    if not isinstance(value, str) or not value or "\0" in value or "\\" in value:
        return False
    parts = PurePosixPath(value).parts
    return not value.startswith("/") and ".." not in parts


# A required field's check, and what the writer gives it.
_FIELD_TYPES = {
    "episode": (_count, "an integer >= 0"),
    "seed": (_count, "an integer >= 0"),
    "anatomy": (lambda v: isinstance(v, str), "a name"),
    "scenario": (lambda v: isinstance(v, str), "a name"),
    "frames": (_count, "an integer >= 0"),
    "bytes": (_count, "an integer >= 0"),
    "sha256": (lambda v: isinstance(v, str), "a hex digest"),
    "file": (_relative, "a path inside the folder"),
    "parts": (
        lambda v: isinstance(v, list) and all(_relative(p) for p in v),
        "a list of paths inside the folder",
    ),
    "version": (lambda v: isinstance(v, str), "a version"),
    "renderer": (lambda v: isinstance(v, str), "a name"),
    "label_pixels": (
        lambda v: isinstance(v, dict) and all(_count(n) for n in v.values()),
        "a mapping of label names to pixel counts",
    ),
}


def record_problem(record: dict) -> str:
    """What is wrong with a record's fields (a type the writer never gives them, a path that
    leaves the folder), or ''."""
    for key, (check, expected) in _FIELD_TYPES.items():
        if key in record and not check(record[key]):
            shown = repr(record[key])
            shown = shown if len(shown) <= 60 else shown[:57] + "..."
            return f"{key} is {type(record[key]).__name__} {shown}, expected {expected}"
    return ""


class ManifestWriter:
    """Appends records to a folder's manifest, one whole line per write."""

    def __init__(self, folder) -> None:
        self.path = Path(folder) / MANIFEST
        self._fd = os.open(self.path, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)

    def append(self, record: dict) -> None:
        line = (json.dumps(record, sort_keys=True) + "\n").encode()
        written = os.write(self._fd, line)
        if written != len(line):
            raise OSError(f"{self.path}: wrote {written} of {len(line)} bytes of a record")

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1


def rewrite_manifest(folder, records: list[dict]) -> None:
    """Replaces the manifest with `records` sorted by episode (atomically)."""
    lines = [json.dumps(r, sort_keys=True) for r in sorted(records, key=lambda r: r["episode"])]
    write_text(Path(folder) / MANIFEST, "".join(line + "\n" for line in lines))
