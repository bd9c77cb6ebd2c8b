"""The live view: a WebSocket client speaking the Foxglove protocol subscribes to a camera, its
calibration, the drill's force and the critical structures of a headless drilling session in
real time, and decodes what it receives (with mcap-ros2-support, not the server's encoder)."""

from __future__ import annotations

import json
import struct
import time

import numpy as np
import pytest

import ambfplus
from ambfplus.scenes import drilling_phantom

pytest.importorskip("foxglove", reason='needs pip install "ambfplus[foxglove]"')
websockets_client = pytest.importorskip("websockets.sync.client",
                                        reason="the test's client needs websockets")  # fmt: skip
pytest.importorskip("mcap_ros2", reason='decoding needs pip install "ambfplus[export]"')

from mcap.records import Schema  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402

from ambfplus.export.live import FoxgloveServer  # noqa: E402

SUBPROTOCOL = "foxglove.sdk.v1"
MESSAGE_DATA = 0x01  # binary opcode: subscription id (u32), log time (u64), payload


def receive_json(connection, op: str) -> dict:
    while True:
        frame = connection.recv(timeout=10)
        if isinstance(frame, str):
            message = json.loads(frame)
            if message.get("op") == op:
                return message


def test_a_client_watches_a_drilling_session_live():
    scene = drilling_phantom(resolution=64, width=160, height=120)
    world, drill, rig = scene.world, scene.drill, scene.rig
    hand = ambfplus.SimulatedDevice()
    world.add_input_device("hand", hand, drill)
    rig.left.capture()  # upload before the clock starts
    rate = 10.0
    loop = ambfplus.RealTimeLoop(world)
    with loop, FoxgloveServer(world, [rig.left], rate=rate, port=0) as server:
        assert server.url.startswith("ws://127.0.0.1:")
        hand.set_target((0.0, 0.0, -0.008), buttons=1)  # down into the bone, spinning
        with websockets_client.connect(server.url, subprotocols=[SUBPROTOCOL]) as connection:
            info = receive_json(connection, "serverInfo")
            assert info["name"] == "ambfplus"
            channels = {}
            while len(channels) < 5:
                for channel in receive_json(connection, "advertise")["channels"]:
                    channels[channel["topic"]] = channel
            wanted = ["/rig_left/image_rect_color", "/rig_left/camera_info", "/drill/wrench",
                      "/drill/critical", "/tf"]  # fmt: skip
            subscriptions = {i + 1: channels[topic] for i, topic in enumerate(wanted)}
            connection.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": i, "channelId": c["id"]} for i, c in subscriptions.items()]}))  # fmt: skip
            decoders = {
                i: DecoderFactory().decoder_for(c["encoding"], Schema(
                    id=c["id"], name=c["schemaName"], encoding=c["schemaEncoding"],
                    data=c["schema"].encode()))
                for i, c in subscriptions.items()
            }  # fmt: skip
            received: dict[str, list] = {topic: [] for topic in wanted}
            started = time.perf_counter()
            while time.perf_counter() - started < 3.0:
                frame = connection.recv(timeout=5)
                if isinstance(frame, str):
                    continue
                opcode, subscription, log_time = struct.unpack_from("<BIQ", frame)
                assert opcode == MESSAGE_DATA
                message = decoders[subscription](frame[13:])
                received[subscriptions[subscription]["topic"]].append((log_time, message))
    assert server.stats.skipped <= 2, server.stats.summary()
    images = received["/rig_left/image_rect_color"]
    # At the stated rate: about 30 images in 3 s, never more than the rate allows.
    assert rate * 3.0 * 0.5 <= len(images) <= rate * 3.0 + 2, len(images)
    for log_time, image in images:
        assert (image.encoding, image.width, image.height) == ("rgb8", 160, 120)
        pixels = np.frombuffer(image.data, np.uint8).reshape(120, 160, 3)
        assert pixels.std() > 5  # the phantom, not an empty frame
        assert image.header.stamp.sec * 10**9 + image.header.stamp.nanosec == log_time
    stamps = [t for t, _ in images]
    assert stamps == sorted(stamps) and stamps[-1] > stamps[0]  # simulation time advances
    info = received["/rig_left/camera_info"][-1][1]
    k = np.reshape(info.k, (3, 3))
    assert k[0, 2] == pytest.approx(rig.left.intrinsics[0, 2] - 0.5)
    forces = np.array([[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z]
                       for _, m in received["/drill/wrench"]])  # fmt: skip
    assert len(forces) >= rate * 3.0 * 0.5 and np.isfinite(forces).all()
    assert np.linalg.norm(forces, axis=1).max() > 0.1  # the bone pushed back
    critical = received["/drill/critical"][-1][1]
    assert critical.status, "no critical structure reported"
    distances = [float(s.values[0].value) for s in critical.status if s.name != "cut"]
    assert distances == sorted(distances)
    frames = {t.child_frame_id for _, m in received["/tf"] for t in m.transforms}
    assert {"rig_left_optical_frame", "drill", "anatomy", "burr"} <= frames
    stats = loop.stats
    print(f"live view: {server.stats.summary()}; physics p99 {stats['p99'] * 1e3:.3f} ms, max "
          f"{stats['max'] * 1e3:.3f} ms, {stats['mean_rate']:.1f} Hz")  # fmt: skip


def test_the_live_view_says_when_its_port_is_taken():
    world = ambfplus.World()
    with FoxgloveServer(world, [], port=0) as first:
        with pytest.raises(RuntimeError, match=f"cannot listen on 127.0.0.1:{first.port}"):
            FoxgloveServer(world, [], port=first.port).start()


def test_the_launcher_serves_its_session_live(fixtures, tmp_path):
    """ambfplus-launch --foxglove: the original drilling scene, headless, advertises its camera,
    calibration, TF and the drill's channels to a client."""
    import re
    import subprocess
    import sys

    launch = fixtures / "volumetric_drilling" / "launch.yaml"
    process = subprocess.Popen(
        [sys.executable, "-m", "ambfplus.launcher", str(launch), "-l", "0,2", "-g", "false",
         "--seconds", "20", "--foxglove", "0"],
        cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
    )  # fmt: skip
    try:
        url = None
        for line in process.stdout:
            found = re.search(r"live view on (ws://127\.0\.0\.1:\d+)", line)
            if found:
                url = found.group(1)
                break
        assert url is not None, "the launcher did not start its live view"
        with websockets_client.connect(url, subprotocols=[SUBPROTOCOL]) as connection:
            topics = set()
            while not {"/main_camera/image_rect_color", "/drill/wrench"} <= topics:
                topics |= {c["topic"] for c in receive_json(connection, "advertise")["channels"]}
        assert {"/main_camera/camera_info", "/tf", "/drill/critical"} <= topics
    finally:
        process.terminate()
        process.wait(timeout=30)
