"""Stereo display: a head-mounted display through OpenHMD's null device (the head turns the
rendered view by the same rotation; the eyes sit the IPD apart), the launcher's side-by-side
output (its halves have the disparity of the pair it states), and the window's lens-distortion
pass (identity, magnification and the PanoTools polynomial, read back from the screen)."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers.x11 import finish, launch, screenshot, window_origin, xdo

import ambfplus
from ambfplus.devices.hmd import HmdError, HmdView, OpenHMD, quaternion_matrix
from ambfplus.stereo import block_match


def null_hmd() -> OpenHMD:
    try:
        return OpenHMD(null=True)
    except HmdError as error:
        pytest.skip(f"{error}")


def sphere_centres(frame, ids) -> np.ndarray:
    """Each sphere's centre in the camera frame, fitted to its rendered surface points."""
    centres = []
    for body_id in ids:
        points = frame.points[frame.instance == body_id].astype(np.float64)
        assert len(points) > 100, "a marker is out of view"
        # |p|^2 = 2 c.p + (r^2 - |c|^2): linear in c and the constant.
        a = np.hstack([2 * points, np.ones((len(points), 1))])
        solution = np.linalg.lstsq(a, (points**2).sum(axis=1), rcond=None)[0]
        centres.append(solution[:3])
    return np.array(centres)


def rigid_fit(source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """R, t with target ~ R source + t (Kabsch)."""
    cs, ct = source.mean(axis=0), target.mean(axis=0)
    u, _, vt = np.linalg.svd((source - cs).T @ (target - ct))
    d = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1, 1, d]) @ u.T
    return r, ct - r @ cs


def angle_of(r: np.ndarray) -> float:
    return math.acos(np.clip((np.trace(r) - 1) / 2, -1, 1))


def test_a_scripted_head_rotation_turns_the_rendered_view_by_the_same_angle():
    hmd = null_hmd()
    world = ambfplus.World()
    world.add_light("key", "directional", direction=(0.2, 0.3, 1.0))
    # Five spheres about a metre in front of the base camera (OpenCV frame: z ahead, y down).
    spots = [(-0.35, -0.25, 1.0), (0.3, -0.3, 1.1), (0.0, 0.05, 1.2), (-0.3, 0.3, 0.9),
             (0.35, 0.25, 1.0)]  # fmt: skip
    ids = [
        world.add_body(f"m{i}", "sphere", radius=0.06, pose=ambfplus.make_pose(p), mass=0.0).id
        for i, p in enumerate(spots)
    ]
    base = world.add_camera("base", 64, 64, fov_y=1.0, near=0.05, far=10.0)
    base.pose = np.eye(4)
    view = HmdView(world, hmd, base)
    left, right = view.cameras
    assert (left.width, left.height) == hmd.eye_resolution

    def centres():
        view.update()
        return [sphere_centres(c.capture(passes=["depth", "instance"]), ids) for c in (left, right)]

    hmd.set_rotation((0, 0, 0, 1))
    ahead = centres()
    # The eyes: the same orientation, the IPD apart along x.
    r, t = rigid_fit(ahead[1], ahead[0])
    assert math.degrees(angle_of(r)) < 0.05
    assert np.linalg.norm(t) == pytest.approx(hmd.ipd, abs=5e-4) and abs(t[0]) > 0.999 * hmd.ipd

    # Turn the head 15 degrees about an oblique axis (OpenHMD's frame: y up, z backwards).
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    angle = math.radians(15.0)
    q = (*(axis * math.sin(angle / 2)), math.cos(angle / 2))
    hmd.set_rotation(q)
    assert np.allclose(hmd.rotation, q, atol=1e-6)
    turned = centres()
    flip = np.diag([1.0, -1.0, -1.0])  # OpenHMD's frame to the camera's
    for before, after in zip(ahead, turned):
        # A point fixed in the world, seen before and after: before = R after + t, where R is
        # the eye's turn (the head's, in camera axes).
        r, _ = rigid_fit(after, before)
        assert math.degrees(abs(angle_of(r) - angle)) < 0.1
        assert np.abs(r - flip @ quaternion_matrix(q) @ flip).max() < 2e-3
    hmd.close()


