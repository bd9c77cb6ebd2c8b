"""Checking and summarising a dataset folder: ``validate_dataset`` (``ambfplus validate DIR``)
and ``dataset_info`` (``ambfplus dataset info DIR``)."""

from __future__ import annotations

import json
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path

from .._core import ConfigError
from .driver import ENVIRONMENT
from .episode import PARTIAL, SHARDS
from .manifest import read_manifest, shard_checksum
from .spec import MAX_EPISODES


@dataclass
class DatasetReport:
    """The result of checking a dataset folder: ``ok`` when nothing is wrong."""

    folder: Path
    expected: int = 0  #: episodes the spec asks for
    listed: int = 0  #: distinct episodes in the manifest
    frames: int = 0
    bytes: int = 0
    problems: list[str] = field(default_factory=list)
    warnings: list[str] = field(default_factory=list)
    shards_checked: int = 0

    @property
    def ok(self) -> bool:
        return not self.problems

    def __str__(self) -> str:
        lines = [
            f"{self.folder}: {self.listed} of {self.expected} episodes listed, {self.frames} "
            f"stereo pairs, {self.bytes / 1e6:.1f} MB; {self.shards_checked} shards checked"
        ]
        lines += [f"  FAIL  {p}" for p in self.problems]
        lines += [f"  WARN  {w}" for w in self.warnings]
        lines.append(f"{'OK' if self.ok else 'FAILED'}: {len(self.problems)} problems")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {
            "folder": str(self.folder),
            "ok": self.ok,
            "expected": self.expected,
            "listed": self.listed,
            "frames": self.frames,
            "bytes": self.bytes,
            "shards_checked": self.shards_checked,
            "problems": self.problems,
            "warnings": self.warnings,
        }


def is_dataset(folder) -> bool:
    """True for a folder that ``generate`` made (it has environment.json)."""
    return (Path(folder) / ENVIRONMENT).is_file()


def _environment(folder: Path) -> dict:
    """environment.json of a dataset folder, checked to be a JSON object whose ``spec`` is an
    object and ``runs`` a list (a ConfigError naming the file otherwise)."""
    path = folder / ENVIRONMENT
    if not path.is_file():
        raise FileNotFoundError(2, f"not a dataset folder (no {ENVIRONMENT})", str(folder))
    try:
        environment = json.loads(path.read_text(encoding="utf-8"))
    except (ValueError, RecursionError) as error:
        raise ConfigError(f"{path}: not JSON ({error})") from None
    if not isinstance(environment, dict):
        raise ConfigError(f"{path}: expected a JSON object, got {type(environment).__name__}")
    for key, kind in (("spec", dict), ("runs", list)):
        if key in environment and not isinstance(environment[key], kind):
            raise ConfigError(f"{path}: '{key}' must be a JSON {kind.__name__}, damaged")
    episodes = environment.get("episodes")
    if (
        not isinstance(episodes, int)
        or isinstance(episodes, bool)
        or not (0 <= episodes <= MAX_EPISODES)
    ):
        raise ConfigError(
            f"{path}: episodes is {episodes!r}, not a whole number in 0..{MAX_EPISODES} as a "
            "spec gives it: the file is damaged"
        )
    return environment


def validate_dataset(folder, match_images: bool = True) -> DatasetReport:
    """Checks a dataset folder: the manifest (readable lines, no duplicate episode, no gap in
    0..episodes-1), every listed shard (its files, size and checksum; its recording's own
    checks, with block matching of stereo pairs when `match_images`; its metadata's episode and
    seed), and nothing unlisted in shards/."""
    folder = Path(folder)
    environment = _environment(folder)
    report = DatasetReport(folder, expected=environment["episodes"])
    records, problems = read_manifest(folder)
    report.problems += problems
    counts = Counter(r["episode"] for r in records)
    duplicates = sorted(e for e, n in counts.items() if n > 1)
    if duplicates:
        report.problems.append(f"episodes listed more than once: {_short_list(duplicates)}")
    outside = sorted(e for e in counts if not 0 <= e < report.expected)
    if outside:
        report.problems.append(f"episodes outside 0..{report.expected - 1}: {_short_list(outside)}")
    missing = sorted(set(range(report.expected)) - set(counts))
    if missing:
        report.problems.append(f"{len(missing)} episodes missing: {_short_list(missing)}")
    report.listed = len(counts)
    listed_files = set()
    for record in records:
        listed_files.add(Path(record["file"]).name)
        listed_files.update(Path(p).name for p in record["parts"])
        report.frames += int(record["frames"])
        report.bytes += int(record["bytes"])
        report.problems += _check_shard(folder, record, match_images)
        report.shards_checked += 1
    shards = folder / SHARDS
    strays = (
        sorted(p.name for p in shards.iterdir() if p.name not in listed_files)
        if (shards.is_dir())
        else []
    )
    if strays:
        report.warnings.append(f"files in {SHARDS}/ that no record lists: {_short_list(strays)}")
    if (folder / PARTIAL).exists() and any((folder / PARTIAL).iterdir()):
        report.warnings.append(
            f"{PARTIAL}/ holds unfinished shards (a run is going on or was "
            "interrupted; generating again resumes)"
        )
    return report


