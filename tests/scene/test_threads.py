"""The thread-safety contract: calls that change a world's structure (add objects, load files,
plugins, volume edits) take the world's lock themselves, so that they are safe from any thread
while a RealTimeLoop steps and other threads capture; what cannot be safe then is a StateError;
interpreter exit stops a running loop. Each crash case runs in its own process, so that a
regression fails its test instead of the test run."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

import ambfplus
from ambfplus.scenes import drilling_phantom

# Three seconds of the phantom scene stepped by a RealTimeLoop while the threads in BODY run;
# prints "ok" and what the threads did.
PRELUDE = """
import threading, time, sys
import ambfplus
from ambfplus.scenes import drilling_phantom

scene = drilling_phantom(resolution=32, width=64, height=48)
world, rig = scene.world, scene.rig
volume = scene.drill.volume
stop = threading.Event()
errors, counts = [], {}

def repeat(name, fn):
    def run():
        i = 0
        while not stop.is_set():
            try:
                fn(i)
            except ambfplus.Error as error:  # a typed refusal is fine; a crash is not
                counts[name + " refused"] = counts.get(name + " refused", 0) + 1
            except Exception as error:
                errors.append(repr(error))
                return
            i += 1
            counts[name] = i
    return threading.Thread(target=run, name=name)

def capture(i):
    rig.capture(("rgb", "depth", "label"))
"""

RUN = """
loop = ambfplus.RealTimeLoop(world, fifo_priority=0)
loop.start()
threads = [repeat(name, fn) for name, fn in JOBS]
for t in threads:
    t.start()
time.sleep(3.0)
stop.set()
for t in threads:
    t.join()
loop.stop()
assert not errors, errors
print("ok", sorted(counts.items()), loop.stats["steps"], flush=True)
"""


def run_child(body: str, tmp_path, timeout: float = 120) -> subprocess.CompletedProcess:
    code = textwrap.dedent(PRELUDE) + textwrap.dedent(body) + textwrap.dedent(RUN)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=timeout)  # fmt: skip


def assert_survived(done: subprocess.CompletedProcess, *names: str) -> None:
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout}\n{done.stderr[-3000:]}"
    assert done.stdout.startswith("ok"), done.stdout
    for name in names:
        assert f"('{name}', " in done.stdout, (name, done.stdout)  # each thread did its work


def test_adding_and_loading_from_threads_while_a_loop_steps_and_a_thread_captures(tmp_path):
    """Before: SIGSEGV, or SIGABRT "free(): invalid next size" with the capture thread."""
    for n in range(400):
        (tmp_path / f"m{n}.yaml").write_text(
            f"bodies: [BODY cube{n}]\nBODY cube{n}:\n  name: cube{n}\n  mass: 0.1\n"
            "  collision shape: BOX\n  collision geometry: {x: 0.002, y: 0.002, z: 0.002}\n"
            "  location: {position: {x: 0.05, y: 0, z: 0.05}, orientation: {r: 0, p: 0, y: 0}}\n"
        )
    body = """
    from pathlib import Path
    def add(i):
        world.add_body(f"ball{i}", "sphere", radius=0.001, pose=None, mass=0.01)
    def load(i):
        world.load_adf(Path(f"m{i % 400}.yaml"))
    JOBS = [("add", add), ("load", load), ("capture", capture)]
    """
    assert_survived(run_child(body, tmp_path), "add", "load", "capture")


def test_volume_edits_resets_and_captures_from_three_threads(tmp_path):
    """Before: SIGSEGV (an edit or a reset while a capture read the grid)."""
    body = """
    import numpy as np
    def edit(i):
        volume.remove_sphere((0.004 * np.sin(i), 0.004 * np.cos(i), 0.006), 0.002)
    def reset(i):
        volume.data.reset()
    JOBS = [("edit", edit), ("reset", reset), ("capture", capture)]
    """
    assert_survived(run_child(body, tmp_path), "edit", "reset", "capture")


def test_plugins_load_close_and_reset_from_three_threads(tmp_path):
    """Before: SIGSEGV."""
    body = """
    class Quiet(ambfplus.Plugin):
        def physics_update(self, dt):
            pass
    def load(i):
        world.load_plugin(Quiet(), name=f"quiet{i}")
    def close(i):
        world.close_plugins()
    def reset(i):
        world.reset_plugins()
    JOBS = [("load", load), ("close", close), ("reset", reset)]
    """
    assert_survived(run_child(body, tmp_path), "load", "close", "reset")


def test_exit_with_a_running_loop_and_a_capturing_daemon_thread_is_clean(tmp_path):
    """Before: SIGABRT ("terminate called without an active exception")."""
    code = textwrap.dedent(PRELUDE) + textwrap.dedent(
        """
        loop = ambfplus.RealTimeLoop(world, fifo_priority=0)
        loop.start()
        def film():
            while True:
                capture(0)
        threading.Thread(target=film, daemon=True).start()
        time.sleep(0.5)
        print("leaving", flush=True)
        """
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, timeout=120)  # fmt: skip
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stderr[-3000:]}"
    assert "leaving" in done.stdout and "terminate called" not in done.stderr


def test_what_cannot_be_safe_during_a_loop_is_a_state_error():
    scene = drilling_phantom(resolution=32, width=64, height=48)
    world = scene.world
    with ambfplus.RealTimeLoop(world, fifo_priority=0):
        with pytest.raises(ambfplus.StateError, match="World.step: a RealTimeLoop is stepping"):
            world.step()
        with pytest.raises(ambfplus.StateError, match="Simulator.step: a RealTimeLoop"):
            world.simulator.step()
    world.step(2)  # the loop stopped: stepping is the script's again


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"fifo_priority": 500}, "fifo_priority must be 0 .* or 1..99"),
        ({"fifo_priority": -1}, "fifo_priority must be 0"),
        ({"cpu": 999}, "cpu must be -2 .* a CPU of this machine, 0..\\d+, got 999"),
        ({"cpu": -3}, "cpu must be -2"),
    ],
)
def test_a_loop_refuses_options_no_machine_honours(options, message):
    world = ambfplus.World()
    with pytest.raises(ambfplus.ArgumentError, match=message):
        ambfplus.RealTimeLoop(world, **options)
