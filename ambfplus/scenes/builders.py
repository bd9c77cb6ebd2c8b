"""Built-in scenes that need no files: used by the demo, the examples and the tests."""

from __future__ import annotations

import json
import math
from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .._core import Drill, Label, VolumeData, World, phantom
from ..stereo import StereoRig
from ..transforms import make_pose, rotation_between
from .scenarios import CameraPath

# The paper's stereo camera: focal length about 1135 px at 640x480, about 250 mm from the anatomy.
PAPER_FOCAL_PX = 1135.0
PAPER_FOV_Y = 2.0 * math.atan(240.0 / PAPER_FOCAL_PX)


def paper_fov(height: int) -> float:
    """The vertical field of view of the paper's camera (f = 1135 px at 480 rows) at `height`."""
    return 2.0 * math.atan(height / 2.0 / (PAPER_FOCAL_PX * height / 480.0))


# The drill's default materials: brushed steel for the burr and shaft, a blue handle.
METAL = {"color": (0.72, 0.74, 0.8), "specular": 0.6}
HANDLE = {"color": (0.2, 0.45, 0.75)}


def add_drill(
    world: World,
    tip: tuple[float, float, float],
    direction,
    burr_radius: float = 0.003,
    metal: dict | None = None,
    handle: dict | None = None,
):
    """A drill built from primitives: a burr at `tip`, a shaft and a handle along `direction`
    (from the tip towards the surgeon's hand), kinematic (held by the hand, not by gravity).
    `metal` (burr and shaft) and `handle` are materials: color, specular, shininess. Returns the
    burr, shaft and handle bodies."""
    tip_pose = make_pose(tip, rotation=rotation_between((0, 0, 1), direction))
    metal = {**METAL, **(metal or {})}
    burr = world.add_body(
        "burr", "sphere", radius=burr_radius, pose=tip_pose, mass=0.01, kinematic=True, **metal
    )
    shaft = world.add_body(
        "shaft",
        "cylinder",
        radius=0.0012,
        height=0.06,
        mass=0.02,
        kinematic=True,
        pose=tip_pose @ make_pose((0, 0, 0.03)),
        **metal,
    )
    grip = world.add_body(
        "handle",
        "capsule",
        radius=0.006,
        height=0.08,
        mass=0.2,
        kinematic=True,
        pose=tip_pose @ make_pose((0, 0, 0.1)),
        **{**HANDLE, **(handle or {})},
    )
    return burr, shaft, grip


def demo_scene(width: int = 640, height: int = 480, resolution: int = 192):
    """The built-in temporal-bone phantom with a drill over its lateral face, seen from 150 mm by
    a camera with the paper's focal length. Returns the world and its camera."""
    world = World()
    world.add_light("key", "directional", direction=(-0.3, 0.4, -1.0), intensity=0.8)
    world.add_light("fill", "point", position=(0.15, -0.2, 0.3), intensity=0.3)
    world.add_volume("anatomy", phantom(resolution), pose=np.eye(4))
    add_drill(world, tip=(-0.002, 0.001, 0.0145), direction=(-0.3, 0.45, 1.0))
    camera = world.add_camera("camera", width, height, PAPER_FOV_Y, 0.01, 10.0)
    camera.look_at(eye=(0.035, -0.075, 0.132), target=(0.0, 0.0, 0.006))
    return world, camera


# The built-in scenes' lights: a key light from above the surgeon's side and a weak fill.
DEFAULT_LIGHTS: tuple[dict[str, Any], ...] = (
    {"name": "key", "type": "directional", "direction": (-0.3, 0.4, -1.0), "intensity": 0.8},
    {"name": "fill", "type": "point", "position": (0.15, -0.2, 0.3), "intensity": 0.3},
)


