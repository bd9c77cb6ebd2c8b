"""Export throughput (ambfplus.export) and the live view's cost to the real-time loop.

``export``: a 640x480 stereo drilling session (rgb, depth, label, instance, voxel,
segmentation every 50 ms) exported to each format, in MB/s of recorded image data and frames/s,
against reading the same recording alone (every frame's passes and the step log) in the same
run: ratio = export rate / read rate. Median and worst of the repetitions.

``foxglove_live``: the 1 kHz physics loop drilling while a 640x480 camera captures in another
thread, without and with the Foxglove live view serving a subscribed WebSocket client (camera,
calibration, TF, force, critical structures at 10 Hz), in alternating rounds.
"""

from __future__ import annotations

import json
import statistics
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import ambfplus


def _session(path: Path, seconds: float) -> dict:
    from ambfplus.scenes import drilling_phantom, orbit_view
    from ambfplus.session import record_session

    scene = drilling_phantom(resolution=128, width=640, height=480)
    r = scene.drill.burr_radius
    surface = scene.drill.volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))["position"]
    down = surface[2] + r - 0.002 - scene.drill.goal[2, 3]
    device = ambfplus.ScriptedDevice()
    device.set_waypoints([
        {"time": 0.0, "position": (0, 0, 0)},
        {"time": 0.3, "position": (0, 0, down + 0.004), "buttons": 1},
        {"time": seconds, "position": (0.002, 0.002, down), "buttons": 1},
    ])  # fmt: skip
    return record_session(scene, path, device, seconds=seconds, capture_every=50,
                          camera_motion=orbit_view)  # fmt: skip


def _read_all(path: Path) -> tuple[int, int]:
    """Reads every frame's passes and the step log: (frames, image bytes)."""
    from ambfplus.recording import open_recording

    frames = nbytes = 0
    with open_recording(path) as rec:
        _ = rec.steps, rec.removed, rec.events
        for stream in rec.cameras.values():
            for index in range(len(stream)):
                frame = stream[index]
                nbytes += sum(getattr(frame, p).nbytes for p in stream.passes)
                frames += 1
    return frames, nbytes


def export_benchmark(args):
    """Export MB/s and frames/s per format against reading the recording alone."""
    from ambfplus.export import FORMATS, export

    repeats = 1 if args.quick else 3
    seconds = 0.5 if args.quick else 2.0
    with tempfile.TemporaryDirectory() as folder:
        folder = Path(folder)
        source = folder / "session.h5"
        summary = _session(source, seconds)
        runs: dict[str, list] = {"read": [], **{f: [] for f in FORMATS}}
        out_bytes: dict[str, int] = {}
        for repeat in range(repeats):
            w0, c0 = time.perf_counter(), time.process_time()
            frames, nbytes = _read_all(source)
            runs["read"].append((time.perf_counter() - w0, time.process_time() - c0))
            for to in FORMATS:
                out = folder / f"out_{to}_{repeat}"
                w0, c0 = time.perf_counter(), time.process_time()
                result = export(source, out, to, progress=False)
                runs[to].append((time.perf_counter() - w0, time.process_time() - c0))
                out_bytes[to] = result.bytes
    source_mb = nbytes / 1e6
    read_wall = statistics.median(w for w, _ in runs["read"])
    common = {"frames": frames, "image_mb": round(source_mb, 2), "quick": args.quick,
              "session": f"{summary['frames']} stereo pairs 640x480, {summary['steps']} steps, "
              f"{summary['voxels_removed']} voxels removed"}  # fmt: skip
    yield {"bench": "export_read_baseline", "value": round(source_mb / read_wall, 1),
           "unit": "MB/s", "frames_per_s": round(frames / read_wall, 1),
           "what": "reading every frame's passes and the step log", **common}  # fmt: skip
    for to in FORMATS:
        walls = [w for w, _ in runs[to]]
        wall, worst = statistics.median(walls), max(walls)
        yield {
            "bench": f"export_{to.replace('-', '_')}",
            "value": round(source_mb / wall, 1),
            "unit": "MB/s (recorded image data)",
            "baseline": round(source_mb / read_wall, 1),
            "ratio": round(read_wall / wall, 3),
            "frames_per_s": round(frames / wall, 1),
            "worst_mb_per_s": round(source_mb / worst, 1),
            "cpu_s_per_frame": round(statistics.median(c for _, c in runs[to]) / frames, 4),
            "output_mb": round(out_bytes[to] / 1e6, 2),
            "what": f"export to {to} against reading the recording alone",
            **common,
        }


