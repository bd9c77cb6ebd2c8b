"""The live view under abuse, beside a drilling session in a real-time loop: hundreds of idle
connections, clients that never read, malformed frames and half-open sockets, from another
process. The server stays up, a well-behaved client keeps receiving, the bad connections are
dropped (the half-open ones within 10 s) and the memory they cost is given back once they have
gone. The loop's timings under the same abuse are a benchmark (bench_export foxglove_abuse)."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

import ambfplus
from ambfplus.scenes import drilling_phantom

pytest.importorskip("foxglove", reason='needs pip install "ambfplus[foxglove]"')
websockets_client = pytest.importorskip("websockets.sync.client",
                                        reason="the test's clients need websockets")  # fmt: skip

from ambfplus.export.live import FoxgloveServer, drill_helpers  # noqa: E402

# The abuser's script (a process of its own, so that what it holds is not in our RSS).
ABUSER = Path(__file__).with_name("live_abuser.py")


def rss_mb() -> float:
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024
    raise RuntimeError("no VmRSS")


def wait_for(condition, seconds: float) -> bool:
    deadline = time.perf_counter() + seconds
    while time.perf_counter() < deadline:
        if condition():
            return True
        time.sleep(0.1)
    return condition()


class Watcher(threading.Thread):
    """A well-behaved client subscribed to /tf and the camera, counting what it receives."""

    def __init__(self, url: str) -> None:
        super().__init__(daemon=True)
        self.url, self.received, self.stop, self.error = url, [], threading.Event(), None
        self.ready = threading.Event()

    def run(self) -> None:
        try:
            with websockets_client.connect(self.url, subprotocols=["foxglove.sdk.v1"],
                                           max_size=None) as connection:  # fmt: skip
                channels: dict = {}
                while not {"/tf", "/rig_left/image_rect_color"} <= set(channels):
                    message = json.loads(connection.recv(timeout=10))
                    if message.get("op") == "advertise":
                        channels.update({c["topic"]: c for c in message["channels"]})
                connection.send(json.dumps({"op": "subscribe", "subscriptions": [
                    {"id": 1, "channelId": channels["/tf"]["id"]},
                    {"id": 2, "channelId": channels["/rig_left/image_rect_color"]["id"]},
                ]}))  # fmt: skip
                self.ready.set()
                while not self.stop.is_set():
                    try:
                        frame = connection.recv(timeout=0.5)
                    except TimeoutError:
                        continue
                    if isinstance(frame, bytes):
                        self.received.append(time.perf_counter())
        except BaseException as error:  # raised by the test
            self.error = error
            self.ready.set()

    def count_since(self, t: float) -> int:
        return sum(1 for r in list(self.received) if r >= t)


@pytest.mark.slow
def test_the_live_view_survives_abuse_and_gives_memory_back():
    scene = drilling_phantom(resolution=64, width=160, height=120)
    world, camera = scene.world, scene.rig.left
    hand = ambfplus.SimulatedDevice()
    world.add_input_device("hand", hand, scene.drill)
    camera.capture()
    n_idle, n_readers, n_half, max_clients = 200, 40, 10, 32
    server = FoxgloveServer(world, [camera], rate=20.0, image_rate=10.0, port=0)
    with ambfplus.RealTimeLoop(world), server:
        counts = server.stats.connections
        hand.set_target((0.0, 0.0, -0.008), buttons=1)
        watcher = Watcher(server.url)
        watcher.start()
        assert watcher.ready.wait(20) and watcher.error is None, watcher.error
        time.sleep(2.0)  # the server's and the client's memory settle
        before = rss_mb()
        lost_before = counts["lost"]  # the half-open ones end as lost connections
        abuser = subprocess.Popen(
            [sys.executable, str(ABUSER), str(server.port), str(n_idle), str(n_readers),
             str(n_half)],
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True,
        )  # fmt: skip
        try:
            opened = json.loads(abuser.stdout.readline())
            peak = rss_mb()
            # Half-open sockets are found dead within 10 s of being made.
            if opened["half_open"]:
                made = opened["half_open_at"]
                dropped = wait_for(lambda: counts["lost"] - lost_before >= opened["half_open"],
                                   10.0 - (time.time() - made))  # fmt: skip
                assert dropped, (opened, counts)
            observed = json.loads(abuser.stdout.readline())
            # The well-behaved client still receives, with every abuser connected.
            during = time.perf_counter()
            time.sleep(1.0)
            assert watcher.count_since(during) > 0 and watcher.error is None, watcher.error
            peak = max(peak, rss_mb())
        finally:
            abuser.stdin.write("go\n")
            abuser.stdin.close()
            abuser.wait(timeout=30)
        closed = {name: (round(max(observed[name]["closed_after_s"]), 2), observed[name]["busy"])
                  for name in ("idle", "partial", "malformed")}  # fmt: skip
        print(f"abuse: last closed (s), 503s: {closed}; connections: {dict(counts)}")
        # Every idle or partial handshake ends: HTTP 503 at once beyond MAX_HANDSHAKES, the
        # rest when the handshake timeout (5 s) runs out; malformed frames end their client.
        for name in ("idle", "partial", "malformed"):
            closed = observed[name]["closed_after_s"]
            assert all(t is not None and t <= 10.0 for t in closed), (name, closed)
        assert observed["idle"]["busy"] > 0  # over the handshake limit: refused, with 503
        for name, t in zip(observed["malformed_names"], observed["malformed"]["closed_after_s"]):
            assert t < 8.0, name  # at once, or a stalled frame after FRAME_TIMEOUT_S
        # At most max_clients served at once (the watcher is one), the others refused.
        served, refused = observed["readers_served"], observed["readers_refused"]
        assert served + refused == n_readers and 0 < served <= max_clients - 1
        assert refused >= n_readers - (max_clients - 1)
        assert counts["malformed"] >= 7 and counts["refused"] >= observed["readers_refused"]
        # All gone but the watcher; memory back within 20 MB of where it was.
        assert wait_for(lambda: counts["open"] == 1 and counts["clients"] == 1, 15.0), counts
        time.sleep(3.0)  # the relay gives memory back a moment after clients leave
        after = rss_mb()
        print(f"RSS {before:.1f} MB before, {peak:.1f} MB with the abusers, {after:.1f} after")
        assert after <= before + 20.0, (before, peak, after)
        # Still serving: the watcher receives, and a new client is let in.
        since = time.perf_counter()
        time.sleep(1.0)
        assert watcher.count_since(since) > 0
        with websockets_client.connect(server.url, subprotocols=["foxglove.sdk.v1"]) as late:
            assert json.loads(late.recv(timeout=10))["op"] == "serverInfo"
        watcher.stop.set()
        watcher.join(10)
    assert watcher.error is None, watcher.error


def test_the_live_view_publishes_no_drill_helper_bodies():
    """The drilling plugin's burr meshes ("1mm" ...) and cursor markers ("drill_goal_0" ...)
    are the drill's, not objects of the scene: they get no frame. A scene's own bodies do."""
    world = ambfplus.World()
    volume = world.add_volume("ear", ambfplus.phantom(32))
    drill = world.add_drill("drill", volume)
    names = ["1mm", "2mm", "4mm", "6mm", "drill_goal_0", "drill_proxy_0", "3mm", "handle"]
    for name in names:
        world.add_body(name, "sphere", radius=0.001, mass=0.0, kinematic=True)
    helpers = drill_helpers(world)
    diameters = {f"{d * 1000:g}mm" for d in drill.burr_diameters}
    assert {"drill_goal_0", "drill_proxy_0"} | ({"1mm", "2mm", "4mm", "6mm"} & diameters) <= helpers
    assert "handle" not in helpers and "drill" not in helpers and "ear" not in helpers
    assert ("3mm" in helpers) == ("3mm" in diameters)  # a body named so only for a burr it has
    with FoxgloveServer(world, [], port=0) as server:
        with websockets_client.connect(server.url, subprotocols=["foxglove.sdk.v1"]) as client:
            channels: dict = {}
            while "/tf" not in channels:
                message = json.loads(client.recv(timeout=10))
                if message.get("op") == "advertise":
                    channels.update({c["topic"]: c for c in message["channels"]})
            client.send(json.dumps({"op": "subscribe", "subscriptions": [
                {"id": 1, "channelId": channels["/tf"]["id"]}]}))  # fmt: skip
            frame = client.recv(timeout=10)
            while not isinstance(frame, bytes):
                frame = client.recv(timeout=10)
    frames = {name.decode() for name in _tf_children(frame[13:])}
    assert {"drill", "ear", "handle"} <= frames and not frames & helpers, frames


def _tf_children(cdr: bytes) -> list[bytes]:
    """The child frame ids of a CDR tf2_msgs/TFMessage (decoded with the export's own reader)."""
    from ambfplus.export.ros import typestore

    store = typestore()
    message = store.deserialize_cdr(cdr, "tf2_msgs/msg/TFMessage")
    return [t.child_frame_id.encode() for t in message.transforms]
