"""Devices from outside the engine: a network device fed by a bridge in another process (pose
in, force out, every message validated), and joysticks, gamepads and foot pedals through the
Linux joystick interface (events injected, or written to a pipe standing in for the device
file)."""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import socket
import struct
import subprocess
import sys
import time

import numpy as np
import pytest
from helpers import EXAMPLES
from test_devices import drill_over_slab

import ambfplus
from ambfplus.devices.network import Bridge, pack_pose

BRIDGE = EXAMPLES / "network_bridge.py"
BUTTON, AXIS, INIT = 0x01, 0x02, 0x80


def wait_for(condition, timeout=10.0):
    deadline = time.time() + timeout
    while not condition():
        assert time.time() < deadline, "timed out"
        time.sleep(0.002)


def test_a_bridge_in_another_process_drills_and_gets_forces_back(tmp_path):
    """The example bridge replays a 10 mm plunge over UDP while the world runs in real time: the
    drill follows it exactly, removes bone and the forces come back; malformed, oversized and
    stale messages sent meanwhile are rejected by reason and change nothing."""
    world, volume, drill = drill_over_slab(height=0.006)  # the 6 mm burr touches 3 mm below
    device = ambfplus.NetworkDevice()
    world.add_input_device("bridge", device, drill)
    start = drill.goal.copy()
    good = pack_pose(1, (0.0, 0.0, 0.0))
    version_2 = good[:4] + struct.pack("<H", 2) + good[6:]
    bad = {
        "size": [b"short", good + bytes(4000)],  # 4080 bytes: larger than the receive buffer
        "magic": [b"XXXX" + good[4:]],
        "version": [version_2],
        "values": [pack_pose(10**9, (math.nan, 0.0, 0.0))],
        "range": [pack_pose(10**9, (100.0, 0.0, 0.0))],
        "rotation": [pack_pose(10**9, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 2.0))],
        "sequence": [pack_pose(1, (0.05, 0.0, 0.0))],  # well formed, but older than the last
    }
    with ambfplus.RealTimeLoop(world):
        bridge = subprocess.Popen(
            [sys.executable, str(BRIDGE), str(tmp_path), "--port", str(device.port)],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip
        wait_for(lambda: device.accepted > 100 or bridge.poll() is not None)
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as intruder:
            for messages in bad.values():
                for message in messages:
                    intruder.sendto(message, ("127.0.0.1", device.port))
        out, err = bridge.communicate(timeout=60)
    assert bridge.returncode == 0, err
    summary = json.loads(out)

    assert device.rejected == {reason: len(messages) for reason, messages in bad.items()}
    assert device.accepted == summary["poses_sent"]
    # The drill's goal went exactly where the bridge took it: 10 mm down, nothing else.
    np.testing.assert_allclose(drill.goal[:3, 3] - start[:3, 3], (0.0, 0.0, -0.010), atol=1e-12)
    np.testing.assert_allclose(drill.goal[:3, :3], start[:3, :3], atol=1e-12)
    assert len(drill.removed["step"]) > 50, "the spinning burr cut into the bone"
    # Forces came back every step, answering the bridge's poses, and push the burr back up.
    assert summary["forces_received"] > 500
    assert summary["last_answered"] == summary["poses_sent"]
    with open(tmp_path / "forces.csv") as f:
        forces = np.array([[float(v) for v in row.values()] for row in csv.DictReader(f)])
    # Poses from 0.75 s of the plunge on (500 a second): the goal 4.5 mm and more into the bone.
    in_bone = forces[forces[:, 0] >= 375]
    assert len(in_bone) > 100 and summary["max_force_n"] > 0.5
    assert np.all(in_bone[:, 4] > 0.2), "the bone pushes the burr up"
    assert np.abs(in_bone[:, 2:4]).max() < 0.2 * in_bone[:, 4].min()


def test_network_readings_start_at_the_first_pose_and_forces_answer_each_step():
    world, volume, drill = drill_over_slab(height=0.02)
    device = ambfplus.NetworkDevice()
    world.add_input_device("bridge", device, drill)
    start = drill.goal.copy()
    turn = (0.0, 0.0, math.sin(0.2), math.cos(0.2))  # the device's own pose: turned and offset
    with Bridge(device.port) as bridge:
        bridge.send((0.3, -0.1, 0.2), turn, buttons=1)
        wait_for(lambda: device.accepted == 1)
        world.step(1)
        np.testing.assert_allclose(drill.goal, start, atol=1e-12)  # taken up where it is
        assert drill.on
        bridge.send((0.302, -0.1, 0.2), turn, buttons=0)
        wait_for(lambda: device.accepted == 2)
        world.step(2)
        np.testing.assert_allclose(drill.goal[:3, 3] - start[:3, 3], (0.002, 0, 0), atol=1e-12)
        assert not drill.on
        wait_for(lambda: len(bridge.receive()) == 0 and len(bridge.forces) == 3)
    answered = [f.sequence for f in bridge.forces]
    assert answered == [1, 2, 2]
    assert bridge.forces[-1].time == pytest.approx(world.time)


def test_network_device_arguments_are_checked():
    with pytest.raises(ValueError, match="port"):
        ambfplus.NetworkDevice(port=70000)
    with pytest.raises(ValueError, match="IPv4"):
        ambfplus.NetworkDevice(address="loopback")
    taken = ambfplus.NetworkDevice()
    with pytest.raises(ambfplus.ResourceError, match=f"127.0.0.1:{taken.port}.*bind"):
        ambfplus.NetworkDevice(port=taken.port)


def js(value: int, kind: int, number: int, ms: int = 0) -> bytes:
    """One Linux js_event."""
    return struct.pack("<IhBB", ms, value, kind, number)


def test_joystick_buttons_and_axes_drive_the_drill():
    world, volume, drill = drill_over_slab(height=0.02)
    stick = ambfplus.JoystickDevice()
    world.add_input_device("stick", stick, drill, clutch_button=1, burr_button=2)
    start = drill.goal.copy()
    # The driver's opening state (init events) changes nothing.
    stick.feed(js(0, BUTTON | INIT, 0) + js(0, AXIS | INIT, 0) + js(0, AXIS | INIT, 1))
    world.step(5)
    np.testing.assert_allclose(drill.goal, start, atol=1e-12)
    assert not drill.on

    # Button 0 held spins the burr.
    stick.feed(js(1, BUTTON, 0))
    world.step(1)
    assert drill.on
    stick.feed(js(0, BUTTON, 0))
    world.step(1)
    assert not drill.on

    # Axis 0 at full deflection moves 0.02 m/s along x; inside the dead band nothing moves.
    stick.feed(js(32767, AXIS, 0))
    world.step(100)
    moved = drill.goal[:3, 3] - start[:3, 3]
    assert moved[0] == pytest.approx(0.02 * 0.1, rel=0.02)
    assert moved[1] == 0 and moved[2] == 0
    stick.feed(js(1000, AXIS, 0))  # 3 % of full deflection
    before = drill.goal.copy()
    world.step(50)
    np.testing.assert_allclose(drill.goal, before, atol=1e-15)

    # The stick pushed up (negative) moves up; with the clutch held the drill stays put, and
    # afterwards it moves on from where it is.
    stick.feed(js(-32767, AXIS, 1) + js(1, BUTTON, 1))
    world.step(50)
    np.testing.assert_allclose(drill.goal, before, atol=1e-15)
    stick.feed(js(0, BUTTON, 1))
    world.step(50)
    up = drill.goal[:3, 3] - before[:3, 3]
    assert up[1] == pytest.approx(0.02 * 0.05, rel=0.05) and up[0] == 0

    # A press and release between two steps still takes the next burr, once.
    burr = drill.burr
    stick.feed(js(1, BUTTON, 2) + js(0, BUTTON, 2))
    world.step(3)
    assert drill.burr == (burr + 1) % len(drill.burr_diameters)

    # A record split across reads waits for its second half.
    event = js(1, BUTTON, 0)
    stick.feed(event[:5])
    world.step(1)
    assert not drill.on
    stick.feed(event[5:])
    world.step(1)
    assert drill.on


def test_a_foot_pedal_with_its_own_mapping_adds_its_buttons_to_another_device():
    world, volume, drill = drill_over_slab(height=0.02)
    hand = ambfplus.ScriptedDevice()
    hand.set_waypoints(
        [{"time": 0.0, "position": (0, 0, 0)}, {"time": 1.0, "position": (0, 0, -0.01)}]
    )
    pedal = ambfplus.JoystickDevice(
        mapping=ambfplus.JoystickMapping(drill=4, clutch=5, burr=-1, axes=(-1, -1, -1))
    )
    merged = ambfplus.MergedDevice(hand, [pedal])
    world.add_input_device("hand", merged, drill, clutch_button=1)
    start = drill.goal.copy()
    pedal.feed(js(1, BUTTON, 0) + js(32767, AXIS, 0))  # unmapped: nothing
    world.step(100)
    assert not drill.on
    assert drill.goal[2, 3] - start[2, 3] == pytest.approx(-0.001, rel=0.02)
    pedal.feed(js(1, BUTTON, 4))  # the drill pedal
    world.step(100)
    assert drill.on
    assert drill.goal[2, 3] - start[2, 3] == pytest.approx(-0.002, rel=0.02)
    pedal.feed(js(1, BUTTON, 5))  # the clutch pedal: the hand moves, the drill does not
    held = drill.goal.copy()
    world.step(100)
    np.testing.assert_allclose(drill.goal, held, atol=1e-15)
    assert merged.spec == hand.spec


def test_a_joystick_device_file_is_read_on_its_own_thread(tmp_path):
    """A named pipe stands in for /dev/input/js0: events written to it reach the drill, and a
    writer that goes away leaves the device waiting, not spinning or failing."""
    with pytest.raises(ambfplus.AssetNotFound, match="js9"):
        ambfplus.JoystickDevice(str(tmp_path / "js9"))
    path = tmp_path / "js0"
    os.mkfifo(path)
    world, volume, drill = drill_over_slab(height=0.02)
    stick = ambfplus.JoystickDevice(str(path))
    world.add_input_device("stick", stick, drill)
    cpu = time.process_time()
    with open(path, "wb", buffering=0) as writer:
        writer.write(js(1, BUTTON, 0))
        wait_for(lambda: (world.step(1), drill.on)[1], timeout=5)
    time.sleep(0.3)  # no writer now
    assert time.process_time() - cpu < 0.25, "the reader spins without a writer"
    assert not stick.disconnected
    with open(path, "wb", buffering=0) as writer:
        writer.write(js(0, BUTTON, 0))
        wait_for(lambda: (world.step(1), not drill.on)[1], timeout=5)


def test_launcher_device_options():
    from ambfplus.launcher.inputs import make_device, pedal_mapping

    mapping = pedal_mapping("drill=3, burr=6")
    assert (mapping.drill, mapping.clutch, mapping.burr, tuple(mapping.axes)) == (
        3,
        -1,
        6,
        (-1, -1, -1),
    )
    with pytest.raises(SystemExit, match="pedal-map"):
        pedal_mapping("spin=1")
    keyboard = ambfplus.KeyboardDevice()

    def options(device, pedal=None):
        return argparse.Namespace(device=device, pedal=pedal, pedal_map="drill=0,clutch=1,burr=2")

    device, name = make_device(options("keyboard"), keyboard)
    assert device is keyboard and name == "keyboard"
    device, name = make_device(options("network:0"), keyboard)
    assert isinstance(device, ambfplus.MergedDevice) and name.startswith("network :")
    with pytest.raises(SystemExit, match="keyboard, network"):
        make_device(options("phantom"), keyboard)
    with pytest.raises(SystemExit, match="js7"):
        make_device(options("keyboard", pedal="/nonexistent/js7"), keyboard)
