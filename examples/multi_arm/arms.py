"""A scene factory for datasets of any scene (examples/multi_arm/dataset_spec.yaml): two planar
arms built from Python, each under a namespace of its own with the same body and joint names
(as two copies of one AMBF arm file with `namespace: /ambf/env/arm1/` and `/ambf/env/arm2/`),
a ghost on each jaw, a grasping actuator, a needle, and a stereo pair riding on a camera frame.

The dataset's spec names ``arms:two_arms``; ``generate`` calls it once per episode, with the
spec's ``params`` and the episode's random stream ``rng`` (here: where the needle lies).

    ambfplus generate examples/multi_arm/dataset_spec.yaml --out arms_dataset --workers 2
"""

from __future__ import annotations

import numpy as np

import ambfplus
from ambfplus.stereo import StereoRig
from ambfplus.transforms import make_pose

LINK = 0.2  # m
PD = {"p": 5.0, "i": 0.0, "d": 0.4}  # the joints' position controller


def _arm(world: ambfplus.World, namespace: str, base, color) -> None:
    """A static base and two links on PD-controlled revolute joints about z, with a ghost (the
    jaw) and a grip at the last link's end, every object under `namespace` as soon as it is made
    (names are unique within a namespace: the other arm uses the same ones)."""

    def under(obj):
        obj.namespace = namespace
        return obj

    x, y, z = base
    box = (LINK, 0.03, 0.03)
    bodies = [under(world.add_body("base", "box", size=(0.06, 0.06, 0.06), mass=0.0,
                                   pose=make_pose(base), color=(0.3, 0.3, 0.35)))]  # fmt: skip
    for i in (1, 2):
        pose = make_pose((x + (i - 0.5) * LINK, y, z))
        bodies.append(under(world.add_body(f"link{i}", "box", size=box, mass=0.6 - 0.2 * i,
                                           pose=pose, color=color)))  # fmt: skip
    for (parent, child), pivot in zip(zip(bodies, bodies[1:]), (0.0, LINK / 2)):
        name = f"{parent.name}-{child.name}"
        under(world.add_joint(name, parent, child, "revolute", parent_pivot=(pivot, 0, 0),
                              child_pivot=(-LINK / 2, 0, 0), parent_axis=(0, 0, 1),
                              child_axis=(0, 0, 1), controller=PD))  # fmt: skip
    tip = make_pose((LINK / 2, 0.0, 0.0))
    jaw = under(world.add_ghost("jaw", "sphere", radius=0.03, pose=bodies[2].pose @ tip))
    jaw.attach_to(bodies[2], tip)
    under(world.add_actuator("grip", bodies[2], location=tip))


def two_arms(rng: np.random.Generator | None = None, needle_offset: float = 0.05):
    """The scene; `rng` moves the needle up to `needle_offset` metres along x."""
    world = ambfplus.World()
    world.gravity = (0.0, 0.0, 0.0)
    _arm(world, "/ambf/env/arm1/", (0.0, 0.0, 0.5), (0.85, 0.55, 0.2))
    _arm(world, "/ambf/env/arm2/", (0.8, 0.0, 0.5), (0.2, 0.55, 0.85))
    shift = 0.0 if rng is None else float(rng.uniform(-needle_offset, needle_offset))
    world.add_body("needle", "sphere", radius=0.02, mass=0.02,
                   pose=make_pose((0.4 + shift, 0.2, 0.5)), color=(0.9, 0.9, 0.2))  # fmt: skip
    frame = world.add_body("CameraFrame", "box", size=(0.02, 0.02, 0.02), mass=0.0,
                           pose=make_pose((0.4, -0.5, 1.5)))  # fmt: skip
    stereo = StereoRig(world, "stereo", baseline=0.05, width=128, height=96, fov_y=0.9)
    stereo.aim((0.4, -0.5, 1.5), (0.4, 0.0, 0.5))
    stereo.left.attach_to(frame, np.linalg.inv(frame.pose) @ stereo.left.pose)
    world.add_light("key", "directional", direction=(0.0, 0.3, -1.0))
    return world
