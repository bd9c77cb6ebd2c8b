"""Virtual fixtures: what a fixture query costs, and what the drill's distance fields cost.

    python tests/benchmarks/run.py --only fixture_query
    python tests/benchmarks/run.py --only drill_distance_fields
    python tests/benchmarks/run.py --only distance_field_build

fixture_query: the 128^3 phantom's drill with a forbidden-region fixture on each of its five
critical structures (start 2 mm); the fixtures' push on a burr centred at 20,000 points (half
anywhere in the phantom, half within 4 mm of the facial nerve), each query timed alone in C++
(ambfplus_bench.fixture_queries): median, p99 and max per cursor per tick (target p99 <= 2 us).
The figures include the clock's own cost (two steady_clock reads, about 20-40 ns); the max is a
wall-clock figure, so on a shared machine it holds the query that the scheduler interrupted.

drill_distance_fields: building the drill on the phantom (one distance field per critical
structure), and the drill's tick (CPU time) over a 10 s novice-like session whose plunges drift
into the protected structures (fields recomputed as they are cut): median, p99 and max.

distance_field_build: building the exact signed distance field of the phantom's sinus and dura
(its largest critical structure, spanning the grid) and of all five critical structures at
once, at 256^3 and 512^3, band 10 mm: CPU seconds, median and worst of 3 (targets 1 s and 8 s).
"""

from __future__ import annotations

import time

import numpy as np

import ambfplus
from ambfplus.scenes import drilling_phantom

STRUCTURES = ["Sinus_+_Dura", "Facial_Nerve", "Chorda_Tympani", "Bony_Labyrinth", "ICA"]


def _baselines():
    import __main__  # noqa: PLC0415 (run.py, which finds the C++ baselines)

    return __main__.baselines()


def _points(data, rng, count: int) -> list:
    size = np.asarray(data.dimensions)
    anywhere = rng.uniform(-0.45, 0.45, size=(count // 2, 3)) * size
    nerve = np.argwhere(np.asarray(data.labels) == 3)
    picks = nerve[rng.integers(0, len(nerve), count - count // 2)]
    voxel = size / np.asarray(data.shape)
    centres = (picks + 0.5) * voxel - size / 2
    near = centres + rng.uniform(-0.004, 0.004, size=centres.shape)
    return [tuple(p) for p in np.vstack([anywhere, near])]


def fixture_query(args):
    bench = _baselines()
    scene = drilling_phantom(resolution=128)
    drill = scene.drill
    drill.set_fixtures([{"structure": s, "start": 0.002, "max_force": 2.0} for s in STRUCTURES])
    points = _points(drill.volume.data, np.random.default_rng(3), 4000 if args.quick else 20000)
    bench.fixture_queries(drill, points[:1000], 1)  # warm the caches
    seconds = np.asarray(bench.fixture_queries(drill, points, 1 if args.quick else 3)["seconds"])
    us = 1e6 * seconds
    for name, value in (
        ("median", np.median(us)),
        ("p99", np.percentile(us, 99)),
        ("p999", np.percentile(us, 99.9)),
        ("max", us.max()),
    ):
        yield {
            "bench": f"fixture_query_{name}",
            "value": round(float(value), 3),
            "unit": "us",
            "fixtures": len(STRUCTURES),
            "queries": int(len(us)),
            "target_p99_us": 2.0,
            "what": "fixtures' push on one cursor (five structures' fields sampled), timed "
            "alone in C++, 128^3 phantom",
        }


def drill_distance_fields(args):
    data = ambfplus.phantom(128)
    world = ambfplus.World()
    volume = world.add_volume("anatomy", data)
    started = time.process_time()
    world.add_drill("drill", volume)
    build = time.process_time() - started
    yield {
        "bench": "drill_distance_fields_build",
        "value": round(build, 3),
        "unit": "s",
        "what": "CPU seconds to create a drill on the 128^3 phantom (five critical structures' "
        "distance fields, 9 mm band)",
    }
    from ambfplus.training import drill_phantom, novice_like  # noqa: PLC0415

    seconds = 4.0 if args.quick else 10.0
    protect = [("facial nerve", "Facial_Nerve", 0.001), ("dura", "Sinus_+_Dura", 0.001)]
    session = drill_phantom(novice_like, 11, seconds, protect)
    cpu = 1e6 * np.asarray(session.drill.tick_cpu_seconds)
    for name, value in (
        ("median", np.median(cpu)),
        ("p99", np.percentile(cpu, 99)),
        ("max", cpu.max()),
    ):
        yield {
            "bench": f"drill_tick_cpu_{name}",
            "value": round(float(value), 2),
            "unit": "us",
            "ticks": int(len(cpu)),
            "critical_voxels_cut": int(np.isin(session.removed["label"], [2, 3, 4, 5, 10]).sum()),
            "what": "drill tick CPU time, novice-like session on the 128^3 phantom, critical "
            "distances from the fields",
        }


def distance_field_build(args):
    for n in (256,) if args.quick else (256, 512):
        data = ambfplus.phantom(n)
        for name, labels in (("Sinus_+_Dura", ["Sinus_+_Dura"]), ("all critical", STRUCTURES)):
            rounds = []
            for _ in range(3):
                started = time.process_time()
                field = ambfplus.DistanceField(data, labels, 0.01)
                rounds.append(time.process_time() - started)
            yield {
                "benchmark": "distance_field_build",
                "grid": n,
                "structure": name,
                "cpu_s": round(float(np.median(rounds)), 3),
                "worst_cpu_s": round(max(rounds), 3),
                "target_cpu_s": 1.0 if n == 256 else 8.0,
                "what": "exact anisotropic signed EDT of a structure of the phantom, band 10 mm, "
                "process CPU time, median and worst of 3",
                "quick": args.quick,
            }
            del field


BENCHMARKS = {
    "distance_field_build": distance_field_build,
    "fixture_query": fixture_query,
    "drill_distance_fields": drill_distance_fields,
}
