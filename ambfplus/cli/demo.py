"""The ``ambfplus`` command line: ``demo``, ``convert``, ``launch``, ``validate``, ``export``,
``generate``, ``dataset info``, ``info``, ``doctor`` (and ``--cmake-dir``, the folder of the
CMake package C++ plugins build against)."""

from __future__ import annotations

import argparse
import atexit
import gc
import json
import sys
from pathlib import Path

import numpy as np

from . import PluginError, ScriptedDevice, Simulator, __version__, gl_info, write_image
from .plugin import cmake_dir
from .volumes import convert_volume

# The demo fails when the anatomy covers less than this share of the view (at the paper's
# 250 mm and f = 1135 px, the 48 mm phantom covers about 15 %).
MIN_COVERAGE = 0.05
# depth.png holds depth in units of 0.1 mm (uint16, so up to 6.5535 m); 0 means no hit.
DEPTH_PNG_SCALE = 10000.0


def colorize_depth(depth: np.ndarray) -> np.ndarray:
    """An RGB picture of a depth map (near = bright yellow, far = dark purple, no hit = black)."""
    valid = depth > 0
    rgb = np.zeros(depth.shape + (3,), dtype=np.uint8)
    if not valid.any():
        return rgb
    lo, hi = float(depth[valid].min()), float(depth[valid].max())
    t = (depth[valid] - lo) / max(hi - lo, 1e-12)
    stops = np.array([0.0, 0.33, 0.66, 1.0])
    colors = np.array([[252, 230, 60], [240, 110, 60], [160, 40, 110], [40, 10, 70]], float)
    for c in range(3):
        rgb[..., c][valid] = np.interp(t, stops, colors[:, c]).astype(np.uint8)
    return rgb


def plunge_script(volume, sites, start, burr_radius, depth=0.003):
    """Waypoints of a scripted hand (device frame = world axes from the drill's start) that
    plunges the burr `depth` into the bone at each (x, y) site: over it with the burr off, down
    spinning, a hold, and back up."""
    waypoints, t = [{"time": 0.0, "position": (0.0, 0.0, 0.0), "buttons": 0}], 0.0
    start = np.asarray(start, float)
    for x, y in sites:
        surface = volume.raycast((x, y, 0.05), (0.0, 0.0, -1.0))["position"]
        above = np.array([x, y, surface[2] + burr_radius + 0.003]) - start
        down = np.array([x, y, surface[2] + burr_radius - depth]) - start
        for dt, where, on in ((0.6, above, 0), (0.4, above, 1), (2.0, down, 1), (0.5, down, 1),
                              (0.4, above, 1)):  # fmt: skip
            t += dt
            waypoints.append({"time": t, "position": tuple(where), "buttons": on})
    return waypoints, t


def write_previews(out: Path, frame, world) -> dict:
    """PNGs of one captured view: rgb, depth (uint16 in 0.1 mm, and a colour preview), labels
    (uint16 ids, and their colours), segmentation; returns the frame's description."""
    volume = world.volumes[0] if world.volumes else None
    colours = np.zeros((65536, 3), np.uint8)
    if volume is not None:
        for label in volume.data.label_table:
            colours[label.id] = label.color
    depth_png = np.clip(np.round(frame.depth * DEPTH_PNG_SCALE), 0, 65535).astype(np.uint16)
    write_image(str(out / "rgb.png"), frame.rgb)
    write_image(str(out / "depth.png"), depth_png)
    write_image(str(out / "depth_preview.png"), colorize_depth(frame.depth))
    write_image(str(out / "label.png"), frame.label)
    write_image(str(out / "label_preview.png"), colours[frame.label])
    if frame.segmentation is not None:
        write_image(str(out / "segmentation.png"), frame.segmentation)
    return {
        "ambfplus_version": __version__,
        "camera": frame.camera,
        "width": frame.width,
        "height": frame.height,
        "time": frame.time,
        "step": frame.step,
        "intrinsics": frame.intrinsics.tolist(),
        "pixel_centre": "pixel (row r, column c) is centred at (c + 0.5, r + 0.5)",
        "pose_world_from_camera": frame.pose.tolist(),
        "camera_frame": "OpenCV: x right, y down, z forward",
        "depth_png": f"uint16, depth in metres * {DEPTH_PNG_SCALE:g}; 0 where nothing was hit",
        "label_png": "uint16 volume label ids (0 = none); label_preview.png shows their colours",
        "labels": [
            {"id": label.id, "name": label.name, "color": list(label.color)}
            for label in (volume.data.label_table if volume is not None else [])
        ],
        "gl": gl_info(),
    }


