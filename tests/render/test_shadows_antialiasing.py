"""Shadows and anti-aliasing of the rgb pass: a sphere's shadow on a plane matches its analytic
outline (directional and spot lights), supersampled edges blend while label and instance stay
pure, and every ground-truth pass is bit-identical with both on or off."""

from __future__ import annotations

import numpy as np
import pytest

import ambfplus

W, H = 640, 480
CENTRE = np.array([0.02, -0.03, 0.25])  # the sphere, metres
RADIUS = 0.08


def near_edge(mask: np.ndarray, reach: int = 1) -> np.ndarray:
    """Pixels within `reach` pixels (8-neighbourhood) of the mask's outline."""
    grown = mask.copy()
    shrunk = mask.copy()
    for _ in range(reach):
        g, s = grown.copy(), shrunk.copy()
        for dy in (-1, 0, 1):
            for dx in (-1, 0, 1):
                g |= np.roll(np.roll(grown, dy, 0), dx, 1)
                s &= np.roll(np.roll(shrunk, dy, 0), dx, 1)
        grown, shrunk = g, s
    return grown & ~shrunk


def sphere_over_plane(light: dict, shadows: bool):
    world = ambfplus.World()
    floor = world.add_body("floor", "box", size=(1.5, 1.5, 0.02), mass=0.0, color=(0.8, 0.8, 0.8))
    floor.pose = np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, -0.01], [0, 0, 0, 1.0]])
    ball = world.add_body("ball", "sphere", radius=RADIUS, mass=0.0, color=(0.9, 0.3, 0.2))
    pose = np.eye(4)
    pose[:3, 3] = CENTRE
    ball.pose = pose
    world.add_light("sun", shadow_quality=4, **light)
    camera = world.add_camera("cam", W, H, fov_y=0.9, near=0.05, far=5.0, shadows=shadows)
    camera.look_at((0.25, -0.55, 0.75), (0.0, 0.05, 0.0))
    return world, floor, camera


def floor_points(frame) -> np.ndarray:
    """World points of every pixel centre, from depth and the intrinsics (H x W x 3)."""
    k = frame.intrinsics
    rows, cols = np.mgrid[0:H, 0:W]
    z = frame.depth.astype(np.float64)
    cam = np.stack([(cols + 0.5 - k[0, 2]) / k[0, 0] * z, (rows + 0.5 - k[1, 2]) / k[1, 1] * z, z])
    pose = frame.pose
    return np.einsum("ij,jhw->hwi", pose[:3, :3], cam) + pose[:3, 3]


def analytic_shadow(points: np.ndarray, light: dict) -> np.ndarray:
    """Whether the segment from each point towards the light passes through the sphere."""
    if light["type"] == "directional":
        d = np.asarray(light["direction"], float)
        to_light = np.broadcast_to(-d / np.linalg.norm(d), points.shape)
        reach = np.full(points.shape[:2], np.inf)
    else:
        v = np.asarray(light["position"], float) - points
        reach = np.linalg.norm(v, axis=-1)
        to_light = v / reach[..., None]
    v = CENTRE - points
    along = np.einsum("hwi,hwi->hw", v, to_light)
    across = np.linalg.norm(v - along[..., None] * to_light, axis=-1)
    return (across < RADIUS) & (along > 0) & (along < reach)


LIGHTS = {
    "directional": {"type": "directional", "direction": (0.35, 0.25, -1.0)},
    "spot": {
        "type": "spot",
        "position": (-0.25, -0.2, 0.9),
        "direction": (0.25, 0.15, -0.9),
        "spot_cutoff": 0.6,
        "spot_exponent": 0.0,
    },
}


