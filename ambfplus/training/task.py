"""Training tasks: a YAML file that says what a session is asked to do and how it is judged,
checked completely before use (errors are ``TaskError``, a ``ConfigError``, naming the file and
the key). Lengths in a task are millimetres and times seconds, as a surgeon states them; the
loaded ``Task`` holds metres.

::

    version: 1
    name: Cortical mastoidectomy
    description: text                    # optional
    anatomy: {phantom: {resolution: 128, seed: 0}}   # or {file: ear.seg.nrrd, ...} as in
                                         # dataset specs (NRRD, Slicer, slice folder, volume ADF)
    target:                              # exactly one of labels, mask, references
      labels: [Bone]                     # names or ids
      box: {min: [-7, -7, 7], max: [7, 7, 13]}   # optional with labels: mm, volume frame; a
                                         # list of boxes is their union
      # mask: target.nrrd                # a volume of the anatomy's grid, non-zero inside
      # references: [expert_1.h5]        # voxels removed by at least half of these recordings
    protect:                             # structures that must not be touched
      - {structure: Facial_Nerve, margin: 1.0}   # a label name or id, or a list; margin mm
    expose:                              # structures to skeletonise (optional)
      - {structure: Sinus_+_Dura, thickness: 1.0, reach: 2.0}  # residual bone mm; the surface
                                         # considered lies within `reach` mm of the target
    burrs: [2, 4, 6]                     # burr diameters allowed, mm (default: any)
    time_limit: 600                      # seconds (default: none)
    excess_force: 3.0                    # N (default 3)
    thresholds: {min_visibility: 0.8}    # optional: the rubric's thresholds (see RUBRIC_DEFAULTS)

Two tasks ship with the package on the built-in phantom: ``builtin_task("cortical_mastoidectomy")``
and ``builtin_task("facial_recess")`` (``BUILTIN_TASKS``).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import ConfigError, NotFound, VolumeData
from ..config import (
    Where,
    anatomy,
    describe,
    existing,
    fixed,
    keys,
    load_yaml,
    mapping,
    non_negative,
    number,
    positive,
    unit,
)

TASK_VERSION = 1
TASKS_DIR = Path(__file__).resolve().parent / "tasks"
BUILTIN_TASKS = ("cortical_mastoidectomy", "facial_recess")
MM = 1e-3

# The rubric's thresholds: what a task may change under `thresholds`, with their defaults.
RUBRIC_DEFAULTS = {
    "max_time_in_margin": 1.0,  # s inside any protected structure's margin
    "max_contacts": 2,  # entries into margins
    "max_excess_force_time": 0.5,  # s of cutting above excess_force
    "min_stroke_length": 3.0,  # mm, median stroke
    "min_straightness": 0.6,  # median stroke
    "max_outside_fraction": 0.2,  # of the volume removed, outside the target
    "min_target_fraction": 0.3,  # of the target removed
    "min_visibility": 0.8,  # of cutting time, the burr in the surgeon's view
    "min_exposed_fraction": 0.5,  # of a structure's surface to skeletonise
}


class TaskError(ConfigError):
    """A task that cannot be used: names the file, the key and what was expected."""


@dataclass
class Structure:
    """A structure named by a task: its key path (for messages), the labels as written, and a
    length in metres (a margin or a target thickness) and a reach (metres)."""

    where: str
    name: str
    labels: list
    length: float
    reach: float = 0.0


@dataclass
class Task:
    """A checked task (see the module). Lengths in metres."""

    name: str
    source: str
    base: Path
    anatomy: dict
    target: dict
    protect: list[Structure]
    expose: list[Structure] = field(default_factory=list)
    burrs: list[float] | None = None
    time_limit: float | None = None
    excess_force: float = 3.0
    thresholds: dict = field(default_factory=lambda: dict(RUBRIC_DEFAULTS))
    description: str = ""
    text: str = ""

    def anatomy_data(self) -> VolumeData:
        """A fresh copy of the task's anatomy."""
        from ..scenes import anatomy_data

        return anatomy_data({k: v for k, v in self.anatomy.items() if k != "name"})

    def label_ids(self, data: VolumeData, structure: Structure) -> list[int]:
        """The ids of a structure's labels in `data`; an unknown label raises TaskError naming
        the task's key."""
        try:
            return list(data.label_ids(structure.labels, f"{self.source}: {structure.where}"))
        except NotFound as error:
            raise TaskError(str(error)) from None

    def protect_config(self, data: VolumeData) -> list[dict]:
        """``SkillMetrics``' protect entries for `data`."""
        return [
            {"name": s.name, "labels": self.label_ids(data, s), "margin": s.length}
            for s in self.protect
        ]

    def target_mask(self, data: VolumeData, reference_cavities=()) -> np.ndarray:
        """The target region over `data`'s grid (bool, [i, j, k]). `reference_cavities` are
        the cavities (bool grids) of the references a `references` target names."""
        shape = tuple(data.shape)
        if "labels" in self.target:
            where = Structure("target.labels", "target", self.target["labels"], 0.0)
            ids = self.label_ids(data, where)
            mask = np.isin(np.asarray(data.labels), ids)
            if "box" in self.target:
                inside = np.zeros_like(mask)
                for low, high in self.target["box"]:
                    inside |= box_mask(data, low, high)
                mask &= inside
            return mask
        if "mask" in self.target:
            from ..volumes import load_volume

            volume = load_volume(self.target["mask"])
            if tuple(volume.shape) != shape:
                raise TaskError(
                    f"{self.source}: target.mask: {self.target['mask']} has shape "
                    f"{tuple(volume.shape)}, the anatomy {shape}"
                )
            return np.asarray(volume.labels) > 0
        cavities = list(reference_cavities)
        if not cavities:
            raise TaskError(
                f"{self.source}: target.references: the target is the references' cavity, but "
                "no reference cavity was given"
            )
        votes = np.sum([np.asarray(c, bool) for c in cavities], axis=0)
        return votes * 2 >= len(cavities)

    def with_thresholds(self, **values) -> Task:
        """A copy with some rubric thresholds changed."""
        out = copy.copy(self)
        out.thresholds = {**self.thresholds, **values}
        return out


