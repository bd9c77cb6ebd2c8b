"""AMBF description files: the original system's launch, world, model and input-device files load
unchanged; names, parents, joint types and counts match the files' own lists (read here with
PyYAML, independently of the engine); every dangling reference has a named outcome."""

from __future__ import annotations

import json
import logging
import math
import textwrap
from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers.rays import backproject

import ambfplus

DESCRIPTIONS = Path("ambf") / "ambf_models" / "descriptions"
TYPES = {
    "hinge": "revolute",
    "revolute": "revolute",
    "continuous": "revolute",
    "slider": "prismatic",
    "prismatic": "prismatic",
    "fixed": "fixed",
    "p2p": "p2p",
}


def launch_path(fixtures: Path) -> Path:
    return fixtures / DESCRIPTIONS / "launch.yaml"


def model_files(fixtures: Path) -> list[Path]:
    return sorted((fixtures / DESCRIPTIONS / "multi-bodies").rglob("*.yaml"))


def expected(path: Path) -> dict:
    """Bodies and joints as the file lists them: names, joint types, parents and children."""
    doc = yaml.safe_load(path.read_text())

    def name(identifier: str) -> str:
        block = doc[identifier]
        return str(block.get("name", identifier.split(" ", 1)[-1])).replace(" ", "")

    bodies = [name(b) for b in doc.get("bodies") or []]
    joints = {}
    for j in doc.get("joints") or []:
        block = doc[j]
        joints[name(j)] = (TYPES[block["type"]], name(block["parent"]), name(block["child"]))
    return {"bodies": bodies, "joints": joints}


def check_model(model, path: Path) -> None:
    want = expected(path)
    bodies = [o for o in model.objects if o.kind == "body"]
    joints = [o for o in model.objects if o.kind == "joint"]
    assert [b.name for b in bodies] == want["bodies"]
    assert len(joints) == len(want["joints"])
    for j in joints:
        assert (j.type, j.parent.name, j.child.name) == want["joints"][j.name], j.name


def test_every_present_launch_index_loads(fixtures):
    launch = ambfplus.read_launch(launch_path(fixtures))
    present = [i for i, f in enumerate(launch["models"]) if Path(f).is_file()]
    assert present == [10, 12]  # parallel_structure and puzzle2; the rest are not in the fixtures
    for i in present:
        sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[i], strict=True)
        report = sim.load_report
        assert report.errors == []
        env, model = report.models
        assert [o.name for o in env.objects] == ["Plane"]
        check_model(model, Path(launch["models"][i]))


def test_every_model_file_loads(fixtures):
    for path in model_files(fixtures):
        world = ambfplus.World()
        if path.name == "compound_example.yaml":
            # Not YAML: a flow mapping followed by ',' in block context. yaml-cpp (and so AMBF)
            # rejects it too; the error names the file and the line.
            with pytest.raises(ambfplus.ConfigError, match=r"compound_example.yaml: line 84"):
                world.load_adf(path)
            assert world.objects == []
            continue
        check_model(world.load_adf(path), path)


def test_exported_bodies_sit_at_joint_position_zero(fixtures):
    # Frame math: the exporter places bodies at the joints' zero (the child offset included).
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10, 12], strict=True)
    revolute = [j for j in sim.world.joints if j.type == "revolute"]
    assert len(revolute) == 7
    for j in revolute:
        assert abs(j.position) < 2e-3, (j.name, j.position)
        a, b = j.anchors
        assert np.linalg.norm(a - b) < 2e-3, j.name


def test_world_file_lights_cameras_gravity(fixtures):
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10])
    world = sim.world
    assert world.gravity == pytest.approx([0, 0, -9.81])
    # Listed lights only (light3 is an unreferenced block); relative namespaces are appended.
    assert sorted(light.qualified_name for light in world.lights) == [
        "/ambf/env/lights/light1",
        "/ambf/env/lights/light2",
    ]
    light1 = world.get("light1")
    assert light1.pose[:3, 3] == pytest.approx([0.0, 0.5, 2.5])
    assert light1.direction == pytest.approx([0, 0, -1])
    (camera,) = world.cameras
    assert camera.qualified_name == "/ambf/env/cameras/default_camera"
    assert (camera.near, camera.far, camera.fov_y) == (0.1, 10.0, 0.8)
    eye, target = np.array([4.0, 0.0, 2.0]), np.array([0.0, 0.0, -0.5])
    assert camera.pose[:3, 3] == pytest.approx(eye)
    assert camera.pose[:3, 2] == pytest.approx((target - eye) / np.linalg.norm(target - eye))
    # Image up follows `up`: the camera's y (down in the image) points away from +z.
    assert camera.pose[2, 1] < 0
    floor = world.get("Plane")
    assert floor.pose[:3, 3] == pytest.approx([0, 0, -1.5])
    assert floor.mesh.endswith("checkered_floor/high_res/Plane.OBJ")
    assert floor.collision_shapes[0][0] == "plane"


