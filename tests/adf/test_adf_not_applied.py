"""Keys AMBF reads that ambfplus does not apply are named in one warning per key and file,
with the blocks that have them; a file without them gets no such warning."""

from __future__ import annotations

import pytest

import ambfplus

JOINT = """
JOINT ab:
  name: ab
  parent: BODY a
  child: BODY b
  type: revolute
  parent axis: {x: 0, y: 0, z: 1}
  child axis: {x: 0, y: 0, z: 1}
"""


def body(name: str, extra: str) -> str:
    text = f"""
BODY {name}:
  name: {name}
  mass: 1.0
  shape: box
  geometry: {{x: 0.1, y: 0.1, z: 0.1}}
"""
    return text + "".join(f"  {line}\n" for line in extra.splitlines())


def load(tmp_path, caplog, body_extra: dict[str, str], joint_extra: str = ""):
    text = "bodies: [BODY a, BODY b, BODY c, BODY d, BODY e]\njoints: [JOINT ab]\n"
    text += "".join(body(n, body_extra.get(n, "")) for n in "abcde")
    text += JOINT + (f"  {joint_extra}\n" if joint_extra else "")
    path = tmp_path / "model.yaml"
    path.write_text(text)
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(path)
    return world, [r.getMessage() for r in caplog.records]


def test_keys_read_but_not_applied_are_one_warning_each_naming_the_blocks(tmp_path, caplog):
    extra = {n: "use material: false" for n in "abcde"}
    extra["a"] += "\ncontroller: {linear: {P: 10, I: 0, D: 1}}"
    world, warnings = load(tmp_path, caplog, extra, joint_extra="enable feedback: true")
    assert len([b for b in "abcde" if world.get(b)]) == 5, "the file still loads whole"
    material = [w for w in warnings if "'use material'" in w]
    assert len(material) == 1, warnings
    assert "BODY a, BODY b, BODY c and 2 more" in material[0] and "not applied" in material[0]
    controller = [w for w in warnings if "'controller'" in w]
    assert len(controller) == 1 and "BODY a is read" in controller[0], warnings
    feedback = [w for w in warnings if "'enable feedback'" in w]
    assert len(feedback) == 1 and "JOINT ab" in feedback[0], warnings


def test_a_file_without_such_keys_has_no_such_warning(tmp_path, caplog):
    _, warnings = load(tmp_path, caplog, {})
    assert not [w for w in warnings if "not applied" in w], warnings


def warnings_of(tmp_path, caplog, text: str, name: str = "model.yaml", how: str = "load_adf"):
    """The warnings loading text (written as tmp_path/name) logs, the world and the path."""
    path = tmp_path / name
    path.write_text(text)
    world = ambfplus.World()
    caplog.clear()
    with caplog.at_level("WARNING"):
        if how == "input devices":
            ambfplus.read_input_devices(path)
        else:
            getattr(world, how)(path)
    return [r.getMessage() for r in caplog.records], world, path


def one_naming(warnings: list[str], path, key: str, *words: str) -> str:
    """The one warning about key: it names the file, a line, the key and every word."""
    about = [w for w in warnings if f"'{key}'" in w]
    assert len(about) == 1, (key, warnings)
    for word in (str(path), "line ", *words):
        assert word in about[0], (word, about[0])
    return about[0]


CAMERA = """
cameras: [CAMERA main, CAMERA side]
lights: [LIGHT lamp]
CAMERA main:
  name: main
  location: {x: 1, y: 0, z: 0}
  look at: {x: 0, y: 0, z: 0}
  publish depth resolution: {width: 320, height: 240}
  monitor: 1
  controlling devices: [MTMR]
  multipass: true
  visible: false
  mouse control multipliers: {pan: 2}
  orthographic view width: 2.0
  depth compute shaders: {path: shaders, vertex: d.vs, fragment: d.fs}
CAMERA side:
  name: side
  location: {x: 0, y: 1, z: 0}
  look at: {x: 0, y: 0, z: 0}
  multipass: false
LIGHT lamp:
  name: lamp
  location: {x: 0, y: 0, z: 2}
  direction: {x: 0, y: 0, z: -1}
  shadow quality: 5
"""


def test_camera_and_light_keys_not_applied_are_named_with_file_line_and_blocks(tmp_path, caplog):
    warnings, world, path = warnings_of(tmp_path, caplog, CAMERA)
    assert world.get("main") and world.get("side") and world.get("lamp"), "the file loads whole"
    for key in ("publish depth resolution", "monitor", "controlling devices", "visible"):
        one_naming(warnings, path, key, "CAMERA main", "not applied")
    one_naming(warnings, path, "mouse control multipliers", "CAMERA main", "not applied")
    one_naming(warnings, path, "multipass", "CAMERA main, CAMERA side", "not applied")
    # Applied since shadows are drawn: the light keeps it, nothing warns.
    assert not [w for w in warnings if "shadow quality" in w], warnings
    assert world.get("lamp").shadow_quality == 5
    one_naming(warnings, path, "orthographic view width", "CAMERA main", "not applied")
    one_naming(warnings, path, "depth compute shaders", "CAMERA main", "ignored")
    assert not [w for w in warnings if "unknown key" in w], warnings


