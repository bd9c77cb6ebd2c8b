"""Textures: meshes keep their texture coordinates, an MTL's diffuse map (or an ADF body's
texture) colours the RGB pass and feeds legacy shaders' diffuseMap, with U running left to
right and V bottom to top of the image as in OBJ files; depth, ids and segmentation stay the
geometry's."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import ambfplus

# A 4x4 image of 2x2 blocks, each block one colour, so that bilinear filtering anywhere inside a
# block gives the block's colour exactly. No two blocks are mirror images of each other: a
# flipped U or V moves a colour to another quadrant.
TOP_LEFT, TOP_RIGHT = (230, 30, 40), (40, 200, 60)
BOTTOM_LEFT, BOTTOM_RIGHT = (50, 60, 220), (240, 220, 50)


def texture_image() -> np.ndarray:
    image = np.zeros((4, 4, 3), np.uint8)
    image[:2, :2], image[:2, 2:] = TOP_LEFT, TOP_RIGHT
    image[2:, :2], image[2:, 2:] = BOTTOM_LEFT, BOTTOM_RIGHT
    return image


def write_quad(folder: Path, with_mtl: bool = True) -> Path:
    """A 0.2 m square in the z = 0 plane, u along +x and v along +y, with its MTL and PNG."""
    ambfplus.write_image(str(folder / "checker.png"), texture_image())
    (folder / "quad.mtl").write_text("newmtl skin\nKd 1 1 1\nmap_Kd checker.png\n")
    head = "mtllib quad.mtl\n" if with_mtl else ""
    (folder / "quad.obj").write_text(
        head + "v -0.1 -0.1 0\nv 0.1 -0.1 0\nv 0.1 0.1 0\nv -0.1 0.1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n"
        + ("usemtl skin\n" if with_mtl else "")
        + "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n"
    )
    return folder / "quad.obj"


def straight_down(world):
    """A camera above the quad looking straight at it, image up = +y, image right = +x."""
    camera = world.add_camera("top", 160, 160, fov_y=0.6, near=0.05, far=2.0)
    camera.look_at((0.0, 0.0, 0.3), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    return camera


# Pixels at the middle of each quadrant's 2x2 texels (x, y = -+0.05 m), where bilinear
# filtering reads only that quadrant's colour: the view spans 2 * 0.3 * tan(0.3) = 0.186 m.
QUADRANT_PIXELS = {
    "top_left": (37, 37),
    "top_right": (37, 123),
    "bottom_left": (123, 37),
    "bottom_right": (123, 123),
}
EXPECTED = {
    "top_left": TOP_LEFT,
    "top_right": TOP_RIGHT,
    "bottom_left": BOTTOM_LEFT,
    "bottom_right": BOTTOM_RIGHT,
}


def test_legacy_shader_samples_the_diffuse_map_texel_for_texel(tmp_path):
    """A legacy shader that draws the diffuse map unlit shows the image exactly."""
    quad = write_quad(tmp_path)
    (tmp_path / "tex.vs").write_text(
        "void main() { gl_TexCoord[0] = gl_MultiTexCoord0; gl_Position = ftransform(); }\n"
    )
    (tmp_path / "tex.fs").write_text(
        "uniform sampler2D diffuseMap;\nuniform bool uTextureEnabled;\n"
        "void main() { gl_FragColor = uTextureEnabled ? texture2D(diffuseMap, "
        "gl_TexCoord[0].st) : vec4(1.0, 0.0, 1.0, 1.0); }\n"
    )
    sim = ambfplus.Simulator()
    world = sim.world
    body = world.add_body("quad", mesh=str(quad), mass=0.0, color=[1, 1, 1, 1])
    body.shader = (str(tmp_path / "tex.vs"), str(tmp_path / "tex.fs"))
    frame = straight_down(world).capture(passes=["rgb", "instance"])
    for where, (row, col) in QUADRANT_PIXELS.items():
        assert frame.instance[row, col] == body.id
        assert tuple(frame.rgb[row, col]) == EXPECTED[where], where


def test_rgb_pass_is_the_texture_times_the_lit_colour(tmp_path):
    """Each quadrant of the textured white quad renders exactly as an untextured quad of that
    quadrant's colour, lit the same way; ground truth is unchanged by the texture."""
    textured = write_quad(tmp_path)
    sub = tmp_path / "plain"
    sub.mkdir()
    plain = write_quad(sub, with_mtl=False)
    sim = ambfplus.Simulator()
    world = sim.world
    world.add_body("quad", mesh=str(textured), mass=0.0, color=[1, 1, 1, 1])
    camera = straight_down(world)
    passes = ["rgb", "depth", "instance", "segmentation"]
    frame = camera.capture(passes=passes)
    for where, (row, col) in QUADRANT_PIXELS.items():
        other = ambfplus.Simulator()
        colour = [c / 255 for c in EXPECTED[where]] + [1.0]
        other.world.add_body("quad", mesh=str(plain), mass=0.0, color=colour)
        reference = straight_down(other.world).capture(passes=passes)
        got = frame.rgb[row, col].astype(int)
        want = reference.rgb[row, col].astype(int)
        assert np.abs(got - want).max() <= 1, (where, got, want)
        # Clearly the quadrant's own colour, not a neighbour's.
        assert np.argmax(got) == np.argmax(EXPECTED[where]), where
    # Ground truth: the same geometry gives the same depth and ids.
    other = ambfplus.Simulator()
    other.world.add_body("quad", mesh=str(plain), mass=0.0, color=[1, 1, 1, 1])
    reference = straight_down(other.world).capture(passes=passes)
    np.testing.assert_array_equal(frame.depth, reference.depth)
    np.testing.assert_array_equal(frame.instance != 0, reference.instance != 0)
    np.testing.assert_array_equal(frame.segmentation, reference.segmentation)


def test_missing_texture_file_draws_untextured(tmp_path, caplog):
    quad = write_quad(tmp_path)
    (tmp_path / "checker.png").unlink()
    sim = ambfplus.Simulator()
    world = sim.world
    world.add_body("quad", mesh=str(quad), mass=0.0, color=[1, 1, 1, 1])
    frame = straight_down(world).capture(passes=["rgb"])
    grey = frame.rgb[37, 37].astype(int)
    # Untextured white: all channels equal.
    assert grey.max() - grey.min() <= 1
    assert grey.max() > 100


if __name__ == "__main__":  # pragma: no cover
    pytest.main([__file__, "-v"])