def box_mask(data: VolumeData, low, high) -> np.ndarray:
    """Voxels of `data` whose centres lie in the box [low, high] (metres, volume frame)."""
    shape = np.asarray(data.shape)
    size = np.asarray(data.dimensions) / shape
    axes = [(np.arange(n) + 0.5) * s - n * s / 2 for n, s in zip(shape, size)]
    inside = [(a >= lo) & (a <= hi) for a, lo, hi in zip(axes, low, high)]
    return inside[0][:, None, None] & inside[1][None, :, None] & inside[2][None, None, :]


def load_task(source) -> Task:
    """Reads and checks a task: a YAML file's path, a built-in task's name (BUILTIN_TASKS) or a
    dict (relative paths then from the current folder)."""
    if isinstance(source, dict):
        return parse_task(source, Path.cwd(), "<task>")
    if isinstance(source, str) and source in BUILTIN_TASKS:
        return builtin_task(source)
    path = Path(source)
    if not path.exists() and isinstance(source, str) and "/" not in source:
        raise TaskError(f"{source}: no such task file, and no built-in task of that name (the "
                        f"built-in tasks: {', '.join(BUILTIN_TASKS)})")  # fmt: skip
    data, text = load_yaml(path, TaskError, "task")
    task = parse_task(data, path.resolve().parent, str(path))
    task.text = text
    return task


def builtin_task(name: str) -> Task:
    """One of the tasks shipped with the package (BUILTIN_TASKS)."""
    if name not in BUILTIN_TASKS:
        raise TaskError(f"no built-in task {name!r}; there are {', '.join(BUILTIN_TASKS)}")
    return load_task(TASKS_DIR / f"{name}.yaml")


def parse_task(data, base: Path, source: str) -> Task:
    """Checks a task's parsed YAML (see the module)."""
    where = Where(source, error=TaskError)
    mapping(data, where, "the task")
    keys(
        data,
        where,
        required=("version", "name", "anatomy", "target"),
        optional=(
            "description",
            "protect",
            "expose",
            "burrs",
            "time_limit",
            "excess_force",
            "thresholds",
        ),
    )
    if data["version"] != TASK_VERSION:
        raise where.error(
            "version",
            f"task version {data['version']!r} is not supported; this ambfplus reads version "
            f"{TASK_VERSION}",
        )
    return Task(
        name=str(data["name"]),
        description=str(data.get("description", "")),
        source=source,
        base=base,
        anatomy=anatomy(data["anatomy"], where.at("anatomy"), base),
        target=_target(data["target"], where.at("target"), base),
        protect=_structures(data.get("protect", []), where.at("protect"), "margin"),
        expose=_structures(data.get("expose", []), where.at("expose"), "thickness"),
        burrs=_burrs(data["burrs"], where.at("burrs")) if "burrs" in data else None,
        time_limit=positive(data["time_limit"], where.at("time_limit"))
        if "time_limit" in data
        else None,
        excess_force=positive(data.get("excess_force", 3.0), where.at("excess_force")),
        thresholds=_thresholds(data.get("thresholds", {}), where.at("thresholds")),
    )


