"""Built-in scenes that need no files: used by the demo, the examples and the tests."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ._core import Drill, World, phantom
from .stereo import StereoRig
from .transforms import make_pose, rotation_between

# The paper's stereo camera: focal length about 1135 px at 640x480, about 250 mm from the anatomy.
PAPER_FOCAL_PX = 1135.0
PAPER_FOV_Y = 2.0 * math.atan(240.0 / PAPER_FOCAL_PX)


def add_drill(world: World, tip: tuple[float, float, float], direction, burr_radius: float = 0.003):
    """A drill built from primitives: a burr at `tip`, a shaft and a handle along `direction`
    (from the tip towards the surgeon's hand), kinematic (held by the hand, not by gravity).
    Returns the burr, shaft and handle bodies."""
    tip_pose = make_pose(tip, rotation=rotation_between((0, 0, 1), direction))
    grey = (0.72, 0.74, 0.8)
    burr = world.add_body(
        "burr",
        "sphere",
        radius=burr_radius,
        pose=tip_pose,
        mass=0.01,
        kinematic=True,
        color=grey,
        specular=0.6,
    )
    shaft = world.add_body(
        "shaft",
        "cylinder",
        radius=0.0012,
        height=0.06,
        mass=0.02,
        kinematic=True,
        pose=tip_pose @ make_pose((0, 0, 0.03)),
        color=grey,
        specular=0.6,
    )
    handle = world.add_body(
        "handle",
        "capsule",
        radius=0.006,
        height=0.08,
        mass=0.2,
        kinematic=True,
        pose=tip_pose @ make_pose((0, 0, 0.1)),
        color=(0.2, 0.45, 0.75),
    )
    return burr, shaft, handle


def demo_scene(width: int = 640, height: int = 480, resolution: int = 192):
    """The built-in temporal-bone phantom with a drill over its lateral face, seen from 150 mm by
    a camera with the paper's focal length. Returns the world and its camera."""
    world = World()
    world.add_light("key", "directional", direction=(-0.3, 0.4, -1.0), intensity=0.8)
    world.add_light("fill", "point", position=(0.15, -0.2, 0.3), intensity=0.3)
    world.add_volume("anatomy", phantom(resolution), pose=np.eye(4))
    add_drill(world, tip=(0.004, -0.002, 0.0125), direction=(-0.3, 0.45, 1.0))
    camera = world.add_camera("camera", width, height, PAPER_FOV_Y, 0.01, 10.0)
    camera.look_at(eye=(0.035, -0.075, 0.13), target=(0.0, 0.0, 0.004))
    return world, camera


@dataclass
class Scene:
    """A built scene: its world, the drill a device drives and how to bind one, the stereo rig
    that films it, and the objects whose state a recording logs every step."""

    world: World
    drill: Drill
    rig: StereoRig | None
    device_name: str
    device_options: dict
    logged: list = field(default_factory=list)
    spec: dict = field(default_factory=dict)  #: what build_scene rebuilds it from


def drilling_phantom(
    resolution: int = 128,
    seed: int = 0,
    width: int = 640,
    height: int = 480,
    baseline: float = 0.065,
    working_distance: float | None = 0.25,
) -> Scene:
    """The built-in temporal-bone phantom (48 mm across) under the paper's stereo rig (65 mm
    baseline, f = 1135 px at 640x480, off-axis with zero disparity at 250 mm), with the 6 mm burr
    of a drill 10 mm above its lateral face (z = 12 mm) and drill meshes riding on it. A device
    named "hand" drives the drill in world axes at scale 1: button 0 spins the burr."""
    world = World()
    world.add_light("key", "directional", direction=(-0.3, 0.4, -1.0), intensity=0.8)
    world.add_light("fill", "point", position=(0.15, -0.2, 0.3), intensity=0.3)
    volume = world.add_volume("anatomy", phantom(resolution, seed), pose=np.eye(4))
    # The drill frame's +x runs up the shaft from the burr, leaning back towards the surgeon.
    shaft = np.array([-0.3, 0.45, 1.0]) / np.linalg.norm([-0.3, 0.45, 1.0])
    start = make_pose((0.0, 0.0, 0.022), rotation=rotation_between((1, 0, 0), shaft))
    drill = world.add_drill("drill", volume, burr=3, pose=start)
    burr, stem, handle = add_drill(world, tip=(0.0, 0.0, 0.022), direction=shaft)
    for body in (burr, stem, handle):
        drill.attach(body, np.linalg.inv(start) @ body.pose)
    fov_y = 2.0 * math.atan(height / 2.0 / (PAPER_FOCAL_PX * height / 480.0))
    rig = StereoRig(
        world, "rig", baseline=baseline, width=width, height=height, fov_y=fov_y, near=0.01,
        far=2.0, working_distance=working_distance,
    )  # fmt: skip
    rig.aim(*orbit_view(0.0))
    spec = {
        "builder": "drilling_phantom",
        "params": {
            "resolution": resolution, "seed": seed, "width": width, "height": height,
            "baseline": baseline, "working_distance": working_distance,
        },
    }  # fmt: skip
    # The drill's bodies are logged too: exports give every body a pose at every step.
    logged = [drill, rig.left, burr, stem, handle]
    return Scene(world, drill, rig, "hand", {"drill_button": 0}, logged, spec)


def orbit_view(t: float, distance: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """(eye, target) of a camera circling above the phantom's lateral face: one turn of 40
    degrees amplitude every 8 s, looking at its centre from `distance`."""
    target = np.array([0.0, 0.0, 0.006])
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
    from ._core import Simulator

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


SCENES = {"drilling_phantom": drilling_phantom, "launch": launch_scene}


def build_scene(spec: dict) -> Scene:
    """Rebuilds a scene from its spec (Scene.spec, as recordings store it)."""
    builder = SCENES.get(spec.get("builder", ""))
    if builder is None:
        raise ValueError(
            f"unknown scene builder {spec.get('builder')!r}; known: {', '.join(sorted(SCENES))}"
        )
    return builder(**spec.get("params", {}))
