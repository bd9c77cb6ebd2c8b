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
# The protocol's first name, which Lichtblick and older clients offer: the same protocol.
LEGACY_SUBPROTOCOL = "foxglove.websocket.v1"
MESSAGE_DATA = 0x01  # binary opcode: subscription id (u32), log time (u64), payload


def receive_json(connection, op: str) -> dict:
    while True:
        frame = connection.recv(timeout=10)
        if isinstance(frame, str):
            message = json.loads(frame)
            if message.get("op") == op:
                return message


# /tf first: subscribed before the images, so every image's pose reaches the client before it.
WANTED = ["/tf", "/rig_left/image_rect_color", "/rig_left/camera_info", "/drill/wrench",
          "/drill/critical"]  # fmt: skip


def watch(server, seconds: float, subprotocol: str = SUBPROTOCOL) -> dict[str, list]:
    """Subscribes a WebSocket client offering only `subprotocol` to WANTED and decodes what it
    receives for `seconds`: topic -> [(log time, message)]."""
    with websockets_client.connect(server.url, subprotocols=[subprotocol],
                                   max_size=None) as connection:  # fmt: skip
        assert connection.subprotocol == subprotocol  # answered in the client's own words
        info = receive_json(connection, "serverInfo")
        assert info["name"] == "ambfplus"
        channels = {}
        while not set(WANTED) <= set(channels):
            for channel in receive_json(connection, "advertise")["channels"]:
                channels[channel["topic"]] = channel
        subscriptions = {i + 1: channels[topic] for i, topic in enumerate(WANTED)}
        connection.send(json.dumps({"op": "subscribe", "subscriptions": [
            {"id": i, "channelId": c["id"]} for i, c in subscriptions.items()]}))  # fmt: skip
        decoders = {
            i: DecoderFactory().decoder_for(c["encoding"], Schema(
                id=c["id"], name=c["schemaName"], encoding=c["schemaEncoding"],
                data=c["schema"].encode()))
            for i, c in subscriptions.items()
        }  # fmt: skip
        received: dict[str, list] = {topic: [] for topic in WANTED}
        started = time.perf_counter()
        while time.perf_counter() - started < seconds:
            frame = connection.recv(timeout=5)
            if isinstance(frame, str):
                continue
            opcode, subscription, log_time = struct.unpack_from("<BIQ", frame)
            assert opcode == MESSAGE_DATA
            message = decoders[subscription](frame[13:])
            received[subscriptions[subscription]["topic"]].append((log_time, message))
    return received


def drilling_world(resolution: int, width: int, height: int):
    scene = drilling_phantom(resolution=resolution, width=width, height=height)
    hand = ambfplus.SimulatedDevice()
    scene.world.add_input_device("hand", hand, scene.drill)
    scene.rig.left.capture()  # upload before the clock starts
    return scene, hand


