"""Values the ADF and Slicer readers once took without a word (issue #33's silent loads, and #34's
list naming one block twice), one small case each: a ConfigError naming the file, the line, the
key and what was expected where AMBF, too, would refuse or misread the value, and a warning naming
the file and the lines where AMBF reads the file as it is."""

from __future__ import annotations

import logging
import textwrap
from pathlib import Path

import numpy as np
import pytest
from helpers.volume_files import nrrd_bytes, segment_keys

import ambfplus

BALL = "BODY a: {name: a, mass: 1, shape: SPHERE, geometry: {radius: 0.1}"


def write(tmp_path: Path, text: str, name: str = "model.yaml") -> Path:
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def refused(tmp_path: Path, text: str, line: int, *words: str) -> str:
    """Loading text is a ConfigError naming the file, the line and every word; nothing stays."""
    path = write(tmp_path, text)
    world = ambfplus.World()
    with pytest.raises(ambfplus.ConfigError) as info:
        world.load_adf(path)
    message = str(info.value)
    assert str(path) in message and f"line {line}:" in message, message
    for word in words:
        assert word in message, message
    assert world.objects == []
    return message


def warnings_of(caplog, path: Path) -> list[str]:
    return [r.getMessage() for r in caplog.records if str(path) in r.getMessage()]


# Opacity: alpha and transparency are in 0..1 ------------------------------------------------


@pytest.mark.parametrize("alpha", ["-1", "1.5"])
def test_color_rgba_alpha_outside_0_1_is_refused(tmp_path, alpha):
    text = f"""\
        bodies: [BODY a]
        {BALL}, color rgba: {{r: 1, g: 0, b: 0, a: {alpha}}}}}
        """
    refused(tmp_path, text, 2, "BODY a", "'color rgba.a' must be in 0..1", alpha)


@pytest.mark.parametrize("transparency", ["2.0", "-0.5"])
def test_transparency_outside_0_1_is_refused(tmp_path, transparency):
    text = f"""\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 1
          shape: SPHERE
          geometry: {{radius: 0.1}}
          color components:
            diffuse: {{r: 1, g: 0, b: 0}}
            transparency: {transparency}
        """
    refused(
        tmp_path, text, 9, "BODY a", "'color components.transparency' must be in 0..1", transparency
    )


def test_opacity_in_range_still_loads(tmp_path):
    path = write(
        tmp_path,
        f"""\
        bodies: [BODY a]
        {BALL}, color rgba: {{r: 1, g: 0, b: 0, a: 0.25}}}}
        """,
    )
    world = ambfplus.World()
    world.load_adf(path)
    assert world.get("a").color[3] == pytest.approx(0.25)


# Mass and inertia ------------------------------------------------------------------------------


@pytest.mark.parametrize("missing", ["ix", "iy", "iz"])
def test_inertia_missing_a_moment_is_refused(tmp_path, missing):
    moments = ", ".join(f"{k}: 0.01" for k in ("ix", "iy", "iz") if k != missing)
    text = f"""\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 1
          shape: SPHERE
          geometry: {{radius: 0.1}}
          inertia: {{{moments}}}
        """
    refused(tmp_path, text, 7, "BODY a", "'inertia' needs ix, iy and iz", f"'{missing}' is missing")


@pytest.mark.parametrize("mass", ["1e308", "1e10"])
def test_mass_beyond_a_bound_is_refused(tmp_path, mass):
    text = f"""\
        bodies: [BODY a]
        BODY a: {{name: a, mass: {mass}, shape: SPHERE, geometry: {{radius: 0.1}}}}
        """
    refused(tmp_path, text, 2, "BODY a", f"'mass' is {mass} kg", "at most 1e9 kg")


