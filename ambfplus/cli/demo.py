"""``ambfplus demo``: a headless drilling session on the built-in phantom, recorded, validated
and previewed as PNG files."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from .._core import ScriptedDevice, __version__, gl_info, write_image
from ..config import MAX_PHANTOM_RESOLUTION
from ..dataset.spec import MAX_SIDE
from .values import within


def add_parser(commands) -> None:
    """Declares ``ambfplus demo``, its options and the function that runs it."""
    demo = commands.add_parser(
        "demo",
        help="a headless drilling session on the built-in phantom: record it, validate it, "
        "write preview PNGs",
    )
    demo.add_argument("--out", type=Path, default=Path("demo_out"), help="output folder")
    demo.add_argument("--width", type=within(8, MAX_SIDE), default=640)
    demo.add_argument("--height", type=within(8, MAX_SIDE), default=480)
    demo.add_argument("--resolution", type=within(8, MAX_PHANTOM_RESOLUTION), default=128,
                      help="phantom voxels per side")  # fmt: skip
    demo.add_argument("--every", type=within(1, 1000), default=50,
                      help="steps (ms) between stereo frames")  # fmt: skip
    demo.add_argument("--plain", action="store_true",
                      help="no shadows, antialiasing or volume looks (the library's defaults); "
                      "without it the cameras draw all three, as the launcher does")  # fmt: skip
    demo.set_defaults(func=run)


def run(args) -> int:
    """Runs the demo with the command line's options."""
    return run_demo(args.out, args.width, args.height, args.resolution, args.every, args.plain)


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


def _debrief(path: Path, out: Path, resolution: int) -> str:
    """The session assessed as a cortical mastoidectomy (the shipped task is on the 128^3
    phantom): debrief.html and assessment.json. Returns what the summary line lists."""
    if resolution != 128:
        print("no debrief: the shipped tasks are on the 128^3 phantom")
        return ""
    from ..training import assess

    result = assess(path, "cortical_mastoidectomy")
    result.write_report(out / "debrief.html")
    result.write_json(out / "assessment.json")
    print(f"debrief: score {result.score:.0f} / 100 as a cortical mastoidectomy, "
          f"{len(result.data['violations'])} violations (debrief.html)")  # fmt: skip
    return ", debrief.html, assessment.json"


def run_demo(
    out: Path, width: int, height: int, resolution: int, every: int, plain: bool = False
) -> int:
    """A headless drilling session on the built-in phantom: scripted plunges at three sites
    while the stereo rig circles, recorded, validated, and previewed as PNG files. The cameras
    draw shadows, antialiasing (level 2) and the volume looks unless `plain`."""
    from ..recording import open_recording, validate
    from ..scenes import drilling_phantom, orbit_view, record_session

    out.mkdir(parents=True, exist_ok=True)
    path = out / "session.h5"
    for old in out.glob("session.h5*"):
        old.unlink()
    print(f"ambfplus {__version__}: {gl_info()['renderer']}", flush=True)
    scene = drilling_phantom(
        resolution=resolution, width=width, height=height, shadows=not plain,
        antialiasing=1 if plain else 2, looks=not plain,
    )  # fmt: skip
    device = ScriptedDevice()
    sites = [(0.0, 0.0), (-0.006, 0.004), (-0.003, -0.006)]
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
    debrief = _debrief(path, out, resolution)
    covered = last.left.depth > 0
    coverage = float(covered.mean())
    contrast = float(last.left.rgb[covered].std()) if covered.any() else 0.0
    print(
        f"wrote {out}: session.h5 ({summary['frames']} stereo frames, {summary['steps']} steps, "
        f"{summary['voxels_removed']} voxels removed), montage.png, rgb.png, right_rgb.png, "
        f"depth.png, depth_preview.png, label.png, label_preview.png, segmentation.png, "
        f"frame.json{debrief}; the anatomy covers {coverage:.1%} of the last view"
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