@pytest.mark.slow
def test_a_client_watches_a_drilling_session_live():
    """State channels at `rate`, images at `image_rate` where rendering keeps up (a small
    camera), everything decodable and consistent with the session."""
    scene, hand = drilling_world(64, 160, 120)
    world, rig = scene.world, scene.rig
    rate, image_rate, seconds = 20.0, 10.0, 3.0
    loop = ambfplus.RealTimeLoop(world)
    with loop, FoxgloveServer(world, [rig.left], rate=rate, image_rate=image_rate,
                              port=0) as server:  # fmt: skip
        assert server.url.startswith("ws://127.0.0.1:")
        hand.set_target((0.0, 0.0, -0.008), buttons=1)  # down into the bone, spinning
        received = watch(server, seconds)
        stats = server.stats.summary()
    # The state channels at the stated rate (the loop of a shared machine may lose a tick).
    for topic in ("/drill/wrench", "/drill/critical", "/rig_left/camera_info"):
        assert 0.7 * rate * seconds <= len(received[topic]) <= rate * seconds + 2, topic
    # Images at the stated rate, never more: this camera renders faster than image_rate.
    images = received["/rig_left/image_rect_color"]
    assert 0.6 * image_rate * seconds <= len(images) <= image_rate * seconds + 2, len(images)
    assert len(images) <= stats["images"] and stats["image_rate_hz"] <= image_rate * 1.05
    for log_time, image in images:
        assert (image.encoding, image.width, image.height) == ("rgb8", 160, 120)
        pixels = np.frombuffer(image.data, np.uint8).reshape(120, 160, 3)
        assert pixels.std() > 5  # the phantom, not an empty frame
        assert image.header.stamp.sec * 10**9 + image.header.stamp.nanosec == log_time
        assert image.header.frame_id == "rig_left_optical_frame"
    stamps = [t for t, _ in images]
    assert stamps == sorted(stamps) and stamps[-1] > stamps[0]  # simulation time advances
    info = received["/rig_left/camera_info"][-1][1]
    k = np.reshape(info.k, (3, 3))
    assert k[0, 2] == pytest.approx(rig.left.intrinsics[0, 2] - 0.5)
    forces = np.array([[m.wrench.force.x, m.wrench.force.y, m.wrench.force.z]
                       for _, m in received["/drill/wrench"]])  # fmt: skip
    assert np.isfinite(forces).all()
    assert np.linalg.norm(forces, axis=1).max() > 0.1  # the bone pushed back
    critical = received["/drill/critical"][-1][1]
    assert critical.status, "no critical structure reported"
    distances = [float(s.values[0].value) for s in critical.status if s.name != "cut"]
    assert distances == sorted(distances)
    # /tf: the state's ticks and one per image, placing the camera at each image's stamp.
    tf = received["/tf"]
    frames = {t.child_frame_id for _, m in tf for t in m.transforms}
    assert {"rig_left_link", "rig_left_optical_frame", "drill", "anatomy", "burr"} <= frames
    optical = "rig_left_optical_frame"
    # The optical frame under the camera's body frame (REP 103), the image's frame id.
    parents = {x.child_frame_id: x.header.frame_id for _, m in tf for x in m.transforms}
    assert parents[optical] == "rig_left_link" and parents["rig_left_link"] == "world"
    camera_stamps = {t for t, m in tf if any(x.child_frame_id == optical for x in m.transforms)}
    assert set(stamps) <= camera_stamps
    assert len(tf) >= len(received["/drill/wrench"])
    loop_stats = loop.stats
    print(f"live view: {stats}; physics p99 {loop_stats['p99'] * 1e3:.3f} ms, max "
          f"{loop_stats['max'] * 1e3:.3f} ms, {loop_stats['mean_rate']:.1f} Hz")  # fmt: skip


@pytest.mark.slow
def test_slow_images_do_not_slow_the_state_channels():
    """A 640x480 camera asked for 1000 images a second (more than any renderer and the
    WebSocket serialising 0.9 MB per image reach): images come as fast as rendering allows (the
    rate the server reports), while TF, force and critical structures keep their own rate."""
    scene, hand = drilling_world(128, 640, 480)
    world, rig = scene.world, scene.rig
    rate, image_rate, seconds = 20.0, 1000.0, 3.0
    with ambfplus.RealTimeLoop(world), FoxgloveServer(world, [rig.left], rate=rate,
                                                      image_rate=image_rate,
                                                      port=0) as server:  # fmt: skip
        hand.set_target((0.0, 0.0, -0.008), buttons=1)
        received = watch(server, seconds)
        stats = server.stats.summary()
    images = received["/rig_left/image_rect_color"]
    assert images and all((m.width, m.height) == (640, 480) for _, m in images)
    # Rendering, not the asked-for 1000 Hz, sets the image rate; what the client saw is what
    # the server reports.
    assert len(images) < image_rate * seconds * 0.8, len(images)
    assert len(images) / seconds == pytest.approx(stats["image_rate_hz"], rel=0.35, abs=1.0)
    for topic in ("/drill/wrench", "/drill/critical", "/rig_left/camera_info"):
        assert 0.7 * rate * seconds <= len(received[topic]) <= rate * seconds + 2, topic


