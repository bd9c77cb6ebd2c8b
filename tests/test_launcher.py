"""The interactive launcher under a virtual display (Xvfb): it opens the original drilling scene
in a window, keys sent with xdotool move the drill by the documented steps, a screenshot of the
X server shows what the camera renders, and a recorded session replays to the same removal."""

from __future__ import annotations

import json
import os
import shutil
import struct
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import ambfplus

TOOLS = ("Xvfb", "xdotool", "xwd")
WIDTH, HEIGHT = 1536, 540


@pytest.fixture(scope="module")
def display():
    """A virtual X display of its own (Xvfb), torn down after the module."""
    missing = [tool for tool in TOOLS if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"needs {', '.join(missing)} (Debian: xvfb xdotool x11-apps)")
    pytest.importorskip("glfw", reason="the launcher's window needs glfw (pip: ambfplus[gui])")
    for number in range(90, 110):
        if not Path(f"/tmp/.X11-unix/X{number}").exists():
            break
    name = f":{number}"
    server = subprocess.Popen(
        ["Xvfb", name, "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    for _ in range(100):
        if Path(f"/tmp/.X11-unix/X{number}").exists():
            break
        time.sleep(0.05)
    yield name
    server.terminate()
    server.wait(timeout=10)


def read_xwd(data: bytes) -> np.ndarray:
    """An RGB image of an xwd dump of a 24- or 32-bit TrueColor screen."""
    fields = struct.unpack(">25I", data[:100])
    header, width, height = fields[0], fields[4], fields[5]
    byte_order, bits_per_pixel, bytes_per_line, ncolors = (
        fields[7],
        fields[11],
        fields[12],
        fields[19],
    )
    masks = fields[14:17]
    assert masks == (0xFF0000, 0xFF00, 0xFF), f"unexpected pixel masks {masks}"
    step = bits_per_pixel // 8
    rows = np.frombuffer(data, np.uint8, bytes_per_line * height, header + 12 * ncolors)
    pixels = rows.reshape(height, bytes_per_line)[:, : width * step].reshape(height, width, step)
    # Least significant byte first: blue, green, red.
    return (
        pixels[..., [2, 1, 0]] if byte_order == 0 else pixels[..., [step - 3, step - 2, step - 1]]
    )


def xdo(display: str, *args: str) -> str:
    return subprocess.run(
        ["xdotool", *args], env={**os.environ, "DISPLAY": display}, capture_output=True,
        text=True, timeout=30, check=True,
    ).stdout  # fmt: skip


def launch(display, tmp_path, launch_file, seconds, *extra):
    """Starts ambfplus-launch on the display; returns the process and its status file."""
    status = tmp_path / "status.json"
    process = subprocess.Popen(
        [sys.executable, "-m", "ambfplus.launcher", str(launch_file), "-l", "0,2",
         "--seconds", str(seconds), "--status", str(status), *extra],
        env={**os.environ, "DISPLAY": display}, cwd=tmp_path,
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    deadline = time.time() + 60
    window = ""
    while time.time() < deadline and not window:
        assert process.poll() is None, process.stdout.read()
        try:
            window = xdo(display, "search", "--name", "^ambfplus$").split()[0]
        except (subprocess.CalledProcessError, IndexError):
            time.sleep(0.2)
    assert window, "the launcher opened no window"
    # Frames are showing once the status file exists.
    while not status.exists() and time.time() < deadline:
        time.sleep(0.1)
    xdo(display, "windowfocus", "--sync", window)
    return process, status, window


def finish(process) -> str:
    out, _ = process.communicate(timeout=90)
    assert process.returncode == 0, out
    return out


def test_keys_move_the_drill_and_the_window_shows_the_scene(fixtures, display, tmp_path):
    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    process, status_file, window = launch(display, tmp_path, launch_file, 12)
    # Two steps into the view, one up; the burr spins; the next burr.
    xdo(display, "key", "--delay", "250", "ctrl+i", "ctrl+i", "ctrl+w", "space", "c")
    time.sleep(2.0)
    status = json.loads(status_file.read_text())
    screen = subprocess.run(["xwd", "-root", "-silent"], env={**os.environ, "DISPLAY": display},
                            capture_output=True, timeout=30, check=True).stdout  # fmt: skip
    geometry = xdo(display, "getwindowgeometry", window)
    finish(process)

    # The fixture's drill starts at (-0.2, 0, 0); main_camera at the origin looks along -x with
    # z up: 2 mm into the view is -x, 1 mm up is +z.
    np.testing.assert_allclose(status["drill_position"], [-0.202, 0.0, 0.001], atol=1e-6)
    assert status["spinning"] and status["burr_mm"] == 1.0
    assert status["mode"] == "keyboard" and status["physics_hz"] > 900
    assert status["critical"] and np.isfinite(status["critical_mm"])  # named by labels.csv

    # The screenshot is what the camera renders for that drill (the 1 mm burr's mesh, moved).
    left, top = (int(v) for v in geometry.split("Position: ")[1].split()[0].split(","))
    shot = read_xwd(screen)[top : top + HEIGHT, left : left + WIDTH]
    sim = ambfplus.Simulator.from_launch(
        launch_file, models=[0, 2], arguments=["--labels", str(launch_file.parent / "labels.csv")]
    )
    drill, main = sim.get("drill"), sim.get("main_camera")
    # The window shows main_camera's view at the window's size.
    camera = sim.world.add_camera("view", WIDTH, HEIGHT, fov_y=main.fov_y, near=main.near,
                                  far=main.far)  # fmt: skip
    camera.pose = main.pose
    goal = drill.goal.copy()
    goal[:3, 3] = status["drill_position"]
    drill.goal, drill.burr = goal, 0
    sim.step(2)
    frame = camera.capture(passes=["rgb", "instance"])
    body = frame.instance == sim.get("1mm").id
    bone = frame.instance == sim.world.volumes[0].id
    assert body.sum() > 200 and bone.sum() > 10000
    below_status = np.zeros(body.shape, bool)
    below_status[60:] = True  # the status line covers the top rows
    difference = np.abs(shot.astype(int) - frame.rgb.astype(int)).max(axis=2)
    assert np.median(difference[bone & below_status]) <= 2
    assert np.median(difference[body & below_status]) <= 2
    assert shot[bone].mean() > 60, "the anatomy is lit, not black"


def test_a_recorded_interactive_session_replays_to_the_same_removal(fixtures, display, tmp_path):
    from ambfplus.session import replay

    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    record = tmp_path / "session.h5"
    process, status_file, _ = launch(display, tmp_path, launch_file, 14, "--record", str(record))
    # The burr touches the ear about 76 mm in front of it: spin it and push 9 mm further.
    xdo(display, "key", "space")
    xdo(display, "key", "--delay", "20", "--repeat", "85", "ctrl+i")
    time.sleep(3.0)
    finish(process)
    status = json.loads(status_file.read_text())
    assert status["spinning"]

    report = replay(record, compare_images=False)
    assert report.voxels_removed > 100, "the session drilled"
    assert report.removal_identical and report.forces_identical, report.differences
