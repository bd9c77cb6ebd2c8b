"""Built-in scenes that need no files: used by the demo, the examples and the tests."""

from __future__ import annotations

import math

import numpy as np

from ._core import World, phantom
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