@pytest.mark.parametrize("kind", ["directional", "spot"])
def test_a_spheres_shadow_on_a_plane_matches_its_analytic_outline_within_a_pixel(kind):
    light = LIGHTS[kind]
    _, floor, lit = sphere_over_plane(light, shadows=True)
    on = lit.capture(passes=["rgb", "depth", "instance"])
    _, _, unlit = sphere_over_plane(light, shadows=False)
    off = unlit.capture(passes=["rgb", "depth", "instance"])
    np.testing.assert_array_equal(on.depth, off.depth)
    np.testing.assert_array_equal(on.instance, off.instance)
    # A pixel is in shadow when less than half the light's share of its colour reaches it; the
    # floor is compared where the light reaches it (a spot's cone).
    ambient = 3 * 0.15 * 0.8 * 255
    rgb_on = on.rgb.astype(float).sum(-1)
    rgb_off = off.rgb.astype(float).sum(-1)
    seen = (on.instance == floor.id) & (rgb_off - ambient > 60)
    expected = analytic_shadow(floor_points(on), light) & seen
    assert expected.sum() > 2000, "the shadow falls in view"
    ratio = (rgb_on - ambient) / np.maximum(rgb_off - ambient, 1e-6)
    measured = (ratio < 0.5) & seen
    wrong = measured != expected
    allowed = near_edge(expected) & seen
    assert not (wrong & ~allowed).any(), (
        f"{(wrong & ~allowed).sum()} pixels off the analytic shadow by more than 1 px"
    )
    assert measured.sum() > 0.9 * expected.sum()
    # No acne: the floor away from the shadow is as bright as without shadows.
    lit = seen & ~expected & ~near_edge(expected, 2)
    assert (ratio[lit] > 0.98).mean() > 0.999, "lit floor stays as bright as without shadows"


def test_without_shadows_the_floor_under_the_sphere_stays_lit():
    light = LIGHTS["directional"]
    _, floor, camera = sphere_over_plane(light, shadows=False)
    frame = camera.capture(passes=["rgb", "depth", "instance"])
    seen = frame.instance == floor.id
    expected = analytic_shadow(floor_points(frame), light) & seen
    inside = expected & ~near_edge(expected, 2)
    outside = ~expected & seen & ~near_edge(expected, 2)
    # The floor faces the light alike everywhere: no darker patch where the shadow belongs (in
    # shadow it would keep its ambient share only, 3 x 0.15 x 0.8 x 255 = 92).
    brightness = frame.rgb.astype(float).sum(-1)
    assert inside.sum() > 1000
    assert brightness[inside].min() > 0.95 * brightness[outside].mean()
    # A light of shadow quality 0 casts none even with the camera's shadows on.
    world, _, shadowed = sphere_over_plane(light, shadows=True)
    world.get("sun").shadow_quality = 0
    np.testing.assert_array_equal(shadowed.capture(passes=["rgb"]).rgb, frame.rgb)


