"""OpenXR sessions against a runtime loaded by the Khronos loader: tests/openxr/test_runtime.cpp,
a head-mounted display without hardware that takes the engine's EGL context, checks the calls it
gets, and writes out the eye images it is given. What is checked: the session follows the
runtime's states; the images the runtime receives show the world where the runtime's eye poses
and fields of view say (reprojection of known points, head ahead and turned); the launcher shows
the eyes in the headset and mirrors them in its window; and a missing runtime, or one without an
EGL binding, is named in the error."""

from __future__ import annotations

import ctypes.util
import json
import math
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import TESTS
from helpers.x11 import finish, launch, screenshot, window_origin

import ambfplus
from ambfplus.devices.hmd import XrView, xr_eye_geometry

SOURCE = TESTS / "openxr" / "test_runtime.cpp"


@pytest.fixture(scope="session")
def runtime_manifest(tmp_path_factory) -> Path:
    """The test runtime, compiled once, and its manifest for XR_RUNTIME_JSON."""
    if not ambfplus.openxr_built():
        pytest.skip("ambfplus was built without OpenXR's headers (libopenxr-dev)")
    if not ctypes.util.find_library("openxr_loader"):
        pytest.skip("no OpenXR loader (Debian: libopenxr-loader1)")
    compiler = shutil.which("c++") or shutil.which("g++")
    if compiler is None or not Path("/usr/include/openxr/openxr_platform.h").exists():
        pytest.skip("the test runtime needs a C++ compiler and OpenXR's headers (libopenxr-dev)")
    epoxy = subprocess.run(["pkg-config", "--cflags", "epoxy"], capture_output=True, text=True)
    out = tmp_path_factory.mktemp("openxr")
    library = out / "libambfplus_test_runtime.so"
    subprocess.run([compiler, "-std=c++17", "-shared", "-fPIC", "-O1", str(SOURCE), "-o",
                    str(library), *epoxy.stdout.split()], check=True)  # fmt: skip
    manifest = out / "runtime.json"
    manifest.write_text(json.dumps({
        "file_format_version": "1.0.0",
        "runtime": {"name": "ambfplus test runtime", "library_path": str(library)},
    }))  # fmt: skip
    return manifest


@pytest.fixture
def xr_env(runtime_manifest, tmp_path, monkeypatch) -> Path:
    """The test runtime for this test; the directory it writes the eyes it is given into."""
    dump = tmp_path / "headset"
    dump.mkdir()
    monkeypatch.setenv("XR_RUNTIME_JSON", str(runtime_manifest))
    monkeypatch.setenv("AMBFPLUS_XR_DUMP", str(dump))
    monkeypatch.setenv("AMBFPLUS_XR_HEAD", str(tmp_path / "head.txt"))
    return dump


def read_ppm(path: Path) -> np.ndarray:
    data = path.read_bytes()
    magic, width, height, depth, pixels = data.split(maxsplit=4)
    assert magic == b"P6" and depth == b"255"
    return np.frombuffer(pixels, np.uint8).reshape(int(height), int(width), 3)


def last_frame(dump: Path) -> dict:
    return json.loads((dump / "frames.jsonl").read_text().splitlines()[-1])


def quaternion_matrix(q) -> np.ndarray:
    x, y, z, w = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def project(view: dict, point_gl: np.ndarray, width: int, height: int) -> np.ndarray:
    """Where OpenXR's view (pose: qx qy qz qw px py pz; fov: left right up down) puts a point
    of its space (OpenGL axes) in its image: pixels from the left and from the top."""
    r = quaternion_matrix(view["pose"][:4])
    p = r.T @ (point_gl - np.asarray(view["pose"][4:]))
    left, right, up, down = (math.tan(a) for a in view["fov"])
    x, y = p[0] / -p[2], p[1] / -p[2]
    return np.array([(x - left) / (right - left) * width, (up - y) / (up - down) * height])


def markers(world) -> list[np.ndarray]:
    """Five spheres about a metre ahead of the head's start (the base camera; OpenCV axes)."""
    world.add_light("key", "directional", direction=(0.1, 0.2, 1.0))
    spots = [(-0.3, -0.2, 1.0), (0.25, -0.25, 1.1), (0.0, 0.05, 1.2), (-0.25, 0.25, 0.9),
             (0.3, 0.2, 1.0)]  # fmt: skip
    for i, p in enumerate(spots):
        world.add_body(f"m{i}", "sphere", radius=0.04, pose=ambfplus.make_pose(p), mass=0.0,
                       color=(0.9, 0.9, 0.9))  # fmt: skip
    return [np.array(p) for p in spots]


