"""Recorded drilling sessions, and replaying them: record once, shoot again.

``record_session(scene, path, device, seconds=...)`` steps a scene (``ambfplus.scenes``) with a
device bound to its drill, films it with the scene's stereo rig every ``capture_every`` steps
(moving the rig along ``camera_motion`` first, if given) and writes everything to a recording
(``ambfplus.recording``): the stereo frames, every step's logged state (drill pose, goal,
force, burr; the device's readings), the removed voxels and the drill's events, with the
scene's spec and the device binding in the metadata.

``replay(path, ...)`` rebuilds the scene from the recording's metadata, drives the drill with
the recorded device readings (a ``ReplayDevice``) and steps to every recorded frame, optionally
capturing each with the same rig or another (``baseline``, ``width``, ``height``,
``working_distance``; the rig keeps the recorded pose of its centre) into a new recording. It
reports whether the removal log and the forces came out identical, and, with the same rig,
whether every re-rendered image equals the recorded one.

Both live with the scenes, not with ``ambfplus.recording``: replaying rebuilds a scene from a
recording's metadata, and the recording package stays below the scenes (it stores what any
script hands it and imports nothing of them).
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._core import Device, ReplayDevice
from ..fileio import refuse_writing_over
from ..recording import Recorder, open_recording
from ..recording.schema import RecordingError, recording_files
from ..recording.values import step_problems
from ..transforms import make_pose
from .builders import FilmedScene, build_scene

PASSES = ("rgb", "depth", "label", "instance", "voxel", "segmentation")
RIG = "rig"


def _serialisable_options(options: dict) -> dict:
    """Device binding options with objects replaced by their keys (the bare name in AMBF's root
    namespace; what the step log names their columns by)."""
    return {k: (v.key if hasattr(v, "key") else v) for k, v in options.items()}


def _bind(scene: FilmedScene, device: Device, options: dict | None = None):
    if scene.drill is None:
        raise ValueError("the scene has no drill for a device to drive")
    options = dict(scene.device_options if options is None else options)
    if isinstance(options.get("reference"), str):
        options["reference"] = scene.world.get(options["reference"])
    return scene.world.add_input_device(scene.device_name, device, scene.drill, **options)


def drain(world, drill, recorder: Recorder | None) -> tuple[dict, dict, list]:
    """Hands the step log, removed voxels and events gathered so far to the recorder (if any)
    and returns them; the launcher drains its live recording through this too. Without a
    drill (None), only the step log."""
    steps = world.take_step_log()
    removed, events = (
        ({"step": ()}, []) if drill is None else (drill.take_removed(), drill.take_events())
    )
    if recorder is not None:
        if len(steps["step"]):
            recorder.add_steps(steps)
        if len(removed["step"]):
            recorder.add_removed(removed, volume=drill.volume.name)
        if events:
            recorder.add_events(events)
    return steps, removed, events


def _progress(report: Callable[[str], None] | None, done: int, total: int, started: float, what):
    if report is None:
        return
    elapsed = time.perf_counter() - started
    report(f"{done / max(total, 1):4.0%}  step {done}/{total}  {what}  {elapsed:5.1f} s")


def record_session(
    scene: FilmedScene,
    path,
    device: Device | None,
    seconds: float,
    capture_every: int = 40,
    passes=PASSES,
    camera_motion: Callable[[float], tuple] | None = None,
    metadata: dict | None = None,
    progress: Callable[[str], None] | None = None,
    progress_every: float = 0.1,
    transform: Callable | None = None,
    recorder_options: dict | None = None,
    controller: Callable[[float], None] | None = None,
) -> dict:
    """Runs the scene for `seconds` with `device` driving its drill and records it to `path`.
    camera_motion(time) -> (eye, target) aims the rig (its midpoint at eye) before each
    capture; transform(stereo_frame) -> stereo_frame changes each pair before it is recorded
    (sensor noise, say); `recorder_options` go to ``Recorder``. A scene no device drives
    (`device` None; a dataset's scene) may have a `controller`, called with the time before
    every step. Returns a summary (steps, frames, voxels removed, events)."""
    world, drill, rig = scene.world, scene.drill, scene.rig
    binding = None if device is None else _bind(scene, device)
    total = int(round(seconds / world.time_step))
    meta = {
        "scene": scene.spec,
        "device": None
        if device is None
        else {
            "name": scene.device_name,
            "kind": type(device).__name__,
            "options": _serialisable_options(scene.device_options),
            "spec": dict(device.spec),
        },
        "capture_every": capture_every,
        "passes": list(passes),
        "rig": RIG,
        "seconds": seconds,
        **(metadata or {}),
    }
    world.start_step_log(list(scene.logged) + ([] if binding is None else [binding]))
    removed = events = frames = 0
    started, next_report = time.perf_counter(), 0.0
    with Recorder(path, metadata=meta, **(recorder_options or {})) as recorder:
        recorder.set_legend(world)
        while world.step_index < total:
            _step(world, min(capture_every, total - world.step_index), controller)
            if rig is None:
                raise ValueError("record_session: the scene has no stereo rig to capture with")
            if camera_motion is not None:
                rig.aim(*camera_motion(world.time))
            pair = rig.capture(passes)
            recorder.add_stereo(RIG, pair if transform is None else transform(pair))
            frames += 1
            _, r, e = drain(world, drill, recorder)
            removed, events = removed + len(r["step"]), events + len(e)
            if world.step_index / total >= next_report:
                _progress(progress, world.step_index, total, started,
                          f"{frames} stereo frames, {removed} voxels removed")  # fmt: skip
                next_report += progress_every
    world.stop_step_log()
    return {"steps": total, "frames": frames, "voxels_removed": removed, "events": events}


def _step(world, count: int, controller: Callable[[float], None] | None) -> None:
    """`count` steps, the controller (if any) called with the time before each."""
    if controller is None:
        world.step(count)
        return
    for _ in range(count):
        controller(world.time)
        world.step(1)


def device_log(steps: dict, name: str) -> dict:
    """A device's readings from a recording's step columns, as ReplayDevice takes them."""
    try:
        return {
            "step": steps["step"],
            "position": steps[f"{name}.position"],
            "orientation": steps[f"{name}.orientation"],
            "buttons": steps[f"{name}.buttons"],
        }
    except KeyError as missing:
        raise ValueError(
            f"the recording has no readings of device '{name}' ({missing} is not among its step "
            "columns): it cannot be replayed"
        ) from None


@dataclass
class ReplayReport:
    """What a replay reproduced."""

    steps: int
    frames: int
    removal_identical: bool
    forces_identical: bool
    #: with the recorded rig: frames whose every image equals the recorded one
    images_identical: int | None = None
    voxels_removed: int = 0
    output: Path | None = None
    differences: list = field(default_factory=list)


def replay(
    path,
    out=None,
    *,
    baseline: float | None = None,
    width: int | None = None,
    height: int | None = None,
    working_distance: float | None | str = "same",
    passes=None,
    compare_images: bool = True,
    progress: Callable[[str], None] | None = None,
) -> ReplayReport:
    """Re-simulates a recording from its device readings and re-renders its frames (see the
    module). With `out`, writes the re-rendered session as a new recording."""
    if out is not None:
        refuse_writing_over(out, recording_files(Path(path)), "replay")
    with open_recording(path) as rec:
        meta = rec.metadata
        missing = [k for k in ("scene", "device") if k not in meta]
        if missing:
            raise RecordingError(
                f"{path}: its metadata has no {' or '.join(missing)}: replay rebuilds the scene "
                "and device of a session recorded by ambfplus (record_session, the launcher)"
            )
        steps = rec.steps
        # A value that is not finite is never reproduced (NaN equals nothing): refused.
        problems = step_problems(steps)
        if problems:
            raise RecordingError(f"{path}: cannot replay {problems[0]}")
        removed = rec.removed
        rig_frames = rec.rigs.get(meta.get("rig", RIG))
        plan = (
            [
                (
                    int(rig_frames.step[i]),
                    np.asarray(rig_frames[i].left.pose),
                    rig_frames.baseline[i],
                )
                for i in range(len(rig_frames))
            ]
            if rig_frames is not None
            else []
        )
        recorded = rig_frames if compare_images else None
        if meta.get("device") is None:
            raise ValueError(
                f"{path}: no device drove this recording's scene, so there is nothing to replay "
                "(a dataset episode of a scene is made again by generating it)"
            )
        spec = {"builder": meta["scene"]["builder"], "params": dict(meta["scene"]["params"])}
        params = spec["params"]
        for key, value in (("baseline", baseline), ("width", width), ("height", height)):
            if value is not None:
                params[key] = value
        if working_distance != "same":
            params["working_distance"] = working_distance
        same_rig = params == meta["scene"]["params"]
        scene = build_scene(spec)
        world, drill, rig = scene.world, scene.drill, scene.rig
        device = meta["device"]
        replay_device = ReplayDevice(device_log(steps, device["name"]))
        options = _replay_options(device)
        binding = _bind(scene, replay_device, options)
        passes = tuple(passes or meta.get("passes", PASSES))
        step_to = _stepper(world, steps, device["options"].get("reference"))
        world.start_step_log(list(scene.logged) + [binding])
        recorder = None
        if out is not None:
            replayed_device = {
                "name": device["name"],
                "kind": type(replay_device).__name__,
                "options": _serialisable_options(options),
                "spec": dict(replay_device.spec),
                "replays": {k: v for k, v in device.items() if k != "replays"},
            }
            recorder = Recorder(
                out,
                metadata={**meta, "scene": spec, "device": replayed_device, "replay_of": str(path)},
            )
            recorder.set_legend(world)
        identical_frames, new_forces, new_removed = 0, [], []
        started = time.perf_counter()
        try:
            for i, (step, left_pose, recorded_baseline) in enumerate(plan):
                step_to(step)
                if rig is None:
                    raise ValueError("replay: the rebuilt scene has no stereo rig to capture with")
                # Keep the recorded rig's centre; the new baseline spreads the cameras about it.
                centre = left_pose @ make_pose((recorded_baseline / 2, 0.0, 0.0))
                rig.pose = centre @ make_pose((-rig.baseline / 2, 0.0, 0.0))
                if recorder is not None or (same_rig and recorded is not None):
                    pair = rig.capture(passes)
                    if recorder is not None:
                        recorder.add_stereo(RIG, pair)
                    if same_rig and recorded is not None:
                        identical_frames += _same_images(pair, recorded[i], passes)
                s, r, _ = drain(world, drill, recorder)
                new_forces.append(s[f"{drill.key}.force"])
                new_removed.append(r)
                if progress is not None and (i + 1) % max(1, len(plan) // 10) == 0:
                    _progress(progress, world.step_index, int(plan[-1][0]), started,
                              f"{i + 1}/{len(plan)} frames")  # fmt: skip
            last = int(steps["step"][-1]) if len(steps["step"]) else world.step_index
            step_to(last)
            s, r, _ = drain(world, drill, recorder)
            new_forces.append(s[f"{drill.key}.force"])
            new_removed.append(r)
        finally:
            world.stop_step_log()
            if recorder is not None:
                recorder.close()
    again = {k: np.concatenate([r[k] for r in new_removed]) for k in ("step", "voxel", "label")}
    forces = np.concatenate(new_forces)
    differences = [
        k for k in ("step", "voxel", "label") if not np.array_equal(removed[k], again[k])
    ]
    recorded_forces = steps[f"{drill.key}.force"]
    return ReplayReport(
        steps=world.step_index,
        frames=len(plan),
        removal_identical=not differences,
        forces_identical=bool(np.array_equal(recorded_forces, forces)),
        images_identical=identical_frames if same_rig and compare_images else None,
        voxels_removed=len(again["step"]),
        output=Path(out) if out is not None else None,
        differences=differences,
    )


def _replay_options(device: dict) -> dict:
    """The recorded binding's options, with the force limit the recorded device set (a
    ReplayDevice sets none), so that the replay's device force equals the recording's."""
    options = dict(device["options"])
    recorded_limit = device.get("spec", {}).get("max_force")
    if recorded_limit is not None:
        options["max_force"] = min(float(options.get("max_force", np.inf)), float(recorded_limit))
    return options


def _stepper(world, steps: dict, reference: str | None) -> Callable[[int], None]:
    """A function stepping the world to a step. A device moving in a camera's axes needs the
    camera where it was at every step: then each step first puts it at its logged pose (a step
    logs the pose its devices read, as nothing moves a parentless camera within a step)."""
    column = f"{reference}.pose" if reference else None
    if column is None or column not in steps:

        def step_to(target: int) -> None:
            if target > world.step_index:
                world.step(target - world.step_index)

        return step_to
    camera = world.get(reference)
    poses = dict(zip(steps["step"].tolist(), steps[column]))

    def step_with_camera(target: int) -> None:
        while world.step_index < target:
            pose = poses.get(world.step_index + 1)
            if pose is not None:
                camera.pose = pose
            world.step(1)

    return step_with_camera


def _same_images(pair, recorded, passes) -> bool:
    """Both views of a pair equal, pass for pass, to a recorded pair."""
    return all(
        np.array_equal(getattr(new, name), getattr(old, name))
        for new, old in ((pair.left, recorded.left), (pair.right, recorded.right))
        for name in passes
        if getattr(new, name, None) is not None
    )
