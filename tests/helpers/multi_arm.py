"""A multi-arm AMBF scene written by a test, as projects that drive two surgical arms lay theirs
out: the same arm file loaded under two namespaces (``/ambf/env/arm1/``, ``/ambf/env/arm2/``:
the same body and joint names in both), link meshes written here as OBJ files, a ghost on each
arm's jaw and a grasping actuator, a needle within the first arm's reach, and a stereo camera
riding on a camera-frame body of a model loaded after the world file.

``write_multi_arm_scene(folder)`` writes it and returns the launch file; ``EPISODE_SCRIPT`` is a
Python episode script for datasets of it (write it as a module and name ``module:drive``): each
episode poses both arms at targets drawn from its random stream, grasps the needle once the first
arm's ghost senses it, and carries it away."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np

LINK = 0.2  # m, each link's length
BASES = {"arm1": (0.0, 0.0, 0.5), "arm2": (0.8, 0.0, 0.5)}
# The first arm's pose before it grasps: its jaw then lies just short of the needle.
ARM1_POSE = (0.9, -1.2)
NEEDLE_GAP = 0.035  # m beyond the jaw, along the last link
BASELINE = 0.05  # m between the stereo camera's eyes
RESOLUTION = (128, 96)


def box_obj(x: float, y: float, z: float) -> str:
    """An OBJ mesh of a box centred on its origin (8 vertices, 12 outward triangles)."""
    corners = [(sx * x / 2, sy * y / 2, sz * z / 2) for sx in (-1, 1) for sy in (-1, 1)
               for sz in (-1, 1)]  # fmt: skip
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    lines = [f"v {a:.6f} {b:.6f} {c:.6f}" for a, b, c in corners]
    for a, b, c, d in faces:
        lines += [f"f {a} {b} {c}", f"f {a} {c} {d}"]
    return "\n".join(lines) + "\n"


def arm_model(ns: str) -> str:
    """One arm (a static base, two links on revolute joints about z, a jaw ghost and a grip
    actuator at the last link's end) under namespace /ambf/env/<ns>/, placed at BASES[ns]. Both
    arms' files use the same names."""
    x, y, z = BASES[ns]
    blocks = [
        f"""\
    namespace: /ambf/env/{ns}/
    high resolution path: meshes/
    bodies: [BODY base, BODY link1, BODY link2]
    joints: [JOINT base-link1, JOINT link1-link2]
    ghost objects: [GHOST jaw]
    actuators: [ACTUATOR grip]
    BODY base:
      name: base
      mass: 0.0
      shape: box
      geometry: {{x: 0.06, y: 0.06, z: 0.06}}
      location: {{position: {{x: {x}, y: {y}, z: {z}}}, orientation: {{r: 0, p: 0, y: 0}}}}
      color components: {{diffuse: {{r: 0.3, g: 0.3, b: 0.35}}}}
    """
    ]
    for i in (1, 2):
        blocks.append(f"""\
    BODY link{i}:
      name: link{i}
      mass: {0.6 - 0.2 * i}
      mesh: link.obj
      collision shape: box
      collision geometry: {{x: {LINK}, y: 0.03, z: 0.03}}
      location: {{position: {{x: {x + (i - 0.5) * LINK}, y: {y}, z: {z}}}}}
      color components: {{diffuse: {{r: {0.9 - 0.3 * i}, g: 0.5, b: {0.2 * i}}}}}
    """)
    for parent, child, pivot in (("base", "link1", 0.0), ("link1", "link2", LINK / 2)):
        blocks.append(f"""\
    JOINT {parent}-{child}:
      name: {parent}-{child}
      parent: BODY {parent}
      child: BODY {child}
      parent pivot: {{x: {pivot}, y: 0.0, z: 0.0}}
      child pivot: {{x: {-LINK / 2}, y: 0.0, z: 0.0}}
      parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
      child axis: {{x: 0.0, y: 0.0, z: 1.0}}
      type: revolute
      controller: {{P: 5, I: 0, D: 0.4}}
    """)
    blocks.append(grasp_blocks("jaw", "grip", "link2"))
    return "".join(textwrap.dedent(block) for block in blocks)


def grasp_blocks(jaw: str, grip: str, link: str) -> str:
    """ADF blocks of a ghost (`jaw`, a sphere) and a grasping actuator (`grip`) at the far end
    of body `link` (a link along x)."""
    at = f"{{position: {{x: {LINK / 2}, y: 0.0, z: 0.0}}, orientation: {{r: 0, p: 0, y: 0}}}}"
    return textwrap.dedent(
        f"""\
        GHOST {jaw}:
          name: {jaw}
          parent: BODY {link}
          shape: sphere
          geometry: {{radius: 0.03}}
          location: {at}
        ACTUATOR {grip}:
          name: {grip}
          type: Constraint
          parent: BODY {link}
          location: {at}
        """
    )


def forward_kinematics(base, q0: float, q1: float) -> dict:
    """World positions of the links' centres and of the jaw, and the links' yaw, of a planar arm
    posed at (q0, q1): computed here, independently of the engine."""

    def along(angle: float, length: float) -> np.ndarray:
        return length * np.array([np.cos(angle), np.sin(angle), 0.0])

    base = np.asarray(base, dtype=float)
    elbow = base + along(q0, LINK)
    return {
        "link1": base + along(q0, LINK / 2),
        "link2": elbow + along(q0 + q1, LINK / 2),
        "jaw": elbow + along(q0 + q1, LINK),
        "yaw1": q0,
        "yaw2": q0 + q1,
    }


def needle_model() -> str:
    jaw = forward_kinematics(BASES["arm1"], *ARM1_POSE)["jaw"]
    direction = np.array([np.cos(sum(ARM1_POSE)), np.sin(sum(ARM1_POSE)), 0.0])
    nx, ny, nz = jaw + NEEDLE_GAP * direction
    return textwrap.dedent(
        f"""\
        bodies: [BODY needle]
        BODY needle:
          name: needle
          mass: 0.02
          shape: sphere
          geometry: {{radius: 0.02}}
          location: {{position: {{x: {nx}, y: {ny}, z: {nz}}}, orientation: {{r: 0, p: 0, y: 0}}}}
          color components: {{diffuse: {{r: 0.9, g: 0.9, b: 0.2}}}}
        """
    )


# The camera frame (a static body of the last model) sits in front of the arms; the world's
# stereo camera rides on it, looking at the middle between the two bases.
CAMERA_FRAME = """\
bodies: [BODY CameraFrame]
BODY CameraFrame:
  name: CameraFrame
  mass: 0.0
  shape: box
  geometry: {x: 0.02, y: 0.02, z: 0.02}
  location: {position: {x: 0.4, y: -0.5, z: 1.5}, orientation: {r: 0, p: 0, y: 0}}
"""

WORLD = f"""\
gravity: {{x: 0.0, y: 0.0, z: 0.0}}
lights: [LIGHT key]
cameras: [CAMERA main]
LIGHT key:
  name: key
  location: {{x: 0.4, y: -1.0, z: 2.0}}
  direction: {{x: 0.0, y: 0.3, z: -1.0}}
CAMERA main:
  name: main
  parent: BODY CameraFrame
  location: {{x: 0.0, y: 0.0, z: 0.0}}
  look at: {{x: 0.0, y: 0.5, z: -1.0}}
  up: {{x: 0.0, y: 0.0, z: 1.0}}
  field view angle: 0.9
  publish image resolution: {{width: {RESOLUTION[0]}, height: {RESOLUTION[1]}}}
  stereo: {{mode: passive, eye separation: {BASELINE}}}
"""


def write_multi_arm_scene(folder: Path) -> Path:
    """Writes the scene's files (and the link mesh) into `folder`; returns the launch file,
    whose models are [arm1, arm2, needle, camera frame] (load them all: models=[0, 1, 2, 3])."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "meshes").mkdir(exist_ok=True)
    (folder / "meshes" / "link.obj").write_text(box_obj(LINK, 0.03, 0.03))
    (folder / "arm1.yaml").write_text(arm_model("arm1"))
    (folder / "arm2.yaml").write_text(arm_model("arm2"))
    (folder / "needle.yaml").write_text(needle_model())
    (folder / "camera_frame.yaml").write_text(CAMERA_FRAME)
    (folder / "world.yaml").write_text(WORLD)
    launch = folder / "launch.yaml"
    launch.write_text(
        "world config: world.yaml\ncolor config: colors.yaml\ninput devices config: devices.yaml\n"
        "multibody configs: [arm1.yaml, arm2.yaml, needle.yaml, camera_frame.yaml]\n"
    )
    return launch


EPISODE_SCRIPT = f'''\
"""An episode of the multi-arm scene: the first arm reaches for the needle, its grip takes the
needle once the arm's jaw ghost senses it, and the arm swings it away by a drawn angle; the
second arm moves to drawn joint targets. Names are AMBF's keys (arm1/link1-link2)."""

import numpy as np

REACH = {ARM1_POSE!r}


def drive(sim, rng, appearance):
    world = sim.world
    arm1 = [world.get("arm1/base-link1"), world.get("arm1/link1-link2")]
    arm2 = [world.get("arm2/base-link1"), world.get("arm2/link1-link2")]
    jaw, grip, needle = world.get("arm1/jaw"), world.get("arm1/grip"), world.get("needle")
    arm2_goal = rng.uniform(-0.8, 0.8, size=2)
    swing = float(rng.uniform(-0.9, -0.3))
    state = {{"grasped_at": None}}

    def control(t):
        ramp = min(t / 0.15, 1.0)
        for joint, goal in zip(arm2, arm2_goal):
            joint.set_position(ramp * float(goal))
        if state["grasped_at"] is None:
            for joint, goal in zip(arm1, REACH):
                joint.set_position(ramp * goal)
            if any(body.key == needle.key for body in jaw.overlapping):
                grip.actuate(needle)
                state["grasped_at"] = t
        else:
            carried = min((t - state["grasped_at"]) / 0.15, 1.0)
            arm1[0].set_position(REACH[0] + carried * swing)

    return control
'''


def write_episode_script(folder: Path, module: str = "arms_episode") -> str:
    """Writes EPISODE_SCRIPT as `module`.py into `folder`; returns its ``module:drive``."""
    (folder / f"{module}.py").write_text(EPISODE_SCRIPT)
    return f"{module}:drive"