def reprojection_errors(image: np.ndarray, view: dict, spots) -> list[float]:
    """For each sphere the view puts well inside its image: the distance between the centroid of
    what the image shows around where the view projects the sphere's centre, and that projection
    (pixels)."""
    height, width = image.shape[:2]
    shown = np.abs(image.astype(int) - image[0, 0].astype(int)).sum(axis=2) > 30
    rows, cols = np.mgrid[0:height, 0:width]
    errors = []
    for spot in spots:
        predicted = project(view, np.array([spot[0], -spot[1], -spot[2]]), width, height)
        if not (25 < predicted[0] < width - 25 and 25 < predicted[1] < height - 25):
            continue
        near = shown & (np.hypot(cols + 0.5 - predicted[0], rows + 0.5 - predicted[1]) < 25)
        assert near.sum() > 100, f"no sphere where the view puts one ({predicted})"
        centroid = np.array([cols[near].mean() + 0.5, rows[near].mean() + 0.5])
        errors.append(float(np.linalg.norm(centroid - predicted)))
    assert len(errors) >= 3, "the spheres are out of view"
    return errors


def run_frames(session, view: XrView, count: int) -> list:
    eyes = []
    for _ in range(count):
        session.poll_events()
        assert session.running, session.state
        eyes = session.wait_frame()
        session.end_frame(view.update(eyes))
    return eyes


def test_the_session_follows_the_runtimes_states(xr_env):
    session = ambfplus.OpenXrSession()
    assert session.runtime == "ambfplus test runtime 0.1.0" and session.system == "test headset"
    assert session.eye_sizes == [[320, 240], [320, 240]]
    assert not session.running
    with pytest.raises(ambfplus.RenderError, match="poll_events"):
        session.wait_frame()
    world = ambfplus.World()
    base = world.add_camera("base", 64, 64)
    view = XrView(world, base)
    run_frames(session, view, 3)
    assert session.state == "focused" and session.frames == 3
    # A camera short: the frame still ends, and the next one goes on.
    session.poll_events()
    session.wait_frame()
    with pytest.raises(ValueError, match="a camera per eye"):
        session.end_frame(view.cameras[:1])
    run_frames(session, view, 1)
    assert session.frames == 4
    session.request_exit()
    session.poll_events()
    assert session.state == "exiting" and session.ended and not session.running


def test_the_headset_shows_the_world_where_its_eyes_are(xr_env, tmp_path):
    world = ambfplus.World()
    spots = markers(world)
    base = world.add_camera("base", 64, 64, near=0.05, far=10.0)
    base.pose = np.eye(4)
    session = ambfplus.OpenXrSession()
    view = XrView(world, base)
    head = tmp_path / "head.txt"

    head.write_text("0 0 0 1")
    ahead = run_frames(session, view, 2)
    frame = last_frame(xr_env)
    # The layer submitted is the located views, each eye its own swapchain image.
    for submitted, located in zip(frame["views"], frame["located"]):
        assert np.allclose(submitted["pose"], located["pose"])
        assert np.allclose(submitted["fov"], located["fov"])
        assert submitted["rect"] == [0, 0, 320, 240]
    # The eye cameras: square pixels over each eye's asymmetric field of view.
    for camera, eye in zip(view.cameras, ahead):
        width, height, fov_y, cx, cy = xr_eye_geometry(eye["fov"], eye["size"])
        assert (camera.width, camera.height) == (width, height)
        k = camera.intrinsics
        assert k[0, 2] == pytest.approx(cx) and k[1, 2] == pytest.approx(cy)
        assert -math.atan(cx / k[0, 0]) == pytest.approx(eye["fov"][0], abs=1e-6)
        assert math.atan((width - cx) / k[0, 0]) == pytest.approx(eye["fov"][1], abs=2e-3)
    assert np.linalg.norm(view.cameras[1].pose[:3, 3] - view.cameras[0].pose[:3, 3]) == (
        pytest.approx(0.064, abs=1e-6)
    )
    for i in range(2):
        errors = reprojection_errors(read_ppm(xr_env / f"eye{i}.ppm"), frame["views"][i], spots)
        assert max(errors) < 1.0, errors

    # The head turns 15 degrees about an oblique axis (OpenXR's axes) and moves 2 cm.
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    angle = math.radians(15.0)
    q = (*(axis * math.sin(angle / 2)), math.cos(angle / 2))
    head.write_text(" ".join(str(v) for v in (*q, 0.02, 0.0, 0.0)))
    before = [c.pose.copy() for c in view.cameras]
    run_frames(session, view, 1)
    frame = last_frame(xr_env)
    for camera, pose in zip(view.cameras, before):
        turn = pose[:3, :3].T @ camera.pose[:3, :3]
        assert math.degrees(math.acos(np.clip((np.trace(turn) - 1) / 2, -1, 1))) == (
            pytest.approx(15.0, abs=0.01)
        )
    for i in range(2):
        errors = reprojection_errors(read_ppm(xr_env / f"eye{i}.ppm"), frame["views"][i], spots)
        assert max(errors) < 1.0, errors


