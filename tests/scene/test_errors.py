"""Bad input gets a typed error that names the file, the key or the value, and what was expected."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus


def test_error_hierarchy():
    assert issubclass(ambfplus.ConfigError, ValueError)
    assert issubclass(ambfplus.AssetNotFound, FileNotFoundError)
    assert issubclass(ambfplus.RenderError, RuntimeError)
    assert issubclass(ambfplus.PluginError, RuntimeError)
    assert issubclass(ambfplus.ArgumentError, ValueError)
    assert issubclass(ambfplus.OutOfRange, IndexError)
    assert issubclass(ambfplus.StateError, RuntimeError)
    assert issubclass(ambfplus.ResourceError, OSError)
    for cls in (
        ambfplus.ConfigError,
        ambfplus.AssetNotFound,
        ambfplus.RenderError,
        ambfplus.PluginError,
        ambfplus.ArgumentError,
        ambfplus.OutOfRange,
        ambfplus.StateError,
        ambfplus.ResourceError,
    ):
        assert issubclass(cls, ambfplus.Error)


def test_engine_errors_are_typed_whatever_throws_them(tmp_path):
    world = ambfplus.World()
    with pytest.raises(ambfplus.ArgumentError, match="radius"):
        world.add_body("ball", "sphere", radius=-1.0)
    cube = tmp_path / "cube.obj"
    cube.write_text(
        "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n"
    )
    soft = world.add_soft_body("soft", str(cube))
    with pytest.raises(ambfplus.OutOfRange, match="nodes 0"):
        soft.fix_nodes([1000])
    loop = ambfplus.RealTimeLoop(world)
    loop.start()
    try:
        with pytest.raises(ambfplus.StateError, match="already running"):
            loop.start()
    finally:
        loop.stop()
    # The standard library's own exceptions, thrown deep in a reader, arrive typed too.
    header = (
        "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n"
        "Segment2147483648_LabelValue:=1\n\n"
    )
    path = tmp_path / "big.seg.nrrd"
    path.write_bytes(header.encode() + bytes(8))
    with pytest.raises(ambfplus.Error):
        ambfplus.load_nrrd(path)


def test_missing_mesh_is_asset_not_found_naming_the_path(tmp_path):
    world = ambfplus.World()
    path = tmp_path / "nowhere" / "drill.stl"
    with pytest.raises(ambfplus.AssetNotFound) as info:
        world.add_body("drill", mesh=str(path))
    assert str(path) in str(info.value)
    assert info.value.filename == str(path)
    assert info.value.errno == 2
    assert "drill" not in world, "a failed add must leave nothing behind"


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("garbage.stl", b"solid x\n this is not a facet\nendsolid"),
        ("empty.obj", b""),
        ("lines.obj", b"v 0 0 0\nv 1 0 0\nl 1 2\n"),
        ("bad.ply", b"ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n"),
        ("unknown.xyz123", b"\x00\x01\x02"),
    ],
)
def test_unreadable_mesh_is_config_error_naming_the_file(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    world = ambfplus.World()
    with pytest.raises(ambfplus.ConfigError) as info:
        world.add_body("part", mesh=str(path))
    assert str(path) in str(info.value)
    assert info.value.filename == str(path)
    assert len(world) == 0


def test_directory_instead_of_mesh(tmp_path):
    with pytest.raises(ambfplus.ConfigError, match="not a regular file but a folder"):
        ambfplus.World().add_body("part", mesh=str(tmp_path))


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"shape": "pyramid"}, "unknown shape 'pyramid'"),
        ({"shape": "box"}, "needs size"),
        ({"shape": "sphere", "radius": -1.0}, "radius must be > 0"),
        ({"shape": "sphere", "radius": 0.1, "size": (1, 1, 1)}, "size does not apply"),
        ({"shape": "capsule", "radius": 0.1, "height": 0.1}, "includes its caps"),
        ({"shape": "box", "size": (1, 0, 1)}, "box size must be > 0"),
        ({"shape": "sphere", "radius": 0.1, "mass": -2.0}, "mass must be >= 0"),
        ({"shape": "sphere", "radius": 0.1, "color": (2, 0, 0)}, "0..1"),
        ({"shape": "sphere", "radius": 0.1, "pose": np.diag([2.0, 1, 1, 1])}, "rigid"),
        ({"shape": "sphere", "radius": 0.1, "scale": 2.0}, "scale applies to mesh"),
    ],
)
def test_bad_body_arguments(kwargs, message):
    world = ambfplus.World()
    with pytest.raises(ValueError, match=message):
        world.add_body("b", **kwargs)
    assert len(world) == 0


def test_names_are_unique_within_a_world():
    world = ambfplus.World()
    world.add_body("thing", "sphere", radius=0.1)
    with pytest.raises(ValueError, match="already has a body"):
        world.add_camera("thing")
    with pytest.raises(ValueError, match="needs a name"):
        world.add_body("", "sphere", radius=0.1)
    other = ambfplus.World()
    other.add_camera("thing")  # another world is another namespace


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"width": 0}, "width and height"),
        ({"fov_y": 3.2}, "fov_y"),
        ({"near": 0.0}, "near"),
        ({"near": 2.0, "far": 1.0}, "near < far"),
        ({"background": (1, 1)}, "background"),
    ],
)
def test_bad_camera_arguments(kwargs, message):
    with pytest.raises(ValueError, match=message):
        ambfplus.World().add_camera("cam", **kwargs)


def test_bad_pose_assignment_keeps_the_old_pose():
    world = ambfplus.World()
    body = world.add_body("b", "sphere", radius=0.1, pose=ambfplus.make_pose((1, 2, 3)))
    bad = np.eye(4)
    bad[3, 0] = 1
    with pytest.raises(ValueError, match="last row"):
        body.pose = bad
    with pytest.raises(ValueError, match="non-finite"):
        body.pose = np.full((4, 4), np.nan)
    with pytest.raises(TypeError):
        body.pose = np.eye(3)
    assert np.allclose(body.pose[:3, 3], (1, 2, 3))


def test_bad_lights():
    world = ambfplus.World()
    with pytest.raises(ValueError, match="unknown light type"):
        world.add_light("l", "laser")
    with pytest.raises(ValueError, match="direction"):
        world.add_light("l", direction=(0, 0, 0))
    for i in range(8):
        world.add_light(f"p{i}", "point")
    with pytest.raises(ValueError, match="already has 8 point lights"):
        world.add_light("p8", "point")
    world.add_light("d", "directional")  # other types still fit


def test_unknown_object_lookup():
    world = ambfplus.World()
    with pytest.raises(KeyError, match="no object named 'ghost'"):
        world.get("ghost")
    with pytest.raises(KeyError):
        world["ghost"]


def test_write_image_errors(tmp_path):
    with pytest.raises(ambfplus.ConfigError, match="no_such_dir"):
        ambfplus.write_image(str(tmp_path / "no_such_dir" / "x.png"), np.zeros((4, 4), np.uint8))
    with pytest.raises(TypeError, match="uint8 or uint16"):
        ambfplus.write_image(str(tmp_path / "x.png"), np.zeros((4, 4), np.float32))
    with pytest.raises(ambfplus.ConfigError, match="channels"):
        ambfplus.write_image(str(tmp_path / "x.png"), np.zeros((4, 4, 5), np.uint8))
    with pytest.raises(ambfplus.ConfigError, match="expected .png, .jpg or .jpeg"):
        ambfplus.write_image(str(tmp_path / "x.bmp"), np.zeros((4, 4), np.uint8))
    with pytest.raises(ambfplus.ConfigError, match="JPEG has no alpha"):
        ambfplus.write_image(str(tmp_path / "x.jpg"), np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(ambfplus.ConfigError, match="JPEG holds 8-bit pixels only"):
        ambfplus.write_image(str(tmp_path / "x.jpg"), np.zeros((4, 4), np.uint16))
    assert not list(tmp_path.iterdir()), "no partial file is left behind"


def test_negative_step_is_refused():
    with pytest.raises(ValueError, match=">= 0"):
        ambfplus.World().step(-1)
    with pytest.raises(ValueError, match="time_step"):
        ambfplus.World(time_step=0.0)