def test_world_file_cameras_and_skybox_are_warned_about(tmp_path, caplog):
    text = CAMERA + "skybox: {path: sky, right: r.png, left: l.png, top: t.png, bottom: b.png,"
    text += " front: f.png, back: k.png}\n"
    warnings, world, path = warnings_of(tmp_path, caplog, text, "world.yaml", "load_world_file")
    assert world.get("main"), "the world's cameras load"
    one_naming(warnings, path, "skybox", "not applied")
    one_naming(warnings, path, "monitor", "CAMERA main", "not applied")


def test_joint_enable_motor_is_named_once_for_the_file(tmp_path, caplog):
    text = "bodies: [BODY a, BODY b]\njoints: [JOINT ab]\n" + body("a", "") + body("b", "")
    text += JOINT + "  enable motor: true\n"
    warnings, world, path = warnings_of(tmp_path, caplog, text)
    assert world.get("ab"), "the joint is made"
    one_naming(warnings, path, "enable motor", "JOINT ab", "not applied")


@pytest.mark.parametrize("value", ["POSITION", "position", "TORQUE"])
def test_joint_controller_output_position_or_unknown_drives_efforts_with_a_warning(
    tmp_path, caplog, value
):
    text = "bodies: [BODY a, BODY b]\njoints: [JOINT ab]\n" + body("a", "") + body("b", "")
    text += JOINT + f"  controller output type: {value}\n"
    warnings, world, path = warnings_of(tmp_path, caplog, text)
    assert world.get("ab").controller["output"] == "effort", "AMBF's fallback: FORCE"
    message = one_naming(warnings, path, "controller output type", "JOINT ab", value, "FORCE")
    line = text.splitlines().index(f"  controller output type: {value}") + 1
    assert f"line {line}:" in message, message


def test_body_mesh_remove_duplicates_is_named_and_ros_keys_are_silent(tmp_path, caplog):
    ros = "publish children names: true\npublish joint names: true\npublish joint positions: true"
    extra = {"a": "mesh remove duplicates: false\n" + ros, "b": ros}
    text = "bodies: [BODY a, BODY b]\n" + "".join(body(n, extra[n]) for n in "ab")
    warnings, _, path = warnings_of(tmp_path, caplog, text)
    one_naming(warnings, path, "mesh remove duplicates", "BODY a", "not applied")
    assert not [w for w in warnings if "publish" in w], "ROS keys are read without a warning"


TETRA = "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"


def test_soft_body_keys_not_applied_are_named(tmp_path, caplog):
    (tmp_path / "tetra.obj").write_text(TETRA)
    text = """
soft bodies: [SOFTBODY s]
SOFTBODY s:
  name: s
  mesh: tetra.obj
  mass: 0.1
  linear gain: {P: 1, I: 0, D: 0}
  angular gain: {P: 1, I: 0, D: 0}
  inertial offset: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}
  collision groups: [1]
  gravity: {x: 0, y: 0, z: 0}
"""
    warnings, world, path = warnings_of(tmp_path, caplog, text)
    assert world.get("s"), "the soft body is made"
    for key in ("linear gain", "angular gain", "inertial offset", "collision groups", "gravity"):
        one_naming(warnings, path, key, "SOFTBODY s", "not applied")


def test_input_device_keys_not_applied_are_named(tmp_path, caplog):
    text = """
input devices: [MTMR, Touch]
MTMR:
  hardware name: MTMR
  controller gain: {linear: {P: 1, D: 0}}
  visible color: red
Touch:
  hardware name: PHANTOM Omni
  visible color: blue
"""
    warnings, _, path = warnings_of(tmp_path, caplog, text, "devices.yaml", "input devices")
    one_naming(warnings, path, "controller gain", "MTMR", "not applied")
    one_naming(warnings, path, "visible color", "MTMR, Touch", "not applied")


def test_top_level_mappings_no_list_names_are_unknown_keys(tmp_path, caplog):
    text = "bodies: [BODY a]\n" + body("a", "") + body("z", "")
    text += "defaults: {mass: 2}\nlimits: 3\n"
    warnings, world, path = warnings_of(tmp_path, caplog, text)
    assert "a" in world and "z" not in world, "a block no list names is not made"
    for key in ("BODY z", "defaults"):
        one_naming(warnings, path, key, "unknown key", "none of bodies")
    one_naming(warnings, path, "limits", "unknown key")
    assert not [w for w in warnings if "'BODY a'" in w], warnings


def test_world_file_top_level_mappings_no_list_names_are_unknown_keys(tmp_path, caplog):
    text = CAMERA + "CAMERA spare: {name: spare}\nenclosure: {length: 2, width: 2, height: 2}\n"
    warnings, _, path = warnings_of(tmp_path, caplog, text, "world.yaml", "load_world_file")
    one_naming(warnings, path, "CAMERA spare", "unknown key", "none of lights, cameras")
    assert not [w for w in warnings if "'enclosure'" in w or "'CAMERA main'" in w], warnings