def test_inertia_beyond_a_bound_is_refused(tmp_path):
    text = """\
        bodies: [BODY a]
        BODY a: {name: a, mass: 1, shape: SPHERE, geometry: {radius: 0.1},
                 inertia: {ix: 1e308, iy: 1, iz: 1}}
        """
    refused(tmp_path, text, 3, "BODY a", "'inertia.ix' must be >= 0 and at most 1e15", "1e308")


def test_heavy_body_with_full_inertia_still_loads(tmp_path):
    path = write(
        tmp_path,
        """\
        bodies: [BODY a]
        BODY a: {name: a, mass: 1e6, shape: SPHERE, geometry: {radius: 0.1},
                 inertia: {ix: 1, iy: 2, iz: 3}}
        """,
    )
    world = ambfplus.World()
    world.load_adf(path)
    body = world.get("a")
    assert body.mass == 1e6 and tuple(body.inertia) == pytest.approx((1, 2, 3))


# Vectors: AMBF reads all three components -------------------------------------------------------


@pytest.mark.parametrize(
    ("location", "key", "missing"),
    [("{position: {x: 1, z: 2}}", "'location.position'", "'y'"),
     ("{position: {y: 1, z: 2}}", "'location.position'", "'x'"),
     ("{orientation: {r: 0, y: 1}}", "'location.orientation'", "'p'")],
)  # fmt: skip
def test_a_position_or_orientation_missing_a_component_is_refused(tmp_path, location, key, missing):
    text = f"""\
        bodies: [BODY a]
        {BALL}, location: {location}}}
        """
    refused(tmp_path, text, 2, "BODY a", key, missing, "is missing")


def test_a_camera_location_missing_a_component_is_refused(tmp_path):
    text = """\
        cameras: [CAM c]
        CAM c: {name: c, location: {x: 1, y: 0}, look at: {x: 0, y: 0, z: 0}}
        """
    refused(tmp_path, text, 2, "CAM c", "'location' needs x, y and z", "'z' is missing")


# Names and paths -------------------------------------------------------------------------------


def ascii_stl(path: Path) -> None:
    path.write_text(
        "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 0.1 0 0\n"
        "vertex 0 0.1 0\nendloop\nendfacet\nendsolid t\n"
    )


def test_a_mesh_name_holding_a_nul_is_refused_not_cut_short(tmp_path):
    ascii_stl(tmp_path / "Ball_A.STL")
    text = """\
        bodies: [BODY a]
        BODY a: {name: a, mass: 1, mesh: "Ball_A.STL\\0.png"}
        """
    refused(tmp_path, text, 2, "BODY a", "'mesh' holds a NUL character", "'Ball_A.STL'")


def test_an_empty_mesh_is_a_body_without_a_visual_as_in_ambf(tmp_path, caplog):
    # AMBF's Blender exporter writes `mesh: ''` for a body that has nothing to draw (its world,
    # drill and compound fixtures do); AMBF makes the body without a visual mesh, and so do we.
    path = write(
        tmp_path,
        """\
        bodies: [BODY a]
        BODY a:
          name: a
          mesh: ''
          mass: 0.4
          compound collision shape:
          - {shape: BOX, geometry: {x: 0.1, y: 0.1, z: 0.1}, offset: {position: {x: 0, y: 0, z: 0}}}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    body = world.get("a")
    assert body.mesh in (None, "") and len(body.collision_shapes) == 1
    assert warnings_of(caplog, path) == []


@pytest.mark.parametrize("scale", ["1e30", "1e7"])
def test_a_scale_beyond_a_bound_is_refused(tmp_path, scale):
    text = f"""\
        bodies: [BODY a]
        {BALL}, scale: {scale}}}
        """
    refused(tmp_path, text, 2, "BODY a", "'scale' must be > 0 and at most 1e6", scale)


# Keys written twice ---------------------------------------------------------------------------


def test_a_key_given_twice_with_one_value_warns_naming_file_lines_and_key(tmp_path, caplog):
    # yaml-cpp (so AMBF) keeps both and reads the first; with one value nothing is lost.
    path = write(
        tmp_path,
        """\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 2
          shape: SPHERE
          mass: 2
          geometry: {radius: 0.1}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    warned = [m for m in warnings_of(caplog, path) if "twice" in m]
    assert len(warned) == 1, warned
    assert "line 6:" in warned[0] and "key 'mass'" in warned[0] and "line 4" in warned[0]
    assert world.get("a").mass == 2