def run_demo(out: Path, width: int, height: int, resolution: int, every: int) -> int:
    """A headless drilling session on the built-in phantom: scripted plunges at three sites
    while the stereo rig circles, recorded, validated, and previewed as PNG files."""
    from .recording import open_recording, validate
    from .scenes import drilling_phantom, orbit_view, record_session

    out.mkdir(parents=True, exist_ok=True)
    path = out / "session.h5"
    for old in out.glob("session.h5*"):
        old.unlink()
    print(f"ambfplus {__version__}: {gl_info()['renderer']}", flush=True)
    scene = drilling_phantom(resolution=resolution, width=width, height=height)
    device = ScriptedDevice()
    sites = [(0.0, 0.0), (0.006, 0.004), (-0.006, 0.004)]
    start = scene.drill.goal[:3, 3]
    waypoints, seconds = plunge_script(scene.drill.volume, sites, start, scene.drill.burr_radius)
    device.set_waypoints(waypoints)
    print(
        f"recording {seconds:.1f} s of drilling ({len(sites)} plunges, a {width}x{height} "
        f"stereo pair every {every} ms) to {path}",
        flush=True,
    )
    summary = record_session(
        scene, path, device, seconds, capture_every=every, camera_motion=orbit_view,
        metadata={"demo": {"sites": sites, "waypoints": waypoints}},
        progress=lambda line: print("  " + line, flush=True),
    )  # fmt: skip
    report = validate(path)
    (out / "validation.txt").write_text(str(report) + "\n")
    print(f"validation: {sum(c.status == 'pass' for c in report.checks)} checks passed, "
          f"{len(report.failed)} failed (validation.txt)")  # fmt: skip
    with open_recording(path) as rec:
        pairs = rec.rigs["rig"]
        last = pairs[len(pairs) - 1]
        lefts = [pairs[i].left.rgb for i in (0, len(pairs) // 2, len(pairs) - 1)]
        write_image(str(out / "montage.png"), np.concatenate(lefts, axis=1))
        write_image(str(out / "right_rgb.png"), last.right.rgb)
        meta = write_previews(out, last.left, scene.world)
    meta["recording"] = {"path": str(path), **summary}
    (out / "frame.json").write_text(json.dumps(meta, indent=2))
    covered = last.left.depth > 0
    coverage = float(covered.mean())
    contrast = float(last.left.rgb[covered].std()) if covered.any() else 0.0
    print(
        f"wrote {out}: session.h5 ({summary['frames']} stereo frames, {summary['steps']} steps, "
        f"{summary['voxels_removed']} voxels removed), montage.png, rgb.png, right_rgb.png, "
        f"depth.png, depth_preview.png, label.png, label_preview.png, segmentation.png, "
        f"frame.json; the anatomy covers {coverage:.1%} of the last view"
    )
    problems = []
    if not report.ok:
        problems.append("the recording does not validate (see validation.txt)")
    if summary["voxels_removed"] == 0:
        problems.append("the drill removed no voxel")
    if coverage < MIN_COVERAGE or contrast < 5.0:
        problems.append(
            f"the scene covers {coverage:.1%} of the view (need >= {MIN_COVERAGE:.0%}) with "
            f"colour contrast {contrast:.1f} (need >= 5): the render is empty or flat"
        )
    for problem in problems:
        print(f"error: {problem}", file=sys.stderr)
    return 1 if problems else 0


def run_replay(args: argparse.Namespace) -> int:
    """Re-simulates a recording from its device readings, optionally re-rendering it."""
    from .scenes import replay

    report = replay(
        args.recording,
        out=args.out,
        baseline=args.baseline,
        width=args.width,
        height=args.height,
        progress=lambda line: print("  " + line, flush=True),
    )
    print(
        json.dumps(
            {
                "steps": report.steps,
                "frames": report.frames,
                "voxels_removed": report.voxels_removed,
                "removal_identical": report.removal_identical,
                "forces_identical": report.forces_identical,
                "images_identical": report.images_identical,
                "output": str(report.output) if report.output else None,
            },
            indent=2,
        )
    )
    same = report.removal_identical and report.forces_identical
    return 0 if same and report.images_identical in (None, report.frames) else 1


def indices(text: str) -> list[int]:
    """AMBF's -l: "0,2, 5" -> [0, 2, 5]."""
    try:
        return [int(part) for part in text.replace(" ", "").split(",") if part]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected launch indices like 0,2 got '{text}'") from None


def run_check_plugins(args: argparse.Namespace) -> int:
    """Loads each plugin file in a probe process; exit code 1 if any is refused."""
    from .plugin import probe_plugin

    refused = 0
    for plugin in args.plugins:
        try:
            result = probe_plugin(plugin, timeout=args.timeout)
        except PluginError as error:
            print(error)
            refused += 1
            continue
        print(result.message)
        refused += not result.ok
    return 1 if refused else 0


def run_launch(args: argparse.Namespace) -> int:
    """Loads an AMBF launch file headless like AMBF's -l/-a, steps it, prints what loaded."""
    extra = [Path(p) for p in args.a.split(",") if p] if args.a else []
    plugins = [p for p in args.plugins.split(",") if p] if args.plugins else []
    if args.check_plugins:
        from .plugin import check_plugin, resolve

        for plugin in plugins:
            if resolve(plugin) is not None:
                check_plugin(plugin)
    sim = Simulator.from_launch(
        args.launch_file,
        models=args.l,
        extra=extra,
        devices=args.i or [],
        strict=args.strict,
        namespace_prefix=args.ns,
        plugins=plugins,
    )
    sim.step(args.steps)
    report = sim.load_report
    summary = {
        "models": [m.name for m in report.models],
        "objects": {
            kind: sum(o.kind == kind for o in sim.world.objects)
            for kind in ("body", "joint", "camera", "light", "volume")
        },
        "plugins": [f"{p.name} ({p.language}, {p.scope})" for p in sim.world.plugins],
        "errors": [f"{f}: {m}" for f, m in report.errors],
        "warnings": len(report.warnings),
        "time": sim.world.time,
    }
    print(json.dumps(summary, indent=2))
    return 1 if report.errors else 0


def run_validate(args: argparse.Namespace) -> int:
    """Checks a recording or a dataset folder; exit code 0 only when every check passes."""
    if args.recording.is_dir():
        from .dataset import validate_dataset

        report = validate_dataset(args.recording, match_images=not args.no_image_matching)
    else:
        from .recording import validate  # h5py is needed only here

        report = validate(args.recording, match_images=not args.no_image_matching)
    print(json.dumps(report.to_dict(), indent=2) if args.json else report)
    return 0 if report.ok else 1


def run_export(args: argparse.Namespace) -> int:
    """Exports a recording or a dataset folder; errors are one line naming what is wrong."""
    from .export import ExportError, MissingExtra, export
    from .recording import RecordingError

    options = {}
    if args.to in ("mcap", "rosbag2"):
        options["point_clouds"] = not args.no_points
        options["image_topics"] = args.image_topics
        options["rgb_codec"] = args.rgb_codec
        options["jpeg_quality"] = args.jpeg_quality
    if args.to == "mcap":
        options["compression"] = None if args.compression == "none" else args.compression
    if args.to == "original-h5":
        options["chunk_size"] = args.chunk_size
    if args.to == "coco":
        options["images"] = not args.no_images
    try:
        results = export(args.source, args.out, args.to, force=args.force,
                         progress=False if args.quiet else None, **options)  # fmt: skip
    except (ExportError, RecordingError, MissingExtra) as error:
        print(f"ambfplus export: {error}", file=sys.stderr)
        return 1
    results = results if isinstance(results, list) else [results]
    for result in results:
        line = result.to_dict()
        if not args.verbose:
            line.pop("topics", None)
            line.pop("messages", None)
        print(json.dumps(line))
    return 0


def run_generate(args: argparse.Namespace) -> int:
    """Generates (or resumes) a dataset from a spec."""
    from .dataset import GenerateError, generate

    try:
        report = generate(
            args.spec, args.out, workers=args.workers, ray=args.ray, retries=args.retries,
            timeout=args.timeout, progress=not args.quiet,
            ray_options={"cpus": args.ray_cpus, "gpus": args.ray_gpus},
        )  # fmt: skip
    except (ValueError, OSError, ImportError, GenerateError) as error:  # SpecError included
        print(f"error: {error}", file=sys.stderr)
        return 2
    print(
        f"{report.folder}: {report.generated} episodes made ({report.frames} stereo pairs), "
        f"{report.skipped} already there, {report.retries} retries, {report.seconds:.1f} s; "
        f"check it with: ambfplus validate {report.folder}"
    )
    return 0


def run_dataset(args: argparse.Namespace) -> int:
    """``dataset info DIR``: counts by anatomy, scenario and label."""
    from .dataset import dataset_info, format_info

    info = dataset_info(args.folder)
    print(json.dumps(info, indent=2) if args.json else format_info(info))
    return 0


class _PrintCmakeDir(argparse.Action):
    """--cmake-dir: prints the folder and exits, as --version does."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(cmake_dir())
        parser.exit()


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="ambfplus", description=__doc__)
    parser.add_argument("--version", action="version", version=f"ambfplus {__version__}")
    parser.add_argument(
        "--cmake-dir",
        action=_PrintCmakeDir,
        help="print the folder of ambfplusConfig.cmake (for -Dambfplus_DIR=...) and exit",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    demo = commands.add_parser(
        "demo",
        help="a headless drilling session on the built-in phantom: record it, validate it, "
        "write preview PNGs",
    )
    demo.add_argument("--out", type=Path, default=Path("demo_out"), help="output folder")
    demo.add_argument("--width", type=int, default=640)
    demo.add_argument("--height", type=int, default=480)
    demo.add_argument("--resolution", type=int, default=128, help="phantom voxels per side")
    demo.add_argument("--every", type=int, default=50, help="steps (ms) between stereo frames")
    replay = commands.add_parser(
        "replay",
        help="re-simulate a recording from its device readings (same removal log?) and "
        "optionally re-render it with another rig",
    )
    replay.add_argument("recording", type=Path)
    replay.add_argument("--out", type=Path, help="write the re-rendered session here")
    replay.add_argument("--baseline", type=float, help="another stereo baseline, metres")
    replay.add_argument("--width", type=int)
    replay.add_argument("--height", type=int)
    convert = commands.add_parser(
        "convert",
        help="convert anatomy volumes: NRRD/Slicer segmentation -> slice stack + volume ADF, "
        "slice stack or ADF -> NRRD, any -> surface mesh (.stl/.ply)",
    )
    convert.add_argument(
        "input", type=Path, help=".nrrd, .seg.nrrd, a volume ADF (.yaml) or a slice folder"
    )
    convert.add_argument(
        "output", type=Path, help="a folder (slice stack + ADF), .nrrd, .stl or .ply"
    )
    convert.add_argument("--prefix", default="plane00", help="slice file prefix")
    convert.add_argument("--labels", type=Path, help="label table (CSV/YAML) for slices")
    size = convert.add_mutually_exclusive_group()
    size.add_argument(
        "--dimensions",
        type=float,
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="a slice folder's size, metres",
    )
    size.add_argument(
        "--voxel-size",
        type=float,
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="a slice folder's voxel size, metres",
    )
    convert.add_argument("--threshold", type=float, help="segment an intensity NRRD at this value")
    convert.add_argument(
        "--label", type=int, default=0, help="mesh only this label id (default: every solid voxel)"
    )
    launch = commands.add_parser(
        "launch", help="load an AMBF launch file headless (AMBF's -l / -a), step it, report"
    )
    launch.add_argument("launch_file", type=Path)
    launch.add_argument("-l", type=indices, help="launch indices to load, e.g. 10,12")
    launch.add_argument("-a", help="more model files, comma separated")
    launch.add_argument("-i", type=indices, help="input devices to set up, e.g. 0,1")
    launch.add_argument("--ns", default="", help="namespace prefix")
    launch.add_argument("--steps", type=int, default=1000, help="1 ms steps to take")
    launch.add_argument(
        "--strict", action="store_true", help="a model or plugin that fails is fatal"
    )
    launch.add_argument(
        "--plugins",
        help="simulator plugins to load after the launch file's, comma separated "
        "(libx.so, x.py, a path, or a name searched in AMBFPLUS_PLUGIN_PATH)",
    )
    launch.add_argument(
        "--check-plugins",
        action="store_true",
        help="load each --plugins file in a probe process first and refuse one whose probe "
        "crashes, hangs or fails",
    )
    check = commands.add_parser(
        "check-plugins",
        help="load plugin files in probe processes (their static initialisers run there, not "
        "here); exit 1 if any crashes, hangs or fails",
    )
    check.add_argument("plugins", nargs="+", help="plugin files (.so, .py) or names")
    check.add_argument("--timeout", type=float, default=60.0, help="seconds a probe may take")
    validate = commands.add_parser(
        "validate",
        help="check a recording (ambfplus.recording) or a dataset folder (its manifest and "
        "every shard); exit 1 if any check fails",
    )
    validate.add_argument(
        "recording", type=Path, help="a recording's head file (name.h5) or a dataset folder"
    )
    validate.add_argument("--json", action="store_true", help="print the report as JSON")
    exporter = commands.add_parser(
        "export",
        help="export a recording or a dataset folder to MCAP or rosbag2 (ROS 2 messages), the "
        "original system's HDF5 layout or COCO masks",
    )
    exporter.add_argument("source", type=Path, help="a recording (name.h5) or a dataset folder")
    exporter.add_argument("--to", required=True, metavar="FORMAT",
                          help="mcap, rosbag2, original-h5 or coco")  # fmt: skip
    exporter.add_argument("out", type=Path, help="the output file (mcap) or folder")
    exporter.add_argument("--force", action="store_true", help="replace an existing output")
    exporter.add_argument("--quiet", action="store_true", help="no progress bar")
    exporter.add_argument("--verbose", action="store_true", help="print message counts")
    exporter.add_argument("--no-points", action="store_true",
                          help="mcap/rosbag2: no point clouds")  # fmt: skip
    exporter.add_argument("--compression", default="zstd", choices=("zstd", "lz4", "none"),
                          help="mcap: chunk compression")  # fmt: skip
    exporter.add_argument("--image-topics", default="raw", choices=("raw", "compressed", "both"),
                          help="mcap/rosbag2: sensor_msgs/Image topics, CompressedImage topics "
                          "(<topic>/compressed: PNG or TIFF, lossless) or both")  # fmt: skip
    exporter.add_argument("--rgb-codec", default="png", choices=("png", "jpeg"),
                          help="mcap/rosbag2: compressed rgb as png or jpeg (lossy)")  # fmt: skip
    exporter.add_argument("--jpeg-quality", type=int, default=90,
                          help="mcap/rosbag2: JPEG quality 1..100 (default 90)")  # fmt: skip
    exporter.add_argument("--chunk-size", type=int, default=500,
                          help="original-h5: samples per file (the original's 500)")  # fmt: skip
    exporter.add_argument("--no-images", action="store_true",
                          help="coco: annotations only, no PNG frames")  # fmt: skip
    validate.add_argument(
        "--no-image-matching",
        action="store_true",
        help="skip block matching the stereo pairs against depth and baseline (the costliest "
        "check)",
    )
    generate = commands.add_parser(
        "generate",
        help="generate a dataset from a YAML spec with local workers or on a Ray cluster; "
        "running it again resumes",
    )
    generate.add_argument("spec", type=Path, help="the dataset spec (YAML)")
    generate.add_argument("--out", type=Path, required=True, help="the dataset folder")
    generate.add_argument(
        "--workers", type=int, default=1, help="local worker processes (default 1)"
    )
    generate.add_argument(
        "--ray",
        metavar="ADDRESS",
        help="run on a Ray cluster instead: host:port, ray://host:port, auto (this machine's "
        'cluster) or local (a new one); needs pip install "ambfplus[ray]"',
    )
    generate.add_argument(
        "--ray-cpus", type=float, default=1.0, help="CPUs each Ray task asks for (default 1)"
    )
    generate.add_argument(
        "--ray-gpus",
        type=float,
        default=0.0,
        help="GPUs each Ray task asks for (default 0); a task given a GPU renders on it",
    )
    generate.add_argument(
        "--retries", type=int, default=3, help="attempts after the first per episode"
    )
    generate.add_argument("--timeout", type=float, help="seconds an episode may take")
    generate.add_argument("--quiet", action="store_true", help="no progress bar")
    dataset = commands.add_parser("dataset", help="dataset folders: info")
    dataset_commands = dataset.add_subparsers(dest="dataset_command", required=True)
    info = dataset_commands.add_parser(
        "info", help="counts by anatomy, scenario and label of a dataset folder"
    )
    info.add_argument("folder", type=Path)
    info.add_argument("--json", action="store_true", help="print JSON")
    commands.add_parser("info", help="print the version and the OpenGL device")
    doctor = commands.add_parser(
        "doctor",
        help="what the engine finds on this machine (renderer, EGL devices and drivers, optional "
        "libraries, extras) and what to install for what is missing; exits 1 if it cannot render",
    )
    doctor.add_argument("--json", action="store_true", help="print the checks as JSON")
    args = parser.parse_args(argv)
    if args.command == "validate":
        return run_validate(args)
    if args.command == "generate":
        # At exit, everything is written and closed: spare the driver the collection Python
        # runs then over every object (with Ray's modules loaded it costs about 0.3 CPU-s).
        atexit.register(gc.freeze)
        return run_generate(args)
    if args.command == "dataset":
        return run_dataset(args)
    if args.command == "launch":
        return run_launch(args)
    if args.command == "check-plugins":
        return run_check_plugins(args)
    if args.command == "export":
        return run_export(args)
    if args.command == "demo":
        return run_demo(args.out, args.width, args.height, args.resolution, args.every)
    if args.command == "replay":
        return run_replay(args)
    if args.command == "convert":
        print(
            convert_volume(
                args.input,
                args.output,
                prefix=args.prefix,
                labels=args.labels,
                dimensions=args.dimensions,
                voxel_size=args.voxel_size,
                threshold=args.threshold,
                label=args.label,
            )
        )
        return 0
    if args.command == "doctor":
        from .doctor import main as doctor

        return doctor(as_json=args.json)
    if args.command == "info":
        print(json.dumps({"version": __version__, "gl": gl_info()}, indent=2))
        return 0
    return 2
