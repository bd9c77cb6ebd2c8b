"""Window tests on a virtual X display (the `display` fixture, conftest.py): reading back what
the screen shows, sending keys, starting the launcher."""

from __future__ import annotations

import os
import struct
import subprocess
import sys
import time

import numpy as np


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


def screenshot(display: str) -> np.ndarray:
    """The whole screen, RGB."""
    data = subprocess.run(["xwd", "-root", "-silent"], env={**os.environ, "DISPLAY": display},
                          capture_output=True, timeout=30, check=True).stdout  # fmt: skip
    return read_xwd(data)


def window_origin(display: str, window: str) -> tuple[int, int]:
    """(left, top) of an X window on the screen."""
    geometry = xdo(display, "getwindowgeometry", window)
    left, top = (int(v) for v in geometry.split("Position: ")[1].split()[0].split(","))
    return left, top


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
