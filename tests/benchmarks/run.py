"""Benchmarks: one JSON line per figure, {"bench", "value", "unit"} plus "baseline" and "ratio"
where a figure is compared with a baseline measured in the same run.

    python tests/benchmarks/run.py [--only NAME] [--quick]
"""

from __future__ import annotations

import os

# NumPy's OpenBLAS threads spin for a while after each call and would be counted as this
# process's CPU time; the engine does not use them.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse  # noqa: E402
import importlib.util  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from collections.abc import Callable, Iterator  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

import ambfplus  # noqa: E402
from ambfplus.scenes import demo_scene  # noqa: E402

# The C++ baselines (bench_module.cpp): a test-only extension module that the build with tests
# on puts in build/cmake/benchmarks (another folder: AMBFPLUS_BENCH_DIR), never in the package.
BENCH_DIR = Path(
    os.environ.get(
        "AMBFPLUS_BENCH_DIR", Path(__file__).resolve().parents[2] / "build" / "cmake" / "benchmarks"
    )
)


def baselines():
    """The module ambfplus_bench, imported after ambfplus (it shares the engine's library)."""
    if str(BENCH_DIR) not in sys.path:
        sys.path.insert(0, str(BENCH_DIR))
    try:
        return importlib.import_module("ambfplus_bench")
    except ImportError as error:
        sys.exit(
            f"the C++ baselines are not built: no ambfplus_bench in {BENCH_DIR} ({error}); "
            "build with tests on (pip install . does) or set AMBFPLUS_BENCH_DIR"
        )


FIXTURES = Path(
    os.environ.get("AMBFPLUS_FIXTURES", Path(__file__).resolve().parents[3] / "shared" / "fixtures")
)
EAR = FIXTURES / "volumetric_drilling"
# The original's measurements on this machine kind (2 cores, llvmpipe), CPU-seconds per frame of
# its 1536x540 window with the drill and the ear: 7.2 at 256^3, 12.5 at 512^3.
ORIGINAL_CPU_SECONDS = {256: 7.2, 512: 12.5}

BENCHMARKS: dict[str, Callable[[argparse.Namespace], Iterator[dict]]] = {}


def benchmark(fn):
    BENCHMARKS[fn.__name__] = fn
    return fn


@benchmark
def capture(args) -> Iterator[dict]:
    """640x480 rgb + depth capture() from Python, against the same draw and readback done in C++
    into buffers allocated once. Rounds alternate the two so machine noise hits both alike."""
    _, camera = demo_scene(640, 480)
    camera.capture()
    rounds, per_round = (3, 20) if args.quick else (7, 40)
    python_wall, python_cpu, bare_wall, bare_cpu = [], [], [], []
    for _ in range(rounds):
        t0, c0 = time.perf_counter(), time.process_time()
        for _ in range(per_round):
            frame = camera.capture()
            frame.rgb, frame.depth  # noqa: B018 (the views are part of the cost)
        python_wall.append((time.perf_counter() - t0) / per_round)
        python_cpu.append((time.process_time() - c0) / per_round)
        bare = baselines().bare_capture(camera, per_round)
        bare_wall.append(bare["wall_seconds"])
        bare_cpu.append(bare["cpu_seconds"])
    info = ambfplus.gl_info()
    for name, ours, base, what in [
        ("capture_640x480_wall", python_wall, bare_wall, "wall"),
        ("capture_640x480_cpu", python_cpu, bare_cpu, "process CPU"),
    ]:
        value, baseline = statistics.median(ours) * 1e3, statistics.median(base) * 1e3
        yield {
            "bench": name,
            "value": round(value, 4),
            "unit": "ms",
            "baseline": round(baseline, 4),
            "ratio": round(value / baseline, 4),
            "what": f"{what} time per capture(); baseline: same draw + bare readback in C++",
            "renderer": info["renderer"],
        }


def cpu_seconds_per_frame(camera, frames: int) -> tuple[float, float]:
    """Median process CPU seconds and wall seconds of one capture()."""
    cpu, wall = [], []
    for _ in range(frames):
        c0, t0 = time.process_time(), time.perf_counter()
        camera.capture()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - t0)
    return statistics.median(cpu), statistics.median(wall)


def ear_scene(upsample: int = 1):
    """The fixture ear (256^3) placed by its ADF, seen by the fixture's main camera at 1536x540,
    with the fixture's 6 mm drill touching the bone. upsample=2 makes it 512^3."""
    world = ambfplus.World()
    labels = EAR / "labels.csv"
    if upsample == 1:
        (volume,) = world.load_volumes(EAR / "ADF" / "volume_256.yaml", labels=labels)
    else:
        (source,) = ambfplus.World().load_volumes(EAR / "ADF" / "volume_256.yaml", labels=labels)
        grid = np.asarray(source.labels)
        for axis in range(3):
            grid = np.repeat(grid, upsample, axis=axis)
        data = ambfplus.VolumeData(
            grid, dimensions=source.data.dimensions, label_table=source.data.label_table
        )
        volume = world.add_volume("ear", data, pose=source.pose)
    camera = world.add_camera("main_camera", 1536, 540, 0.2, 0.001, 50.0)
    camera.look_at((0.0, 0.0, 0.0), (-0.3, 0.0, 0.0), (0.0, 0.0, 1.0))
    # The drill's burr on the bone where the camera looks, its shaft towards the viewer.
    hit = volume.raycast((0.0, 0.0, 0.0), (-1.0, 0.05, 0.02))
    # The mesh's shaft runs along +x from the burr at its origin.
    rotation = ambfplus.rotation_between((1, 0, 0), (0.55, 0.45, 0.7))
    world.add_body(
        "drill",
        mesh=str(EAR / "ADF" / "meshes" / "high_res" / "6mm.OBJ"),
        pose=ambfplus.make_pose(hit["position"], rotation=rotation),
        mass=0,
    )
    return world, volume, camera