def test_mesh_paths_high_res_for_drawing_low_res_for_collision(fixtures):
    world = ambfplus.World()
    world.load_adf(fixtures / DESCRIPTIONS / "multi-bodies" / "puzzles" / "peg_and_base.yaml")
    torus = world.get("Torus")
    assert torus.mesh.endswith("peg_and_base/high_res/Torus.STL")
    assert torus.collision_mesh.endswith("peg_and_base/low_res/Torus.STL")
    base = world.get("PegBase")
    assert [s for s, _ in base.collision_shapes] == ["cylinder", "cylinder"]
    assert base.collision_shapes[0][1][2, 3] == pytest.approx(0.21000000834465027)


def test_lookup_like_ambf(fixtures):
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10, 12])
    l1 = sim.get("l1")
    for name in ("/ambf/env/l1", "BODY l1", "/ambf/env/BODY l1"):
        assert sim.get(name).id == l1.id
    assert sim.get("HandleLidL").name == "HandleLidLeft"  # a unique part of a name
    with pytest.raises(KeyError, match="ambiguous"):
        sim.get("HandleLid")
    with pytest.raises(KeyError, match="no object"):
        sim.get("Gripper")
    assert sim.get("l1-l2", kind="joint").type == "revolute"


def test_root_body_joints_in_ambf_order(fixtures):
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10, 12])
    names = [j.name for j in sim.get("world").joints]
    assert names == ["world-l1", "l1-l2", "l2-l3", "l3-l4", "l1-l4"]
    mold = [j.name for j in sim.get("Mold_A").joints]
    assert mold == [
        "Mold_A-HandleBaseLeft",
        "HandleBaseLeft-HandleLidLeft",
        "Mold_A-HandleBaseRight",
        "HandleBaseRight-HandleLidRight",
        "Mold_A-MoldHinge",
        "MoldHinge-TopPlate",
    ]
    assert [j.name for j in sim.get("HandleBaseLeft").joints] == ["HandleBaseLeft-HandleLidLeft"]


def test_missing_launch_files_are_reported_not_fatal(fixtures, caplog):
    with caplog.at_level(logging.ERROR, logger="ambfplus"):
        sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[0, 10, 40])
    report = sim.load_report
    assert [m.name for m in report.models] == ["checkered_floor", "parallel_structure"]
    (absent, out_of_range) = report.errors
    assert absent[0].endswith("blender-toy-car.yaml") and "launch index 0" in absent[1]
    assert "file not found" in absent[1]
    assert "launch index 40 is out of range" in out_of_range[1]
    assert "blender-toy-car.yaml" in caplog.text
    with pytest.raises(ambfplus.AssetNotFound):
        ambfplus.Simulator.from_launch(launch_path(fixtures), models=[0, 10], strict=True)


def test_default_selection_is_launch_index_1(fixtures):
    # AMBF loads index 1 when neither -l nor -a is given; the fixtures do not have that file.
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures))
    (error,) = sim.load_report.errors
    assert error[0].endswith("blender-toy-car2.yaml")
    assert [m.name for m in sim.load_report.models] == ["checkered_floor"]
    extra = fixtures / DESCRIPTIONS / "multi-bodies" / "puzzles" / "peg_and_base.yaml"
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), extra=[extra])
    assert sim.load_report.errors == []
    assert [m.name for m in sim.load_report.models] == ["checkered_floor", "peg_and_base"]


