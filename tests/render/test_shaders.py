"""Shaders declared in AMBF files: world < model < object precedence, AMBF's legacy GLSL 1.x
shaders on a compatibility context, modern shaders with the engine's uniforms, the segmentation
pass (the camera's preprocessing shader or the engine's equivalent), and shaders that cannot run
(reported once, the engine's own colours kept)."""

from __future__ import annotations

import logging
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus

# Flat colours in both dialects: legacy (GLSL 1.10, compatibility built-ins) and modern.
LEGACY_VS = "void main() { gl_Position = ftransform(); }\n"
MODERN_VS = textwrap.dedent(
    """\
    #version 450 core
    layout(location = 0) in vec4 a_position;
    uniform mat4 u_model_view;
    uniform mat4 u_projection;
    void main() { gl_Position = u_projection * (u_model_view * a_position); }
    """
)


def vec3(rgb) -> str:
    return "vec3(" + ", ".join(f"{c:.3f}" for c in rgb) + ")"


def legacy_fs(rgb) -> str:
    return f"void main() {{ gl_FragColor = vec4({vec3(rgb)}, 1.0); }}\n"


def modern_fs(rgb) -> str:
    return (
        "#version 450 core\nlayout(location = 0) out vec4 o_color;\n"
        f"void main() {{ o_color = vec4({vec3(rgb)}, 1.0); }}\n"
    )


def write_shader(folder: Path, vs: str, fs: str) -> dict:
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "shader.vs").write_text(vs)
    (folder / "shader.fs").write_text(fs)
    return {"path": folder.name, "vertex": "shader.vs", "fragment": "shader.fs"}


def yaml_block(d: dict) -> str:
    return "{" + ", ".join(f"{k}: {v}" for k, v in d.items()) + "}"


def box(name: str, x: float, shader: dict | None = None) -> str:
    text = (
        f"BODY {name}:\n  name: {name}\n  mass: 0.0\n  shape: box\n"
        f"  geometry: {{x: 0.08, y: 0.08, z: 0.04}}\n"
        f"  location: {{position: {{x: {x}, y: 0.0, z: 0.0}}, orientation: {{r: 0, p: 0, y: 0}}}}\n"
        f"  color rgba: {{r: 0.5, g: 0.5, b: 0.5, a: 1.0}}\n"
    )
    if shader:
        text += f"  shaders: {yaml_block(shader)}\n"
    return text


RED, GREEN, BLUE, YELLOW = (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0), (1.0, 1.0, 0.0)


@pytest.fixture
def scene(tmp_path) -> Path:
    """A world shader (red, legacy), model A with a model shader (green, modern) whose body a2
    has its own (blue, legacy), model B without one, and an environment model (AMBF builds it
    before the world's shader, so it keeps the engine's colours)."""
    world_shader = write_shader(tmp_path / "red", LEGACY_VS, legacy_fs(RED))
    model_shader = write_shader(tmp_path / "green", MODERN_VS, modern_fs(GREEN))
    body_shader = write_shader(tmp_path / "blue", LEGACY_VS, legacy_fs(BLUE))
    write_shader(tmp_path / "yellow", MODERN_VS, modern_fs(YELLOW))
    (tmp_path / "env.yaml").write_text("bodies: [BODY floor]\n" + box("floor", -0.3))
    (tmp_path / "world.yaml").write_text(
        f"environment: env.yaml\nshaders: {yaml_block(world_shader)}\n"
    )
    (tmp_path / "a.yaml").write_text(
        f"bodies: [BODY a1, BODY a2]\nshaders: {yaml_block(model_shader)}\n"
        + box("a1", -0.1)
        + box("a2", 0.0, body_shader)
    )
    (tmp_path / "b.yaml").write_text("bodies: [BODY b1]\n" + box("b1", 0.1))
    (tmp_path / "launch.yaml").write_text(
        "world config: world.yaml\ncolor config: colors.yaml\n"
        "input devices config: devices.yaml\nmultibody configs: [a.yaml, b.yaml]\n"
    )
    return tmp_path / "launch.yaml"


