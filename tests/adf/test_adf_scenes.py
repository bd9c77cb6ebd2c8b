"""Scenes written as other projects write them load unchanged: objects whose parent is declared
in a file loaded later (world-file cameras and lights on a model's body, joints and sensors
across model files, the same for world.load_adf later), an environment whose mesh is missing
(reported, the rest of the world loads), AMBF's older single-ray proximity sensor, and ghost
objects that report what overlaps them."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


# A model whose body CameraFrame is kinematic, so the test can move it.
CAMERA_FRAME_MODEL = """
    bodies: [BODY CameraFrame]
    BODY CameraFrame:
      name: CameraFrame
      mass: 0.0
      shape: box
      geometry: {x: 0.05, y: 0.05, z: 0.05}
      location: {position: {x: 0.1, y: -0.2, z: 0.6}, orientation: {r: 0.3, p: 0.0, y: 0.5}}
    """

RIG = """
    cameras: [CAM left, CAM right]
    lights: [LIGHT lamp]
    CAM left:
      name: cameraL
      parent: BODY CameraFrame
      location: {x: -0.02, y: 0.0, z: 0.0}
      look at: {x: -0.02, y: 0.0, z: -1.0}
      up: {x: 0.0, y: 1.0, z: 0.0}
    CAM right:
      name: cameraR
      parent: BODY CameraFrame
      location: {x: 0.02, y: 0.0, z: 0.0}
      look at: {x: 0.02, y: 0.0, z: -1.0}
      up: {x: 0.0, y: 1.0, z: 0.0}
    LIGHT lamp:
      name: lamp
      parent: BODY CameraFrame
      location: {x: 0.0, y: 0.0, z: 0.1}
      direction: {x: 0, y: 0, z: -1}
    """


def launch_file(folder: Path, world: str, models: list[str]) -> Path:
    return write(
        folder,
        "launch.yaml",
        f"""
        world config: {world}
        color config: colors.yaml
        input devices config: devices.yaml
        multibody configs: [{", ".join(models)}]
        """,
    )


def relative(parent, child) -> np.ndarray:
    return np.linalg.inv(parent.pose) @ child.pose


def test_world_cameras_and_light_ride_on_a_body_loaded_later(tmp_path):
    write(tmp_path, "world.yaml", RIG)
    write(tmp_path, "frame.yaml", CAMERA_FRAME_MODEL)
    sim = ambfplus.Simulator.from_launch(
        launch_file(tmp_path, "world.yaml", ["frame.yaml"]), models=[0], strict=True
    )
    report = sim.load_report
    assert report.errors == []
    assert not [w for w in report.warnings if "parent" in w[1]], report.warnings
    world = sim.world
    frame = world.get("CameraFrame")
    objects = [world.get(n) for n in ("cameraL", "cameraR", "lamp")]
    assert all(o.attached_to is not None and o.attached_to.name == "CameraFrame" for o in objects)

    # The pose AMBF gives them: the same as when the rig and its body share one file.
    write(tmp_path, "together.yaml", CAMERA_FRAME_MODEL + RIG)
    same = ambfplus.World()
    same.load_adf(tmp_path / "together.yaml")
    for o in objects:
        np.testing.assert_allclose(
            relative(frame, o), relative(same.get("CameraFrame"), same.get(o.name)), atol=1e-12
        )

    # They follow the body as it moves.
    before = {o.name: relative(frame, o) for o in objects}
    moved = ambfplus.make_pose((0.4, 0.3, 0.2), rpy=(0.0, 0.7, -0.2))
    frame.kinematic = True
    frame.pose = moved
    world.step(3)
    for o in objects:
        np.testing.assert_allclose(o.pose, moved @ before[o.name], atol=1e-9)
    left, right = world.get("cameraL"), world.get("cameraR")
    assert np.linalg.norm(left.pose[:3, 3] - right.pose[:3, 3]) == pytest.approx(0.04)


def test_joint_and_sensor_whose_bodies_come_in_a_later_file(tmp_path):
    """A model file may name bodies of a file loaded after it (the launch order)."""
    write(
        tmp_path,
        "tool.yaml",
        """
        bodies: [BODY tip]
        joints: [JOINT tip-base]
        sensors: [SENSOR probe]
        BODY tip:
          name: tip
          mass: 0.1
          shape: sphere
          geometry: {radius: 0.01}
          location: {position: {x: 0.0, y: 0.0, z: 0.5}, orientation: {r: 0, p: 0, y: 0}}
        JOINT tip-base:
          name: tip-base
          parent: BODY base
          child: BODY tip
          parent pivot: {x: 0.0, y: 0.0, z: 0.5}
          child pivot: {x: 0.0, y: 0.0, z: 0.0}
          parent axis: {x: 0.0, y: 0.0, z: 1.0}
          child axis: {x: 0.0, y: 0.0, z: 1.0}
          type: fixed
        SENSOR probe:
          name: probe
          type: Proximity
          parent: BODY base
          location: {position: {x: 0.0, y: 0.0, z: 0.0}, orientation: {r: 0, p: 0, y: 0}}
          range: 2.0
          array: [{offset: {x: 0, y: 0, z: 0}, direction: {x: 0, y: 0, z: -1}}]
        """,
    )
    write(
        tmp_path,
        "base.yaml",
        """
        bodies: [BODY base]
        BODY base:
          name: base
          mass: 0.0
          shape: box
          geometry: {x: 0.1, y: 0.1, z: 0.1}
        """,
    )
    write(tmp_path, "world.yaml", "gravity: {x: 0.0, y: 0.0, z: -9.8}\n")
    sim = ambfplus.Simulator.from_launch(
        launch_file(tmp_path, "world.yaml", ["tool.yaml", "base.yaml"]), models=[0, 1]
    )
    assert sim.load_report.errors == []
    world = sim.world
    joint = world.get("tip-base")
    assert (joint.parent.name, joint.child.name) == ("base", "tip")
    assert world.get("probe").parent.name == "base"
    world.step(500)
    # Held by its joint to the static base, not fallen.
    assert world.get("tip").pose[2, 3] == pytest.approx(0.5, abs=1e-3)


def test_load_adf_later_attaches_what_was_waiting(tmp_path, caplog):
    write(
        tmp_path, "rig.yaml", RIG.replace("cameras: [CAM left, CAM right]", "cameras: [CAM left]")
    )
    write(tmp_path, "frame.yaml", CAMERA_FRAME_MODEL)
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(tmp_path / "rig.yaml")
    # Missing so far: a warning that says it will attach when the parent comes.
    assert any("CameraFrame" in r.getMessage() for r in caplog.records)
    assert world.get("cameraL").attached_to is None
    world.load_adf(tmp_path / "frame.yaml")
    assert world.get("cameraL").attached_to.name == "CameraFrame"
    assert world.get("lamp").attached_to.name == "CameraFrame"
    same = ambfplus.World()
    write(tmp_path, "together.yaml", CAMERA_FRAME_MODEL + RIG)
    same.load_adf(tmp_path / "together.yaml")
    np.testing.assert_allclose(
        relative(world.get("CameraFrame"), world.get("cameraL")),
        relative(same.get("CameraFrame"), same.get("cameraL")),
        atol=1e-12,
    )


def test_parent_missing_everywhere_is_a_warning_at_the_end(tmp_path):
    write(tmp_path, "world.yaml", RIG.replace("BODY CameraFrame", "BODY Nowhere"))
    write(tmp_path, "frame.yaml", CAMERA_FRAME_MODEL)
    sim = ambfplus.Simulator.from_launch(
        launch_file(tmp_path, "world.yaml", ["frame.yaml"]), models=[0]
    )
    warned = [w[1] for w in sim.load_report.warnings if "BODY Nowhere" in w[1]]
    assert len(warned) == 3  # two cameras and the light, once each
    assert all("not found" in w for w in warned)
    assert sim.world.get("cameraL").attached_to is None


def test_environment_with_a_missing_mesh_is_reported_and_the_world_loads(tmp_path):
    write(
        tmp_path,
        "env.yaml",
        """
        bodies: [BODY table, BODY floor]
        high resolution path: meshes/
        BODY table:
          name: table
          mass: 0.0
          mesh: table.STL
        BODY floor:
          name: floor
          mass: 0.0
          shape: box
          geometry: {x: 1.0, y: 1.0, z: 0.01}
        """,
    )
    write(tmp_path, "world.yaml", "environment: env.yaml\n" + textwrap.dedent(RIG))
    write(tmp_path, "frame.yaml", CAMERA_FRAME_MODEL)
    launch = launch_file(tmp_path, "world.yaml", ["frame.yaml"])
    sim = ambfplus.Simulator.from_launch(launch, models=[0])
    errors = sim.load_report.errors
    assert len(errors) == 1 and "table.STL" in errors[0][1], errors
    world = sim.world
    # The rest of the environment, the world's cameras and light, and the models are there.
    assert "floor" in world and "table" not in world
    assert world.get("cameraL").attached_to.name == "CameraFrame"
    assert "lamp" in world
    with pytest.raises(ambfplus.AssetNotFound, match="table.STL"):
        ambfplus.Simulator.from_launch(launch, models=[0], strict=True)


def test_single_ray_proximity_sensor_reads_the_analytic_distance(tmp_path):
    """AMBF's older sensor form: one ray from `location` along `direction`, `range` long."""
    write(
        tmp_path,
        "probe.yaml",
        """
        bodies: [BODY holder, BODY wall]
        sensors: [SENSOR beam]
        BODY holder:
          name: holder
          mass: 0.0
          shape: sphere
          geometry: {radius: 0.01}
          location: {position: {x: 0.0, y: 0.0, z: 0.3}, orientation: {r: 0, p: 0, y: 0.4}}
        BODY wall:
          name: wall
          mass: 0.0
          shape: box
          geometry: {x: 0.5, y: 0.5, z: 0.02}
        SENSOR beam:
          name: beam
          type: Proximity
          parent: BODY holder
          location: {position: {x: 0.05, y: 0.0, z: -0.02}, orientation: {r: 0, p: 0, y: 0}}
          direction: {x: 0.0, y: 0.6, z: -0.8}
          range: 0.5
        """,
    )
    world = ambfplus.World()
    world.load_adf(tmp_path / "probe.yaml")
    world.step(1)
    beam = world.get("beam")
    assert beam.ray_count == 1
    (hit,) = beam.hits
    # From z = 0.28 down to the wall's top (z = 0.01) along a ray falling 0.8 per unit length.
    assert hit["triggered"] and hit["body"].name == "wall"
    assert hit["distance"] == pytest.approx((0.28 - 0.01) / 0.8, abs=1e-5)