def test_input_devices_file(fixtures):
    path = fixtures / DESCRIPTIONS / "input_devices" / "input_devices.yaml"
    devices = ambfplus.read_input_devices(path)
    assert [d["identifier"] for d in devices] == [
        "MTMR",
        "MTML",
        "Geomagic Touch",
        "Razer Hydra0",
        "Razer Hydra1",
        "Novint Falcon1",
        "Novint Falcon2",
    ]
    touch = devices[2]
    assert touch["hardware_name"] == "PHANTOM Omni"
    assert touch["workspace_scaling"] == 10 and touch["max_force"] == 2
    assert touch["deadband"] == 0.01 and touch["haptic_gain"] == (10.0, 0.0)
    assert touch["buttons"] == {"a1": 0, "a2": -1, "g1": 1, "next mode": 2, "prev mode": 3}
    assert touch["location"][:3, 3] == pytest.approx([0.0, 0.5, 0.0])
    assert touch["simulated_multibody"].endswith("grippers/pr2 gripper.yaml")
    # The device's simulated multibody is not among the fixtures: reported, the rest loads.
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10], devices=[2])
    (error,) = sim.load_report.errors
    assert error[0].endswith("pr2 gripper.yaml") and "Geomagic Touch" in error[1]
    assert [d["identifier"] for d in sim.load_report.input_devices] == ["Geomagic Touch"]
    assert "l1" in sim.world


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


def small_launch(tmp_path: Path, fixtures: Path, world: str, colors: str) -> Path:
    d = fixtures / DESCRIPTIONS
    return write(
        tmp_path,
        "launch.yaml",
        f"""
        world config: {world}
        color config: {colors}
        input devices config: {d / "input_devices" / "input_devices.yaml"}
        multibody configs:
          - {d / "multi-bodies" / "puzzles" / "parallel_structure.yaml"}
        """,
    )


def test_missing_colour_file_warns_and_loads(fixtures, tmp_path):
    world_file = fixtures / DESCRIPTIONS / "world" / "world.yaml"
    launch = small_launch(tmp_path, fixtures, str(world_file), str(tmp_path / "no_colors.yaml"))
    sim = ambfplus.Simulator.from_launch(launch, models=[0])
    report = sim.load_report
    assert report.errors == []
    assert any("no_colors.yaml not found" in w[1] for w in report.warnings)
    assert "l1" in sim.world


def test_light_with_absent_parent_warns_and_a_camera_waits_for_its_parent(fixtures, tmp_path):
    world_file = write(
        tmp_path,
        "world.yaml",
        """
        lights: [lamp]
        cameras: [cam]
        lamp:
          location: {x: 0.5, y: 0.0, z: 2.0}
          direction: {x: 0, y: 0, z: -1}
          parent: /ambf/env/BODY LightCone
        cam:
          location: {x: 0.0, y: 0.0, z: -0.1}
          look at: {x: 0.0, y: 0.0, z: -1.0}
          up: {x: 1.0, y: 0.0, z: 0.0}
          parent: BODY l2
        """,
    )
    colors = fixtures / DESCRIPTIONS / "color" / "colors.yaml"
    launch = small_launch(tmp_path, fixtures, str(world_file), str(colors))
    sim = ambfplus.Simulator.from_launch(launch, models=[0])
    report = sim.load_report
    warned = [w[1] for w in report.warnings if "lamp" in w[1]]
    assert len(warned) == 1 and "parent '/ambf/env/BODY LightCone' not found" in warned[0]
    lamp = sim.get("lamp")
    assert lamp.attached_to is None and lamp.pose[:3, 3] == pytest.approx([0.5, 0, 2.0])
    # The world file loads before the models: its camera's parent comes later, and the camera
    # rides on it once it does (AMBF's parents across files), without a warning.
    cam = sim.get("cam")
    assert cam.attached_to is not None and cam.attached_to.name == "l2"
    assert not [w for w in report.warnings if w[1].startswith("cam:")]


def test_camera_rides_on_its_parent_body(fixtures, tmp_path):
    model = write(
        tmp_path,
        "arm.yaml",
        """
        bodies: [BODY link]
        cameras: [CAM endoscope]
        BODY link:
          name: link
          mass: 1.0
          shape: BOX
          geometry: {x: 0.1, y: 0.1, z: 0.1}
        CAM endoscope:
          name: endo
          parent: BODY link
          location: {x: 0.0, y: 0.0, z: -0.1}
          look at: {x: 0.0, y: 0.0, z: -1.0}
          up: {x: 1.0, y: 0.0, z: 0.0}
        """,
    )
    world = ambfplus.World()
    world.load_adf(model)
    world.step(200)  # the link falls; the camera goes with it
    link, cam = world.get("link"), world.get("endo")
    assert cam.attached_to.name == "link"
    assert link.pose[2, 3] < -0.1
    assert cam.pose[:3, 3] == pytest.approx(link.pose[:3, :3] @ [0, 0, -0.1] + link.pose[:3, 3])
    assert cam.pose[:3, 2] == pytest.approx(link.pose[:3, :3] @ [0, 0, -1.0])


