"""Scenes and what happens in them: the built-in scenes (``builders``: the drilling phantom, an
anatomy from files, an AMBF launch file, each rebuilt from a JSON-able spec), the scripted
scenarios that move the rig and the drill (``scenarios``), and sessions that run a scene into a
recording and replay a recording in its scene again (``session``).

The flow runs one way: scenes -> session -> ``ambfplus.recording``. A recording knows nothing
of scenes, so replaying one (rebuilding its scene from the metadata) belongs here, not there.
"""

from .builders import (
    ANATOMY_CACHE_SIZE,
    DEFAULT_LIGHTS,
    HANDLE,
    METAL,
    PAPER_FOCAL_PX,
    PAPER_FOV_Y,
    SCENES,
    FilmedScene,
    Scene,
    add_drill,
    anatomy_data,
    build_scene,
    demo_scene,
    drilling_phantom,
    drilling_scene,
    launch_scene,
    orbit_view,
    paper_fov,
)
from .scenarios import DRILL_AREA, CameraPath, DrillScript
from .session import ReplayReport, device_log, drain, record_session, replay

__all__ = [
    "ANATOMY_CACHE_SIZE",
    "CameraPath",
    "DEFAULT_LIGHTS",
    "DRILL_AREA",
    "DrillScript",
    "FilmedScene",
    "HANDLE",
    "METAL",
    "PAPER_FOCAL_PX",
    "PAPER_FOV_Y",
    "ReplayReport",
    "SCENES",
    "Scene",
    "add_drill",
    "anatomy_data",
    "build_scene",
    "demo_scene",
    "device_log",
    "drain",
    "drilling_phantom",
    "drilling_scene",
    "launch_scene",
    "orbit_view",
    "paper_fov",
    "record_session",
    "replay",
]
