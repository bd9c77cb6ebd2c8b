"""A network bridge that replays a trajectory: what a bridge for a real haptic device looks like.

    python examples/network_bridge.py OUT --port 5555 [--trajectory plunge.csv]

sends poses to an engine's NetworkDevice on UDP port 5555 (e.g. ``ambfplus-launch ... --device
network:5555``) at --rate Hz, collects the forces it sends back and writes them to
OUT/forces.csv with a summary in OUT/bridge.json. A bridge for a real device reads the device
through its SDK instead of the trajectory and renders the forces it receives.

The trajectory is a CSV file with a header ``time,x,y,z,qx,qy,qz,qw,buttons`` (seconds, metres,
quaternion, button bits), or the built-in plunge: 10 mm down in 1 s with the burr spinning, held
for half a second.

Without --port it runs a whole session: the built-in phantom scene with a NetworkDevice in this
process, driven in real time by this script started again as a second process, and it writes
what the drill removed to OUT/session.json.
"""

from __future__ import annotations

import argparse
import csv
import json
import subprocess
import sys
import time
from pathlib import Path

import numpy as np


def plunge(rate: float) -> np.ndarray:
    """Rows of time, x, y, z, qx, qy, qz, qw, buttons."""
    t = np.arange(0.0, 1.5, 1.0 / rate)
    rows = np.zeros((len(t), 9))
    rows[:, 0] = t
    rows[:, 3] = -0.010 * np.clip(t, 0.0, 1.0)
    rows[:, 7] = 1.0
    rows[:, 8] = 1  # the burr spins
    return rows


def read_trajectory(path: Path) -> np.ndarray:
    columns = ["time", "x", "y", "z", "qx", "qy", "qz", "qw", "buttons"]
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames != columns:
            raise SystemExit(f"{path}: expected the header {','.join(columns)}")
        try:
            rows = [[float(row[c]) for c in columns] for row in reader]
        except ValueError as error:
            raise SystemExit(f"{path}: line {reader.line_num}: {error}") from None
    if not rows:
        raise SystemExit(f"{path}: no poses")
    return np.array(rows)


def bridge(out: Path, port: int, trajectory: np.ndarray) -> dict:
    from ambfplus.devices.network import Bridge

    started = time.perf_counter()
    with Bridge(port) as link:
        for t, x, y, z, qx, qy, qz, qw, buttons in trajectory:
            # Absolute deadlines: the trajectory's own clock, however long a send takes.
            delay = started + t - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            link.send((x, y, z), (qx, qy, qz, qw), int(buttons))
            link.receive()
        time.sleep(0.05)
        link.receive()
        forces = link.forces
    with open(out / "forces.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["sequence", "time", "fx", "fy", "fz"])
        writer.writerows([f.sequence, f.time, *f.force] for f in forces)
    summary = {
        "poses_sent": len(trajectory),
        "forces_received": len(forces),
        "max_force_n": max((f.magnitude for f in forces), default=0.0),
        "last_answered": forces[-1].sequence if forces else 0,
    }
    (out / "bridge.json").write_text(json.dumps(summary, indent=1))
    return summary


def session(out: Path, rate: float) -> dict:
    """The phantom scene driven through a NetworkDevice by this script in another process."""
    import ambfplus
    from ambfplus.scenes import drilling_phantom

    scene = drilling_phantom(resolution=96)
    device = ambfplus.NetworkDevice()
    scene.world.add_input_device("bridge", device, scene.drill, **scene.device_options)
    with ambfplus.RealTimeLoop(scene.world):
        child = subprocess.run(
            [sys.executable, __file__, str(out), "--port", str(device.port), "--rate", str(rate)],
            capture_output=True, text=True, timeout=120,
        )  # fmt: skip
    if child.returncode != 0:
        raise SystemExit(f"the bridge failed:\n{child.stderr}")
    summary = {
        "bridge": json.loads(child.stdout),
        "poses_accepted": device.accepted,
        "rejected": device.rejected,
        "voxels_removed": len(scene.drill.removed["step"]),
        "drill_moved_mm": float(1e3 * np.linalg.norm(scene.drill.goal[:3, 3] - (0, 0, 0.022))),
    }
    (out / "session.json").write_text(json.dumps(summary, indent=1))
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="folder for forces.csv and the summaries")
    parser.add_argument("--port", type=int, help="the engine's UDP port (none: a whole session)")
    parser.add_argument("--trajectory", type=Path, help="CSV of poses (default: a plunge)")
    parser.add_argument("--rate", type=float, default=500.0, help="poses per second (plunge)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    if args.port is None:
        print(json.dumps(session(args.out, args.rate), indent=1))
        return
    trajectory = read_trajectory(args.trajectory) if args.trajectory else plunge(args.rate)
    print(json.dumps(bridge(args.out, args.port, trajectory)))


if __name__ == "__main__":
    main()
