"""Shared test helpers. Tests use the installed package only."""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

# Real files from the original system live beside the repository (../shared/fixtures) on the
# project's machines and in CI; elsewhere the tests that need them skip.
FIXTURES = Path(
    os.environ.get("AMBFPLUS_FIXTURES", Path(__file__).resolve().parents[2] / "shared" / "fixtures")
)


@pytest.fixture
def fixtures() -> Path:
    if not FIXTURES.is_dir():
        pytest.skip(
            f"the original system's fixture files are not here ({FIXTURES}); "
            "set AMBFPLUS_FIXTURES to their folder to run this test"
        )
    return FIXTURES


def pixel_rays(intrinsics: np.ndarray, height: int, width: int) -> np.ndarray:
    """Camera-frame ray directions (z = 1) through every pixel centre, (H, W, 3)."""
    cols, rows = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    k = intrinsics
    x = (cols - k[0, 2]) / k[0, 0]
    y = (rows - k[1, 2]) / k[1, 1]
    return np.stack([x, y, np.ones_like(x)], axis=-1)


def backproject(frame) -> np.ndarray:
    """World-frame points of every pixel with a hit, (N, 3), from depth, intrinsics and pose."""
    rays = pixel_rays(frame.intrinsics, frame.height, frame.width)
    valid = frame.depth > 0
    cam = rays[valid] * frame.depth[valid][:, None].astype(np.float64)
    pose = frame.pose
    return cam @ pose[:3, :3].T + pose[:3, 3]


# What window tests need: a virtual X server, keys sent to it, the screen read back.
X11_TOOLS = ("Xvfb", "xdotool", "xwd")


@pytest.fixture(scope="session")
def display():
    """A virtual X display of its own (Xvfb), torn down after the tests."""
    missing = [tool for tool in X11_TOOLS if shutil.which(tool) is None]
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