def _target(value, where: Where, base: Path) -> dict:
    mapping(value, where, "the target region")
    kinds = [k for k in ("labels", "mask", "references") if k in value]
    if len(kinds) != 1:
        raise where.error(
            None, f"expected exactly one of labels, mask, references; got {sorted(value) or 'none'}"
        )
    if kinds[0] == "labels":
        keys(value, where, required=("labels",), optional=("box",))
        out: dict = {"labels": _labels(value["labels"], where.at("labels"))}
        if "box" in value:
            boxes = value["box"] if isinstance(value["box"], list) else [value["box"]]
            if not boxes:
                raise where.error("box", "expected a box {min, max} or a list of boxes")
            out["box"] = [
                _box(
                    b, where.at("box").at(i) if isinstance(value["box"], list) else where.at("box")
                )
                for i, b in enumerate(boxes)
            ]
        return out
    if kinds[0] == "mask":
        keys(value, where, required=("mask",))
        return {"mask": str(existing(value["mask"], base, where.at("mask")))}
    keys(value, where, required=("references",))
    paths = value["references"]
    if not isinstance(paths, list) or not paths:
        raise where.error(
            "references", f"expected a non-empty list of recordings, got {describe(paths)}"
        )
    return {
        "references": [
            str(existing(p, base, where.at("references").at(i))) for i, p in enumerate(paths)
        ]
    }


def _box(value, where: Where) -> tuple[list[float], list[float]]:
    """A box {min, max} in mm, as metres."""
    box = mapping(value, where, "a box {min, max} in mm")
    keys(box, where, required=("min", "max"))
    low = fixed(box["min"], where.at("min"), number, 3)
    high = fixed(box["max"], where.at("max"), number, 3)
    for axis, (lo, hi) in enumerate(zip(low, high)):
        if lo >= hi:
            raise where.error("max", f"expected max > min on every axis; axis {axis}: {lo} >= {hi}")
    return [v * MM for v in low], [v * MM for v in high]


def _labels(value, where: Where) -> list:
    items = value if isinstance(value, list) else [value]
    if not items:
        raise where.error(None, "expected a label name or id, or a non-empty list of them")
    for i, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, (str, int)):
            raise (where.at(i) if isinstance(value, list) else where).error(
                None, f"expected a label name or id, got {describe(item)}"
            )
    return list(items)


def _structures(value, where: Where, length: str) -> list[Structure]:
    if not isinstance(value, list):
        raise where.error(None, f"expected a list of structures, got {describe(value)}")
    out, names = [], set()
    for i, entry in enumerate(value):
        at = where.at(i)
        mapping(entry, at, f"a structure {{structure, {length}}}")
        keys(
            entry,
            at,
            required=("structure", length),
            optional=("name", "reach") if length == "thickness" else ("name",),
        )
        labels = _labels(entry["structure"], at.at("structure"))
        name = str(entry.get("name", "+".join(str(x) for x in labels)))
        if name in names:
            raise at.error("structure", f"{name} is listed twice")
        names.add(name)
        out.append(
            Structure(
                where=at.at("structure").path,
                name=name,
                labels=labels,
                length=non_negative(entry[length], at.at(length)) * MM,
                reach=positive(entry.get("reach", 2.0), at.at("reach")) * MM,
            )
        )
    return out


def _burrs(value, where: Where) -> list[float]:
    if not isinstance(value, list) or not value:
        raise where.error(
            None, f"expected a non-empty list of burr diameters (mm), got {describe(value)}"
        )
    return [positive(v, where.at(i)) * MM for i, v in enumerate(value)]


def _thresholds(value, where: Where) -> dict:
    mapping(value, where, "rubric thresholds")
    keys(value, where, optional=tuple(RUBRIC_DEFAULTS))
    out = dict(RUBRIC_DEFAULTS)
    for key, given in value.items():
        check = unit if key.endswith(("fraction", "visibility", "straightness")) else non_negative
        out[key] = check(given, where.at(key))
    return out
