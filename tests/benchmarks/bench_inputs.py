"""Bad input at run time: memory under a flood of malformed UDP datagrams at a NetworkDevice.

    python tests/benchmarks/run.py --only udp_flood

A sender process fires malformed datagrams (wrong sizes, magic, versions, non-finite numbers,
out-of-range positions, non-rotations, stale sequence numbers; a few good poses among them) at a
``NetworkDevice`` bound to a drill over bone, for 30 s (10 s with --quick), while a
``RealTimeLoop`` steps the world at 1 kHz. Reports the growth of the process's resident memory
(target: < 20 MB), the datagrams rejected and accepted, the device log's length (its bound is
65,536 readings) and whether the drill's pose stayed finite. The baseline is the same run's RSS
growth over an equally long stretch with no datagrams.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time

import numpy as np

import ambfplus

SENDER = r"""
import math, socket, struct, sys, time
sys.path.insert(0, sys.argv[3])
from ambfplus.devices.network import pack_pose
port, seconds = int(sys.argv[1]), float(sys.argv[2])
good = pack_pose(1, (0.0, 0.0, 0.0))
bad = [b"short", good + bytes(64), b"XXXX" + good[4:], good[:4] + struct.pack("<H", 9) + good[6:],
       pack_pose(10**12, (math.nan, 0.0, 0.0)), pack_pose(10**12, (1e9, 0.0, 0.0)),
       pack_pose(10**12, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 2.0)), pack_pose(0, (0.01, 0.0, 0.0)),
       bytes(80), bytes(4000)]
sent, sequence = 0, 1
end = time.monotonic() + seconds
with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
    while time.monotonic() < end:
        for message in bad:
            try:
                s.sendto(message, ("127.0.0.1", port))
                sent += 1
            except OSError:
                pass
        if sent % 1000 < len(bad):  # now and then a good pose
            sequence += 1
            s.sendto(pack_pose(sequence, (0.0001 * (sequence % 10), 0.0, 0.0)), ("127.0.0.1", port))
print(sent)
"""


def rss_mb() -> float:
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def drilling_world():
    n, voxel = 80, 0.0002
    grid = np.zeros((n, n, n), np.uint8)
    grid[:, :, : n // 2] = 1
    data = ambfplus.VolumeData(
        grid, voxel_size=(voxel,) * 3, label_table=[ambfplus.Label(1, "Bone")]
    )
    world = ambfplus.World()
    volume = world.add_volume("bone", data)
    down = np.array([[1.0, 0, 0], [0, -1, 0], [0, 0, -1]])
    drill = world.add_drill("drill", volume, pose=ambfplus.make_pose((0, 0, 0.01), rotation=down))
    return world, drill


def udp_flood(args):
    seconds = 10.0 if args.quick else 30.0
    world, drill = drilling_world()
    device = ambfplus.NetworkDevice()
    binding = world.add_input_device("bridge", device, drill)
    package_parent = os.path.dirname(os.path.dirname(ambfplus.__file__))
    with ambfplus.RealTimeLoop(world):
        time.sleep(2.0)  # warm up: first steps allocate the drill's caches
        quiet_start = rss_mb()
        time.sleep(seconds / 3)
        quiet_growth = rss_mb() - quiet_start
        start, steps_before = rss_mb(), world.step_index
        sender = subprocess.run(
            [sys.executable, "-c", SENDER, str(device.port), str(seconds), package_parent],
            capture_output=True, text=True, timeout=seconds + 60,
        )  # fmt: skip
        end = rss_mb()
        steps = world.step_index - steps_before
    sent = int(sender.stdout.strip() or 0)
    log = binding.log
    finite = bool(np.isfinite(drill.pose).all())
    yield {
        "bench": "udp_flood_rss_growth",
        "value": round(end - start, 2),
        "unit": "MB",
        "baseline": round(quiet_growth, 2),
        "ratio": round((end - start) / max(abs(quiet_growth), 0.01), 2),
        "what": f"RSS growth over {seconds:g} s of malformed UDP datagrams at a NetworkDevice "
        "driving a drill in a 1 kHz RealTimeLoop (target < 20 MB); baseline: RSS growth over "
        f"{seconds / 3:g} s of the same loop without datagrams",
        "rss_start_mb": round(start, 1),
        "rss_end_mb": round(end, 1),
        "datagrams_sent": sent,
        "rejected": dict(device.rejected),
        "accepted": int(device.accepted),
        "steps": int(steps),
        "device_log_readings": int(len(log["step"])),
        "drill_pose_finite": finite,
    }


BENCHMARKS = {"udp_flood": udp_flood}

if __name__ == "__main__":  # pragma: no cover - run.py is the usual way in
    import argparse
    import json

    parser = argparse.ArgumentParser()
    parser.add_argument("--quick", action="store_true")
    for figure in udp_flood(parser.parse_args()):
        print(json.dumps(figure))