def edge_scene(antialiasing: int):
    """A bright slanted bar on a dark background, lit head-on: two flat colours."""
    world = ambfplus.World()
    bar = world.add_body(
        "bar", "box", size=(0.6, 0.012, 0.01), mass=0.0, color=(1.0, 1.0, 1.0), specular=0.0
    )
    a = 0.3
    bar.pose = np.array(
        [[np.cos(a), -np.sin(a), 0, 0], [np.sin(a), np.cos(a), 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    )
    world.add_light("key", direction=(0, 0, -1), shadow_quality=2)
    camera = world.add_camera(
        "cam", 160, 120, fov_y=0.6, near=0.05, far=5.0, background=(0.1, 0.1, 0.1),
        shadows=True, antialiasing=antialiasing,
    )  # fmt: skip
    camera.look_at((0, 0, 1.0), (0, 0, 0), up=(0, 1, 0))
    return bar, camera


@pytest.mark.parametrize("k", [2, 3])
def test_antialiasing_blends_edges_and_leaves_label_and_instance_pure(k):
    bar, plain_camera = edge_scene(1)
    plain = plain_camera.capture(passes=["rgb", "label", "instance", "depth"])
    colours = {tuple(c) for c in plain.rgb.reshape(-1, 3)}
    assert len(colours) == 2, "the scene has two flat colours"
    dark, bright = sorted(colours)
    _, smooth_camera = edge_scene(k)
    smooth = smooth_camera.capture(passes=["rgb", "label", "instance", "depth"])
    grey = smooth.rgb[..., 0].astype(int)
    between = (grey > dark[0]) & (grey < bright[0])
    on_edges = near_edge(plain.instance == bar.id)
    assert between.sum() > 150, "edge pixels take intermediate values"
    assert not (between & ~on_edges).any(), "only edge pixels blend"
    assert not ((plain.rgb[..., 0] > dark[0]) & (plain.rgb[..., 0] < bright[0])).any()
    # Pixels away from edges keep their one sample's colour exactly.
    np.testing.assert_array_equal(smooth.rgb[~on_edges], plain.rgb[~on_edges])
    # Ground truth stays one exact sample per pixel: only the scene's ids, no blends.
    assert set(np.unique(smooth.instance)) == {0, bar.id}
    assert set(np.unique(smooth.label)) == {0}
    np.testing.assert_array_equal(smooth.instance, plain.instance)
    np.testing.assert_array_equal(smooth.depth, plain.depth)


GROUND_TRUTH = ["depth", "label", "instance", "voxel", "segmentation", "points"]


@pytest.mark.parametrize("k", [2, 3])
def test_supersampled_pixels_are_the_filter_of_a_finer_render(k):
    """Every pixel supersampling changes takes the filter of a camera with more pixels whose
    pixel centres are the sample positions: for k = 3 the box filter of a camera with k times the
    pixels; for k = 2 half the pixel's centre and an eighth of each of its corners, from a camera
    with 2n + 1 pixels along each axis over the same view widened by half a pixel. The scene: the
    phantom's silhouettes and label boundaries and a rod in front of it, with the looks on. The
    volume's samples are rays packed densely and search only near the depths their pixels'
    neighbours see (volume.frag); this finds what a full search finds."""
    world = ambfplus.World()
    world.add_volume("bone", ambfplus.phantom(96))
    rod = world.add_body("rod", "cylinder", radius=0.002, height=0.06, mass=0.0, axis="x")
    pose = np.eye(4)
    pose[:3, 3] = (0, 0, 0.028)
    rod.pose = pose
    world.add_light("sun", direction=(0.3, 0.4, -1.0))
    w, h, fov = 240, 180, 0.8
    fine_size = (2 * w + 1, 2 * h + 1) if k == 2 else (k * w, k * h)
    fine_fov = 2 * np.arctan(np.tan(fov / 2) * (h + 0.5) / h) if k == 2 else fov
    cameras = {
        name: world.add_camera(name, *size, fov_y=f, near=0.01, far=2.0, looks=True)
        for name, size, f in (
            ("plain", (w, h), fov), ("sampled", (w, h), fov), ("fine", fine_size, fine_fov)
        )
    }  # fmt: skip
    cameras["sampled"].antialiasing = k
    for camera in cameras.values():
        camera.look_at((0.03, -0.075, 0.075), (0, 0, 0.005))
    rgb = {
        name: c.capture(passes=["rgb"]).rgb[..., :3].astype(float) for name, c in cameras.items()
    }
    fine = rgb["fine"]
    if k == 2:
        # Fine pixel 2i is the corner i, 2i + 1 the centre of pixel i, along both axes.
        corners = fine[0::2, 0::2]
        centre = fine[1::2, 1::2]
        reference = 0.5 * centre + 0.125 * (
            corners[:-1, :-1] + corners[:-1, 1:] + corners[1:, :-1] + corners[1:, 1:]
        )
        # The fine camera's layout is right: its odd pixels are the plain camera's (to rounding).
        assert np.abs(centre - rgb["plain"]).max() <= 1.0
        assert (centre != rgb["plain"]).any(axis=-1).mean() < 0.01
    else:
        reference = fine.reshape(h, k, w, k, 3).mean(axis=(1, 3))
    changed = (rgb["sampled"] != rgb["plain"]).any(axis=-1)
    assert changed.sum() > 2000
    error = np.abs(rgb["sampled"] - reference).max(axis=-1)[changed]
    plain_error = np.abs(rgb["plain"] - reference).max(axis=-1)[changed]
    if k == 2:
        # The lattice draws the meshes through the camera's own projection narrowed to the
        # corners, the fine camera through a wider one: a corner lying on a mesh's edge to within
        # rounding may fall on the other side of it (found: one corner, shared by 4 pixels).
        assert (error > 2.0).sum() <= 0.002 * changed.sum(), int((error > 2).sum())
        assert error.max() <= 2.0 + 255 / 8  # never more than one corner's share
    else:
        assert error.max() <= 2.0, (error.max(), int((error > 2).sum()))
    assert plain_error.mean() > 5.0  # the one centre sample is far from the filter there


def test_ground_truth_is_bit_identical_with_shadows_and_antialiasing_on_or_off():
    world = ambfplus.World()
    volume = world.add_volume("bone", ambfplus.phantom(64))
    ball = world.add_body("ball", "sphere", radius=0.008, mass=0.0, color=(0.2, 0.7, 0.3))
    pose = np.eye(4)
    pose[:3, 3] = (0.004, -0.006, 0.034)  # above the 48 mm bone, shadowing it
    ball.pose = pose
    rod = world.add_body("rod", "cylinder", radius=0.002, height=0.06, mass=0.0, axis="x")
    pose[:3, 3] = (0, 0, 0.028)
    rod.pose = pose
    world.add_light("sun", direction=(0.3, 0.4, -1.0), shadow_quality=3)
    world.add_light("lamp", "spot", position=(0.0, -0.1, 0.2), direction=(0, 0.4, -1.0),
                    shadow_quality=2)  # fmt: skip
    camera = world.add_camera("cam", 320, 240, fov_y=0.8, near=0.01, far=2.0)
    camera.look_at((0.03, -0.075, 0.075), (0, 0, 0.005))
    frames = {}
    for shadows, k in ((False, 1), (True, 1), (False, 3), (True, 2)):
        camera.shadows, camera.antialiasing = shadows, k
        frames[shadows, k] = camera.capture(passes=["rgb", *GROUND_TRUTH])
    base = frames[False, 1]
    assert (base.instance == volume.id).sum() > 5000 and (base.instance == ball.id).sum() > 500
    assert len(np.unique(base.label)) > 2
    for key, frame in frames.items():
        for name in GROUND_TRUTH:
            a, b = getattr(frame, name), getattr(base, name)
            assert a.tobytes() == b.tobytes(), f"{name} differs with shadows, k = {key}"
    # The options did change the rgb image: shadows darken, supersampling blends.
    assert (frames[True, 1].rgb.sum(-1) < base.rgb.sum(-1) - 30).sum() > 500
    assert (frames[False, 3].rgb != base.rgb).any(axis=-1).sum() > 200


def test_options_are_checked_and_kept():
    world = ambfplus.World()
    camera = world.add_camera("cam", 32, 24)
    assert (camera.shadows, camera.antialiasing) == (False, 1), "the library's defaults"
    camera.antialiasing = 4
    assert camera.antialiasing == 4
    with pytest.raises(ValueError, match="camera 'cam': antialiasing must be 1 .* got 5"):
        camera.antialiasing = 5
    with pytest.raises(ValueError, match="antialiasing must be 1"):
        world.add_camera("bad", 32, 24, antialiasing=0)
    light = world.add_light("sun")
    assert light.shadow_quality == 3
    with pytest.raises(ValueError, match="light 'sun': shadow_quality must be 0 .* got 6"):
        light.shadow_quality = 6
    with pytest.raises(ValueError, match="shadow_quality must be 0"):
        world.add_light("dim", shadow_quality=-1)


ADF = """
cameras: [CAMERA main]
lights: [LIGHT lamp]
CAMERA main:
  name: main
  location: {x: 1, y: 0, z: 0}
  look at: {x: 0, y: 0, z: 0}
  shadows: true
  antialiasing: %s
LIGHT lamp:
  name: lamp
  location: {x: 0, y: 0, z: 2}
  direction: {x: 0, y: 0, z: -1}
  shadow quality: 2
"""


def test_adf_keys_choose_a_cameras_shadows_and_antialiasing(tmp_path):
    path = tmp_path / "world.yaml"
    path.write_text(ADF % 3)
    world = ambfplus.World()
    world.load_adf(path)
    camera, lamp = world.get("main"), world.get("lamp")
    assert (camera.shadows, camera.antialiasing, lamp.shadow_quality) == (True, 3, 2)
    path.write_text(ADF % 7)
    with pytest.raises(ambfplus.ConfigError, match=r"world.yaml.*antialiasing.*1 \(off\) to 4"):
        ambfplus.World().load_adf(path)
