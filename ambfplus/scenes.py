"""Built-in scenes that need no files: used by the demo, the examples and the tests."""

from __future__ import annotations

import math

from ._core import Camera, World
from .transforms import make_pose

# The paper's stereo camera: focal length about 1135 px at 640x480, about 250 mm from the anatomy.
PAPER_FOCAL_PX = 1135.0
PAPER_FOV_Y = 2.0 * math.atan(240.0 / PAPER_FOCAL_PX)


def demo_scene(width: int = 640, height: int = 480) -> tuple[World, Camera]:
    """A drill over a stand-in for the anatomy (a bone block with a skull-like dome), lit from two
    sides and seen from 250 mm by a camera with the paper's focal length.

    Returns the world and its camera. The anatomy becomes a segmented CT volume once volumes exist.
    """
    world = World()
    world.add_light("key", "directional", direction=(-0.4, 0.5, -1.0), intensity=0.85)
    world.add_light("fill", "point", position=(0.2, -0.25, 0.35), intensity=0.35)
    world.add_body(
        "table",
        "box",
        size=(0.5, 0.4, 0.02),
        pose=make_pose((0, 0, -0.01)),
        mass=0,
        color=(0.28, 0.36, 0.45),
    )
    world.add_body(
        "bone_block",
        "box",
        size=(0.09, 0.07, 0.03),
        pose=make_pose((0, 0, 0.015)),
        mass=0,
        color=(0.9, 0.86, 0.74),
    )
    world.add_body(
        "dome",
        "sphere",
        radius=0.03,
        pose=make_pose((0.005, 0.0, 0.03)),
        mass=0,
        color=(0.95, 0.91, 0.8),
    )
    world.add_body(
        "canal",
        "cylinder",
        radius=0.004,
        height=0.1,
        mass=0,
        color=(0.85, 0.3, 0.25),
        pose=make_pose((-0.02, 0.0, 0.031), rpy=(math.pi / 2, 0, 0.3)),
    )
    # The drill: a shaft tilted towards the dome, a burr at its tip and a handle.
    tip = (0.022, -0.012, 0.058)
    tilt = make_pose(tip, rpy=(-0.5, -0.3, 0.0))
    world.add_body("burr", "sphere", radius=0.003, pose=tilt, mass=0.01, color=(0.75, 0.75, 0.8))
    shaft = tilt @ make_pose((0, 0, 0.035))
    world.add_body(
        "shaft",
        "cylinder",
        radius=0.0015,
        height=0.064,
        pose=shaft,
        mass=0.02,
        color=(0.7, 0.72, 0.78),
    )
    handle = tilt @ make_pose((0, 0, 0.09))
    world.add_body(
        "handle",
        "capsule",
        radius=0.007,
        height=0.06,
        pose=handle,
        mass=0.2,
        color=(0.2, 0.45, 0.75),
    )
    camera = world.add_camera("camera", width, height, PAPER_FOV_Y, 0.01, 10.0)
    camera.look_at(eye=(0.12, -0.16, 0.19), target=(0.0, 0.0, 0.03))
    return world, camera
