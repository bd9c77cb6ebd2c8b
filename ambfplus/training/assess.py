"""Assessment of a recorded session against a task and expert references: ``assess(path,
task, references)`` returns an ``Assessment`` (``as_dict()`` is JSON; ``write_report`` writes
the debrief page). It works on every recording the package makes (demo, launcher,
``record_session``, dataset episodes, replays): each stores the scene it ran, from which the
anatomy as the session began is rebuilt.

The skill metrics are the engine's (``ambfplus.SkillMetrics``, as live), replayed onto that
anatomy; cavities, exposure and burr visibility are measured here (``cavity``,
``visibility``); the rubric and the composite score are ``rubric``'s.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import DistanceField, VolumeData, __version__
from ..fileio import write_text
from ..recording import open_recording
from .cavity import cavity_mask, compare_cavities, exposure, mask_distance
from .metrics import drill_ticks
from .rubric import composite, rubric
from .task import Structure, Task, TaskError, load_task
from .visibility import visibility

MM = 1e-3
# The timeline's resolution: one sample per this many seconds.
TIMELINE_STEP = 0.01
# How far the timeline's distance curves reach (metres).
TIMELINE_BAND = 0.01


@dataclass
class SessionData:
    """What assessment reads from a recording."""

    path: Path
    kind: str
    metadata: dict
    created: str
    software_version: str
    drill: str
    burr_diameters: list[float]
    volume_pose: np.ndarray
    anatomy: VolumeData  # as the session began
    steps: dict
    removed: dict
    events: list[dict]
    camera: dict | None  # the surgeon's view: steps, intrinsics, poses, depth(i), rgb(i)


def _kind(meta: dict) -> str:
    if "replay_of" in meta:
        return "replay"
    if "dataset" in meta:
        return "dataset episode"
    if "launcher" in meta:
        return "launcher"
    if meta.get("demo"):
        return "demo"
    return "session"


def load_session(path) -> SessionData:
    """Reads a recording for assessment; a recording that holds no drilling session (no scene,
    no drill) raises ValueError saying what is missing."""
    from ..scenes import build_scene

    path = Path(path)
    rec = open_recording(path)
    meta = rec.metadata
    if "scene" not in meta:
        raise ValueError(
            f"{path}: the recording names no scene (metadata 'scene'), so its "
            "anatomy cannot be rebuilt"
        )
    scene = build_scene(meta["scene"])
    drill = scene.drill
    if drill is None:
        raise ValueError(f"{path}: the recorded scene has no drill: nothing to assess")
    wanted = ["step", "time"] + [f"{drill.key}.{c}" for c in ("pose", "force", "on", "burr")]
    # A real-time session's live metrics say when they took each updated field.
    if f"{drill.key}.metrics_fields" in rec.column_names("steps"):
        wanted.append(f"{drill.key}.metrics_fields")
    rig = rec.rigs.get(meta.get("rig", "rig"))
    stream = rig.left if rig is not None else rec.cameras.get(meta.get("camera", ""))
    if stream is not None and not len(stream):
        stream = None
    # Only the columns assessment reads (a long session's step log holds many more), with the
    # camera's and the removed voxels and events, in one pass over the recording's parts.
    groups: dict = {"steps": wanted}
    if stream is not None:
        groups[f"cameras/{stream.name}"] = ["step", "intrinsics", "pose"]
    groups.update({g: None for g in ("removed", "events") if rec.rows(g)})
    try:
        read = rec.read_groups(groups)
    except KeyError as error:  # the camera's columns are every stream's: the step log's
        raise ValueError(
            f"{path}: the step log lacks what assessment needs of drill "
            f"'{drill.name}': {error.args[0]}"
        ) from None
    steps = read["steps"]
    camera = None
    if stream is not None:
        columns = stream.columns
        small = read[f"cameras/{stream.name}"]
        camera = {
            "name": stream.camera,
            "steps": np.asarray(small["step"], np.int64),
            "intrinsics": np.asarray(small["intrinsics"], float),
            "poses": np.asarray(small["pose"], float),
            "depth": (lambda i: columns["depth"][i]) if "depth" in columns else (lambda i: None),
            "rgb": (lambda i: columns["rgb"][i]) if "rgb" in columns else (lambda i: None),
            "label": (lambda i: columns["label"][i]) if "label" in columns else None,
        }
    return SessionData(
        path=path,
        kind=_kind(meta),
        metadata=meta,
        created=rec.created,
        software_version=rec.software_version,
        drill=drill.key,
        burr_diameters=list(drill.burr_diameters),
        volume_pose=np.asarray(drill.volume.pose, float),
        anatomy=drill.volume.data,
        steps=steps,
        removed=rec.removed,
        events=rec.events,
        camera=camera,
    )


def default_task(data: VolumeData) -> Task:
    """The task assumed without one: every critical structure protected with a 1 mm margin, no
    target, no limits."""
    protect = [
        Structure(f"critical label {label.id}", label.name, [int(label.id)], 0.001)
        for label in data.label_table
        if label.critical
    ]
    return Task(
        name="Free drilling (no task)",
        source="<default>",
        base=Path.cwd(),
        anatomy={},
        target={},
        protect=protect,
    )


@dataclass
class Assessment:
    """An assessed session: ``data`` (JSON-ready: the metrics, rubric, score, references,
    violations), ``timeline`` (arrays for the report) and what the report renders from."""

    data: dict
    timeline: dict = field(repr=False)
    session: SessionData = field(repr=False)
    task: Task = field(repr=False)
    cavity: np.ndarray = field(repr=False)
    target: np.ndarray | None = field(repr=False)
    reference: np.ndarray | None = field(repr=False)

    @property
    def score(self) -> float | None:
        return self.data["score"]

    def as_dict(self) -> dict:
        return self.data

    def write_json(self, path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        write_text(path, json.dumps(self.data, indent=1, default=_json_default) + "\n")
        return path

    def write_report(self, path, views: bool = True) -> Path:
        """The debrief page: one self-contained HTML file (see ``training.report``)."""
        from .report import write_report

        return write_report(self, path, views=views)


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    raise TypeError(f"not JSON: {type(value).__name__}")


def assess(session, task=None, references=(), *, measure_visibility: bool = True) -> Assessment:
    """Assesses a recorded session (a path, or ``load_session``'s result) against `task` (a
    ``Task``, a task file, a built-in task's name, or None for ``default_task``) and expert
    `references` (recordings of the same anatomy)."""
    from .._core import SkillMetrics

    s = session if isinstance(session, SessionData) else load_session(session)
    anatomy = s.anatomy
    labels = np.array(anatomy.labels)
    if task is None:
        task = default_task(anatomy)
    elif not isinstance(task, Task):
        task = load_task(task)
    if task.anatomy:
        expected = task.anatomy_data()
        if tuple(expected.shape) != labels.shape or not np.array_equal(
            np.asarray(expected.labels), labels
        ):
            raise TaskError(
                f"{task.source}: the task's anatomy ({task.anatomy}) is not the anatomy "
                f"{s.path} was drilled on ({labels.shape[0]}x{labels.shape[1]}x"
                f"{labels.shape[2]} voxels from {s.metadata['scene'].get('builder')})"
            )
    ref_sessions = [load_session(r) for r in references]
    task_refs = [load_session(r) for r in task.target.get("references", [])]
    ref_cavities = {}
    for ref in ref_sessions + task_refs:
        ref_labels = np.asarray(ref.anatomy.labels)
        if ref_labels.shape != labels.shape or not np.array_equal(ref_labels, labels):
            raise ValueError(
                f"{ref.path}: the reference was drilled on another anatomy than {s.path}"
            )
        ref_cavities[str(ref.path)] = cavity_mask(labels.shape, ref.removed["voxel"])
    target = None
    if task.target:
        target = task.target_mask(
            anatomy, [ref_cavities[str(r.path)] for r in task_refs] if task_refs else ()
        )
    # The engine's metrics, replayed onto a copy of the anatomy as it began.
    ticks = drill_ticks(s.steps, s.removed, s.drill, s.burr_diameters, s.volume_pose)
    metrics = SkillMetrics(
        _copy(anatomy),
        protect=task.protect_config(anatomy),
        target_mask=target,
        excess_force=task.excess_force,
        apply_removals=True,
    )
    metrics.add_ticks(**ticks)
    summary = metrics.summary()
    cavity = cavity_mask(labels.shape, s.removed["voxel"])
    voxel_volume = float(np.prod(np.asarray(anatomy.dimensions) / np.asarray(labels.shape)))
    names = {int(label.id): label.name for label in anatomy.label_table}
    summary["removed_by_name"] = {
        names.get(int(k), str(k)): int(v) for k, v in summary["removed_by_label"].items()
    }
    cutting: np.ndarray = np.zeros(len(ticks["steps"]), bool)
    cutting[ticks["removed_tick"]] = True
    burrs_cutting = sorted({float(d) for d in 2 * ticks["burr_radii"][cutting]})
    data: dict = {
        "recording": str(s.path),
        "session": {
            "kind": s.kind,
            "created": s.created,
            "software_version": s.software_version,
            "drill": s.drill,
            "seconds": summary["total_time"],
        },
        "task": {
            "name": task.name,
            "source": task.source,
            "description": task.description,
            "text": task.text,
        },
        "software_version": __version__,
        "metrics": summary,
        "burrs_cutting": burrs_cutting,
    }
    if target is not None:
        target_voxels = int(target.sum())
        removed_total = summary["removed_in_target"] + summary["removed_outside_target"]
        data["target"] = {
            "voxels": target_voxels,
            "volume": target_voxels * voxel_volume,
            "removed_fraction": summary["removed_in_target"] / target_voxels
            if target_voxels
            else 0,
            "outside_fraction": summary["removed_outside_target"] / removed_total
            if removed_total
            else 0.0,
        }
    final = labels.copy()
    final[cavity] = 0
    data["exposure"] = {}
    for e in task.expose:
        structure = np.isin(labels, task.label_ids(anatomy, e))
        result = exposure(
            final,
            structure,
            target if target is not None else cavity,
            anatomy.dimensions,
            e.length,
            e.reach,
        )
        result["voxels_removed"] = int((structure & cavity).sum())
        result["thickness_target"] = e.length
        data["exposure"][e.name] = result
    data["visibility"] = None
    if measure_visibility and s.camera is not None:
        c = s.camera
        data["visibility"] = visibility(
            c["steps"],
            c["intrinsics"],
            c["poses"],
            c["depth"],
            s.steps,
            s.drill,
            ticks["burr_radii"],
            cutting,
            label=c["label"],
        )
    protected = None
    if task.protect and ref_cavities:
        ids = sorted({i for p in task.protect for i in task.label_ids(anatomy, p)})
        protected = mask_distance(np.isin(labels, ids), anatomy.dimensions, 0.01)
    reference_union: np.ndarray | None = None
    data["references"] = []
    for path in [str(r.path) for r in ref_sessions]:
        expert = ref_cavities[path]
        reference_union = expert if reference_union is None else reference_union | expert
        data["references"].append(
            {
                "recording": path,
                **compare_cavities(
                    cavity,
                    expert,
                    labels,
                    voxel_volume,
                    anatomy.dimensions,
                    target=target,
                    protected=protected,
                    label_names=names,
                ),
            }
        )
    items = rubric(data, task)
    data["rubric"] = [i.as_dict() for i in items]
    data["score"] = composite(items)
    data["violations"] = _violations(summary)
    timeline = _timeline(s, ticks, task, anatomy)
    return Assessment(data, timeline, s, task, cavity, target, reference_union)


def _copy(data: VolumeData) -> VolumeData:
    return VolumeData(
        np.array(data.labels, order="F"),
        dimensions=np.asarray(data.dimensions),
        label_table=list(data.label_table),
    )


def _violations(summary: dict) -> list[dict]:
    """Each breach of a protected structure (when, how many voxels) and each structure whose
    margin was entered."""
    out = []
    for s in summary["structures"]:
        if s["voxels_removed"]:
            out.append(
                {
                    "kind": "breach",
                    "structure": s["name"],
                    "time": s["first_breach_time"],
                    "step": s["first_breach_step"],
                    "voxels": s["voxels_removed"],
                }
            )
        if s["contacts"]:
            out.append(
                {
                    "kind": "margin",
                    "structure": s["name"],
                    "contacts": s["contacts"],
                    "time_in_margin": s["time_in_margin"],
                    "closest": s["closest"],
                    "time": s["closest_time"],
                }
            )
    return out


def _timeline(s: SessionData, ticks: dict, task: Task, anatomy: VolumeData) -> dict:
    """Force, burr on, removal and the burr's distance to each protected structure, one sample
    per TIMELINE_STEP (the distances from each structure's field as the session began: exact
    until the structure itself is cut)."""
    times = ticks["times"]
    every = max(1, int(round(TIMELINE_STEP / max(ticks["dt"], 1e-6))))
    rows = np.arange(0, len(times), every)
    force = np.linalg.norm(ticks["forces"], axis=1)
    removed = np.bincount(ticks["removed_tick"], minlength=len(times)) if len(times) else []
    out = {
        "time": times[rows],
        "force": np.maximum.reduceat(force, rows) if len(rows) else force[:0],
        "on": ticks["burr_on"][rows],
        "removed": np.add.reduceat(removed, rows) if len(rows) else removed,
        "distance": {},
    }
    for p in task.protect:
        field = DistanceField(anatomy, task.label_ids(anatomy, p), max(TIMELINE_BAND, p.length))
        d, _ = field.sample(ticks["tips"][rows])
        out["distance"][p.name] = np.asarray(d) - ticks["burr_radii"][rows]
    return out