def test_a_key_given_twice_with_two_values_is_refused_naming_both_lines(tmp_path):
    text = """\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 2
          shape: SPHERE
          geometry: {radius: 0.1, radius: 0.2}
        """
    refused(tmp_path, text, 6, "key 'radius' is given twice", "first on line 6", "different")
    text = """\
        bodies: [BODY a]
        BODY a:
          name: a
          mass: 2
          shape: SPHERE
          geometry: {radius: 0.1}
          mass: 3
        """
    refused(tmp_path, text, 7, "key 'mass' is given twice", "first on line 4", "different")


def test_two_different_blocks_of_one_identifier_are_refused(tmp_path):
    text = f"""\
        bodies: [BODY a]
        {BALL}}}
        BODY a: {{name: a, mass: 5, shape: SPHERE, geometry: {{radius: 0.1}}}}
        """
    refused(tmp_path, text, 3, "key 'BODY a' is given twice", "first on line 2", "different")


# A list naming one block twice ------------------------------------------------------------------


def test_a_list_naming_a_block_twice_makes_it_once_and_warns_naming_both_lines(tmp_path, caplog):
    path = write(
        tmp_path,
        """\
        bodies:
        - BODY a
        - BODY b
        - BODY a
        joints: [JOINT ab]
        BODY a: {name: a, mass: 1, shape: SPHERE, geometry: {radius: 0.1}}
        BODY b: {name: b, mass: 1, shape: SPHERE, geometry: {radius: 0.1}}
        JOINT ab: {name: ab, parent: BODY a, child: BODY b, type: fixed}
        """,
    )
    world = ambfplus.World()
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(path)
    names = sorted(o.name for o in world.objects)
    assert names == ["a", "ab", "b"], names
    warned = [m for m in warnings_of(caplog, path) if "BODY a" in m]
    assert len(warned) == 1, warned
    assert "line 4:" in warned[0] and "line 2" in warned[0] and "made once" in warned[0]


# Slicer segmentations: voxels no segment declares --------------------------------------------


def test_slicer_voxels_of_an_undeclared_value_warn_with_count_and_value(tmp_path, caplog):
    data = np.zeros((8, 8, 8), dtype=np.uint8)
    data[2:6, 2:6, 2:6] = 1
    data[0, 0, 0:3] = 7  # declared by no segment
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0)])
    path = tmp_path / "seg.seg.nrrd"
    path.write_bytes(nrrd_bytes(data, "uchar", extra=keys))
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        volume = ambfplus.load_nrrd(path)
    warned = [m for m in warnings_of(caplog, path) if "no Segment" in m]
    assert len(warned) == 1, [r.getMessage() for r in caplog.records]
    assert "3 voxels" in warned[0] and "(7)" in warned[0], warned
    labels = np.asarray(volume.labels)
    assert np.count_nonzero(labels) == 64 and set(np.unique(labels)) == {0, 1}


def test_slicer_segmentation_with_every_value_declared_does_not_warn(tmp_path, caplog):
    data = np.zeros((8, 8, 8), dtype=np.uint8)
    data[2:6, 2:6, 2:6] = 1
    data[0, 0, 0] = 2
    keys = segment_keys([("Bone", (200, 200, 200), 1, 0), ("Nerve", (250, 200, 0), 2, 0)])
    path = tmp_path / "seg.seg.nrrd"
    path.write_bytes(nrrd_bytes(data, "uchar", extra=keys))
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        ambfplus.load_nrrd(path)
    assert warnings_of(caplog, path) == []
