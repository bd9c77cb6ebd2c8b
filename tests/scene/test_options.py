"""Keyword options: one table per spec in C++, shared by Python's add_* methods, the ADF loader
and plugins; kinds are enums that also take their names; every spec checks its values."""

from __future__ import annotations

import math

import pytest

import ambfplus


def test_kinds_are_enums_that_also_take_their_names():
    assert ambfplus.ShapeKind("Sphere") == ambfplus.ShapeKind.sphere
    assert ambfplus.JointType("six dof") == ambfplus.JointType.six_dof
    assert ambfplus.MeshCollision("CONVEX_HULL") == ambfplus.MeshCollision.convex_hull
    with pytest.raises(ambfplus.ArgumentError, match="unknown shape 'pyramid'.*sphere"):
        ambfplus.ShapeKind("pyramid")
    world = ambfplus.World()
    by_member = world.add_body("a", ambfplus.ShapeKind.sphere, radius=0.1)
    by_name = world.add_body("b", "sphere", radius=0.1)
    assert by_member.shape == by_name.shape == "sphere"
    joint = world.add_joint("j", by_member, by_name, ambfplus.JointType.prismatic)
    assert joint.type == "prismatic"
    light = world.add_light("l", ambfplus.LightType.spot)
    assert world.add_light("m", "spot").type == light.type
    body = world.add_body("c", "box", size=(1, 1, 1), collision_type=ambfplus.MeshCollision.concave)
    assert body.shape == "box"
    with pytest.raises(ambfplus.ArgumentTypeError, match="'shape' must be text, got the integer 3"):
        world.add_body("d", 3, radius=0.1)


def test_an_unknown_keyword_names_itself_and_the_known_ones():
    world = ambfplus.World()
    with pytest.raises(ambfplus.ArgumentTypeError) as info:
        world.add_body("b", "sphere", radius=0.1, frition=0.5)
    message = str(info.value)
    assert "'frition'" in message and "friction" in message and "restitution" in message
    assert isinstance(info.value, TypeError) and isinstance(info.value, ambfplus.ArgumentError)
    assert len(world) == 0
    volume = world.add_volume("v", ambfplus.phantom(16, 0))
    with pytest.raises(TypeError, match="'burr_size'.*burr_diameters"):
        world.add_drill("d", volume, burr_size=0.004)
    with pytest.raises(ambfplus.ArgumentTypeError, match="friction takes static and dynamic"):
        world.add_drill("d", volume, friction={"kinetic": 0.1})


@pytest.mark.parametrize(
    ("adder", "kwargs", "message"),
    [
        ("body", {"shape": "sphere", "radius": math.nan}, "body 'x': radius must be > 0, got nan"),
        ("body", {"shape": "sphere", "radius": 0.1, "friction": -1.0}, "friction must be >= 0"),
        ("body", {"shape": "plane", "mass": 1.0}, "plane is infinite"),
        ("camera", {"fov_y": math.pi}, "camera 'x': fov_y"),
        ("camera", {"width": 0}, "camera 'x': width and height"),
        ("camera", {"far": math.inf}, "camera 'x'"),
        ("light", {"intensity": -1.0}, "light 'x'"),
        ("light", {"direction": (0, 0, 0)}, "light 'x'"),
        ("drill", {"burr_diameters": [0.004, -0.001]}, "drill 'x': burr diameters must be > 0"),
        ("drill", {"burr": 7}, "drill 'x': burr index"),
        ("drill", {"cursors": 0}, "drill 'x': cursors must be 1..16"),
        ("drill", {"stiffness": math.inf}, "drill 'x': stiffness"),
        ("drill", {"removal": "melting"}, "removal must be physical or compatible"),
        ("volume", {"iso": 1.5}, "volume 'x'"),
        ("sensor", {"range": -0.1}, "sensor 'x': range must be > 0"),
        ("sensor", {"direction": (0, 0, 0)}, "sensor 'x': ray 0"),
        ("actuator", {"tau": 2.0}, "actuator 'x'"),
        ("joint", {"damping": -1.0}, "joint 'x': damping"),
        ("joint", {"parent_axis": (0, 0, 0)}, "joint 'x': axes"),
        ("joint", {"controller": {"p": math.nan}}, "joint 'x': controller gains"),
    ],
)
def test_specs_refuse_values_naming_the_object_and_the_value(adder, kwargs, message):
    world = ambfplus.World()
    parent = world.add_body("parent", "sphere", radius=0.1)
    child = world.add_body("child", "sphere", radius=0.1)
    volume = world.add_volume("volume", ambfplus.phantom(16, 0))
    before = len(world)
    add = {
        "body": lambda: world.add_body("x", **kwargs),
        "camera": lambda: world.add_camera("x", **kwargs),
        "light": lambda: world.add_light("x", **kwargs),
        "drill": lambda: world.add_drill("x", volume, **kwargs),
        "volume": lambda: world.add_volume("x", ambfplus.phantom(16, 0), **kwargs),
        "sensor": lambda: world.add_sensor("x", parent, **kwargs),
        "actuator": lambda: world.add_actuator("x", parent, **kwargs),
        "joint": lambda: world.add_joint("x", parent, child, **kwargs),
    }[adder]
    with pytest.raises(ambfplus.ArgumentError, match=message):
        add()
    assert len(world) == before, "a refused spec leaves nothing behind"


def test_drill_removal_takes_the_enum_or_its_name():
    world = ambfplus.World()
    volume = world.add_volume("v", ambfplus.phantom(16, 0))
    drill = world.add_drill("d", volume, removal=ambfplus.RemovalMode.compatible)
    assert drill.removal == "compatible"
    drill.removal = "physical"
    assert drill.removal == "physical"
    drill.removal = ambfplus.RemovalMode.compatible
    assert drill.removal == "compatible"
    with pytest.raises(ambfplus.ArgumentError, match="physical or compatible"):
        drill.removal = "melting"
