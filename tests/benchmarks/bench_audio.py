"""Drill sound: how long a haptic event takes to reach the audio buffer, what the sound costs
the real-time loop, and what synthesis costs the audio thread.

    python tests/benchmarks/run.py --only audio_latency
    python tests/benchmarks/run.py --only audio_synthesis

audio_latency: the built-in phantom stepped by a RealTimeLoop at 1 kHz with a DrillSound on
miniaudio's null device (which pulls samples on its own thread at the real rate, in 128-frame
periods; it polls its clock every 10 ms, so it asks in bursts), then on the virtual sound card
(`output="virtual"`, miniaudio's custom backend: called back once per 128-frame period at each
period's deadline, as a card's interrupt paces its driver): seconds from each tick's push (the
haptic step) to the moment its first sample is written into the device's buffer, median, p99
and max after 0.5 s of warm-up (target 10 ms); beside each, the loop's period p99 and max with
the sound on. Then the player alone with a paced consumer (a thread calling the audio callback
every 128 frames on absolute deadlines): the latency the player itself adds.

audio_synthesis: CPU seconds to synthesise one second of sound (48 kHz, burr on and cutting,
one warning beeping), offline: the audio thread's load as a fraction of real time.
"""

from __future__ import annotations

import importlib
import os
import sys
import time
from pathlib import Path

import numpy as np

import ambfplus
from ambfplus.scenes import drilling_phantom

BENCH_DIR = Path(
    os.environ.get(
        "AMBFPLUS_BENCH_DIR", Path(__file__).resolve().parents[2] / "build" / "cmake" / "benchmarks"
    )
)


def figures(name: str, seconds: np.ndarray) -> dict:
    ms = np.asarray(seconds, dtype=float) * 1e3
    return {
        "bench": name,
        "value": round(float(np.percentile(ms, 99)), 3),
        "unit": "ms (p99)",
        "median_ms": round(float(np.median(ms)), 3),
        "max_ms": round(float(ms.max()), 3),
        "ticks": int(len(ms)),
        "target_ms": 10.0,
    }


WHERE = {
    "null": "miniaudio's null device buffer (it wakes every 10 ms)",
    "virtual": "the virtual sound card's buffer (miniaudio's custom backend, called back every "
    "period on its own clock)",
}


def latency(args):
    seconds = 3.0 if args.quick else 10.0
    for output in ("null", "virtual"):
        scene = drilling_phantom(resolution=128)
        world, drill = scene.world, scene.drill
        drill.on = True
        sound = ambfplus.DrillSound(drill, output=output)
        taken = []  # taken each second: the player keeps the last 8192
        with ambfplus.RealTimeLoop(world) as loop:
            for _ in range(int(seconds)):
                time.sleep(1.0)
                taken.append(sound.take_latencies())
        stats = loop.stats
        samples = np.concatenate(taken)
        counters = sound.stats
        sound.close()
        out = figures(f"audio_latency_{output}_device", samples[500:])
        out.update(
            period_frames=sound.period_frames,
            callbacks=counters["callbacks"],
            dropped=counters["dropped"],
            held=counters["held"],
            loop_period_p99_ms=round(stats["p99"] * 1e3, 3),
            loop_period_max_ms=round(stats["max"] * 1e3, 3),
            loop_scheduling=loop.scheduling,
            what=f"haptic step (1 kHz RealTimeLoop) to the sample written into {WHERE[output]}",
        )
        yield out

    if str(BENCH_DIR) not in sys.path:
        sys.path.insert(0, str(BENCH_DIR))
    try:
        bench = importlib.import_module("ambfplus_bench")
    except ImportError as error:
        yield {"bench": "audio_latency_paced", "skipped": f"no ambfplus_bench ({error})"}
        return
    paced = np.asarray(bench.drill_sound_paced_latency(seconds, 128))
    out = figures("audio_latency_paced", paced[500:])
    out["what"] = "tick pushed at 1 kHz to the sample written, callbacks of 128 frames paced"
    yield out


def synthesis(args):
    seconds = 5 if args.quick else 20
    n = seconds * 1000
    on = np.ones(n)
    load = 1.0 + np.sin(np.arange(n) / 300.0)
    rate = np.abs(np.sin(np.arange(n) / 70.0)) * 30e-9
    distances = np.linspace(0.001, 0.0, n)[:, None]
    start = time.process_time()
    samples = ambfplus.render_drill_sound(
        on, load, rate, warnings={"nerve": 0.001}, distances=distances
    )
    cpu = time.process_time() - start
    yield {
        "bench": "audio_synthesis",
        "value": round(cpu / seconds, 5),
        "unit": "CPU s per s of sound",
        "samples": int(len(samples)),
        "what": "48 kHz mono: motor with 4 harmonics, band-passed cutting noise, a warning tone",
    }


BENCHMARKS = {"audio_latency": latency, "audio_synthesis": synthesis}