def _drill_over(world: World, volume, tip, metal: dict | None = None, handle: dict | None = None):
    """The paper's drill (6 mm burr) with its burr at `tip`, leaning back towards the surgeon,
    and primitive meshes riding on it."""
    # The drill frame's +x runs up the shaft from the burr.
    shaft = np.array([-0.3, 0.45, 1.0]) / np.linalg.norm([-0.3, 0.45, 1.0])
    start = make_pose(tip, rotation=rotation_between((1, 0, 0), shaft))
    drill = world.add_drill("drill", volume, burr=3, pose=start)
    bodies = add_drill(world, tip=tip, direction=shaft, metal=metal, handle=handle)
    for body in bodies:
        drill.attach(body, np.linalg.inv(start) @ body.pose)
    return drill, list(bodies)


@dataclass
class FilmedScene:
    """A built scene a recording films (``record_session``): its world, the stereo rig that
    films it, the objects whose state the recording logs every step, and the drill a device
    drives, if any (None: a dataset's scene of any kind, driven by its own script)."""

    world: World
    drill: Drill | None
    rig: StereoRig | None
    device_name: str
    device_options: dict
    logged: list = field(default_factory=list)
    spec: dict = field(default_factory=dict)  #: what build_scene rebuilds it from
    #: the point of the anatomy cameras look at (world frame, metres)
    target: tuple[float, float, float] = (0.0, 0.0, 0.008)
    #: the simulator that owns the world, where the scene was loaded as one (kept alive here)
    simulator: object = None


@dataclass
class Scene(FilmedScene):
    """A built scene with the drill a device drives and how to bind one (device_name,
    device_options)."""

    drill: Drill


def drilling_phantom(
    resolution: int = 128,
    seed: int = 0,
    width: int = 640,
    height: int = 480,
    baseline: float = 0.065,
    working_distance: float | None = 0.25,
    shadows: bool = False,
    antialiasing: int = 1,
    looks: bool = False,
) -> Scene:
    """The built-in temporal-bone phantom (48 mm across) under the paper's stereo rig (65 mm
    baseline, f = 1135 px at 640x480, off-axis with zero disparity at 250 mm), with the 6 mm burr
    of a drill 10 mm above its lateral face (z = 14 mm) and drill meshes riding on it. A device
    named "hand" drives the drill in world axes at scale 1: button 0 spins the burr. ``shadows``,
    ``antialiasing`` and ``looks`` are the rig's cameras' (``StereoRig``); the scene's spec
    keeps them, so a replay renders what was recorded."""
    world = World()
    for light in DEFAULT_LIGHTS:
        world.add_light(**light)
    volume = world.add_volume("anatomy", phantom(resolution, seed), pose=np.eye(4))
    drill, bodies = _drill_over(world, volume, tip=(0.0, 0.0, 0.024))
    rig = StereoRig(
        world, "rig", baseline=baseline, width=width, height=height, fov_y=paper_fov(height),
        near=0.01, far=2.0, working_distance=working_distance, shadows=shadows,
        antialiasing=antialiasing, looks=looks,
    )  # fmt: skip
    rig.aim(*orbit_view(0.0))
    spec = {
        "builder": "drilling_phantom",
        "params": {
            "resolution": resolution, "seed": seed, "width": width, "height": height,
            "baseline": baseline, "working_distance": working_distance,
            "shadows": shadows, "antialiasing": antialiasing, "looks": looks,
        },
    }  # fmt: skip
    # The drill's bodies are logged too: exports give every body a pose at every step.
    logged = [drill, rig.left, *bodies]
    return Scene(world, drill, rig, "hand", {"drill_button": 0}, logged, spec)