def _live_client(url: str, stop: threading.Event, counts: dict) -> None:
    """A Foxglove WebSocket client subscribed to every channel, counting what it receives."""
    from websockets.sync.client import connect

    with connect(url, subprotocols=["foxglove.sdk.v1"], max_size=None) as connection:
        channels = []
        while len(channels) < 5:
            message = connection.recv(timeout=10)
            if isinstance(message, str) and json.loads(message).get("op") == "advertise":
                channels += json.loads(message)["channels"]
        connection.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": i, "channelId": c["id"]} for i, c in enumerate(channels)]}))  # fmt: skip
        while not stop.is_set():
            try:
                message = connection.recv(timeout=0.5)
            except TimeoutError:
                continue
            if isinstance(message, bytes):
                counts["messages"] += 1
                counts["bytes"] += len(message)


def _live_round(seconds: float, serve: bool, capturing: bool) -> dict:
    from ambfplus.export.live import FoxgloveServer

    world = ambfplus.World()
    volume = world.add_volume("ear", ambfplus.phantom(256))
    drill = world.add_drill("drill", volume)
    camera = world.add_camera("cam", 640, 480, fov_y=0.5, near=0.01, far=1.0)
    camera.look_at((0.05, -0.1, 0.1), (0, 0, 0))
    hit = volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))
    into = -hit["normal"] / np.linalg.norm(hit["normal"])
    start = hit["position"] - into * (drill.burr_radius + 0.002)
    drill.goal = ambfplus.make_pose(start, rotation=ambfplus.rotation_between((1, 0, 0), -into))
    hand = ambfplus.SimulatedDevice()
    world.add_input_device("hand", hand, drill)
    camera.capture()
    stop = threading.Event()
    frames = [0]

    def capture():
        while not stop.is_set():
            camera.capture(passes=["rgb", "depth"])
            frames[0] += 1

    counts = {"messages": 0, "bytes": 0}
    loop = ambfplus.RealTimeLoop(world)
    server = FoxgloveServer(world, [camera], rate=10.0, port=0) if serve else None
    with loop:
        threads = [threading.Thread(target=capture)] if capturing else []
        if server is not None:
            server.start()
            threads.append(threading.Thread(target=_live_client,
                                            args=(server.url, stop, counts)))  # fmt: skip
        for thread in threads:
            thread.start()
        hand.set_target(into * 0.005, buttons=1)
        time.sleep(seconds)
        stop.set()
        for thread in threads:
            thread.join()
        if server is not None:
            server.stop()
    s = loop.stats
    return {"p99": s["p99"], "max": s["max"], "rate": s["mean_rate"], "over_2ms": s["over_2ms"],
            "frames_per_s": frames[0] / s["seconds"], "messages": counts["messages"],
            "mb": counts["bytes"] / 1e6, "seconds": s["seconds"],
            "live": server.stats.summary() if server else None}  # fmt: skip


def foxglove_live(args):
    """The real-time loop's periods without and with the live view serving a client: in a
    headless session (nothing else renders) and while another thread captures continuously."""
    seconds = 3.0 if args.quick else 8.0
    rounds = 1 if args.quick else 2
    for capturing in (False, True):
        results = {False: [], True: []}
        for _ in range(rounds):
            for serve in (False, True):
                results[serve].append(_live_round(seconds, serve, capturing))
        for serve in (False, True):
            runs = results[serve]
            name = "foxglove_live_loop" + ("_capturing" if capturing else "_headless")
            line = {
                "bench": name if serve else name + "_baseline",
                "value": round(statistics.median(r["p99"] for r in runs) * 1e3, 4),
                "unit": "ms (p99 period)",
                "target": 1.2,
                "worst_p99_ms": round(max(r["p99"] for r in runs) * 1e3, 4),
                "max_ms": round(max(r["max"] for r in runs) * 1e3, 4),
                "max_target_ms": 2.0,
                "mean_rate_hz": round(statistics.median(r["rate"] for r in runs), 2),
                "rate_target_hz": 995,
                "over_2ms": [r["over_2ms"] for r in runs],
                "seconds_per_round": seconds,
                "rounds": rounds,
                "what": "1 kHz loop drilling the ear phantom 256^3"
                + (", a 640x480 camera capturing in a thread" if capturing else ", headless")
                + (
                    ", the Foxglove live view (640x480 camera) serving a subscribed client at 10 Hz"
                    if serve
                    else ""
                ),
            }
            if capturing:
                line["capture_frames_per_s"] = round(
                    statistics.median(r["frames_per_s"] for r in runs), 1
                )
            if serve:
                base = statistics.median(r["p99"] for r in results[False])
                line.update(
                    baseline=round(base * 1e3, 4), ratio=round(line["value"] / (base * 1e3), 3),
                    client_messages_per_s=round(statistics.median(
                        r["messages"] / r["seconds"] for r in runs), 1),
                    client_mb_per_s=round(statistics.median(r["mb"] / r["seconds"]
                                                            for r in runs), 2),
                    live=runs[-1]["live"],
                )  # fmt: skip
            yield line


BENCHMARKS = {"export": export_benchmark, "foxglove_live": foxglove_live}
