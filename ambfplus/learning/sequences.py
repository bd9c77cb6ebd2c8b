"""The paper's two recorded sequences on the built-in phantom (``drilling_phantom``: 65 mm
baseline, f = 1135 px at 640x480, off-axis with zero disparity at 250 mm):

- moving camera: the rig circles the phantom (``ambfplus.scenes.orbit_view``) while the drill
  rests above the bone; the anatomy is never touched (the paper's training sequence);
- moving drill: the rig holds the first view of that orbit while a scripted hand plunges the
  spinning burr into the bone at random sites and sweeps it (the paper's testing sequence).

Both write ordinary recordings (``ambfplus.scenes.record_session``) with a ``sequence`` entry
in their metadata that says how they were made, so that a later run can reuse them.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .. import NullDevice, ScriptedDevice
from ..recording import open_recording
from ..scenes import DrillScript, drilling_phantom, orbit_view, record_session

PASSES = ("rgb", "depth", "label", "instance", "segmentation")
MOVING_CAMERA, MOVING_DRILL = "moving camera", "moving drill"


def sequence_spec(
    kind: str, frames: int, width: int, height: int, resolution: int, capture_every: int, seed: int
) -> dict:
    """What a sequence is made from (stored in its metadata)."""
    if kind not in (MOVING_CAMERA, MOVING_DRILL):
        raise ValueError(
            f"unknown sequence {kind!r}; expected {MOVING_CAMERA!r} or {MOVING_DRILL!r}"
        )
    return {
        "kind": kind, "frames": frames, "width": width, "height": height,
        "resolution": resolution, "capture_every": capture_every, "seed": seed,
    }  # fmt: skip


def record_sequence(
    path,
    kind: str,
    frames: int = 500,
    width: int = 640,
    height: int = 480,
    resolution: int = 128,
    capture_every: int = 20,
    seed: int = 0,
    progress=None,
) -> dict:
    """Records one of the paper's sequences (`kind`: "moving camera" or "moving drill") to
    `path`: `frames` stereo pairs, one every `capture_every` 1 ms steps. Returns the summary of
    ``record_session``."""
    spec = sequence_spec(kind, frames, width, height, resolution, capture_every, seed)
    scene = drilling_phantom(resolution=resolution, width=width, height=height)
    seconds = frames * capture_every * scene.world.time_step
    device: NullDevice | ScriptedDevice
    if kind == MOVING_CAMERA:
        device, motion = NullDevice(), orbit_view
    else:
        drill = scene.drill
        script = DrillScript(
            drill.volume, drill.goal[:3, 3], drill.burr_radius, np.random.default_rng(seed)
        )
        script.plunge_until(seconds)
        scripted = ScriptedDevice()
        scripted.set_callback(script, every=10)
        device, motion = scripted, None
    return record_session(
        scene, path, device, seconds, capture_every=capture_every, passes=PASSES,
        camera_motion=motion, metadata={"sequence": spec}, progress=progress,
    )  # fmt: skip


def recorded_spec(path) -> dict | None:
    """The sequence spec a recording was made with (None if it is not a complete sequence)."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        with open_recording(path) as rec:
            return rec.metadata.get("sequence") if rec.complete else None
    except (OSError, ValueError):
        return None


def ensure_sequence(path, kind: str, progress=None, **options) -> bool:
    """Records a sequence unless `path` already holds one made the same way. Returns True when
    it recorded."""
    defaults = {
        "frames": 500, "width": 640, "height": 480, "resolution": 128, "capture_every": 20,
        "seed": 0,
    }  # fmt: skip
    wanted = sequence_spec(kind, **{**defaults, **options})
    if recorded_spec(path) == wanted:
        return False
    for old in Path(path).parent.glob(Path(path).name + "*"):
        old.unlink()
    record_sequence(path, kind, progress=progress, **{**defaults, **options})
    return True