def test_a_missing_runtime_or_one_without_egl_is_named(runtime_manifest, tmp_path, monkeypatch):
    monkeypatch.setenv("XR_RUNTIME_JSON", str(tmp_path / "no-runtime.json"))
    with pytest.raises(ambfplus.RenderError, match="xrCreateInstance|XR_ERROR"):
        ambfplus.OpenXrSession()
    monkeypatch.setenv("XR_RUNTIME_JSON", str(runtime_manifest))
    monkeypatch.setenv("AMBFPLUS_XR_NO_EGL", "1")
    with pytest.raises(ambfplus.RenderError, match="XR_MNDX_egl_enable"):
        ambfplus.OpenXrSession()


@pytest.mark.slow
def test_the_launcher_shows_the_eyes_in_the_headset_and_mirrors_them(
    fixtures, display, xr_env, tmp_path, monkeypatch
):
    """The launcher on the original drilling scene with --stereo openxr: the runtime gets frames
    of the eyes, the window mirrors them, and when the runtime ends the session the window goes
    on showing the eyes."""
    monkeypatch.setenv("AMBFPLUS_XR_EXIT_AFTER", "15")
    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    process, status_file, window = launch(display, tmp_path, launch_file, 8, "--stereo", "openxr")
    time.sleep(1.0)
    deadline = time.time() + 60
    while time.time() < deadline:
        status = json.loads(status_file.read_text())
        if status["stereo"]["openxr"]["state"] == "exiting":
            break
        time.sleep(0.2)
    frames_then = status["frames"]
    time.sleep(1.5)
    shot = screenshot(display)
    left_edge, top = window_origin(display, window)
    output = finish(process)
    assert "OpenXR: test headset on ambfplus test runtime 0.1.0" in output, output
    status = json.loads(status_file.read_text())
    stereo = status["stereo"]
    assert stereo["mode"] == "openxr" and stereo["openxr"]["frames"] == 15
    assert stereo["openxr"]["state"] == "exiting"
    assert status["frames"] > frames_then, "the window stopped when the headset did"
    assert stereo["ipd"] == pytest.approx(0.064, abs=1e-6)
    assert len((xr_env / "frames.jsonl").read_text().splitlines()) == 15
    eye = read_ppm(xr_env / "eye0.ppm")
    assert eye.std() > 10, "the headset got a blank eye"
    # The window (two eyes side by side, 640x240) mirrors what the headset got.
    mirror = shot[top : top + 240, left_edge : left_edge + 320].astype(float)
    assert np.abs(mirror - eye.astype(float)).mean() < 8


def test_an_eye_camera_follows_a_changed_field_of_view():
    """Runtimes may change an eye's field of view; the camera's focal length and principal point
    follow it (fov_y is settable and checked)."""
    world = ambfplus.World()
    camera = world.add_camera("eye", 282, 240)
    width, height, fov_y, cx, cy = xr_eye_geometry((-0.5, 0.6, 0.45, -0.5), (320, 240))
    camera.fov_y = fov_y
    camera.principal_point = (cx, cy)
    k = camera.intrinsics
    assert k[0, 0] == pytest.approx(height / (math.tan(0.45) + math.tan(0.5)))
    assert k[0, 2] == pytest.approx(math.tan(0.5) * k[0, 0])
    assert k[1, 2] == pytest.approx(math.tan(0.45) * k[1, 1])
    with pytest.raises(ValueError, match="fov_y"):
        camera.fov_y = math.pi
    assert camera.fov_y == fov_y