def top_view(world, width=320, height=96):
    camera = world.add_camera("top", width, height, fov_y=0.5, near=0.05, far=5.0)
    camera.look_at((0.0, 0.0, 0.6), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    return camera


def colours_by_body(frame, world) -> dict[str, np.ndarray]:
    """The distinct RGB colours each body's pixels show."""
    out = {}
    for body in world.bodies:
        mask = frame.instance == body.id
        assert mask.sum() > 50, f"{body.name} is not in view"
        out[body.name] = np.unique(frame.rgb[mask].reshape(-1, 3), axis=0)
    return out


def test_each_body_takes_the_nearest_scopes_shader(scene):
    sim = ambfplus.Simulator.from_launch(scene, models=[0, 1], strict=True)
    world = sim.world
    camera = top_view(world)
    frame = camera.capture(passes=["rgb", "instance"])
    colours = colours_by_body(frame, world)
    assert colours["a1"].tolist() == [[0, 255, 0]]  # the model's (modern)
    assert colours["a2"].tolist() == [[0, 0, 255]]  # its own (legacy)
    assert colours["b1"].tolist() == [[255, 0, 0]]  # the world's (legacy)
    # The environment was built before the world's shader: the engine's lit grey, shaded.
    floor = colours["floor"]
    assert not any(tuple(c) in {(255, 0, 0), (0, 255, 0), (0, 0, 255)} for c in floor)
    assert float(frame.rgb[frame.instance == world["floor"].id].mean()) > 20

    # Settings from Python follow the same chain: a body's own beats its model's, 'builtin'
    # on a model stops the world's.
    a1, b1 = world["a1"], world["b1"]
    yellow = (scene.parent / "yellow" / "shader.vs", scene.parent / "yellow" / "shader.fs")
    a1.shader = yellow
    b1.model.shader = "builtin"
    assert a1.shader == tuple(str(p) for p in yellow)
    frame = camera.capture(passes=["rgb", "instance"])
    colours = colours_by_body(frame, world)
    assert colours["a1"].tolist() == [[255, 255, 0]]
    assert colours["a2"].tolist() == [[0, 0, 255]]
    assert [255, 0, 0] not in colours["b1"].tolist()
    a1.shader = None
    assert colours_by_body(camera.capture(passes=["rgb", "instance"]), world)["a1"].tolist() == [
        [0, 255, 0]
    ]


def test_shaders_colour_only_ground_truth_stays_the_geometrys(scene):
    sim = ambfplus.Simulator.from_launch(scene, models=[0, 1], strict=True)
    world = sim.world
    camera = top_view(world)
    shaded = camera.capture(passes=["rgb", "depth", "instance", "segmentation"])
    depth, instance, seg = shaded.depth.copy(), shaded.instance.copy(), shaded.segmentation.copy()
    world.shader = None
    for model in world.models:
        model.shader = None
    world["a2"].shader = None
    plain = camera.capture(passes=["rgb", "depth", "instance", "segmentation"])
    np.testing.assert_array_equal(depth, plain.depth)
    np.testing.assert_array_equal(instance, plain.instance)
    np.testing.assert_array_equal(seg, plain.segmentation)
    assert not np.array_equal(shaded.rgb, plain.rgb)


def test_builtin_segmentation_draws_ambfs_flat_colours(tmp_path):
    """Meshes: material ambient x CHAI3D's light ambient (0.4), as AMBF's preprocessing shader
    draws them; volumes: their labels' colours; the background: the camera's."""
    world = ambfplus.World()
    world.add_body("box", "box", size=(0.1, 0.1, 0.02), mass=0, color=(0.8, 0.4, 0.2, 1.0))
    data = ambfplus.phantom(48)
    volume = world.add_volume("ear", data, pose=ambfplus.make_pose((0.2, 0.0, 0.0)))
    camera = world.add_camera("cam", 256, 128, fov_y=0.6, near=0.05, far=5.0)
    camera.look_at((0.1, 0.0, 0.5), (0.1, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    frame = camera.capture(passes=["segmentation", "instance", "label"])
    box_pixels = frame.segmentation[frame.instance == world["box"].id]
    # color rgba gives ambient = 0.5 x colour (AMBF); light ambient 0.4.
    expected = np.round(255 * 0.4 * 0.5 * np.array([0.8, 0.4, 0.2]))
    assert np.abs(box_pixels.astype(int) - expected).max() <= 1
    on_volume = frame.label > 0
    assert on_volume.sum() > 100
    table = {label.id: label.color for label in data.label_table}
    want = np.array([table[i] for i in frame.label[on_volume]])
    np.testing.assert_array_equal(frame.segmentation[on_volume], want)
    assert (frame.segmentation[frame.instance == 0] == 0).all()
    assert volume.id in np.unique(frame.instance)


def test_legacy_built_ins_carry_material_lights_and_matrices(tmp_path):
    """gl_FrontMaterial, gl_FrontLightProduct[0] and the eye frame reach a legacy shader as AMBF
    sets them: diffuse = colour, ambient product = 0.4 x material ambient, and eye-space z < 0
    in front of the camera."""
    world = ambfplus.World()
    body = world.add_body("box", "box", size=(0.1, 0.1, 0.02), mass=0, color=(0.6, 0.3, 0.9, 1))
    camera = world.add_camera("cam", 64, 64, fov_y=0.6, near=0.05, far=5.0)
    camera.look_at((0.0, 0.0, 0.5), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    vs = (
        "varying vec4 p;\n"
        "void main() { p = gl_ModelViewMatrix * gl_Vertex; gl_Position = ftransform(); }"
    )
    checks = {
        "diffuse": ("gl_FrontMaterial.diffuse.rgb", [0.6, 0.3, 0.9]),
        "ambient": (
            "gl_FrontLightProduct[0].ambient.rgb",
            [0.4 * 0.5 * c for c in (0.6, 0.3, 0.9)],
        ),
        # Eye space looks down -z: a point 0.49 m ahead has z = -0.49 (encoded as -z / 1 m).
        "eye": ("vec3(-p.z, 0.0, 0.0)", [0.49, 0.0, 0.0]),
    }
    for name, (expression, want) in checks.items():
        folder = tmp_path / name
        folder.mkdir()
        (folder / "v.vs").write_text(vs)
        (folder / "f.fs").write_text(
            f"varying vec4 p; void main() {{ gl_FragColor = vec4({expression}, 1.0); }}"
        )
        body.shader = (folder / "v.vs", folder / "f.fs")
        frame = camera.capture(passes=["rgb", "instance"])
        seen = frame.rgb[frame.instance == body.id].reshape(-1, 3).mean(axis=0) / 255
        np.testing.assert_allclose(seen, want, atol=1.5 / 255, err_msg=name)


@pytest.mark.slow
def test_fixture_legacy_shaders_run(fixtures):
    """The drilling scene's matcap (model shaders of the drills) and preprocessing shaders
    (segmentation_camera) compile on the compatibility context and draw non-black images."""
    sim = ambfplus.Simulator.from_launch(
        fixtures / "volumetric_drilling" / "launch.yaml", models=[0, 2, 4]
    )
    world = sim.world
    drills = next(m for m in world.models if m.name == "drills")
    assert drills.shader is not None and drills.shader[0].endswith("matcap/shader.vs")
    camera = sim.get("segmentation_camera")
    assert camera.preprocessing_shader[1].endswith("preprocessing/shader.fs")
    frame = camera.capture(passes=["rgb", "instance", "label", "segmentation"])
    drill_ids = [world[n].id for n in ("1mm", "2mm", "4mm", "6mm") if n in world]
    on_drill = np.isin(frame.instance, drill_ids)
    assert on_drill.sum() > 1000
    matcap = frame.rgb[on_drill].astype(int)
    assert matcap.mean() > 40  # lit metal, not black

    # The matcap, not the engine's shading, coloured the drill; nothing else changed.
    rgb, seg = frame.rgb.copy(), frame.segmentation.copy()
    drills.shader = "builtin"
    plain = camera.capture(passes=["rgb", "instance", "label", "segmentation"])
    changed = np.abs(rgb.astype(int) - plain.rgb.astype(int)).sum(axis=-1) > 0
    assert changed[on_drill].mean() > 0.95
    assert not changed[~on_drill].any()

    # Preprocessing: the shader outputs gl_FrontLightProduct[0].ambient = 0.4 x ambient, and
    # the drills' `color components` give ambient = level (1.0) x diffuse.
    diffuse = np.array([0.53162, 0.50121, 0.51455])
    expected = np.round(255 * 0.4 * diffuse)
    assert np.abs(seg[on_drill].astype(int) - expected).max() <= 1
    # Volumes keep their label colours (AMBF's voxel-colour mode).
    volume = world.volumes[0]
    table = {label.id: label.color for label in volume.data.label_table}
    on_volume = frame.label > 0
    assert on_volume.sum() > 1000
    want = np.array([table[i] for i in frame.label[on_volume]])
    np.testing.assert_array_equal(seg[on_volume], want)


def test_a_shader_that_cannot_run_is_reported_once_and_replaced(tmp_path, caplog):
    world = ambfplus.World()
    body = world.add_body("box", "box", size=(0.1, 0.1, 0.02), mass=0, color=(0.2, 0.7, 0.3, 1))
    camera = world.add_camera("cam", 64, 64, fov_y=0.6, near=0.05, far=5.0)
    camera.look_at((0.0, 0.0, 0.5), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    plain = camera.capture(passes=["rgb"]).rgb.copy()
    (tmp_path / "bad.vs").write_text(LEGACY_VS)
    (tmp_path / "bad.fs").write_text("void main() { gl_FragColor = vec4(1.0) }  // missing ;\n")
    body.shader = (tmp_path / "bad.vs", tmp_path / "bad.fs")
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        first = camera.capture(passes=["rgb"]).rgb.copy()
        second = camera.capture(passes=["rgb"]).rgb.copy()
    reports = [r for r in caplog.records if "cannot run" in r.getMessage()]
    assert len(reports) == 1
    assert "bad.fs" in reports[0].getMessage()
    np.testing.assert_array_equal(first, plain)
    np.testing.assert_array_equal(second, plain)

    body.shader = (tmp_path / "absent.vs", tmp_path / "absent.fs")
    np.testing.assert_array_equal(camera.capture(passes=["rgb"]).rgb, plain)


def test_missing_shader_file_in_an_adf_is_a_warning(tmp_path):
    (tmp_path / "world.yaml").write_text("namespace: /ambf/env/\n")
    (tmp_path / "m.yaml").write_text(
        "bodies: [BODY a]\nshaders: {path: nowhere, vertex: s.vs, fragment: s.fs}\n" + box("a", 0.0)
    )
    (tmp_path / "launch.yaml").write_text(
        "world config: world.yaml\ncolor config: c.yaml\ninput devices config: d.yaml\n"
        "multibody configs: [m.yaml]\n"
    )
    sim = ambfplus.Simulator.from_launch(tmp_path / "launch.yaml", models=[0], strict=True)
    messages = [message for _, message in sim.load_report.warnings]
    assert any("'shaders'" in m and "nowhere" in m and "not found" in m for m in messages)
    assert sim.world.models[-1].shader is None


def test_shader_values_are_checked():
    world = ambfplus.World()
    with pytest.raises(TypeError, match="pair of file paths"):
        world.shader = "matcap"
    with pytest.raises(TypeError, match="pair of file paths"):
        world.shader = ("a.vs",)
    world.shader = "builtin"
    assert world.shader == "builtin"
    camera = world.add_camera("c", 8, 8)
    with pytest.raises(ValueError, match="unknown pass 'segment'"):
        camera.capture(passes=["segment"])