def drilling_scene(
    anatomy: dict | None = None,
    width: int = 640,
    height: int = 480,
    baseline: float = 0.065,
    working_distance: float | None = 0.25,
    fov_y: float | None = None,
    principal_point_offset=(0.0, 0.0),
    background=(0.0, 0.0, 0.0),
    lights: list | None = None,
    label_colors: dict | None = None,
    volume_material: dict | None = None,
    drill_metal: dict | None = None,
    drill_handle: dict | None = None,
    shadows: bool = False,
    antialiasing: int = 1,
    looks: bool = False,
) -> Scene:
    """Any anatomy under a stereo rig with a drill over it, every look of it a parameter (the
    scene of a dataset episode; ``drilling_phantom`` is the paper's fixed version).

    `anatomy` is ``{"phantom": {"resolution": 128, "seed": 0}}`` (the default) or ``{"file":
    path, ...}`` with ``load_volume``'s options; it is centred on the origin. The drill's burr
    starts 10 mm above the anatomy's surface straight above the origin, and cameras aim 6 mm
    below that surface (``Scene.target``). The rig: `fov_y` (radians, default the paper's
    f = 1135 px at 480 rows), `principal_point_offset` (pixels, both views), `background` (RGB
    0..1). Appearance: `lights` (dicts of ``World.add_light``'s arguments, without a name;
    default the paper scene's key and fill), `label_colors` ({label id: RGB 0..255}),
    `volume_material` and the drill's `drill_metal` and `drill_handle` (color, specular,
    shininess); the rig's `shadows`, `antialiasing` and `looks`. Geometry objects come first
    and lights last, so that object ids do not depend on the number of lights."""
    anatomy = anatomy or {"phantom": {"resolution": 128, "seed": 0}}
    world = World()
    data = anatomy_data(anatomy, label_colors)
    volume = world.add_volume("anatomy", data, pose=np.eye(4), **(volume_material or {}))
    surface = _surface_height(volume, data)
    drill, bodies = _drill_over(
        world, volume, (0.0, 0.0, surface + 0.010), drill_metal, drill_handle
    )
    rig = StereoRig(
        world, "rig", baseline=baseline, width=width, height=height,
        fov_y=paper_fov(height) if fov_y is None else fov_y, near=0.01, far=2.0,
        working_distance=working_distance, background=background,
        principal_point_offset=principal_point_offset, shadows=shadows,
        antialiasing=antialiasing, looks=looks,
    )  # fmt: skip
    target = (0.0, 0.0, surface - 0.006)
    rig.aim(*CameraPath(target=target)(0.0))
    for i, light in enumerate(DEFAULT_LIGHTS if lights is None else lights):
        world.add_light(**{"name": f"light{i}", **light})
    spec = {
        "builder": "drilling_scene",
        "params": {
            "anatomy": anatomy, "width": width, "height": height, "baseline": baseline,
            "working_distance": working_distance, "fov_y": fov_y,
            "principal_point_offset": list(principal_point_offset),
            "background": list(background), "lights": lights, "label_colors": label_colors,
            "volume_material": volume_material, "drill_metal": drill_metal,
            "drill_handle": drill_handle, "shadows": shadows, "antialiasing": antialiasing,
            "looks": looks,
        },
    }  # fmt: skip
    # The drill's bodies are logged too: exports give every body a pose at every step.
    logged = [drill, rig.left, *bodies]
    scene = Scene(world, drill, rig, "hand", {"drill_button": 0}, logged, spec)
    scene.target = target
    return scene


def _surface_height(volume, data) -> float:
    """Height of the anatomy's surface above the origin (the top of its box if a ray straight
    down misses it)."""
    top = float(data.dimensions[2]) / 2
    hit = volume.raycast((0.0, 0.0, top + 0.05), (0.0, 0.0, -1.0))
    return float(hit["position"][2]) if hit is not None else top


# Pristine anatomies a process loaded (label grid, size, label table), most recent last: a
# worker's episodes often share one, and each episode drills its own copy.
_ANATOMY_CACHE: OrderedDict = OrderedDict()
ANATOMY_CACHE_SIZE = 4


