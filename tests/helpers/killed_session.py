"""A recorded drilling session killed with SIGKILL at a chosen moment, and what it lost: the
simulation time it had reached against the latest time its recording holds. Used by the crash
safety test and the ``sigkill_loss`` benchmark."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

TESTS = Path(__file__).resolve().parents[1]

# The child: the phantom scene drilled by a scripted device, a stereo pair and the step log
# recorded every 40 steps; it prints the simulation time reached after every world.step, before
# anything of those steps is handed to the recorder. `slow_writer_s` makes each part append of
# the writer thread sleep (a slow disk or a starved writer).
CHILD = """
import sys, time
sys.path.insert(0, {tests!r})
import ambfplus.recording.writer as writer
from ambfplus.recording import Recorder
from ambfplus.scenes import drilling_phantom
from ambfplus.scenes.session import drain
from helpers.drilling import plunge_and_cut

slow = {slow_writer_s!r}
if slow:
    append = writer._PartFile.append
    def slow_append(self, rows):
        time.sleep(slow)
        return append(self, rows)
    writer._PartFile.append = slow_append
scene = drilling_phantom(resolution=48, width=160, height=120)
world, drill, rig = scene.world, scene.drill, scene.rig
binding = world.add_input_device("hand", plunge_and_cut(scene), drill)
world.start_step_log(list(scene.logged) + [binding])
with Recorder({path!r}, metadata={{"run": "sigkill"}}, flush_interval_s={flush!r}) as rec:
    rec.set_legend(world)
    print("start", flush=True)
    while True:
        world.step(40)
        print(world.time, flush=True)
        rec.add_stereo("rig", rig.capture(("rgb", "depth", "label")))
        drain(world, drill, rec)
"""


def recorded_time(path: Path) -> float:
    """The latest simulation time the (killed) recording holds, 0 when it holds nothing."""
    from ambfplus.recording import RecordingError, open_recording

    try:
        with open_recording(path) as rec:
            times = [float(rec.steps["time"][-1])] if rec.steps and len(rec.steps["time"]) else []
            for stream in rec.cameras.values():
                if len(stream):
                    times.append(float(stream.time[len(stream) - 1]))
            return max(times, default=0.0)
    except RecordingError:
        return 0.0


def kill_session(folder: Path, at_sim_s: float, flush: float = 1.0, slow_writer_s: float = 0.0,
                 timeout: float = 120.0) -> dict:  # fmt: skip
    """Runs the child until it reports `at_sim_s` of simulation time, kills it with SIGKILL and
    returns the time reached, the time recorded and the loss (seconds of simulation time)."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "killed.h5"
    code = CHILD.format(tests=str(TESTS), path=str(path), flush=flush,
                        slow_writer_s=slow_writer_s)  # fmt: skip
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True,
                             cwd=folder)  # fmt: skip
    reached = 0.0
    try:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            line = child.stdout.readline()
            if not line:
                raise RuntimeError(f"the recording session ended early (code {child.poll()})")
            if line.strip() == "start":
                continue
            reached = float(line)
            if reached >= at_sim_s:
                break
        os.kill(child.pid, signal.SIGKILL)
        child.wait(timeout=10)
        # What it printed before it died: the time it had reached.
        for line in child.stdout.read().splitlines():
            reached = max(reached, float(line))
    finally:
        if child.poll() is None:
            child.kill()
        child.stdout.close()
    recorded = recorded_time(path)
    return {"reached": reached, "recorded": recorded, "loss": reached - recorded}