@pytest.mark.slow
def test_side_by_side_halves_have_the_disparity_of_the_stated_pair(fixtures, display, tmp_path):
    """The launcher's side-by-side window on the original drilling scene: block matching between
    the two halves of a screenshot gives the disparity the stated pair predicts from depth
    (Z = f B / (d + dcx)), with zero disparity at the depth the camera looks at."""
    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    width, height = 1280, 480
    process, status_file, window = launch(
        display, tmp_path, launch_file, 8, "--stereo", "side-by-side", "--ipd", "0.025",
        "--width", str(width), "--height", str(height),
    )  # fmt: skip
    time.sleep(1.5)
    shot = screenshot(display)
    left_edge, top = window_origin(display, window)
    finish(process)
    shot = shot[top : top + height, left_edge : left_edge + width]
    stereo = json.loads(status_file.read_text())["stereo"]
    assert stereo["mode"] == "side-by-side" and stereo["views"] == 2
    eyes = stereo["eyes"]
    assert [e["size"] for e in eyes] == [[640, 480], [640, 480]]
    baseline = stereo["ipd"]
    assert baseline == 0.025
    focal = eyes[0]["focal"]
    dcx = eyes[1]["principal_point"][0] - eyes[0]["principal_point"][0]
    assert focal * baseline / stereo["convergence"] - dcx == pytest.approx(0.0, abs=1e-6)

    # The left eye, rebuilt from what the status states, gives depth.
    sim = ambfplus.Simulator.from_launch(launch_file, models=[0, 2])
    main = sim.get("main_camera")
    eye = sim.world.add_camera("eye", 640, 480, fov_y=main.fov_y, near=main.near, far=main.far)
    eye.pose = main.pose @ ambfplus.make_pose((-baseline / 2, 0.0, 0.0))
    eye.principal_point = eyes[0]["principal_point"]
    frame = eye.capture(passes=["rgb", "depth", "instance"])
    bone = frame.instance == sim.world.volumes[0].id
    below_status = np.zeros(bone.shape, bool)
    below_status[70:-20, 20:-20] = True
    left, right = shot[:, :640], shot[:, 640:]
    difference = np.abs(left.astype(int) - frame.rgb.astype(int)).max(axis=2)
    assert np.median(difference[bone & below_status]) <= 2, "the left half is the left eye"

    # Block matching where the window sees one surface (depth spread under 2 mm: no occlusion
    # edges) and has texture (block_match skips flat windows; the bone is mostly flat white).
    half = 8
    depth = np.where(bone, frame.depth, np.inf)
    windows = np.lib.stride_tricks.sliding_window_view(
        np.pad(depth, half, mode="edge"), (2 * half + 1, 2 * half + 1)
    )
    with np.errstate(invalid="ignore"):
        smooth = windows.max(axis=(2, 3)) - windows.min(axis=(2, 3)) < 0.002
    rows, cols = np.nonzero(bone & below_status & smooth)
    pick = np.arange(0, len(rows), max(1, len(rows) // 2500))
    rows, cols = rows[pick], cols[pick]
    predicted = focal * baseline / frame.depth[rows, cols] - dcx
    measured = block_match(left, right, rows, cols, int(predicted.min()) - 15,
                           int(predicted.max()) + 15, half=half)  # fmt: skip
    ok = ~np.isnan(measured)
    assert ok.sum() > 100
    error = np.abs(measured[ok] - predicted[ok])
    assert np.median(error) <= 0.5 and np.percentile(error, 95) <= 1.5


LENS_SCRIPT = r"""
import ctypes, json, sys
import glfw, numpy as np
from ambfplus._core import Window, use_x11_display
from ambfplus.scenes import demo_scene

glfw.init()
use_x11_display(ctypes.cast(glfw.get_x11_display(), ctypes.c_void_p).value)
glfw.window_hint(glfw.CLIENT_API, glfw.NO_API)
handle = glfw.create_window(320, 240, "lens-test", None, None)
world, camera = demo_scene(320, 240, resolution=64)
window = Window(glfw.get_x11_window(handle))
np.save(sys.argv[1], camera.capture(passes=["rgb"]).rgb)
print("ready", flush=True)
for line in sys.stdin:
    lens = json.loads(line)
    window.set_lens(**lens) if lens else window.set_lens(None)
    for _ in range(2):
        window.present([camera], 320, 240)
        glfw.poll_events()
    print("shown", flush=True)
"""


def through_lens(image, k, aberration=(1, 1, 1), centre=(0.5, 0.5), radius=0.5, aspect=1.0):
    """The documented lens model on the CPU: each window pixel shows the image at r (a r^3 +
    b r^2 + c r + d) from the lens centre, per channel; bilinear, black outside."""
    height, width = image.shape[:2]
    rows, cols = np.mgrid[0:height, 0:width].astype(np.float64)
    x, y = (cols + 0.5) / width, 1 - (rows + 0.5) / height  # y from the bottom
    px, py = x - centre[0], (y - centre[1]) / aspect
    r = np.hypot(px, py) / radius
    scale = ((k[0] * r + k[1]) * r + k[2]) * r + k[3]
    out = np.zeros(image.shape[:2] + (3,))
    for c in range(3):
        u = centre[0] + px * scale * aberration[c]
        v = centre[1] + py * scale * aberration[c] * aspect
        inside = (u >= 0) & (u <= 1) & (v >= 0) & (v <= 1)
        # Texel coordinates (row 0 at the image's top), clamped at the edges.
        tx = np.clip(u * width - 0.5, 0, width - 1)
        ty = np.clip((1 - v) * height - 0.5, 0, height - 1)
        x0, y0 = np.floor(tx).astype(int), np.floor(ty).astype(int)
        x1, y1 = np.minimum(x0 + 1, width - 1), np.minimum(y0 + 1, height - 1)
        fx, fy = tx - x0, ty - y0
        channel = image[..., c].astype(np.float64)
        value = (channel[y0, x0] * (1 - fx) * (1 - fy) + channel[y0, x1] * fx * (1 - fy)
                 + channel[y1, x0] * (1 - fx) * fy + channel[y1, x1] * fx * fy)  # fmt: skip
        out[..., c] = np.where(inside, value, 0)
    return out


def test_lens_distortion_pass_matches_the_documented_model(display, tmp_path):
    script = tmp_path / "lens.py"
    script.write_text(LENS_SCRIPT)
    process = subprocess.Popen(
        [sys.executable, str(script), str(tmp_path / "rgb.npy")],
        env={**os.environ, "DISPLAY": display}, stdin=subprocess.PIPE, stdout=subprocess.PIPE,
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    try:
        assert process.stdout.readline().strip() == "ready", process.stderr.read()
        window = xdo(display, "search", "--sync", "--name", "^lens-test$").split()[0]
        left, top = window_origin(display, window)

        def show(lens):
            process.stdin.write(json.dumps(lens) + "\n")
            process.stdin.flush()
            assert process.stdout.readline().strip() == "shown", process.stderr.read()
            return screenshot(display)[top : top + 240, left : left + 320].astype(np.float64)

        plain = show(None)
        rgb = np.load(tmp_path / "rgb.npy").astype(np.float64)
        assert np.abs(plain - rgb).max() <= 1, "without a lens the window shows the image"
        assert rgb.mean() > 20

        identity = show({"k": [0, 0, 0, 1]})
        assert np.abs(identity - plain).max() <= 2

        # d = 0.5: every pixel shows the image at half its distance from the centre, i.e. the
        # image magnified twice about the centre.
        zoom = show({"k": [0, 0, 0, 0.5], "aspect": 320 / 240})
        rows, cols = np.mgrid[0:240, 0:320]
        source = rgb[(60 + rows // 2), (80 + cols // 2)]
        agree = np.abs(zoom - source).max(axis=2)
        assert np.median(agree) <= 1

        # Barrel correction with chromatic aberration, off-centre lens: the CPU model.
        lens = {"k": [0.1, 0.15, 0.25, 0.45], "aberration": [0.99, 1.0, 1.02],
                "centres": [[0.55, 0.48]], "radius": 0.6, "aspect": 320 / 240}  # fmt: skip
        shown = show(lens)
        expected = through_lens(rgb, lens["k"], lens["aberration"], lens["centres"][0],
                                lens["radius"], lens["aspect"])  # fmt: skip
        error = np.abs(shown - expected).max(axis=2)
        assert np.median(error) <= 1 and np.percentile(error, 99) <= 3
        assert (shown.max(axis=2) == 0).sum() > 0.01 * error.size, "some pixels see past the image"
    finally:
        process.stdin.close()
        process.wait(timeout=30)
