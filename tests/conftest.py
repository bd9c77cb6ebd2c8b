"""Shared fixtures (helper functions are in tests/helpers/). Tests use the installed package
only."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

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


# What window tests need: a virtual X server, keys sent to it, the screen read back.
X11_TOOLS = ("Xvfb", "xdotool", "xwd")


@pytest.fixture(scope="session")
def display():
    """A virtual X display of its own (Xvfb), torn down after the tests."""
    missing = [tool for tool in X11_TOOLS if shutil.which(tool) is None]
    if missing:
        pytest.skip(f"needs {', '.join(missing)} (Debian: xvfb xdotool x11-apps)")
    pytest.importorskip("glfw", reason="the launcher's window needs glfw (pip: ambfplus[gui])")
    # Xvfb picks a free display itself and writes its number to the pipe once it listens, so
    # test runs side by side never share (or lose) a display.
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        pass_fds=(write,),
    )
    os.close(write)
    with os.fdopen(read) as numbers:
        number = numbers.readline().strip()
    if not number:
        server.kill()
        pytest.fail(f"Xvfb did not start (exit status {server.wait(timeout=10)})")
    name = f":{number}"
    yield name
    server.terminate()
    server.wait(timeout=10)


# A small dataset spec that uses every kind of draw (12 episodes of 160x120 stereo pairs), and
# its dataset made once per session by one local worker: the reference the dataset tests
# compare other executors, worker counts and interrupted runs against.
DATASET_SPEC = """\
version: 1
name: ci-tiny
episodes: 12
seed: 7
capture: {every: 250, frames: 3, passes: [rgb, depth, label, instance, voxel]}
anatomies:
  - phantom: {resolution: 40, seed: {choice: [0, 1]}}
    weight: 2
  - phantom: {resolution: 48, seed: 3}
    name: phantom48
scenarios:
  - kind: camera
  - kind: drilling
    frames: {uniform: [5, 6]}
  - kind: mixed
    frames: 5
rigs:
  - resolution: [160, 120]
    baseline: {uniform: [0.05, 0.08]}
    working_distance: {uniform: [0.22, 0.28]}
  - resolution: [160, 120]
    working_distance: null
    weight: 0.5
appearance:
  lights: {count: {uniform: [1, 3]}, types: [directional, point, spot],
           intensity: {uniform: [0.3, 1.0]}, color: {uniform: [0.8, 1.0]}}
  labels: {color_jitter: 25}
  material: {specular: {uniform: [0.05, 0.4]}, shininess: {uniform: [8, 48]}}
  drill: {color_jitter: 0.05, specular: {uniform: [0.3, 0.8]}}
  background: {uniform: [0.0, 0.25]}
  intrinsics: {fov_y_jitter: 0.03, principal_point_jitter: 2.0}
  noise: {rgb_sigma: {uniform: [0.5, 2.0]}}
"""


@pytest.fixture(scope="session")
def dataset_spec(tmp_path_factory) -> Path:
    """The small dataset spec, written to a file."""
    path = tmp_path_factory.mktemp("spec") / "spec.yaml"
    path.write_text(DATASET_SPEC)
    return path


@pytest.fixture(scope="session")
def reference_dataset(dataset_spec, tmp_path_factory) -> Path:
    """The small spec's dataset, made by one local worker."""
    from ambfplus.dataset import generate

    out = tmp_path_factory.mktemp("reference") / "data"
    generate(dataset_spec, out, workers=1, progress=False)
    return out


# A dataset of any scene (issue #34): the multi-arm AMBF scene of tests/helpers/multi_arm.py,
# loaded from its launch file, driven by a Python episode script; its dataset made once per
# session by one local worker, the reference for other worker counts, Ray and resumed runs.
MULTI_ARM_SPEC = """\
version: 1
name: two arms
episodes: 6
seed: 11
scene:
  launch: scene/launch.yaml
  models: [0, 1, 2, 3]
  python_path: [scene]
episode:
  script: {script}
capture: {{every: 50, frames: 10, passes: [rgb, depth, instance]}}
appearance:
  lights: {{count: 1, types: [directional], intensity: {{uniform: [0.4, 0.9]}}}}
  background: {{uniform: [0.0, 0.2]}}
  noise: {{rgb_sigma: 1.5}}
"""


@pytest.fixture(scope="session")
def multi_arm_spec(tmp_path_factory) -> Path:
    """The multi-arm scene's files and its dataset spec, written to a folder."""
    from helpers.multi_arm import write_episode_script, write_multi_arm_scene

    folder = tmp_path_factory.mktemp("multi_arm")
    write_multi_arm_scene(folder / "scene")
    script = write_episode_script(folder / "scene")
    path = folder / "spec.yaml"
    path.write_text(MULTI_ARM_SPEC.format(script=script))
    return path


@pytest.fixture(scope="session")
def multi_arm_dataset(multi_arm_spec, tmp_path_factory) -> Path:
    """The multi-arm spec's dataset, made by one local worker."""
    from ambfplus.dataset import generate

    out = tmp_path_factory.mktemp("multi_arm_reference") / "data"
    generate(multi_arm_spec, out, workers=1, progress=False)
    return out


# Long measurements run only when asked for: `pytest -m benchmark`. (Fuzz-marked tests run
# wherever atheris is installed, as in CI; `-m "not fuzz"` leaves them out.)
OPT_IN_MARKS = ("benchmark",)


@pytest.hookimpl(tryfirst=True)  # before -m deselects by marks
def pytest_collection_modifyitems(config, items):
    # A test that needs a virtual X display is a window test, whichever file it is in.
    for item in items:
        if "display" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.gui)
    asked = config.getoption("markexpr") or ""
    for mark in OPT_IN_MARKS:
        if re.search(rf"(?<!not )\b{mark}\b", asked):
            continue
        skip = pytest.mark.skip(reason=f"long test: run it with pytest -m {mark}")
        for item in items:
            if mark in item.keywords:
                item.add_marker(skip)
