"""Memory of a long session (issue #20): nothing the engine keeps may grow with every step.

``session_memory``: a scripted drilling session of the built-in phantom (256^3) on the 1 kHz
real-time loop for 10 minutes (2 with --quick), the drill driven along a fixed script, with a
640x480 stereo pair captured every 50 ms (rgb, depth, label) in another thread. The figure is the
growth of the process's resident set after the first minute (target < 20 MB): the largest RSS
seen after minute 1 minus the RSS at minute 1. The first minute is excluded because allocators,
shader caches and the renderer's uploads settle there.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator

import numpy as np

import ambfplus

PAGE = 4096


def resident_mb() -> float:
    """This process's resident set, MB (from /proc, no extra dependency)."""
    with open("/proc/self/statm") as statm:
        return int(statm.read().split()[1]) * PAGE / 1e6


def _script(hand, into: np.ndarray, side: np.ndarray, stop: threading.Event, period: float):
    """Moves the hand into the bone and along it, burr on, a new target every `period` s."""
    k = 0
    while not stop.wait(period):
        depth = 0.007 + 0.003 * (0.5 + 0.5 * np.sin(0.05 * k))  # 0-3 mm into the bone
        hand.set_target(into * depth + side * 0.006 * np.sin(0.3 * k), buttons=1)
        k += 1


def session_memory(args) -> Iterator[dict]:
    from ambfplus.scenes import drilling_phantom

    seconds = 120.0 if args.quick else 600.0
    scene = drilling_phantom(resolution=256, width=640, height=480)
    world, drill = scene.world, scene.drill
    hand = ambfplus.SimulatedDevice()
    world.add_input_device("hand", hand, drill, **scene.device_options)
    into = np.array([0.0, 0.0, -1.0])
    side = np.array([1.0, 0.0, 0.0])
    rig = scene.rig
    rig.capture(passes=["rgb", "depth", "label"])  # uploads and programs before the clock

    stop = threading.Event()
    captures = [0]

    def capture():
        next_time = time.monotonic()
        while not stop.is_set():
            rig.capture(passes=["rgb", "depth", "label"])
            captures[0] += 1
            next_time += 0.05
            stop.wait(max(0.0, next_time - time.monotonic()))

    samples: list[tuple[float, float]] = []
    loop = ambfplus.RealTimeLoop(world)
    threads = [
        threading.Thread(target=capture),
        threading.Thread(target=_script, args=(hand, into, side, stop, 0.1)),
    ]
    start = time.monotonic()
    with loop:
        for thread in threads:
            thread.start()
        while (elapsed := time.monotonic() - start) < seconds:
            samples.append((elapsed, resident_mb()))
            time.sleep(5.0)
        stop.set()
        for thread in threads:
            thread.join()
    samples.append((time.monotonic() - start, resident_mb()))

    settled = min(samples, key=lambda s: abs(s[0] - 60.0))[1]
    later = [mb for t, mb in samples if t >= 60.0]
    stats = loop.stats
    yield {
        "bench": "session_memory",
        "value": round(max(later) - settled, 2),
        "unit": "MB RSS growth after minute 1",
        "target": 20,
        "rss_at_1min_mb": round(settled, 1),
        "rss_end_mb": round(samples[-1][1], 1),
        "rss_max_mb": round(max(mb for _, mb in samples), 1),
        "rss_by_minute_mb": [round(mb, 1) for t, mb in samples if int(t) % 60 < 5],
        "seconds": round(samples[-1][0], 1),
        "steps": int(stats["steps"]),
        "max_period_ms": round(stats["max"] * 1e3, 3),
        "captures": captures[0],
        "voxels_removed": int(len(drill.removed["step"])),
        "what": "RSS of a scripted real-time drilling session, 640x480 stereo captured every 50 ms",
    }


BENCHMARKS = {"session_memory": session_memory}