def anatomy_data(anatomy: dict, label_colors: dict | None = None) -> VolumeData:
    """A fresh VolumeData of an anatomy spec (see drilling_scene), its label colours replaced
    by `label_colors` ({id: RGB 0..255}). Loaded once per process; every call returns a copy."""
    key = json.dumps(anatomy, sort_keys=True)
    cached = _ANATOMY_CACHE.get(key)
    if cached is None:
        data = _load_anatomy(anatomy)
        table = [(e.id, e.name, tuple(e.color), e.removable, e.critical) for e in data.label_table]
        cached = (np.array(data.labels), np.array(data.dimensions), table)
        _ANATOMY_CACHE[key] = cached
        while len(_ANATOMY_CACHE) > ANATOMY_CACHE_SIZE:
            _ANATOMY_CACHE.popitem(last=False)
    _ANATOMY_CACHE.move_to_end(key)
    labels, dimensions, table = cached
    colors = {int(k): tuple(int(c) for c in v) for k, v in (label_colors or {}).items()}
    unknown = sorted(set(colors) - {entry[0] for entry in table})
    if unknown:
        raise ValueError(f"label_colors: labels {unknown} are not in the anatomy's label table")
    return VolumeData(
        labels,
        dimensions=dimensions,
        label_table=[
            Label(i, name, colors.get(i, color), removable, critical)
            for i, name, color, removable, critical in table
        ],
    )


def _load_anatomy(anatomy: dict) -> VolumeData:
    if set(anatomy) == {"phantom"}:
        return phantom(**anatomy["phantom"])
    if "file" in anatomy and "phantom" not in anatomy:
        from ..volumes import load_volume

        options = {k: v for k, v in anatomy.items() if k != "file"}
        return load_volume(anatomy["file"], **options)
    raise ValueError(
        f"anatomy {anatomy!r}: expected {{'phantom': {{resolution, seed}}}} or {{'file': path, "
        "...load_volume options}"
    )


def orbit_view(t: float, distance: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """(eye, target) of a camera circling above the phantom's lateral face: one turn of 40
    degrees amplitude every 8 s, looking at its centre from `distance`."""
    target = np.array([0.0, 0.0, 0.008])
    azimuth = math.radians(-100.0 + 40.0 * math.sin(2 * math.pi * t / 8.0))
    elevation = math.radians(55.0 + 10.0 * math.sin(2 * math.pi * t / 5.0))
    direction = np.array(
        [
            math.cos(elevation) * math.cos(azimuth),
            math.cos(elevation) * math.sin(azimuth),
            math.sin(elevation),
        ]
    )
    return target + distance * direction, target


def launch_scene(
    file: str,
    models: list | None = None,
    extra: list | None = None,
    namespace_prefix: str = "",
    plugins: list | None = None,
    arguments: list | None = None,
    time_step: float = 0.001,
) -> Scene:
    """An AMBF launch file loaded as ambfplus-launch loads it, with the drill its plugins make
    (the first drill) driven by a device named "keyboard"; the stereo rig of its stereoL and
    stereoR cameras when it has them."""
    from .._core import Simulator

    sim = Simulator.from_launch(
        file,
        models=models,
        extra=extra or [],
        namespace_prefix=namespace_prefix,
        time_step=time_step,
        plugins=plugins or [],
        arguments=arguments or [],
    )
    world = sim.world
    if not world.drills:
        raise ValueError(f"{file}: the loaded scene has no drill to drive")
    rig = None
    if "stereoL" in world and "stereoR" in world:
        rig = StereoRig.from_cameras(world["stereoL"], world["stereoR"])
    drill = world.drills[0]
    spec = {
        "builder": "launch",
        "params": {
            "file": file, "models": models, "extra": extra or [],
            "namespace_prefix": namespace_prefix, "plugins": plugins or [],
            "arguments": arguments or [], "time_step": time_step,
        },
    }  # fmt: skip
    return Scene(world, drill, rig, "keyboard", {}, [drill], spec)


SCENES: dict[str, Callable[..., Scene]] = {
    "drilling_phantom": drilling_phantom,
    "drilling_scene": drilling_scene,
    "launch": launch_scene,
}


def build_scene(spec: dict) -> Scene:
    """Rebuilds a scene from its spec (Scene.spec, as recordings store it)."""
    builder = SCENES.get(spec.get("builder", ""))
    if builder is None:
        raise ValueError(
            f"unknown scene builder {spec.get('builder')!r}; known: {', '.join(sorted(SCENES))}"
        )
    return builder(**spec.get("params", {}))