@benchmark
def volume(args) -> Iterator[dict]:
    """The fixture ear at 1536x540 with a drill mesh in view: process CPU seconds per frame,
    against the naive ray march (fixed half-voxel steps, same shading) in the same run and the
    original's figures; load times; a 6 mm burr's dirty-box upload at 512^3."""
    if not EAR.is_dir():
        yield {"bench": "volume", "skipped": f"fixtures absent ({EAR})"}
        return
    frames = 3 if args.quick else 7
    for size, upsample in ((256, 1), (512, 2)):
        world, vol, camera = ear_scene(upsample)
        camera.capture()
        cpu, wall = cpu_seconds_per_frame(camera, frames)
        vol.empty_space_skipping = False
        naive_cpu, naive_wall = cpu_seconds_per_frame(camera, max(2, frames // 2))
        vol.empty_space_skipping = True
        yield {
            "bench": f"volume_ear{size}_1536x540_cpu",
            "value": round(cpu, 4),
            "unit": "CPU-s/frame",
            "baseline": round(naive_cpu, 4),
            "ratio": round(cpu / naive_cpu, 4),
            "wall_s": round(wall, 4),
            "naive_wall_s": round(naive_wall, 4),
            "original_cpu_s": ORIGINAL_CPU_SECONDS[size],
            "speedup_vs_original": round(ORIGINAL_CPU_SECONDS[size] / cpu, 1),
            "target": 0.24 if size == 256 else None,
            "what": "process CPU per capture(); baseline: naive half-voxel ray march, same run",
        }
        del world, vol, camera

    t0 = time.perf_counter()
    ambfplus.load_slice_stack(
        EAR / "resources" / "volumes" / "ear3_256",
        count=512,
        dimensions=(0.0492, 0.0492, 0.0485),
        labels=EAR / "labels.csv",
    )
    yield {"bench": "load_ear3_256", "value": round(time.perf_counter() - t0, 4), "unit": "s"}
    t0 = time.perf_counter()
    data = ambfplus.phantom(512)
    yield {"bench": "phantom_512", "value": round(time.perf_counter() - t0, 4), "unit": "s"}
    builds = []
    for seed in range(3 if args.quick else 10):
        t0 = time.perf_counter()
        ambfplus.phantom(256, seed, side=("right", "left")[seed % 2])
        builds.append(time.perf_counter() - t0)
    yield {
        "bench": "phantom_256",
        "value": round(float(np.median(builds)), 4),
        "max": round(max(builds), 4),
        "unit": "s",
        "what": f"phantom(256, seed) median over {len(builds)} seeds, both sides",
    }

    world = ambfplus.World()
    vol = world.add_volume("phantom", data)
    camera = world.add_camera("cam", 640, 480, 0.7, 0.001, 1.0)
    camera.look_at((0.03, -0.05, 0.12), (0.0, 0.0, 0.0))
    camera.capture()
    yield {
        "bench": "volume_first_upload_512",
        "value": round(vol.last_upload["seconds"], 4),
        "unit": "s",
        "what": "whole grid: smoothing, bricks, textures",
    }
    uploads = []
    for n in range(5 if args.quick else 15):
        centre = (-0.012 + 0.004 * (n % 6), 0.004 * (n // 6) - 0.004, 0.011)
        removed = vol.remove_sphere(centre, 0.003)
        camera.capture()
        assert removed > 0 and not vol.last_upload["full"]
        uploads.append(vol.last_upload["seconds"])
    yield {
        "bench": "dirty_upload_6mm_burr_512",
        "value": round(statistics.median(uploads) * 1e3, 3),
        "unit": "ms",
        "what": "smoothing, bricks and texture upload of one 6 mm burr's box",
    }


def drilling_run(data, seconds: float, ticks: int):
    """The 6 mm burr pressed 0.5 mm into the phantom's lateral face and swept 6 mm sideways in
    `seconds`, drilling, with 8 cursors. Returns the world, the drill and the last ticks' CPU and
    wall times (us)."""
    world = ambfplus.World()
    volume = world.add_volume("anatomy", data)
    shaft = ambfplus.rotation_between((1, 0, 0), (0.2, 0.1, 1.0))  # shaft up, tilted
    start = ambfplus.make_pose((0.0, 0.0, 0.02), rotation=shaft)
    drill = world.add_drill("drill", volume, burr=3, cursors=8, pose=start)
    surface = volume.raycast((0.0, 0.0, 0.03), (0.0, 0.0, -1.0))["position"]
    depth = drill.burr_radius - 0.0005
    drill.on = True
    drill.set_waypoints(
        [
            {
                "time": 0.05,
                "pose": ambfplus.make_pose(surface + (0, 0, depth), rotation=shaft),
                "on": True,
            },
            {
                "time": 0.05 + seconds,
                "pose": ambfplus.make_pose(surface + (0.006, 0.002, depth), rotation=shaft),
                "on": True,
            },
        ]
    )
    world.step(60 + ticks)
    cpu = np.asarray(drill.tick_cpu_seconds)[-ticks:] * 1e6
    wall = np.asarray(drill.tick_seconds)[-ticks:] * 1e6
    return world, drill, cpu, wall


@benchmark
def haptics(args) -> Iterator[dict]:
    """The drill at 512^3 (the phantom, 0.094 mm voxels), 8 cursors, the 6 mm burr in contact and
    drilling: tick time (the thread's CPU time, robust on a busy shared machine) at a moderate
    (1.5 mm/s) and a fast (6 mm/s) sweep; the collision query against the original's full-cube
    scan; how many voxels a tick can remove within 1 ms."""
    data = ambfplus.phantom(512)
    ticks = 400 if args.quick else 1500
    for name, seconds in (("1.5mm_s", 4.0), ("6mm_s", 1.0)):
        world, drill, cpu, wall = drilling_run(data, seconds, min(ticks, int(seconds * 1000)))
        yield {
            "bench": f"haptic_tick_512_{name}",
            "value": round(float(np.median(cpu)), 1),
            "unit": "us (thread CPU)",
            "target": 250,
            "p99_us": round(float(np.percentile(cpu, 99)), 1),
            "p99_target": 500,
            "max_us": round(float(cpu.max()), 1),
            "wall_median_us": round(float(np.median(wall)), 1),
            "wall_p99_us": round(float(np.percentile(wall, 99)), 1),
            "voxels_removed": len(drill.removed["step"]),
            "what": f"8 cursors, 6 mm burr pressed 0.5 mm, sweeping at {name.replace('_', '/')}",
        }
    query = baselines().collision(drill, 0, 20 if args.quick else 100)
    yield {
        "bench": "haptic_query_512_gather",
        "value": round(query["gather_seconds"] * 1e6, 2),
        "unit": "us",
        "baseline": round(query["full_cube_seconds"] * 1e6, 2),
        "ratio": round(query["gather_seconds"] / query["full_cube_seconds"], 4),
        "speedup": round(query["full_cube_seconds"] / query["gather_seconds"], 1),
        "target_speedup": 5,
        "gather_voxels": query["gather_voxels"],
        "full_cube_voxels": query["full_cube_voxels"],
        "same_hit": query["same_hit"],
        "what": "tip sweep: surface voxels of nearby bricks vs the full cube (original)",
    }
    # Removal capacity: what removing voxels costs (collider bitmaps, volume, edit log), and so
    # how many fit in a 1 ms tick beside the median tick's other work.
    removal = baselines().removal(drill, 2000)
    per_voxel_us = removal["seconds"] * 1e6 / max(removal["voxels"], 1)
    spare_us = 1000.0 - float(np.median(cpu))
    yield {
        "bench": "haptic_removal_capacity_512",
        "value": round(spare_us / per_voxel_us),
        "unit": "voxels/tick",
        "target": 200,
        "per_voxel_us": round(per_voxel_us, 3),
        "measured_voxels": removal["voxels"],
        "budget_us": 1000,
        "what": "voxels a 1 ms tick can remove besides the median fast tick's cursor work",
    }


LAUNCH = FIXTURES / "ambf" / "ambf_models" / "descriptions" / "launch.yaml"


@benchmark
def adf(args) -> Iterator[dict]:
    if not LAUNCH.is_file():
        print(f"adf: skipped, fixtures not found at {LAUNCH}", file=sys.stderr)
        return
    present = [i for i, f in enumerate(ambfplus.read_launch(LAUNCH)["models"]) if Path(f).is_file()]
    walls, cpus = [], []
    for _ in range(3 if args.quick else 7):
        w0, c0 = time.perf_counter(), time.process_time()
        sim = ambfplus.Simulator.from_launch(LAUNCH, models=present, strict=True)
        cpus.append(time.process_time() - c0)
        walls.append(time.perf_counter() - w0)
        del sim  # meshes are shared only while a loaded scene holds them
    yield {
        "bench": "adf_launch_load",
        "value": round(statistics.median(walls), 4),
        "unit": "s",
        "target": 2.0,
        "cpu_s": round(statistics.median(cpus), 4),
        "models": present,
        "what": "fixture launch.yaml: world, environment and every present model, from files",
    }
    # Physics of puzzle2 on its floor, one core: simulated seconds per CPU second. The first
    # 2 s have every piece falling and settling; over 10 s settled pieces sleep.
    for seconds in (2, 10):
        sim = ambfplus.Simulator.from_launch(LAUNCH, models=[12], strict=True)
        c0 = time.process_time()
        sim.step(seconds * 1000)
        cpu = time.process_time() - c0
        yield {
            "bench": f"adf_puzzle2_realtime_factor_{seconds}s",
            "value": round(seconds / cpu, 1),
            "unit": "x real time",
            "target": 10,
            "cpu_s": round(cpu, 3),
            "steps_per_cpu_s": round(seconds * 1000 / cpu),
            "what": f"puzzle2 + floor, 1 ms steps, first {seconds} s after loading",
        }


DRILLING_LAUNCH = FIXTURES / "volumetric_drilling" / "launch.yaml"


@benchmark
def stereo(args) -> Iterator[dict]:
    """The original's stereo pair (stereoL/R, 640x480) on the drill and the 256^3 ear."""
    if not DRILLING_LAUNCH.is_file():
        print(f"stereo: skipped, fixtures not found at {DRILLING_LAUNCH}", file=sys.stderr)
        return
    from ambfplus.stereo import StereoRig

    sim = ambfplus.Simulator.from_launch(DRILLING_LAUNCH, models=[0, 2, 5])
    rig = StereoRig.from_cameras(sim.get("stereoL"), sim.get("stereoR"))
    repeats = 3 if args.quick else 7

    def cpu_per_capture(passes) -> float:
        rig.capture(passes)  # warm-up: programs, targets
        times = []
        for _ in range(repeats):
            c0 = time.process_time()
            rig.capture(passes)
            times.append(time.process_time() - c0)
        return statistics.median(times)

    def look(shadows: bool, antialiasing: int, looks: bool = False) -> None:
        for camera in (rig.left, rig.right):
            camera.shadows, camera.antialiasing, camera.looks = shadows, antialiasing, looks

    everything = ("rgb", "depth", "instance", "label")
    look(False, 1)
    full = cpu_per_capture(everything)
    rgb = cpu_per_capture(("rgb",))
    yield {
        "bench": "stereo_capture_640x480_cpu",
        "value": round(full, 4),
        "unit": "CPU-s per stereo pair",
        "target": 0.3,
        "passes": "rgb+depth+instance+label",
        "original_cpu_s": 3.3,
        "what": "drill + ear 256^3, both views of the fixture's stereoL/stereoR",
    }
    for name in ("rgb", "depth", "instance", "label", "voxel", "segmentation"):
        cost = rgb if name == "rgb" else cpu_per_capture((name,))
        yield {
            "bench": f"stereo_pass_{name}_cpu",
            "value": round(cost, 4),
            "unit": "CPU-s per stereo pair",
            "baseline": round(rgb, 4),
            "ratio": round(cost / rgb, 3),
            "what": f"the {name} pass alone, relative to rgb alone",
        }
    # Shadows (the fixture's lights and their shadow quality), supersampling at level 2 and the
    # volume looks (ambient occlusion, bone texture, wet highlights), against everything off,
    # rounds alternating so that machine noise hits all alike. The shadow maps are kept while
    # nothing that casts moves; "redrawn" nudges the drill in view before each pair, so each
    # pair draws them again (what a session pays while the drill moves).
    lights = [(light.name, light.shadow_quality) for light in sim.world.lights]
    seen = rig.left.capture(passes=["instance"]).instance
    body = max(sim.world.bodies, key=lambda b: int((seen == b.id).sum()))  # the drill in view
    pose = body.pose.copy()

    nudges = iter(range(1, 1_000_000))

    def nudged(passes) -> None:
        moved = pose.copy()
        moved[0, 3] += 1e-7 * next(nudges)  # a new place each time: no map is reused
        body.pose = moved
        rig.capture(passes)
        body.pose = pose

    off, on, moving, shadows_only, antialiasing_only, looks_only, shadows_antialiasing = (
        [] for _ in range(7)
    )
    for _ in range(repeats):
        look(False, 1)
        off.append(cpu_per_capture(everything))
        look(True, 1)
        shadows_only.append(cpu_per_capture(everything))
        look(False, 2)
        antialiasing_only.append(cpu_per_capture(everything))
        look(False, 1, looks=True)
        looks_only.append(cpu_per_capture(everything))
        look(True, 2)
        shadows_antialiasing.append(cpu_per_capture(everything))
        look(True, 2, looks=True)
        on.append(cpu_per_capture(everything))
        nudged(everything)
        c0 = time.process_time()
        nudged(everything)
        moving.append(time.process_time() - c0)
    look(False, 1)
    common = {
        "unit": "CPU-s per stereo pair",
        "passes": "+".join(everything),
        "lights": lights,
        "what": "drill + ear 256^3, stereoL/stereoR; on = shadows + antialiasing 2 + looks; "
        "baseline: all off (the capture as before)",
    }
    figures = (
        ("on", on),
        ("on_shadow_maps_redrawn", moving),
        ("shadows_only", shadows_only),
        ("antialiasing_only", antialiasing_only),
        ("looks_only", looks_only),
        ("shadows_antialiasing", shadows_antialiasing),
    )
    for name, values in figures:
        yield {
            "bench": f"stereo_capture_640x480_{name}_cpu",
            "value": round(statistics.median(values), 4),
            "baseline": round(statistics.median(off), 4),
            "ratio": round(statistics.median(values) / statistics.median(off), 3),
            "target_ratio": 1.6,
            "max": round(max(values), 4),
            **common,
        }


@benchmark
def antialiasing(args) -> Iterator[dict]:
    """What supersampling buys: on the fixture's stereoL view (drill and ear, shadows and looks
    on), each pixel supersampling changes, against the mean of a 4 x 4 grid of samples over it
    (a render at 4 times the resolution). Errors are the largest channel's, 0-255."""
    if not DRILLING_LAUNCH.is_file():
        print(f"antialiasing: skipped, fixtures not found at {DRILLING_LAUNCH}", file=sys.stderr)
        return
    sim = ambfplus.Simulator.from_launch(DRILLING_LAUNCH, models=[0, 2, 5])
    base = sim.get("stereoL")
    w, h = base.width, base.height

    def render(name, factor, antialiasing=1):
        camera = sim.world.add_camera(
            name, factor * w, factor * h, fov_y=base.fov_y, near=base.near, far=base.far,
            shadows=True, looks=True, antialiasing=antialiasing,
        )  # fmt: skip
        camera.attach_to(base.attached_to)
        camera.pose = base.pose
        rgb = camera.capture(passes=["rgb"]).rgb[..., :3].astype(float)
        return rgb.reshape(h, factor, w, factor, 3).mean(axis=(1, 3))

    truth = render("x4", 4)
    images = {
        "off": render("k1", 1),
        "k2": render("k2", 1, antialiasing=2),
        "k3": render("k3", 1, antialiasing=3),
        "grid_2x2": render("x2", 2),  # the 2 x 2 grid k = 2 took before stop 45
    }
    changed = (images["k2"] != images["off"]).any(axis=-1)
    what = {
        "off": "no antialiasing: the pixel centre",
        "k2": "antialiasing 2: centre 1/2, corners 1/8 each (shared with neighbours)",
        "k3": "antialiasing 3: a 3 x 3 grid per pixel",
        "grid_2x2": "a 2 x 2 grid per pixel (a render at twice the resolution)",
    }
    for name, image in images.items():
        error = np.abs(image - truth).max(axis=-1)[changed]
        yield {
            "bench": f"antialiasing_error_{name}",
            "value": round(float(error.mean()), 3),
            "unit": "mean error (0-255) over the pixels antialiasing 2 changes",
            "median": round(float(np.median(error)), 3),
            "p99": round(float(np.percentile(error, 99)), 3),
            "max": round(float(error.max()), 3),
            "pixels": int(changed.sum()),
            "what": what[name],
        }


def realtime_scene():
    """The drilling fixture (drill meshes, ear 256^3, its main camera at 640x480) with the
    drilling plugin's drill, or the built-in phantom when the fixtures are absent. Returns the
    world, the drill, the camera and where the burr meets the bone."""
    if DRILLING_LAUNCH.is_file():
        sim = ambfplus.Simulator.from_launch(DRILLING_LAUNCH, models=[0, 2])
        world, drill, camera = sim.world, sim.get("drill"), sim.get("main_camera")
        volume = world.volumes[0]
        hit = volume.raycast(camera.pose[:3, 3], camera.pose[:3, 2])
    else:
        world = ambfplus.World()
        volume = world.add_volume("ear", ambfplus.phantom(256))
        drill = world.add_drill("drill", volume)
        camera = world.add_camera("cam", 640, 480, fov_y=0.5, near=0.01, far=1.0)
        camera.look_at((0.05, -0.1, 0.1), (0, 0, 0))
        hit = volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))
    into = -hit["normal"] / np.linalg.norm(hit["normal"])
    start = hit["position"] - into * (drill.burr_radius + 0.002)
    # Placed there at once (goal and cursors), as a scene's drill starts: a drill made at the
    # phantom's centre would start inside the bone.
    drill.pose = ambfplus.make_pose(start, rotation=ambfplus.rotation_between((1, 0, 0), -into))
    return world, drill, camera, into


def guide(world, drill):
    """Everything guidance and training add to the haptic loop: a forbidden-region fixture on
    every critical structure (from 1 mm, 0.3 N: the hand's push then still cuts bone, and the
    fixture of the structure it drills toward holds the burr), the drill's sound played to
    miniaudio's null device (with a warning beep per critical structure) and live skill metrics
    protecting every critical structure. Returns what must stay alive (the sound)."""
    data = world.volumes[0].data
    critical = [label.id for label in data.label_table if label.critical]
    drill.set_fixtures([{"structure": i, "start": 0.001, "max_force": 0.3} for i in critical])
    ambfplus.live_metrics(
        drill, protect=[{"name": str(i), "labels": [i], "margin": 0.001} for i in critical]
    )
    return ambfplus.DrillSound(drill, output="null")


def realtime_session(seconds: float, drilling: bool, witness=None, guided: bool = False):
    """A real-time session of the scene driven by a simulated hand, a camera capturing
    continuously in another thread: loop statistics, frames, the input log, and what tells a
    stall of the machine from ours (rt_witness: the loop's steps against CLOCK_MONOTONIC, its
    thread's counters; a running witness is put out of the loop's phase). `guided`: with
    fixtures, sound and live metrics on (guide())."""
    import threading

    from rt_witness import anchored, loop_thread, thread_counters

    world, drill, camera, into = realtime_scene()
    sound = guide(world, drill) if guided else None
    hand = ambfplus.SimulatedDevice()
    binding = world.add_input_device("hand", hand, drill)
    camera.capture()  # uploads and programs before the clock starts
    frames, stop = [0], threading.Event()

    def capture():
        while not stop.is_set():
            camera.capture(passes=["rgb", "depth"])
            frames[0] += 1

    loop = ambfplus.RealTimeLoop(world)
    thread = threading.Thread(target=capture)
    first_index = world.step_index
    with loop, anchored(world, first_index, witness) as anchors:
        tid = loop_thread()
        before = thread_counters(tid)
        thread.start()
        if drilling:
            # Into the bone (3 mm past the surface) and along it, burr on.
            side = np.cross(into, (0.0, 0.0, 1.0))
            side /= np.linalg.norm(side)
            for k in range(int(seconds)):
                offset = into * 0.005 + side * 0.002 * np.sin(k)
                hand.set_target(offset, buttons=1)
                time.sleep(1.0)
        else:
            time.sleep(seconds)
        stop.set()
        thread.join()
        after = thread_counters(tid)
    if sound is not None:
        sound.close()
    counters = {k: round(after[k] - before[k], 3) for k in before if k != "timer_slack_ns"}
    counters["timer_slack_ns"] = before.get("timer_slack_ns")
    return world, drill, binding, loop, frames[0], anchors, counters


@benchmark
def realtime(args) -> Iterator[dict]:
    """Real-time mode: the 1 kHz physics/haptics loop while a camera captures continuously in
    another thread, idle and drilling; then the drilling session's logged inputs replayed in
    scripted mode, which must give the same removal log. Every period over 2 ms is split into
    the step's time and the wake-up's lateness and attributed to the host or to us by a witness
    probe on every CPU (rt_witness.py)."""
    from rt_witness import Witness, realtime_attribution

    seconds = 3.0 if args.quick else 10.0
    for drilling, guided in ((False, False), (True, False), (True, True)):
        with Witness() as witness:
            world, drill, binding, loop, frames, anchors, counters = realtime_session(
                seconds, drilling, witness, guided
            )
        s = loop.stats
        name = "realtime_loop_guided" if guided else "realtime_loop_drilling"
        line = {
            "bench": name if drilling else "realtime_loop",
            "value": round(s["p99"] * 1e3, 4),
            "unit": "ms (p99 period)",
            "target": 1.2,
            "max_ms": round(s["max"] * 1e3, 4),
            "max_target_ms": 2.0,
            "over_2ms": s["over_2ms"],
            "mean_rate_hz": round(s["mean_rate"], 2),
            "rate_target_hz": 995,
            "step_cpu_p99_us": round(s["step_cpu_p99"] * 1e6, 1),
            "step_cpu_max_us": round(s["step_cpu_max"] * 1e6, 1),
            "step_wall_max_us": round(s["step_wall_max"] * 1e6, 1),
            # The longest the physics thread waited for the world's lock (a capture's copy).
            "lock_wait_max_us": round(s["lock_wait_max"] * 1e6, 1),
            "lock_wait_p99_us": round(s["lock_wait_p99"] * 1e6, 1),
            "lock_wait_target_us": 200,
            **realtime_attribution(s, anchors, witness, loop.scheduling),
            # The loop thread over the run: page faults (its own allocations) and switches
            # (voluntary: sleeps and lock waits; involuntary: preempted by a higher priority).
            "loop_thread": counters,
            "rt_runtime": Path("/proc/sys/kernel/sched_rt_runtime_us").read_text().strip(),
            "frames": frames,
            "frames_per_s": round(frames / s["seconds"], 2),
            "scheduling": loop.scheduling,
            "seconds": round(s["seconds"], 2),
            "what": "periods of the physics thread while a 640x480 camera captures in a thread"
            + (", drilling" if drilling else "")
            + (", fixtures, sound and live metrics on" if guided else ""),
        }
        if guided:
            line["voxels_removed"] = len(drill.removed["step"])
        if drilling and not guided:
            removed = drill.removed
            log = binding.take_log()
            replay_world, replay_drill, _, _ = realtime_scene()
            replay_world.add_input_device("hand", ambfplus.ReplayDevice(log), replay_drill)
            replay_world.step(len(log["step"]))
            again = replay_drill.removed
            line["voxels_removed"] = len(removed["step"])
            line["replay_identical"] = bool(
                all(np.array_equal(removed[k], again[k]) for k in ("step", "voxel", "label"))
            )
        yield line


@benchmark
def recording(args) -> Iterator[dict]:
    """640x480 stereo rgb + depth + label + instance of the phantom (128^3) in a capture loop,
    without recording, recording every pair (Blosc-LZ4, the default; lzf) and recording
    uncompressed, in alternating rounds; a recorded round ends when its pairs are flushed to
    closed parts.
    Capture rate (wall) and process CPU (all threads: rendering, copies, compression), data
    rate in frames/s and MB/s, and the recorder alone replaying captured pairs."""
    import tempfile

    from ambfplus.recording import Recorder
    from ambfplus.stereo import StereoRig

    world = ambfplus.World()
    world.add_volume("ear", ambfplus.phantom(128))
    # The paper's optics (f = 1135 px at 640x480, 65 mm baseline), 120 mm from the 48 mm phantom
    # so that anatomy covers about 40 % of each view.
    rig = StereoRig(
        world, "rig", baseline=0.065, width=640, height=480,
        fov_y=2 * np.arctan(240 / 1135), working_distance=0.12,
    )  # fmt: skip
    rig.look_at((0.0155, -0.072, 0.084), (-0.0325, 0.0, 0.0))
    passes = ("rgb", "depth", "label", "instance")
    rounds, per_round = (3, 12) if args.quick else (5, 30)

    def capture_round(recorder=None) -> tuple[float, float]:
        w0, c0 = time.perf_counter(), time.process_time()
        for _ in range(per_round):
            world.step(1)
            pair = rig.capture(passes)
            if recorder is not None:
                recorder.add_stereo("rig", pair)
        if recorder is not None:
            recorder.flush()
        return time.perf_counter() - w0, time.process_time() - c0

    with tempfile.TemporaryDirectory() as folder:
        rig.capture(passes)  # warm-up: programs, targets
        kinds = ("blosc-lz4", "lzf", None)
        times = {"plain": [], **{kind: [] for kind in kinds}}
        recorders = {
            kind: Recorder(Path(folder) / f"{kind}.h5", compression=kind) for kind in kinds
        }
        for recorder in recorders.values():
            recorder.set_legend(world)
        for _ in range(rounds):
            times["plain"].append(capture_round())
            for kind, recorder in recorders.items():
                times[kind].append(capture_round(recorder))
        sizes = {}
        for kind, recorder in recorders.items():
            recorder.close()
            sizes[kind] = sum(p.stat().st_size for p in Path(folder).glob(f"{kind}.h5*"))
        stats = recorders["blosc-lz4"].stats
        replay = _replay_throughput(Path(folder) / "replay.h5", rig.capture(passes), 2 * per_round)

    pairs = rounds * per_round
    pair_bytes = stats.bytes_written / pairs

    def median(kind, which) -> float:
        return statistics.median(t[which] for t in times[kind]) / per_round

    plain_wall, plain_cpu = median("plain", 0), median("plain", 1)
    common = {"frame": "640x480 stereo pair, rgb+depth+label+instance", "quick": args.quick}
    for kind, suffix in (("blosc-lz4", ""), ("lzf", "_lzf"), (None, "_uncompressed")):
        wall, cpu = median(kind, 0), median(kind, 1)
        yield {
            "bench": f"recording_capture_rate{suffix}",
            "value": round(1 / wall, 2),
            "unit": "pairs/s (wall)",
            "baseline": round(1 / plain_wall, 2),
            "ratio": round(plain_wall / wall, 4),
            "target_ratio": 0.9,
            "cpu_s_per_pair": round(cpu, 4),
            "baseline_cpu_s_per_pair": round(plain_cpu, 4),
            "cpu_ratio": round(cpu / plain_cpu, 4),
            "frames_per_s": round(2 / wall, 2),
            "mb_per_s": round(pair_bytes / wall / 1e6, 1),
            "file_mb_per_pair": round(sizes[kind] / pairs / 1e6, 3),
            "compression": kind or "none",
            "what": "capture loop recording every pair (flushed each round) vs not recording",
            **common,
        }
    yield {
        "bench": "recording_writer_throughput",
        "value": round(replay["bytes"] / replay["wall"] / 1e6, 1),
        "unit": "MB/s (uncompressed)",
        "baseline": round(pair_bytes / plain_wall / 1e6, 1),
        "ratio": round(replay["bytes"] / replay["wall"] / (pair_bytes / plain_wall), 3),
        "frames_per_s": round(2 * replay["pairs"] / replay["wall"], 1),
        "cpu_s_per_pair": round(replay["cpu"] / replay["pairs"], 4),
        "pair_mb": round(pair_bytes / 1e6, 3),
        "compression_ratio": round(stats.bytes_written / sizes["blosc-lz4"], 2),
        "seconds_blocked": round(stats.seconds_blocked, 3),
        "queue_high_water_mb": round(stats.pending_high_water_bytes / 1e6, 1),
        "what": "the recorder alone (copy, queue, Blosc-LZ4, HDF5, until closed) replaying a "
        "captured "
        "pair; baseline: the data rate of the capture loop without recording",
        **common,
    }


def _replay_throughput(path: Path, pair, pairs: int) -> dict:
    """Wall and CPU seconds to record ``pairs`` copies of one captured pair, until closed."""
    from ambfplus.recording import Recorder
    from ambfplus.stereo import StereoFrame

    w0, c0 = time.perf_counter(), time.process_time()
    with Recorder(path) as recorder:
        for i in range(pairs):
            views = [_with_step(view, i + 1) for view in (pair.left, pair.right)]
            recorder.add_stereo("rig", StereoFrame(*views, pair.baseline, pair.dcx))
    return {
        "wall": time.perf_counter() - w0,
        "cpu": time.process_time() - c0,
        "bytes": recorder.stats.bytes_written,
        "pairs": pairs,
    }


def _with_step(frame, step: int) -> dict:
    """A captured view as a mapping with its own step (streams need increasing steps)."""
    out = {name: getattr(frame, name) for name in ("rgb", "depth", "label", "instance")}
    out.update(
        camera=frame.camera, time=step * 1e-3, step=step, intrinsics=frame.intrinsics,
        pose=frame.pose,
    )  # fmt: skip
    return out


@benchmark
def launcher(args) -> Iterator[dict]:
    """ambfplus-launch on a virtual display (Xvfb): the drilling fixture's main camera in a
    1536x540 window (drill + ear 256^3), keys sent by xdotool every 0.5 s. Process CPU seconds
    per frame (everything: rendering, physics, status), key-to-screen latency (from the key
    event to the swap of the first frame of a later step), the physics loop's periods."""
    import shutil
    import subprocess
    import tempfile

    missing = [t for t in ("Xvfb", "xdotool") if shutil.which(t) is None]
    if missing or not DRILLING_LAUNCH.is_file():
        yield {"bench": "launcher", "skipped": f"needs {missing or DRILLING_LAUNCH}"}
        return
    number = next(n for n in range(120, 140) if not Path(f"/tmp/.X11-unix/X{n}").exists())
    display = f":{number}"
    server = subprocess.Popen(["Xvfb", display, "-screen", "0", "1920x1080x24"],
                              stderr=subprocess.DEVNULL)  # fmt: skip
    env = {**os.environ, "DISPLAY": display}
    seconds = 12 if args.quick else 30
    try:
        with tempfile.TemporaryDirectory() as folder:
            status, latency = Path(folder) / "status.json", Path(folder) / "latency.jsonl"
            time.sleep(1.0)
            process = subprocess.Popen(
                [sys.executable, "-m", "ambfplus.launcher", str(DRILLING_LAUNCH), "-l", "0,2",
                 "--seconds", str(seconds), "--status", str(status),
                 "--latency-log", str(latency)],
                env=env, cwd=folder, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
            )  # fmt: skip
            while not status.exists() and process.poll() is None:
                time.sleep(0.2)
            window = subprocess.run(["xdotool", "search", "--name", "^ambfplus$"], env=env,
                                    capture_output=True, text=True).stdout.split()[0]  # fmt: skip
            subprocess.run(["xdotool", "windowfocus", "--sync", window], env=env)
            presses = int((seconds - 6) / 0.5)
            for i in range(presses):
                key = "ctrl+w" if i % 2 == 0 else "ctrl+s"
                subprocess.run(["xdotool", "key", key], env=env)
                time.sleep(0.5)
            process.wait(timeout=120)
            final = json.loads(status.read_text())
            latencies = [json.loads(line)["latency_s"] for line in latency.read_text().splitlines()]
    finally:
        server.terminate()
    yield {
        "bench": "launcher_window_cpu_per_frame",
        "value": round(final["cpu_s_per_frame"], 4),
        "unit": "CPU-s/frame",
        "target": 0.24,
        "original_cpu_s": ORIGINAL_CPU_SECONDS[256],
        "speedup_vs_original": round(ORIGINAL_CPU_SECONDS[256] / final["cpu_s_per_frame"], 1),
        "fps": round(final["fps"], 2),
        "frames": final["frames"],
        "what": "process CPU per shown frame, 1536x540 window, drill + ear 256^3, on llvmpipe",
    }
    lat = np.array(latencies) * 1e3
    yield {
        "bench": "launcher_key_to_screen",
        "value": round(float(np.median(lat)), 1),
        "unit": "ms (median)",
        "target": 100,
        "p95_ms": round(float(np.percentile(lat, 95)), 1),
        "max_ms": round(float(lat.max()), 1),
        "keys": len(lat),
        "what": "key event (xdotool) to the swap of the first frame showing a later step",
    }
    yield {
        "bench": "launcher_physics_p99",
        "value": round(final["physics_p99_ms"], 4),
        "unit": "ms (p99 period)",
        "target": 1.2,
        "max_ms": round(final["physics_max_ms"], 4),
        "rate_hz": round(final["physics_hz"], 2),
        "what": "the 1 kHz loop's periods while the window renders",
    }


@benchmark
def learning(args) -> Iterator[dict]:
    """Stereo samples per second delivered to a training loop through make_loader (2 spawned
    workers, batches of 4): rendered in the loop by SimulatorStereoDataset (the paper's rig at
    640x480 over the phantom, mixed camera and drilling scenarios, with targets) against reading
    the same samples back from their recordings with RecordingStereoDataset. Rates are steady
    state, from the first batch to the last; worker start-up is reported apart. CPU counts the
    parent and the workers (all threads)."""
    import resource
    import tempfile

    from ambfplus.learning import RecordingStereoDataset, SimulatorStereoDataset, make_loader

    samples, batch, workers = (40, 4, 2) if args.quick else (160, 4, 2)

    def children_cpu() -> float:
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        return usage.ru_utime + usage.ru_stime

    def deliver(dataset) -> dict:
        """Runs a loader to the end; the loop touches every tensor as training would."""
        w0, c0, k0 = time.perf_counter(), time.process_time(), children_cpu()
        first, count = None, 0
        for item in make_loader(dataset, batch_size=batch, num_workers=workers):
            for value in item.values():
                value.sum()
            count += len(item["left"])
            if first is None:
                first = time.perf_counter()
        end = time.perf_counter()
        return {
            "rate": (count - batch) / (end - first),
            "startup": first - w0,
            "cpu_per_sample": (time.process_time() - c0 + children_cpu() - k0) / count,
            "count": count,
        }

    def simulator(record_to=None):
        return SimulatorStereoDataset(samples=samples, seed=7, record_to=record_to)

    with tempfile.TemporaryDirectory() as folder:
        deliver(simulator(record_to=folder))  # the same samples, recorded once
        recordings = sorted(Path(folder).glob("worker*_epoch0.h5"))
        rounds = 1 if args.quick else 2
        live = [deliver(simulator()) for _ in range(rounds)]
        recorded = [deliver(RecordingStereoDataset(recordings)) for _ in range(rounds)]
        megabytes = sum(p.stat().st_size for p in Path(folder).glob("worker*")) / 1e6

    def median(runs, key) -> float:
        return statistics.median(r[key] for r in runs)

    live_rate, recorded_rate = median(live, "rate"), median(recorded, "rate")
    yield {
        "bench": "learning_samples_per_s_in_loop",
        "value": round(live_rate, 2),
        "unit": "samples/s",
        "baseline": round(recorded_rate, 2),
        "ratio": round(live_rate / recorded_rate, 4),
        "cpu_s_per_sample": round(median(live, "cpu_per_sample"), 4),
        "baseline_cpu_s_per_sample": round(median(recorded, "cpu_per_sample"), 4),
        "startup_s": round(median(live, "startup"), 2),
        "baseline_startup_s": round(median(recorded, "startup"), 2),
        "samples": live[0]["count"],
        "recording_mb_per_sample": round(megabytes / samples, 3),
        "what": "640x480 stereo samples (rgb, depth, label, instance, segmentation, disparity, "
        "occlusion) to a training loop, 2 spawned workers, batch 4: rendered in the loop vs "
        "read from their recordings",
        "quick": args.quick,
    }


def load_benchmark_files() -> None:
    """Adds the benchmarks of each tests/benchmarks/bench_<area>.py: its module-level dict
    BENCHMARKS maps names to functions of (args) yielding figures, like the ones above."""
    for path in sorted(Path(__file__).resolve().parent.glob("bench_*.py")):
        spec = importlib.util.spec_from_file_location(f"ambfplus_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        for name, fn in module.BENCHMARKS.items():
            if name in BENCHMARKS:
                raise SystemExit(f"benchmark {name!r} of {path.name} is already defined")
            BENCHMARKS[name] = fn


def main() -> int:
    load_benchmark_files()
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--only", choices=sorted(BENCHMARKS), help="run one benchmark")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions")
    args = parser.parse_args()
    for name in [args.only] if args.only else sorted(BENCHMARKS):
        for line in BENCHMARKS[name](args):
            print(json.dumps(line), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