def test_unknown_keys_warn_once_and_repeated_keys_warn_or_refuse(tmp_path, caplog):
    # yaml-cpp (and so AMBF) keeps a key written twice and reads the first: with one value it
    # is a warning naming the key and both lines; with two, a ConfigError (see test_silent_cases).
    model = write(
        tmp_path,
        "dup.yaml",
        """
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 2.0
          mass: 2.0
          shape: SPHERE
          geometry: {radius: 0.1}
          detached: true
          visiblity: true
          detached: true
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(model)
    assert world.get("a").mass == 2.0
    messages = [r.getMessage() for r in caplog.records]
    assert sum("unknown key 'detached'" in m for m in messages) == 1
    assert sum("unknown key 'visiblity'" in m for m in messages) == 1
    assert sum("line 6: key 'mass' is given twice" in m and "line 5" in m for m in messages) == 1
    assert sum("key 'detached' is given twice" in m for m in messages) == 1
    model.write_text(model.read_text().replace("mass: 2.0\n  mass: 2.0", "mass: 2.0\n  mass: 7.0"))
    with pytest.raises(ambfplus.ConfigError, match=r"line 6: key 'mass' is given twice"):
        ambfplus.World().load_adf(model)


def test_bad_input_names_file_object_and_key(tmp_path):
    world = ambfplus.World()
    bad_yaml = write(tmp_path, "syntax.yaml", "bodies: [BODY a\nBODY a: {name: a}\n")
    with pytest.raises(ambfplus.ConfigError, match=r"syntax.yaml: line \d+"):
        world.load_adf(bad_yaml)
    no_type = write(
        tmp_path,
        "no_type.yaml",
        """
        bodies: [BODY a, BODY b]
        joints: [JOINT a-b]
        BODY a: {name: a, mass: 0, shape: BOX, geometry: {x: 1, y: 1, z: 1}}
        BODY b: {name: b, mass: 1, shape: BOX, geometry: {x: 1, y: 1, z: 1}}
        JOINT a-b: {name: a-b, parent: BODY a, child: BODY b}
        """,
    )
    with pytest.raises(ambfplus.ConfigError, match=r"no_type.yaml: line 6: JOINT a-b: .*'type'"):
        world.load_adf(no_type)
    wrong = write(
        tmp_path,
        "wrong.yaml",
        """
        bodies: [BODY a]
        BODY a: {name: a, mass: heavy, shape: BOX, geometry: {x: 1, y: 1, z: 1}}
        """,
    )
    with pytest.raises(ambfplus.ConfigError, match=r"BODY a: 'mass' must be a number"):
        world.load_adf(wrong)
    unlisted = write(tmp_path, "unlisted.yaml", "bodies: [BODY ghost]\n")
    with pytest.raises(ambfplus.ConfigError, match="lists 'BODY ghost' but the file has no block"):
        world.load_adf(unlisted)
    version = write(tmp_path, "v2.yaml", "adf version: '2.0'\nbodies: []\n")
    with pytest.raises(ambfplus.ConfigError, match="adf version"):
        world.load_adf(version)
    assert world.objects == []


def test_missing_mesh_lists_every_path_tried(tmp_path):
    (tmp_path / "meshes" / "high").mkdir(parents=True)
    model = write(
        tmp_path,
        "m.yaml",
        """
        bodies: [BODY a]
        high resolution path: meshes/high/
        low resolution path: meshes/low/
        BODY a: {name: a, mass: 1, mesh: part.STL, high resolution path: mine/}
        """,
    )
    with pytest.raises(ambfplus.AssetNotFound) as error:
        ambfplus.World().load_adf(model)
    assert error.value.tried == [
        str(tmp_path / "mine" / "part.STL"),
        str(tmp_path / "meshes" / "high" / "part.STL"),
        str(tmp_path / "part.STL"),
    ]
    assert all(p in str(error.value) for p in error.value.tried)


def test_a_model_loads_all_or_nothing(fixtures, tmp_path):
    good = fixtures / DESCRIPTIONS / "multi-bodies" / "puzzles" / "parallel_structure.yaml"
    text = good.read_text().replace(
        "../../../meshes", str(fixtures / "ambf" / "ambf_models" / "meshes")
    )
    # The last body cannot be built (restitution above 1): nothing of the model may stay.
    broken = write(
        tmp_path, "broken.yaml", text.replace("  mesh: l4.STL", "  mesh: l4.STL\n  restitution: 3")
    )
    world = ambfplus.World()
    with pytest.raises(ambfplus.ConfigError, match=r"broken.yaml: BODY l4: .*restitution"):
        world.load_adf(broken)
    assert world.objects == [] and [m.name for m in world.models] == ["World"]
    world.step(10)
    model = world.load_adf(good)
    assert model.name == "parallel_structure" and "l4" in world


def test_duplicate_loads_get_numbered_and_joints_bind_their_own_copy(fixtures):
    path = fixtures / DESCRIPTIONS / "multi-bodies" / "grippers" / "single joint1.yaml"
    world = ambfplus.World()
    first = world.load_adf(path)
    second = world.load_adf(path)
    assert second.name == "single joint11"
    names = [o.name for o in second.objects]
    assert names == ["gripperR11", "gripperL11", "gripperR1-gripperL11"]
    joint = world.get("gripperR1-gripperL11")
    assert (joint.parent.name, joint.child.name) == ("gripperR11", "gripperL11")
    assert first.objects[2].parent.name == "gripperR1"


def test_joint_to_a_body_of_another_file(fixtures, tmp_path):
    tool = write(
        tmp_path,
        "tool.yaml",
        """
        bodies: [BODY tip]
        joints: [JOINT l4-tip]
        BODY tip: {name: tip, mass: 0.1, shape: SPHERE, geometry: {radius: 0.02}}
        JOINT l4-tip: {name: l4-tip, parent: BODY l4, child: BODY tip, type: fixed,
                       parent pivot: {x: 0, y: 0, z: 0.1}}
        JOINT nowhere: {name: nowhere, parent: BODY l9, child: BODY tip, type: fixed}
        """,
    )
    text = tool.read_text().replace(
        "joints: [JOINT l4-tip]", "joints: [JOINT l4-tip, JOINT nowhere]"
    )
    tool.write_text(text)
    sim = ambfplus.Simulator.from_launch(
        launch_path(fixtures), models=[10], extra=[tool], strict=True
    )
    joint = sim.get("l4-tip")
    assert joint.parent.name == "l4" and joint.parent.model.name == "parallel_structure"
    warned = [w[1] for w in sim.load_report.warnings if "nowhere" in w[1]]
    assert len(warned) == 1 and "joint left out: no body 'BODY l9'" in warned[0]
    assert "nowhere" not in sim.world


def test_namespaces(fixtures, tmp_path):
    model = write(
        tmp_path,
        "ns.yaml",
        """
        namespace: robot/
        bodies: [BODY a, BODY b]
        BODY a: {name: a, mass: 0, shape: BOX, geometry: {x: 1, y: 1, z: 1}}
        BODY b: {name: b, namespace: /other/, mass: 0, shape: BOX, geometry: {x: 1, y: 1, z: 1}}
        """,
    )
    world = ambfplus.World()
    world.load_adf(model)
    assert world.get("a").qualified_name == "/ambf/env/robot/a"
    assert world.get("b").qualified_name == "/other/b"
    sim = ambfplus.Simulator.from_launch(
        launch_path(fixtures), models=[], extra=[model], namespace_prefix="/lab"
    )
    assert sim.get("a").qualified_name == "/lab/ambf/env/robot/a"
    assert sim.get("b").qualified_name == "/lab/other/b"
    assert math.isclose(sim.world.gravity[2], -9.81, rel_tol=1e-6)


def test_launch_command(fixtures, capsys):
    from ambfplus.cli import main

    assert main(["launch", str(launch_path(fixtures)), "-l", "10, 12", "--steps", "10"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert out["models"] == ["checkered_floor", "parallel_structure", "puzzle2"]
    assert out["objects"]["joint"] == 14 and out["time"] == pytest.approx(0.01)
    assert main(["launch", str(launch_path(fixtures)), "-l", "0,10", "--steps", "0"]) == 1
    out = json.loads(capsys.readouterr().out)
    assert out["models"] == ["checkered_floor", "parallel_structure"]
    assert "blender-toy-car.yaml" in out["errors"][0]


def test_loaded_models_render(fixtures):
    # The parallel structure's `world` body has no geometry (mesh: ''): drawn as nothing.
    sim = ambfplus.Simulator.from_launch(launch_path(fixtures), models=[10], strict=True)
    world = sim.world
    assert world.get("world").shape == "none"
    camera = world.get("default_camera")
    frame = camera.capture()
    assert frame.rgb.shape == (480, 640, 3)
    hit = frame.depth > 0
    assert 0.2 < hit.mean() < 1.0  # floor and links in view, sky above
    # Back-projected, the pixels reach from the floor (z = -1.5) up the links (to z > -1).
    heights = backproject(frame)[:, 2]
    assert heights.min() == pytest.approx(world.get("Plane").pose[2, 3], abs=0.01)
    assert heights.max() > -1.0


def test_enclosure_when_no_environment(fixtures, tmp_path):
    world_file = write(
        tmp_path, "world.yaml", "enclosure: {length: 2.0, width: 3.0, height: 2.0}\n"
    )
    ball = write(
        tmp_path,
        "ball.yaml",
        """
        bodies: [BODY ball]
        BODY ball: {name: ball, mass: 0.1, shape: SPHERE, geometry: {radius: 0.05},
                    location: {position: {x: 0.9, y: 0, z: 0}}, restitution: 0}
        """,
    )
    colors = fixtures / DESCRIPTIONS / "color" / "colors.yaml"
    launch = small_launch(tmp_path, fixtures, str(world_file), str(colors))
    sim = ambfplus.Simulator.from_launch(launch, models=[], extra=[ball], strict=True)
    assert [m.name for m in sim.load_report.models] == ["enclosure", "ball"]
    sim.get("ball").linear_velocity = (1.0, 0.0, 0.0)  # into the wall at x = 1
    sim.step(1500)
    p = sim.get("ball").pose[:3, 3]
    assert p[2] == pytest.approx(-1.0 + 0.05, abs=2e-3)  # on the floor, height / 2 down
    assert p[0] < 1.0 - 0.05 + 2e-3  # not through the wall


@pytest.mark.slow
def test_drilling_fixture_cameras_ride_on_the_main_camera(fixtures):
    # The original drilling scene: its stereo pair and its headlight are children of a camera,
    # placed in that camera's AMBF frame (x back from the view, y right, z up).
    launch = fixtures / "volumetric_drilling" / "launch.yaml"
    sim = ambfplus.Simulator.from_launch(launch, models=[0, 2, 5])
    # Only the launch file's plugin (the original's drilling plugin binary) may be missing.
    assert all("libvolumetric_drilling" in e[1] for e in sim.load_report.errors)
    assert [m.name for m in sim.load_report.models][-3:] == [
        "drills",
        "volume_256",
        "stereo_cameras",
    ]
    assert not [w for w in sim.load_report.warnings if "not found" in w[1] and "parent" in w[1]]
    main, left, right = (sim.get(n) for n in ("main_camera", "stereoL", "stereoR"))
    assert left.attached_to.name == "main_camera" and right.attached_to.name == "main_camera"
    assert left.pose == pytest.approx(main.pose)
    right_in_left = np.linalg.inv(left.pose) @ right.pose
    assert right_in_left[:3, :3] == pytest.approx(np.eye(3))
    assert right_in_left[:3, 3] == pytest.approx([0.025, 0, 0])  # 25 mm to the right
    light = sim.get("light1")
    assert light.pose[:3, 3] == pytest.approx(main.pose[:3, :3] @ [0, -0.025, 0])  # 25 mm up
    assert light.direction == pytest.approx(main.pose[:3, 2])  # along the view
    sim.get("main_camera").look_at((0.1, 0.2, 0.3), (0, 0, 0))
    sim.step(1)
    assert np.linalg.inv(sim.get("stereoL").pose) @ sim.get("stereoR").pose == pytest.approx(
        right_in_left
    )