def test_the_live_view_answers_each_name_of_the_protocol_in_kind():
    """A client offering foxglove.sdk.v1 or foxglove.websocket.v1 (alone, or beside names the
    server does not speak) is answered with the name it offered and served; one offering
    neither, or no subprotocol at all, is refused with HTTP 400."""
    from websockets.exceptions import ConnectionClosed, InvalidStatus

    world = ambfplus.World()
    offers = {(SUBPROTOCOL,): SUBPROTOCOL, (LEGACY_SUBPROTOCOL,): LEGACY_SUBPROTOCOL,
              ("example.v2", LEGACY_SUBPROTOCOL): LEGACY_SUBPROTOCOL,
              (LEGACY_SUBPROTOCOL, SUBPROTOCOL): SUBPROTOCOL}  # fmt: skip
    with FoxgloveServer(world, [], port=0) as server:
        for offered, answer in offers.items():
            with websockets_client.connect(server.url, subprotocols=list(offered)) as connection:
                assert connection.subprotocol == answer, offered
                assert receive_json(connection, "serverInfo")["name"] == "ambfplus"
                topics = {c["topic"] for c in receive_json(connection, "advertise")["channels"]}
                assert topics == {"/tf"}
        for offered in (["example.v2"], None):
            with pytest.raises(InvalidStatus) as refused:
                websockets_client.connect(server.url, subprotocols=offered)
            assert refused.value.response.status_code == 400, offered
    # A client still connected when the server stops is closed, not left hanging.
    server = FoxgloveServer(world, [], port=0).start()
    with websockets_client.connect(server.url, subprotocols=[LEGACY_SUBPROTOCOL]) as connection:
        receive_json(connection, "serverInfo")
        server.stop()
        with pytest.raises(ConnectionClosed):
            while True:
                connection.recv(timeout=10)


@pytest.mark.slow
def test_clients_of_either_protocol_name_watch_one_session():
    """Two clients at once, one offering only foxglove.websocket.v1 (as Lichtblick does), one
    only foxglove.sdk.v1: each receives the images, calibration and TF, decodable, at the rates
    the server keeps (printed)."""
    import threading

    scene, hand = drilling_world(64, 160, 120)
    world, rig = scene.world, scene.rig
    rate, image_rate, seconds = 10.0, 10.0, 3.0
    received: dict[str, dict] = {}
    errors: list[BaseException] = []

    def client(subprotocol: str) -> None:
        try:
            received[subprotocol] = watch(server, seconds, subprotocol)
        except BaseException as error:  # raised below, in the test's thread
            errors.append(error)

    with ambfplus.RealTimeLoop(world), FoxgloveServer(world, [rig.left], rate=rate,
                                                      image_rate=image_rate,
                                                      port=0) as server:  # fmt: skip
        hand.set_target((0.0, 0.0, -0.008), buttons=1)
        threads = [threading.Thread(target=client, args=(name,))
                   for name in (LEGACY_SUBPROTOCOL, SUBPROTOCOL)]  # fmt: skip
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
        stats = server.stats.summary()
    if errors:
        raise errors[0]
    for subprotocol, topics in received.items():
        rates = {topic: round(len(messages) / seconds, 2) for topic, messages in topics.items()}
        print(f"{subprotocol}: messages/s {rates}")
        images = topics["/rig_left/image_rect_color"]
        assert images, subprotocol
        for _, image in images:
            assert (image.encoding, image.width, image.height) == ("rgb8", 160, 120)
            assert np.frombuffer(image.data, np.uint8).std() > 5  # the phantom
        info = topics["/rig_left/camera_info"]
        assert info and (info[-1][1].width, info[-1][1].height) == (160, 120), subprotocol
        frames = {t.child_frame_id for _, m in topics["/tf"] for t in m.transforms}
        assert {"rig_left_optical_frame", "drill"} <= frames, subprotocol
    print(f"live view: {stats}")


def test_the_live_view_says_when_its_port_is_taken():
    world = ambfplus.World()
    with FoxgloveServer(world, [], port=0) as first:
        with pytest.raises(RuntimeError, match=f"cannot listen on 127.0.0.1:{first.port}"):
            FoxgloveServer(world, [], port=first.port).start()


@pytest.mark.slow
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