def _check_shard(folder: Path, record: dict, match_images: bool) -> list[str]:
    from ..recording import open_recording, validate

    name = f"episode {record['episode']} ({record['file']})"
    files = [folder / record["file"]] + [folder / p for p in record["parts"]]
    absent = [str(f.relative_to(folder)) for f in files if not f.is_file()]
    if absent:
        return [f"{name}: missing files {absent}"]
    digest, size = shard_checksum(files)
    problems = []
    if size != record["bytes"]:
        problems.append(f"{name}: {size} bytes on disk, the manifest says {record['bytes']}")
    if digest != record["sha256"]:
        problems.append(f"{name}: checksum differs from the manifest's (the files changed)")
    shard = validate(files[0], match_images=match_images)
    problems += [f"{name}: {c.name}: {c.detail}" for c in shard.failed]
    if not shard.ok:
        return problems
    with open_recording(files[0]) as rec:
        meta = rec.metadata.get("dataset", {})
        if meta.get("episode") != record["episode"] or meta.get("seed") != record["seed"]:
            problems.append(
                f"{name}: its metadata says episode {meta.get('episode')} seed "
                f"{meta.get('seed')}, the manifest {record['seed']}"
            )
        pairs = len(rec.rigs["rig"]) if "rig" in rec.rigs else 0
        if pairs != record["frames"]:
            problems.append(f"{name}: {pairs} stereo pairs, the manifest says {record['frames']}")
    return problems


def _short_list(items: list, limit: int = 10) -> str:
    shown = ", ".join(str(i) for i in items[:limit])
    return shown + (f", ... ({len(items)} in all)" if len(items) > limit else "")


def dataset_info(folder) -> dict:
    """Counts of a dataset folder from its manifest: episodes and stereo pairs in all, by
    anatomy and by scenario; label pixels by label; sizes, renderers and versions."""
    folder = Path(folder)
    environment = _environment(folder)
    records, problems = read_manifest(folder)
    by_anatomy: dict[str, Counter] = {}
    by_scenario: dict[str, Counter] = {}
    labels: Counter = Counter()
    for record in records:
        for table, key in ((by_anatomy, record["anatomy"]), (by_scenario, record["scenario"])):
            entry = table.setdefault(key, Counter())
            entry["episodes"] += 1
            entry["frames"] += int(record["frames"])
        labels.update(record.get("label_pixels", {}))
    total_pixels = sum(labels.values())
    return {
        "folder": str(folder),
        "name": environment.get("spec", {}).get("name", ""),
        "episodes": {
            "listed": len({r["episode"] for r in records}),
            "expected": environment["episodes"],
        },
        "frames": sum(int(r["frames"]) for r in records),
        "bytes": sum(int(r["bytes"]) for r in records),
        "by_anatomy": {k: dict(v) for k, v in sorted(by_anatomy.items())},
        "by_scenario": {k: dict(v) for k, v in sorted(by_scenario.items())},
        "label_pixels": {
            name: {"pixels": n, "share": round(n / total_pixels, 6) if total_pixels else 0.0}
            for name, n in labels.most_common()
        },
        "renderers": sorted({r.get("renderer", "") for r in records}),
        "versions": sorted({r["version"] for r in records}),
        "runs": len(environment.get("runs", [])),
        "manifest_problems": problems,
    }


def format_info(info: dict) -> str:
    """``dataset_info`` as text for a terminal."""
    lines = [
        f"{info['folder']}{' (' + info['name'] + ')' if info['name'] else ''}: "
        f"{info['episodes']['listed']} of {info['episodes']['expected']} episodes, "
        f"{info['frames']} stereo pairs, {info['bytes'] / 1e6:.1f} MB",
    ]
    for title, key in (("anatomy", "by_anatomy"), ("scenario", "by_scenario")):
        lines.append(f"by {title}:")
        lines += [
            f"  {name:24} {c['episodes']:7} episodes {c['frames']:9} pairs"
            for name, c in info[key].items()
        ]
    lines.append("by label (pixels over both views):")
    lines += [
        f"  {name:24} {v['pixels']:12} {100 * v['share']:6.2f} %"
        for name, v in info["label_pixels"].items()
    ]
    lines.append(
        f"renderers: {', '.join(info['renderers']) or '-'}; ambfplus "
        f"{', '.join(info['versions']) or '-'}; {info['runs']} runs"
    )
    lines += [f"manifest: {p}" for p in info["manifest_problems"]]
    return "\n".join(lines)
