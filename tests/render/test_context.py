"""The one EGL context per process: what it reports, threads, and forks."""

from __future__ import annotations

import multiprocessing
import subprocess
import sys
import textwrap
import threading

import numpy as np

import ambfplus


def test_gl_info_reports_an_opengl_45_context():
    info = ambfplus.gl_info()
    assert set(info) >= {
        "vendor",
        "renderer",
        "version",
        "glsl_version",
        "profile",
        "platform",
        "device",
        "egl_vendor",
        "egl_version",
        "device_index",
    }
    major, minor = (int(v) for v in info["version"].split()[0].split(".")[:2])
    assert (major, minor) >= (4, 5)
    assert info["profile"] in ("compatibility", "core")
    assert info["platform"] in ("device", "surfaceless")
    assert info["renderer"]


def scene(name: str, offset: float):
    world = ambfplus.World()
    world.add_body("ball", "sphere", radius=0.1, pose=ambfplus.make_pose((0, offset, 0)))
    camera = world.add_camera(name, 96, 72, 0.7, 0.01, 10.0)
    camera.look_at((0.6, 0, 0), (0, 0, 0))
    return world, camera


def test_captures_from_several_threads_are_correct():
    cameras = [scene(f"cam{i}", 0.05 * i) for i in range(3)]
    expected = [camera.capture().depth.copy() for _, camera in cameras]
    failures = []

    def run(i):
        for _ in range(15):
            if not np.array_equal(cameras[i][1].capture().depth, expected[i]):
                failures.append(i)

    threads = [threading.Thread(target=run, args=(i,)) for i in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not failures
    assert not np.array_equal(expected[0], expected[2]), "the scenes differ"


def test_python_runs_while_a_capture_renders():
    world = ambfplus.World()
    world.add_body("wall", "plane", mass=0)
    camera = world.add_camera("big", 2048, 2048, 0.7, 0.01, 10.0)
    camera.look_at((0, 0, 1), (0, 0, 0), (0, 1, 0))
    camera.capture()

    # This thread counts loop turns made while the worker is inside capture(). Had capture()
    # kept the GIL, no bytecode of this thread could run between the two flags (whatever the
    # machine's load, so the count says it, not a timing).
    inside, done = threading.Event(), threading.Event()

    def work():
        inside.set()
        camera.capture()
        inside.clear()
        done.set()

    worker = threading.Thread(target=work)
    turns = 0
    worker.start()
    while not done.is_set():
        if inside.is_set():
            turns += 1
    worker.join()
    assert turns > 100, f"only {turns} turns of Python ran during a 2048x2048 capture"


def child_capture(queue):
    try:
        _, camera = scene("child", 0.0)
        camera.capture()
        queue.put("rendered")
    except ambfplus.RenderError as e:
        queue.put(f"RenderError: {e}")


def test_a_forked_child_cannot_use_its_parents_context():
    _, camera = scene("parent", 0.0)
    camera.capture()  # the parent's context now exists
    ctx = multiprocessing.get_context("fork")
    queue = ctx.Queue()
    p = ctx.Process(target=child_capture, args=(queue,))
    p.start()
    message = queue.get(timeout=60)
    p.join(timeout=60)
    assert message.startswith("RenderError"), message
    assert "fork" in message and "before" in message


def test_a_child_forked_before_any_rendering_renders(tmp_path):
    script = textwrap.dedent(
        """
        import multiprocessing, ambfplus

        def work(q):
            w = ambfplus.World()
            w.add_body("b", "sphere", radius=0.1)
            c = w.add_camera("c", 32, 24)
            c.look_at((0.5, 0, 0), (0, 0, 0))
            q.put(float((c.capture().depth > 0).mean()))

        if __name__ == "__main__":
            ctx = multiprocessing.get_context("fork")
            q = ctx.Queue()
            p = ctx.Process(target=work, args=(q,))
            p.start()
            child = q.get(timeout=60)
            p.join()
            work(q)
            print(child, q.get())
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=120, cwd=tmp_path
    )
    assert out.returncode == 0, out.stderr
    child, parent = (float(v) for v in out.stdout.split())
    assert child > 0 and child == parent
