"""Bad scenes, one small case each: numbers that would turn a scene into NaN, contradictions
(duplicate names, parent cycles, a camera looking at itself) and YAML shapes the loader did not
expect. A bad ADF file is a ConfigError naming the file, the line and the key, and leaves nothing
of the model behind; a bad Python call is an ArgumentError naming the object and the keyword."""

from __future__ import annotations

import logging
import math
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus

BODY_A = "BODY a: {name: a, mass: 1, shape: SPHERE, geometry: {radius: 0.1}}"
BODY_B = "BODY b: {name: b, mass: 1, shape: SPHERE, geometry: {radius: 0.1}}"


def write(tmp_path: Path, text: str, name: str = "model.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def refused(tmp_path: Path, text: str, *words: str) -> str:
    """Loading text is a ConfigError naming the file, a line and every word; nothing stays."""
    path = write(tmp_path, text)
    world = ambfplus.World()
    with pytest.raises(ambfplus.ConfigError) as info:
        world.load_adf(path)
    message = str(info.value)
    assert str(path) in message and "line " in message, message
    for word in words:
        assert word in message, message
    assert world.objects == [] and [m.name for m in world.models] == ["World"]
    return message


def indented(keys: str) -> str:
    """keys (lines joined by newlines) indented as a block's keys in the texts below."""
    return keys.replace("\n", "\n" + " " * 10)


def jointed(joint_keys: str) -> str:
    joint_keys = indented(joint_keys)
    return f"""\
        bodies: [BODY a, BODY b]
        joints: [JOINT a-b]
        {BODY_A}
        {BODY_B}
        JOINT a-b:
          name: a-b
          parent: BODY a
          child: BODY b
          type: revolute
          {joint_keys}
        """


# Numbers that would turn a scene into NaN ----------------------------------------------------


@pytest.mark.parametrize("value", [".nan", "nan", ".inf", "-.inf"])
@pytest.mark.parametrize("key", ["joint offset", "offset", "damping"])
def test_non_finite_joint_numbers_are_refused(tmp_path, key, value):
    refused(tmp_path, jointed(f"{key}: {value}"), "JOINT a-b", f"'{key}'")


@pytest.mark.parametrize(
    ("location", "key"),
    [("{position: {x: 1e300, y: 0, z: 0}}", "location.position.x"),
     ("{position: {x: 0, y: .nan, z: 0}}", "location.position.y"),
     ("{position: {x: 0, y: 0, z: -2e6}}", "location.position.z"),
     ("{orientation: {r: .inf, p: 0, y: 0}}", "location.orientation.r")],
)  # fmt: skip
def test_body_positions_must_be_finite_and_within_a_bound(tmp_path, location, key):
    text = f"""\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 1
          shape: SPHERE
          geometry: {{radius: 0.1}}
          location: {location}
        """
    refused(tmp_path, text, "BODY a", f"'{key}'")


def test_python_pose_beyond_the_bound_is_refused():
    world = ambfplus.World()
    with pytest.raises(ambfplus.ArgumentError, match=r"body 'a'.*1e\+06 m"):
        world.add_body("a", "sphere", radius=0.1, pose=ambfplus.make_pose((1e300, 0, 0)))
    assert len(world) == 0


def with_pose_setter(world: ambfplus.World, kind: str):
    """An object of each kind whose pose Python may set, placed at (1, 2, 3)."""
    if kind == "body":
        return world.add_body("a", "sphere", radius=0.1, pose=ambfplus.make_pose((1, 2, 3)))
    if kind == "camera":
        return world.add_camera("a", pose=ambfplus.make_pose((1, 2, 3)))
    light = world.add_light("a", "point", position=(1, 2, 3))
    light.pose = ambfplus.make_pose((1, 2, 3))
    return light


@pytest.mark.parametrize("kind", ["body", "camera", "light"])
@pytest.mark.parametrize(
    ("position", "words"),
    [((1e300, 0, 0), "1e+06 m"), ((0, -2e6, 0), "1e+06 m"), ((0, 0, math.inf), "non-finite")],
)
def test_pose_setter_is_bounded_and_names_the_object(kind, position, words):
    world = ambfplus.World()
    thing = with_pose_setter(world, kind)
    pose = np.eye(4)
    pose[:3, 3] = position
    with pytest.raises(ambfplus.ArgumentError) as info:
        thing.pose = pose
    message = str(info.value)
    assert message.startswith(f"{kind} 'a': ") and words in message, message
    assert np.allclose(thing.pose[:3, 3], (1, 2, 3))
    world.step(2)
    assert np.isfinite(thing.pose).all()


def test_pose_setter_accepts_the_bound_itself():
    world = ambfplus.World()
    body = with_pose_setter(world, "body")
    body.pose = ambfplus.make_pose((1e6, -1e6, 0))
    assert body.pose[:3, 3].tolist() == [1e6, -1e6, 0]


@pytest.mark.parametrize("kind", ["camera", "light"])
def test_python_camera_or_light_position_beyond_the_bound_is_refused(kind):
    world = ambfplus.World()
    with pytest.raises(ambfplus.ArgumentError, match=rf"{kind} 'a'.*1e\+06 m"):
        if kind == "camera":
            world.add_camera("a", pose=ambfplus.make_pose((0, 0, 3e6)))
        else:
            world.add_light("a", "point", position=(0, 0, 3e6))
    assert len(world) == 0


@pytest.mark.parametrize("gains", ["{P: .nan, I: 0, D: 1}", "{P: -10, I: 0, D: 1}"])
def test_controller_gains_must_be_finite_and_non_negative_in_a_file(tmp_path, gains):
    refused(tmp_path, jointed(f"controller: {gains}"), "JOINT a-b", "controller")


@pytest.mark.parametrize("p", [math.nan, -10.0, math.inf])
def test_controller_gains_must_be_finite_and_non_negative_in_python(p):
    world = ambfplus.World()
    a = world.add_body("a", "sphere", radius=0.1)
    b = world.add_body("b", "sphere", radius=0.1)
    with pytest.raises(ambfplus.ArgumentError, match="joint 'j': controller gains"):
        world.add_joint("j", a, b, controller={"p": p, "i": 0.0, "d": 1.0})
    assert len(world) == 2
    joint = world.add_joint("j", a, b)
    with pytest.raises(ambfplus.ArgumentError, match="controller gains"):
        joint.controller = {"p": p}


def camera_file(keys: str) -> str:
    keys = indented(keys)
    return f"""\
        cameras: [CAM c]
        CAM c:
          name: c
          location: {{x: 1, y: 0, z: 0}}
          {keys}
        """


@pytest.mark.parametrize(
    "resolution", ["{width: 640.5, height: 480}", "{width: 640, height: wide}"]
)
def test_camera_resolution_must_be_whole_pixels(tmp_path, resolution):
    text = camera_file(f"look at: {{x: 0, y: 0, z: 0}}\npublish image resolution: {resolution}")
    refused(tmp_path, text, "CAM c", "publish image resolution.", "integer")


@pytest.mark.parametrize("angle", ["3.1416", "0", "-0.5", "4"])
def test_camera_field_view_angle_outside_0_pi_is_refused_where_read(tmp_path, angle):
    text = camera_file(f"look at: {{x: 0, y: 0, z: 0}}\nfield view angle: {angle}")
    message = refused(tmp_path, text, "CAM c", "'field view angle'", "(0, pi)")
    assert "line 6:" in message, message


@pytest.mark.parametrize("planes", ["{near: 0, far: 10}", "{near: 2, far: 1}", "{near: -1}"])
def test_camera_clipping_planes_out_of_order_are_refused_where_read(tmp_path, planes):
    text = camera_file(f"look at: {{x: 0, y: 0, z: 0}}\nclipping plane: {planes}")
    message = refused(tmp_path, text, "CAM c", "'clipping plane'", "0 < near < far")
    assert "line 6:" in message, message


def test_camera_looking_at_its_own_location_is_refused(tmp_path):
    text = camera_file("look at: {x: 1, y: 0, z: 0}")
    refused(tmp_path, text, "CAM c", "'look at'", "'location'")


def test_python_look_at_its_own_eye_is_refused():
    camera = ambfplus.World().add_camera("c")
    before = camera.pose.copy()
    with pytest.raises(ambfplus.ArgumentError, match="camera 'c': look_at"):
        camera.look_at((1, 0, 0), (1, 0, 0))
    with pytest.raises(ambfplus.ArgumentError, match="camera 'c': look_at"):
        camera.look_at((0, 0, 0), (0, 0, 1), up=(0, 0, 1))  # up along the view
    with pytest.raises(ambfplus.ArgumentError, match="camera 'c': look_at"):
        camera.look_at((math.nan, 0, 0), (0, 0, 1))
    np.testing.assert_array_equal(camera.pose, before)


@pytest.mark.parametrize("group", [-1, 32, 100000])
def test_collision_groups_out_of_range_warn_naming_the_key_as_ambf_does(tmp_path, caplog, group):
    # AMBF ignores a group number outside its range with a warning, so a file still loads; the
    # warning names the file, line, block and key.
    path = write(
        tmp_path,
        f"""\
        bodies: [BODY a]
        BODY a: {{name: a, mass: 1, shape: SPHERE, geometry: {{radius: 0.1}},
                 collision groups: [0, {group}]}}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    warned = [r.getMessage() for r in caplog.records if "collision groups" in r.getMessage()]
    assert len(warned) == 1 and str(path) in warned[0] and "BODY a" in warned[0], warned
    assert f"{group} ignored" in warned[0]
    with pytest.raises(ambfplus.ArgumentError, match="collision groups are 0..31"):
        world.add_body("b", "sphere", radius=0.1, groups=[group])


@pytest.mark.parametrize(
    ("keys", "key"),
    [("collision shape: BOX\ncollision geometry: {x: -1, y: 1, z: 1}", "geometry.x"),
     ("collision shape: SPHERE\ncollision geometry: {radius: -0.1}", "geometry.radius"),
     ("collision shape: CYLINDER\ncollision geometry: {radius: 0.1, height: .nan}",
      "geometry.height"),
     ("shape: BOX\ngeometry: {x: 1, y: 0, z: 1}", "geometry.y")],
)  # fmt: skip
def test_negative_or_zero_geometry_sizes_are_refused(tmp_path, keys, key):
    keys = indented(keys)
    text = f"""\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 1
          {keys}
        """
    refused(tmp_path, text, "BODY a", key)


@pytest.mark.parametrize("size", ["length: -4", "width: 0", "height: .nan"])
def test_enclosure_sizes_must_be_positive(tmp_path, size):
    world_file = write(tmp_path, f"enclosure: {{{size}}}\n", "world.yaml")
    launch = write(
        tmp_path,
        f"""\
        world config: {world_file}
        color config: {tmp_path / "none.yaml"}
        input devices config: {tmp_path / "none.yaml"}
        multibody configs: []
        """,
        "launch.yaml",
    )
    with pytest.raises(ambfplus.ConfigError, match="enclosure") as info:
        ambfplus.Simulator.from_launch(launch)
    assert "world.yaml" in str(info.value) and size.split(":")[0] in str(info.value)


def test_make_pose_refuses_non_finite_values():
    for position in [(math.nan, 0, 0), (0, math.inf, 0)]:
        with pytest.raises(ambfplus.ArgumentError, match="make_pose: position"):
            ambfplus.make_pose(position)
    with pytest.raises(ambfplus.ArgumentError, match="make_pose: rpy"):
        ambfplus.make_pose(rpy=(0, math.nan, 0))
    with pytest.raises(ambfplus.ArgumentError, match="make_pose: rotation"):
        ambfplus.make_pose(rotation=np.diag([1.0, 1.0, 2.0]))
    assert ambfplus.make_pose((1, 2, 3))[:3, 3].tolist() == [1, 2, 3]


# Contradictions -------------------------------------------------------------------------------


def test_two_cameras_of_one_name_warn_naming_both_blocks(tmp_path, caplog):
    # AMBF suffixes a repeated name (its rule for duplicate loads); the warning says so.
    path = write(
        tmp_path,
        """\
        cameras: [CAM one, CAM two]
        CAM one: {name: stereoL, location: {x: 1, y: 0, z: 0}, look at: {x: 0, y: 0, z: 0}}
        CAM two: {name: stereoL, location: {x: 2, y: 0, z: 0}, look at: {x: 0, y: 0, z: 0}}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    warned = [r.getMessage() for r in caplog.records if "stereoL" in r.getMessage()]
    assert len(warned) == 1, warned
    assert "CAM one" in warned[0] and "CAM two" in warned[0] and "renamed" in warned[0]
    assert str(path) in warned[0], warned
    assert {"stereoL", "stereoL1"} <= {o.name for o in world.objects}


def test_two_bodies_or_joints_of_one_name_warn_naming_both_blocks(tmp_path, caplog):
    path = write(
        tmp_path,
        f"""\
        bodies: [BODY a, BODY b]
        joints: [JOINT one, JOINT two]
        {BODY_A}
        BODY b: {{name: a, mass: 1, shape: SPHERE, geometry: {{radius: 0.1}}}}
        JOINT one: {{name: j, parent: BODY a, child: BODY b, type: revolute}}
        JOINT two: {{name: j, parent: BODY a, child: BODY b, type: fixed}}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    messages = [r.getMessage() for r in caplog.records if str(path) in r.getMessage()]
    assert any("BODY a" in m and "BODY b" in m and "renamed" in m for m in messages), messages
    assert any("JOINT one" in m and "JOINT two" in m and "renamed" in m for m in messages), messages
    assert {"a", "a1", "j", "j1"} <= {o.name for o in world.objects}


def test_a_block_listed_twice_is_made_once_with_a_warning(tmp_path, caplog):
    # The same block named twice is one block (issue #34); test_silent_cases checks the lines.
    path = write(tmp_path, f"bodies: [BODY a, BODY a]\n{BODY_A}\n")
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    assert [o.name for o in world.objects] == ["a"]
    warned = [r.getMessage() for r in caplog.records if "again" in r.getMessage()]
    assert len(warned) == 1 and str(path) in warned[0] and "'BODY a'" in warned[0], warned


def test_a_camera_cycle_is_refused_naming_the_cycle(tmp_path):
    text = """\
        cameras: [CAM A, CAM B]
        CAM A: {name: A, parent: CAM B, location: {x: 1, y: 0, z: 0}, look at: {x: 0, y: 0, z: 0}}
        CAM B: {name: B, parent: CAM A, location: {x: 2, y: 0, z: 0}, look at: {x: 0, y: 0, z: 0}}
        """
    refused(tmp_path, text, "cycle", "A -> B -> A")


def test_a_light_camera_light_cycle_is_refused(tmp_path):
    text = """\
        cameras: [CAM c]
        lights: [LIGHT l]
        CAM c: {name: c, parent: LIGHT l, location: {x: 1, y: 0, z: 0}, look at: {x: 0, y: 0, z: 0}}
        LIGHT l: {name: l, parent: CAM c, location: {x: 0, y: 0, z: 1}}
        """
    refused(tmp_path, text, "cycle", "c -> l -> c")


def test_python_attach_to_refuses_a_cycle_naming_it():
    world = ambfplus.World()
    a, b, c = (world.add_camera(n) for n in "abc")
    b.attach_to(a)
    c.attach_to(b)
    with pytest.raises(ambfplus.ArgumentError, match=r"a -> c -> b -> a"):
        a.attach_to(c)
    with pytest.raises(ambfplus.ArgumentError, match=r"a -> a"):
        a.attach_to(a)
    assert a.attached_to is None


# YAML shapes the loader did not expect --------------------------------------------------------


@pytest.mark.parametrize(
    ("keys", "key"),
    [("color rgba: red", "color rgba"), ("friction: slippery", "friction"),
     ("damping: 3", "damping"), ("location: {position: 3}", "location.position"),
     ("inertia: heavy", "inertia")],
)  # fmt: skip
def test_a_scalar_where_a_mapping_belongs_names_the_key_body(tmp_path, keys, key):
    text = f"""\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 1
          shape: SPHERE
          geometry: {{radius: 0.1}}
          {keys}
        """
    refused(tmp_path, text, "BODY a", f"'{key}'", "mapping")


@pytest.mark.parametrize(
    ("keys", "key"),
    [("joint limits: wide", "joint limits"), ("controller: stiff", "controller")],
)
def test_a_scalar_where_a_mapping_belongs_names_the_key_joint(tmp_path, keys, key):
    refused(tmp_path, jointed(keys), "JOINT a-b", f"'{key}'")


@pytest.mark.parametrize(
    ("keys", "key"),
    [("clipping plane: near", "clipping plane"), ("publish image resolution: 640",
      "publish image resolution"), ("stereo: yes", "stereo"), ("publish depth noise: 1",
      "publish depth noise")],
)  # fmt: skip
def test_a_scalar_where_a_mapping_belongs_names_the_key_camera(tmp_path, keys, key):
    refused(tmp_path, camera_file(keys), "CAM c", f"'{key}'", "mapping")


# Device callbacks -----------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("result", "words"),
    [("abc", "a dict"), (("abc",), "position"), ({"position": "abc"}, "position"),
     ({"position": (0, 0, 0), "orientation": "up"}, "orientation"),
     ({"position": (0, 0, 0), "buttons": "all"}, "buttons")],
)  # fmt: skip
def test_a_device_callback_returning_text_is_a_typed_error_naming_it(result, words):
    world = ambfplus.World()
    drill = world.add_drill("drill", world.add_volume("v", ambfplus.phantom(16, 0)))
    device = ambfplus.ScriptedDevice()

    def wobbly_hand(t):
        return result

    device.set_callback(wobbly_hand, every=1)
    world.add_input_device("hand", device, drill)
    with pytest.raises(ambfplus.ArgumentTypeError) as info:
        world.step(1)
    message = str(info.value)
    assert "wobbly_hand" in message and words in message, message
