"""A world served live over the Foxglove WebSocket protocol (the Foxglove SDK's server), so that
Foxglove, or any client of the protocol, watches a headless session from another machine or
process.

    from ambfplus.export.live import FoxgloveServer
    with ambfplus.RealTimeLoop(world), FoxgloveServer(world, [camera], rate=10.0) as server:
        ...  # ws://127.0.0.1:8765 (server.url); server.stats.summary() says what it sent

It publishes, as ROS 2 messages (CDR, ``ros2msg`` schemas: the same types and conventions as
the ``mcap`` export), only on channels a client subscribed to, from two threads of its own:

- at ``rate`` Hz of wall time (10 by default; ticks it misses are skipped, never caught up in a
  burst): ``/tf`` (tf2_msgs/TFMessage: world -> each camera's ``<camera>_link`` -> its
  ``<camera>_optical_frame``, and world -> the drill, its bodies and the volumes, each frame
  named after its object, as the ``mcap`` export names them), ``/<camera>/camera_info`` (K
  and P in ROS's pixel convention),
  ``/<drill>/wrench`` (geometry_msgs/WrenchStamped: the force fed back to the device, world
  axes) and ``/<drill>/critical`` (diagnostic_msgs/DiagnosticArray: every critical structure's
  distance from the burr, nearest first, level WARN under 2 mm, ERROR at 0). These are a few
  reads of the world's state each, so they keep their rate whatever the cameras cost;
- images, ``/<camera>/image_rect_color`` (sensor_msgs/Image rgb8; ``depth=True`` adds
  ``/<camera>/depth/image_rect``, 32FC1 metres), at most ``image_rate`` times a second (``rate``
  by default) and otherwise as fast as the renderer makes them: one capture follows another, so
  where a frame takes longer than 1 / ``image_rate`` to render, rendering sets the image rate
  (on llvmpipe with 2 cores, a 640x480 frame of the 128^3 phantom took 40-120 ms to capture
  and send, so 8-25 images a second). ``stats.summary()["image_rate_hz"]`` is the rate
  achieved. Each image comes with a
  ``/tf`` message placing its camera (and the posed objects) at the image's own time.

Stamps are simulation time. The physics loop (``ambfplus.RealTimeLoop``) does not wait for the
server's encoding: images are captured as any other thread captures (the engine holds the
world's lock only to copy what it draws, with the poses TF needs), the state thread holds the
lock for one batch of reads per tick, and encoding and sending happen off the lock; a slow
client loses its oldest messages (the SDK's per-client backlog), it never stalls the publisher.
It listens on 127.0.0.1 unless ``host`` says otherwise. Needs ``pip install
"ambfplus[foxglove]"``.

Clients name the protocol in the WebSocket handshake: ``foxglove.sdk.v1`` (Foxglove, the SDK's
clients) or ``foxglove.websocket.v1`` (Lichtblick, older tools), the same protocol under its
first name. The SDK's server accepts only the new name, so it listens on a loopback port of its
own and a small relay holds the public one: it passes each connection through unchanged, except
that a handshake offering only the old name reaches the SDK offering the new one and is
answered with the name the client offered. The relay runs on a thread of its own and copies
bytes as they come; the physics loop never waits for it.

The relay also guards the server: at most ``max_clients`` WebSocket clients (32; more are
answered HTTP 503) and MAX_HANDSHAKES connections in their handshake (past it the oldest is
answered 503), each head within ``handshake_timeout`` (5 s), client frames checked as they pass
(masked, known opcodes, messages of ``max_client_message`` bytes at most, each frame whole
within FRAME_TIMEOUT_S: otherwise that client alone is cut), dead peers (half-open connections)
found by TCP keepalive and a user timeout within about 7 s, and at most RELAY_CHUNK +
RELAY_WRITE_BUFFER bytes held each way for a client, whether it reads or not. A second after
clients leave, the C heap's free memory goes back to the system. The drills' helper bodies
(drill_helpers) get no frame.
"""

from __future__ import annotations

import asyncio
import contextlib
import ctypes
import re
import socket
import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._common import LINK_FROM_OPTICAL, camera_frames, link_pose, nanoseconds, require, tf_frame
from .ros import (
    CAMERA_INFO,
    DIAGNOSTICS,
    IMAGE,
    TF,
    WORLD,
    WRENCH,
    camera_info,
    for_rosbags,
    header,
    image_message,
    transform,
    typestore,
)

DEFAULT_PORT = 8765
WARN_DISTANCE = 0.002  # m; as the launcher's status line
DIAGNOSTIC_OK, DIAGNOSTIC_WARN, DIAGNOSTIC_ERROR = 0, 1, 2
TIMINGS_KEPT = 1000  # the last tick and capture durations the statistics cover
IDLE_POLL_S = 0.05  # how often the image thread looks for a subscriber while there is none
# The protocol's names in the WebSocket handshake: the SDK's, then the one it had first.
SUBPROTOCOL = "foxglove.sdk.v1"
LEGACY_SUBPROTOCOL = "foxglove.websocket.v1"
SUBPROTOCOLS = (SUBPROTOCOL, LEGACY_SUBPROTOCOL)
HANDSHAKE_LIMIT = 64 * 1024  # bytes; a longer HTTP head is refused
HANDSHAKE_TIMEOUT_S = 5.0  # a client that sends no complete head in this time is dropped
MAX_CLIENTS = 32  # WebSocket clients served at once; more are answered HTTP 503
MAX_HANDSHAKES = 64  # connections still in their HTTP head; past it the oldest gets HTTP 503
MAX_CLIENT_MESSAGE = 1024 * 1024  # bytes; a longer frame or message from a client drops it
FRAME_TIMEOUT_S = 5.0  # a client frame begun must be whole within this time
MESSAGE_BACKLOG = 64  # messages the SDK queues per client; a slow client loses the oldest
# A dead peer (a half-open connection) is dropped within about 7 s: keepalive probes after 2 s
# of silence, and data or probes unacknowledged for 6 s end the connection (TCP_USER_TIMEOUT).
KEEPALIVE_IDLE_S, KEEPALIVE_INTERVAL_S, KEEPALIVE_PROBES = 2, 1, 4
USER_TIMEOUT_MS = 6000
RELAY_CHUNK = 64 * 1024  # bytes copied per read
# What the relay holds for one client at most, each way: a chunk read and a write buffer the
# reading waits on (asyncio's drain), so a client that does not read costs no more.
RELAY_WRITE_BUFFER = 128 * 1024
CLOSE_GRACE_S = 1.0  # on stop, how long relays may finish the SDK's closing handshakes
TRIM_DELAY_S = 1.0  # after the last of a group of clients leaves, memory goes back to the system


def _durations() -> deque:
    return deque(maxlen=TIMINGS_KEPT)


def _connection_counts() -> dict:
    return {"accepted": 0, "refused": 0, "malformed": 0, "timed_out": 0, "lost": 0,
            "clients": 0, "open": 0}  # fmt: skip


@dataclass
class LiveStats:
    """What the server did: state ticks run and skipped, messages sent, images sent,
    durations of the last ticks and image rounds (a capture of every subscribed camera), and
    what became of connections: ``connections`` counts those accepted, refused (HTTP 503: over
    a limit), dropped for a malformed or oversized frame, timed out (no whole handshake or frame
    in time) and lost (reset, or a dead peer found by keepalive), with the WebSocket clients
    served and the connections open now."""

    ticks: int = 0
    skipped: int = 0
    messages: int = 0
    images: int = 0
    image_rounds: int = 0
    image_seconds: float = 0.0  # wall time with an image subscriber
    tick_seconds: deque = field(default_factory=_durations)
    round_seconds: deque = field(default_factory=_durations)
    connections: dict = field(default_factory=_connection_counts)

    def summary(self) -> dict:
        ticks = np.asarray(self.tick_seconds) if self.tick_seconds else np.zeros(1)
        rounds = np.asarray(self.round_seconds) if self.round_seconds else np.zeros(1)
        rate = self.image_rounds / self.image_seconds if self.image_seconds > 0 else 0.0
        return {"ticks": self.ticks, "skipped": self.skipped, "messages": self.messages,
                "images": self.images, "image_rounds": self.image_rounds,
                "image_rate_hz": round(rate, 3),
                "tick_ms_median": float(np.median(ticks) * 1e3),
                "tick_ms_max": float(ticks.max() * 1e3),
                "image_round_ms_median": float(np.median(rounds) * 1e3),
                "image_round_ms_max": float(rounds.max() * 1e3),
                "connections": dict(self.connections)}  # fmt: skip


# A burr's mesh as the drilling plugin finds it: a body named by its diameter in mm ("1mm").
_BURR_MESH = re.compile(r"([0-9]+(?:\.[0-9]+)?)mm")


def drill_helpers(world) -> set[str]:
    """The names of the bodies that stand in for parts of the world's drills rather than being
    objects of the scene, so the live view gives them no frame: the burr meshes the drilling
    plugin shows one at a time on the drill, named by a diameter the drill has (``1mm`` ...
    ``6mm``; the drill's own frame places them), and its cursor markers (``<drill>_proxy_<i>``
    and ``<drill>_goal_<i>``, one of each per cursor, hidden unless asked for). These are the
    names the plugin gives and looks for; bodies attached with ``Drill.attach`` in Python (a
    scene's burr, shaft and handle) keep their frames."""
    helpers: set[str] = set()
    drills = list(world.drills)
    if not drills:
        return helpers
    diameters = [d for drill in drills for d in drill.burr_diameters]
    for body in world.objects:
        found = _BURR_MESH.fullmatch(body.name) if body.kind == "body" else None
        if found and any(abs(float(found[1]) * 1e-3 - d) < 1e-9 for d in diameters):
            helpers.add(body.key)
    for drill in drills:
        for i in range(len(drill.cursor_radii)):
            helpers.update((f"{drill.key}_proxy_{i}", f"{drill.key}_goal_{i}"))
    return helpers


class FoxgloveServer:
    """Serves ``world`` live (see the module docstring): ``cameras`` (default: all of the
    world's) and its first drill (or ``drill``), the state at ``rate`` Hz and images at up to
    ``image_rate`` Hz (default ``rate``), on ``host``:``port`` (0: any free port), to at most
    ``max_clients`` clients at once, each sending messages of ``max_client_message`` bytes at
    most and its handshake within ``handshake_timeout`` s. ``start()``/``stop()`` or a
    ``with`` block."""

    def __init__(self, world, cameras=None, *, drill=None, rate: float = 10.0,
                 image_rate: float | None = None, host: str = "127.0.0.1",
                 port: int = DEFAULT_PORT, depth: bool = False, name: str = "ambfplus",
                 max_clients: int = MAX_CLIENTS, max_client_message: int = MAX_CLIENT_MESSAGE,
                 handshake_timeout: float = HANDSHAKE_TIMEOUT_S) -> None:  # fmt: skip
        self._foxglove = require("foxglove", "foxglove")
        require("foxglove", "rosbags.typesys")
        image_rate = rate if image_rate is None else image_rate
        for what, value in (("rate", rate), ("image_rate", image_rate),
                            ("max_clients", max_clients),
                            ("max_client_message", max_client_message),
                            ("handshake_timeout", handshake_timeout)):  # fmt: skip
            if not value > 0:
                raise ValueError(f"{what} must be > 0, got {value}")
        self.max_clients, self.max_client_message = int(max_clients), int(max_client_message)
        self.handshake_timeout = float(handshake_timeout)
        self.world = world
        self.cameras = list(world.cameras if cameras is None else cameras)
        drills = list(world.drills)
        self.drill = drill if drill is not None else (drills[0] if drills else None)
        self.rate, self.image_rate = float(rate), float(image_rate)
        self.host, self.requested_port, self.depth, self.name = host, port, depth, name
        self.stats = LiveStats()
        self._store = typestore()
        self._server = None
        self._relay: _SubprotocolRelay | None = None
        self._threads: list[threading.Thread] = []
        self._stop = threading.Event()
        self._errors: list[BaseException] = []
        # Objects whose pose /tf carries, chosen once: not the drills' helper bodies.
        helpers = drill_helpers(world)
        self._posed_objects = [o for o in world.objects if o.kind in ("body", "volume", "drill")
                               and o.key not in helpers]  # fmt: skip
        # (object name, its TF frame: the rule the ROS exports follow)
        self._posed = [(o.key, tf_frame(o.key)) for o in self._posed_objects]
        self._posed_names = [o.key for o in self._posed_objects]
        # What each tick reads: the posed objects, the cameras, then the drill.
        self._read_objects = self._posed_objects + list(self.cameras)
        if self.drill is not None:
            self._read_objects.append(self.drill)

    # Life cycle -------------------------------------------------------------------------------

    def start(self) -> FoxgloveServer:
        fox = self._foxglove
        self._context = fox.Context()
        self._channels: dict[str, Any] = {}
        self._msgtypes: dict[str, Any] = {}
        for camera in self.cameras:
            self._channel(f"/{camera.name}/image_rect_color", IMAGE)
            self._channel(f"/{camera.name}/camera_info", CAMERA_INFO)
            if self.depth:
                self._channel(f"/{camera.name}/depth/image_rect", IMAGE)
        self._channel("/tf", TF)
        if self.drill is not None:
            self._channel(f"/{self.drill.key}/wrench", WRENCH)
            self._channel(f"/{self.drill.key}/critical", DIAGNOSTICS)
        # The public port first, so that a port in use fails before anything starts.
        try:
            listener = _listen(self.host, self.requested_port)
        except OSError as error:
            raise RuntimeError(
                f"the Foxglove server cannot listen on {self.host}:{self.requested_port}: {error}"
            ) from None
        try:
            server = fox.start_server(name=self.name, host="127.0.0.1", port=0,
                                      context=self._context,
                                      message_backlog_size=MESSAGE_BACKLOG)  # fmt: skip
        except Exception as error:
            listener.close()
            raise RuntimeError(f"the Foxglove SDK's server did not start: {error}") from None
        try:
            self._relay = _SubprotocolRelay(
                listener, server.port, max_clients=self.max_clients,
                max_message=self.max_client_message, handshake_timeout=self.handshake_timeout,
                counts=self.stats.connections,
            )  # fmt: skip
        except BaseException:
            server.stop()
            raise
        self._server = server
        self._stop.clear()
        self._threads = [
            threading.Thread(target=self._guard, args=(self._run_state,), daemon=True,
                             name="foxglove-state"),
            threading.Thread(target=self._guard, args=(self._run_images,), daemon=True,
                             name="foxglove-images"),
        ]  # fmt: skip
        for thread in self._threads:
            thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        for thread in self._threads:
            thread.join()
        self._threads = []
        # The SDK's server first: it closes its connections, which the relay passes on.
        if self._server is not None:
            self._server.stop()
            self._server = None
        if self._relay is not None:
            self._errors += self._relay.stop()
            self._relay = None
        for channel in getattr(self, "_channels", {}).values():
            channel.close()
        if self._errors:
            error, self._errors = self._errors[0], []
            raise RuntimeError(f"the live view stopped: {error!r}") from error

    def __enter__(self) -> FoxgloveServer:
        return self.start()

    def __exit__(self, *exc_info) -> None:
        self.stop()

    @property
    def port(self) -> int:
        """The port it listens on (the one chosen when asked for port 0)."""
        return self._relay.port if self._relay is not None else self.requested_port

    @property
    def url(self) -> str:
        return f"ws://{self.host}:{self.port}"

    def _channel(self, topic: str, msgtype: str) -> None:
        fox = self._foxglove
        # rosbags builds a type's serialiser on first use (tens of ms): not in a tick.
        self._store.get_msgdef(msgtype)
        text, _ = self._store.generate_msgdef(msgtype, ros_version=2)
        schema = fox.Schema(name=msgtype, encoding="ros2msg", data=text.encode())
        self._channels[topic] = fox.Channel(topic, schema=schema, message_encoding="cdr",
                                            context=self._context)  # fmt: skip
        self._msgtypes[topic] = msgtype

    # The two threads ---------------------------------------------------------------------------

    def _guard(self, body) -> None:
        try:
            body()
        except BaseException as error:  # reported by stop()
            self._errors.append(error)
            self._stop.set()

    def _run_state(self) -> None:
        """The state channels at `rate`: a late tick skips the ticks it missed."""
        period = 1.0 / self.rate
        deadline = time.perf_counter()
        while not self._stop.is_set():
            started = time.perf_counter()
            self.publish_state()
            self.stats.ticks += 1
            self.stats.tick_seconds.append(time.perf_counter() - started)
            deadline += period
            now = time.perf_counter()
            if now > deadline:  # late: skip the missed ticks instead of bursting
                missed = int((now - deadline) / period) + 1
                self.stats.skipped += missed
                deadline += missed * period
            self._stop.wait(max(0.0, deadline - time.perf_counter()))

    def _run_images(self) -> None:
        """Images at most `image_rate` times a second, a capture as soon as the last one is
        sent when rendering is slower than that; idle while nobody subscribes."""
        period = 1.0 / self.image_rate
        due = time.perf_counter()
        while not self._stop.is_set():
            started = time.perf_counter()
            if not self.publish_images():
                due = started + IDLE_POLL_S
                self._stop.wait(IDLE_POLL_S)
                continue
            now = time.perf_counter()
            self.stats.round_seconds.append(now - started)
            due = max(due + period, now)  # never catch up in a burst
            self._stop.wait(max(0.0, due - now))
            self.stats.image_seconds += time.perf_counter() - started

    # Publishing -------------------------------------------------------------------------------

    def _wanted(self, topic: str) -> bool:
        channel = self._channels.get(topic)
        return channel is not None and channel.has_sinks()

    def _send(self, topic: str, time_ns: int, body: dict) -> None:
        msgtype = self._msgtypes[topic]
        message = for_rosbags(self._store, body, msgtype)
        data = bytes(self._store.serialize_cdr(message, msgtype))
        self._channels[topic].log(data, log_time=time_ns)
        self.stats.messages += 1

    def publish_images(self) -> bool:
        """One round of images: each subscribed camera captured (with the poses the engine
        copies under the lock for it), sent with a /tf placing it at the image's time. Returns
        whether anything was subscribed."""
        sent = False
        for camera in self.cameras:
            topics = {"rgb": f"/{camera.name}/image_rect_color",
                      "depth": f"/{camera.name}/depth/image_rect"}  # fmt: skip
            passes = [p for p, topic in topics.items()
                      if (p == "rgb" or self.depth) and self._wanted(topic)]  # fmt: skip
            if not passes:
                continue
            frame = camera.capture(passes=passes, poses=self._posed_names)
            t = nanoseconds(frame.time)
            link, frame_id = camera_frames(camera.name)
            if self._wanted("/tf"):  # first, so a client has the pose when the image comes
                poses = frame.poses
                transforms = [transform(t, WORLD, child, poses[name])
                              for name, child in self._posed if name in poses]  # fmt: skip
                transforms += self._camera_transforms(t, link, frame_id, frame.pose)
                self._send("/tf", t, {"transforms": transforms})
            for pass_name, encoding in (("rgb", "rgb8"), ("depth", "32FC1")):
                image = getattr(frame, pass_name, None)
                if image is not None:
                    self._send(topics[pass_name], t, image_message(t, frame_id, image, encoding))
                    self.stats.images += 1
            sent = True
        if sent:
            self.stats.image_rounds += 1
        return sent

    def publish_state(self) -> None:
        """One tick of the state channels: TF, calibration, the drill's force and critical
        structures, from one batch of reads under the world's lock."""
        topics = ["/tf"] + [f"/{c.name}/camera_info" for c in self.cameras]
        if self.drill is not None:
            topics += [f"/{self.drill.key}/wrench", f"/{self.drill.key}/critical"]
        if not any(self._wanted(topic) for topic in topics):
            return
        state = self._snapshot()
        t = nanoseconds(state["time"])
        transforms = [transform(t, WORLD, child, pose) for child, pose in state["poses"]]
        for camera in self.cameras:
            link, frame_id = camera_frames(camera.name)
            pose, intrinsics = state["cameras"][camera.name]
            transforms += self._camera_transforms(t, link, frame_id, pose)
            info_topic = f"/{camera.name}/camera_info"
            if self._wanted(info_topic):
                self._send(info_topic, t, camera_info(t, frame_id, camera.width, camera.height,
                                                      intrinsics))  # fmt: skip
        if self._wanted("/tf"):
            self._send("/tf", t, {"transforms": transforms})
        if self.drill is None:
            return
        wrench_topic = f"/{self.drill.key}/wrench"
        if self._wanted(wrench_topic):
            f = state["force"]
            self._send(wrench_topic, t, {
                "header": header(t, WORLD),
                "wrench": {"force": {"x": f[0], "y": f[1], "z": f[2]},
                           "torque": {"x": 0.0, "y": 0.0, "z": 0.0}},
            })  # fmt: skip
        critical_topic = f"/{self.drill.key}/critical"
        if self._wanted(critical_topic):
            self._send(critical_topic, t, self._critical(t, state))

    @staticmethod
    def _camera_transforms(t: int, link: str, optical: str, pose) -> list[dict]:
        """A camera's body frame in the world and its optical frame under it (REP 103; the
        exports put the second on /tf_static, the live view sends both with each pose)."""
        return [transform(t, WORLD, link, link_pose(pose)),
                transform(t, link, optical, LINK_FROM_OPTICAL)]  # fmt: skip

    def publish(self) -> None:
        """One tick of everything: the state channels, then a round of images."""
        self.publish_state()
        self.publish_images()

    def _snapshot(self) -> dict:
        """The state a tick publishes, read in one engine call that holds the world's lock with
        no Python running under it (World.read_state): the messages are built afterwards."""
        drill = self.drill
        read = self.world.read_state(self._read_objects)
        states = read["objects"]
        n = len(self._posed_objects)
        cameras = states[n : n + len(self.cameras)]
        state = {
            "time": read["time"],
            "poses": [(frame, s["pose"]) for (_, frame), s in zip(self._posed, states)],
            "cameras": {
                c.name: (s["pose"], s["intrinsics"]) for c, s in zip(self.cameras, cameras)
            },
        }
        if drill is not None:
            state["force"] = [float(v) for v in states[-1]["force"]]
            state["distances"] = states[-1]["critical_distances"]
        return state

    def _critical(self, t: int, state: dict) -> dict:
        assert self.drill is not None, "publish_state asks only with a drill"
        statuses = []
        for name, distance in sorted(state["distances"].items(), key=lambda kv: kv[1]):
            level = DIAGNOSTIC_OK
            if distance <= 0.0:
                level = DIAGNOSTIC_ERROR  # the burr is in it
            elif distance < WARN_DISTANCE:
                level = DIAGNOSTIC_WARN
            statuses.append({
                "level": level, "name": name, "message": f"{distance * 1000:.2f} mm",
                "hardware_id": self.drill.key,
                "values": [{"key": "distance_m", "value": repr(float(distance))}],
            })  # fmt: skip
        return {"header": header(t, tf_frame(self.drill.key)), "status": statuses}


# The relay on the public port -----------------------------------------------------------------


def _listen(host: str, port: int) -> socket.socket:
    """A listening TCP socket on host:port (the first address the host resolves to)."""
    family, _, _, _, address = socket.getaddrinfo(host, port, type=socket.SOCK_STREAM,
                                                  flags=socket.AI_PASSIVE)[0]  # fmt: skip
    return socket.create_server(address[:2], family=family)


def _header_lines(head: bytes) -> list[bytes]:
    return head.split(b"\r\n")


def _is_subprotocol_header(line: bytes) -> bool:
    name, colon, _ = line.partition(b":")
    return bool(colon) and name.strip().lower() == b"sec-websocket-protocol"


def _offer_sdk_name(request: bytes) -> tuple[bytes, bool]:
    """A client's HTTP upgrade request as the SDK accepts it: where the client offers the
    protocol only under its old name, that name becomes the SDK's (other offers are kept).
    Returns the request and whether it was renamed."""
    lines = _header_lines(request)
    offered = [token.strip() for line in lines[1:] if _is_subprotocol_header(line)
               for token in line.partition(b":")[2].split(b",")]  # fmt: skip
    if SUBPROTOCOL.encode() in offered or LEGACY_SUBPROTOCOL.encode() not in offered:
        return request, False
    renamed = []
    for line in lines:
        if line is not lines[0] and _is_subprotocol_header(line):
            tokens = [t.strip() for t in line.partition(b":")[2].split(b",")]
            tokens = [SUBPROTOCOL.encode() if t == LEGACY_SUBPROTOCOL.encode() else t
                      for t in tokens]  # fmt: skip
            line = b"Sec-WebSocket-Protocol: " + b", ".join(tokens)
        renamed.append(line)
    return b"\r\n".join(renamed), True


def _answer_legacy_name(response: bytes) -> bytes:
    """The SDK's handshake response as a client that offered the old name expects it: the
    protocol it chose named as the client named it."""
    lines = [b"Sec-WebSocket-Protocol: " + LEGACY_SUBPROTOCOL.encode()
             if _is_subprotocol_header(line)
             and line.partition(b":")[2].strip() == SUBPROTOCOL.encode() else line
             for line in _header_lines(response)]  # fmt: skip
    return b"\r\n".join(lines)


class _Refused(Exception):
    """A connection the relay ends on purpose; `what` is the count it goes to."""

    def __init__(self, what: str, why: str) -> None:
        super().__init__(why)
        self.what = what


def _busy(why: str) -> bytes:
    """The HTTP answer to a connection over a limit: 503, saying which."""
    body = f"the live view is busy: {why}\n".encode()
    return (b"HTTP/1.1 503 Service Unavailable\r\nRetry-After: 5\r\nContent-Type: text/plain\r\n"
            b"Connection: close\r\nContent-Length: %d\r\n\r\n%s" % (len(body), body))  # fmt: skip


# A client's close frame, code 1001 (going away), masked with a zero key (RFC 6455 5.3).
GOING_AWAY = b"\x88\x82\x00\x00\x00\x00" + (1001).to_bytes(2, "big")


def _frame_head_size(head: bytes) -> int | None:
    """The length of the frame header `head` begins (RFC 6455 5.2), None before 2 bytes."""
    if len(head) < 2:
        return None
    length = head[1] & 0x7F
    return 2 + (2 if length == 126 else 8 if length == 127 else 0) + (4 if head[1] & 0x80 else 0)


class _ClientFrames:
    """Follows the frames a client sends as the bytes pass, without keeping payloads (RFC 6455
    5.2): each must be masked, of a known opcode, with no reserved bit that the handshake did not
    negotiate (`reserved`), control frames whole and short, and no frame or fragmented message
    longer than `limit` bytes, refused from its header on. Raises _Refused at the first that is
    not. `begun`: when the frame under way began (None between frames)."""

    def __init__(self, limit: int, reserved: int = 0) -> None:
        self.limit, self.reserved = limit, reserved
        self.begun: float | None = None
        self.closed = False  # the client sent its close frame
        self.whole = True  # what was passed on ends with a whole frame (set by _pump_client)
        self._head = b""  # a header cut short by a read
        self._left = 0  # payload bytes of the frame under way still to come
        self._message: int | None = None  # bytes so far of a fragmented message

    def feed(self, data: bytes) -> None:
        i, n = 0, len(data)
        while i < n:
            if self.begun is None:
                self.begun = time.monotonic()
            if self._left:
                step = min(self._left, n - i)
                self._left -= step
                i += step
            else:
                head = self._head + data[i : i + 14]
                size = _frame_head_size(head)
                if size is None or len(head) < size:  # the rest of the data is header
                    self._head = head
                    return
                i += size - len(self._head)
                self._head = b""
                self._left = self._check(head[:size])
            if not self._left:
                self.begun = None

    def _check(self, head: bytes) -> int:
        """The payload length of a frame with header `head`, or _Refused."""
        opcode, final = head[0] & 0x0F, head[0] & 0x80
        if head[0] & 0x70 & ~self.reserved:
            raise _Refused("malformed", "a reserved bit set")
        if not head[1] & 0x80:
            raise _Refused("malformed", "an unmasked frame")
        length = head[1] & 0x7F
        if length >= 126:
            length = int.from_bytes(head[2:4] if length == 126 else head[2:10], "big")
        if opcode >= 8:
            if opcode > 10 or not final or length > 125:
                raise _Refused("malformed", "a bad control frame")
            self.closed = self.closed or opcode == 8
            return length
        if opcode > 2 or (opcode == 0) != (self._message is not None):
            raise _Refused("malformed", f"opcode {opcode} out of place")
        total = (self._message or 0) + length
        if total > self.limit:
            raise _Refused("malformed", f"a message over {self.limit} bytes")
        self._message = None if final else total
        return length


def _guard_socket(writer: asyncio.StreamWriter) -> None:
    """Keepalive and a user timeout on a client's socket, so that a dead peer (a half-open
    connection) is dropped within seconds (Linux; elsewhere what the system offers)."""
    sock = writer.get_extra_info("socket")
    if sock is None:
        return
    options = [(socket.SOL_SOCKET, "SO_KEEPALIVE", 1),
               (socket.IPPROTO_TCP, "TCP_KEEPIDLE", KEEPALIVE_IDLE_S),
               (socket.IPPROTO_TCP, "TCP_KEEPINTVL", KEEPALIVE_INTERVAL_S),
               (socket.IPPROTO_TCP, "TCP_KEEPCNT", KEEPALIVE_PROBES),
               (socket.IPPROTO_TCP, "TCP_USER_TIMEOUT", USER_TIMEOUT_MS)]  # fmt: skip
    for level, name, value in options:
        if hasattr(socket, name):
            with contextlib.suppress(OSError):
                sock.setsockopt(level, getattr(socket, name), value)


def _give_back_memory() -> None:
    """Returns the C heap's free pages to the system (glibc's malloc_trim), so that what the
    clients used (the SDK's queues, sockets' buffers) leaves the RSS when they do."""
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):  # not glibc
        pass


class _SubprotocolRelay:
    """Accepts connections on `listener` and relays each to the SDK's server on the loopback
    `backend_port`, renaming the subprotocol in the handshake of a client that offers only
    the old name (_offer_sdk_name, _answer_legacy_name); after the handshake, bytes are copied
    both ways unchanged, the client's frames checked on the way (_ClientFrames). An asyncio loop
    on a thread of its own. Limits: `max_clients` WebSocket clients (more get HTTP 503) and
    MAX_HANDSHAKES connections in their handshake (past it the oldest gets HTTP 503), the head
    within `handshake_timeout`,
    client messages of `max_message` bytes at most, each frame whole within FRAME_TIMEOUT_S,
    and at most RELAY_CHUNK + RELAY_WRITE_BUFFER bytes held each way per client. `counts`
    (LiveStats.connections) says what happened to connections."""

    def __init__(self, listener: socket.socket, backend_port: int, *, max_clients: int,
                 max_message: int, handshake_timeout: float, counts: dict) -> None:  # fmt: skip
        self.port: int = listener.getsockname()[1]
        self.backend_port = backend_port
        self.max_clients, self.max_message = max_clients, max_message
        self.handshake_timeout = handshake_timeout
        self.counts = counts
        self.errors: list[BaseException] = []  # unexpected ones, reported by stop()
        self._listener = listener
        self._loop = asyncio.new_event_loop()
        self._closing: asyncio.Event | None = None
        self._connections: dict[asyncio.Task, list[asyncio.StreamWriter]] = {}
        # Connections in their handshake, oldest first, and those cut to make room.
        self._handshaking: dict[asyncio.Task, asyncio.StreamWriter] = {}
        self._evicted: set[asyncio.Task] = set()
        self._trim: asyncio.TimerHandle | None = None
        started = threading.Event()
        self._thread = threading.Thread(target=self._run, args=(started,), daemon=True,
                                        name="foxglove-relay")  # fmt: skip
        self._thread.start()
        started.wait()
        if self.errors:
            self._thread.join()
            raise RuntimeError(f"the live view's relay did not start: {self.errors[0]!r}")

    def stop(self) -> list[BaseException]:
        """Stops accepting, lets open connections finish closing for up to CLOSE_GRACE_S,
        cuts the rest and returns the unexpected errors met."""
        if self._thread.is_alive():
            self._loop.call_soon_threadsafe(self._close)
            self._thread.join()
        errors, self.errors = self.errors, []
        return errors

    def _close(self) -> None:
        assert self._closing is not None, "set before the thread says it started"
        self._closing.set()

    def _run(self, started: threading.Event) -> None:
        asyncio.set_event_loop(self._loop)
        try:
            self._loop.run_until_complete(self._main(started))
        except BaseException as error:  # reported by stop()
            self.errors.append(error)
        finally:
            started.set()
            self._listener.close()
            self._loop.close()
            _give_back_memory()

    async def _main(self, started: threading.Event) -> None:
        self._closing = asyncio.Event()
        server = await asyncio.start_server(self._serve, sock=self._listener,
                                            limit=HANDSHAKE_LIMIT)  # fmt: skip
        started.set()
        await self._closing.wait()
        server.close()
        if self._trim is not None:
            self._trim.cancel()
        # Cut the connections still in their handshake at once; the others pass on the SDK's
        # closing (it stopped first) for up to CLOSE_GRACE_S, then are cut. Cut transports
        # end their tasks (cancelling a connection's task makes asyncio log it on 3.11).
        for writers in self._connections.values():
            if len(writers) == 1:
                writers[0].transport.abort()
        if self._connections:
            _, late = await asyncio.wait(list(self._connections), timeout=CLOSE_GRACE_S)
            for task in late:
                for writer in self._connections.get(task, []):
                    writer.transport.abort()
            if late:
                await asyncio.wait(late, timeout=CLOSE_GRACE_S)
        with contextlib.suppress(asyncio.TimeoutError):  # 3.12 waits for the connections too
            await asyncio.wait_for(server.wait_closed(), CLOSE_GRACE_S)

    async def _serve(self, client_reader: asyncio.StreamReader,
                     client_writer: asyncio.StreamWriter) -> None:  # fmt: skip
        task = asyncio.current_task()
        assert task is not None, "a connection is served by a task"
        writers = self._connections[task] = [client_writer]
        counts = self.counts
        counts["accepted"] += 1
        counts["open"] = len(self._connections)
        outcome, served = None, False
        try:
            _guard_socket(client_writer)
            client_writer.transport.set_write_buffer_limits(high=RELAY_WRITE_BUFFER)
            # Over MAX_HANDSHAKES, the oldest handshake makes room: a client sends its head
            # as soon as it connects, so idle connections cannot keep one out.
            self._handshaking[task] = client_writer
            if len(self._handshaking) > MAX_HANDSHAKES:
                self._evict(next(iter(self._handshaking)))
            try:
                request = await asyncio.wait_for(client_reader.readuntil(b"\r\n\r\n"),
                                                 self.handshake_timeout)  # fmt: skip
            finally:
                self._handshaking.pop(task, None)
            if counts["clients"] >= self.max_clients:
                client_writer.write(_busy(f"it serves {self.max_clients} clients at most"))
                raise _Refused("refused", "too many clients")
            counts["clients"] += 1
            served = True
            await self._relay(request, client_reader, client_writer, writers)
        except _Refused as refusal:
            outcome = refusal.what
            if refusal.what != "refused":  # cut mid-stream: no closing handshake to wait for
                client_writer.transport.abort()
        except asyncio.TimeoutError:
            outcome = "timed_out"
        except (OSError, EOFError, asyncio.LimitOverrunError):
            outcome = "lost"  # a peer that left, reset or sent an HTTP head too long
        except Exception as error:  # reported by stop()
            self.errors.append(error)
        finally:
            if task in self._evicted:
                self._evicted.discard(task)
                outcome = "refused"
            if outcome is not None:
                counts[outcome] += 1
            if served:
                counts["clients"] -= 1
            for writer in writers:
                writer.close()  # sends what is buffered first (the SDK's closing frame)
            for writer in writers:
                with contextlib.suppress(Exception):
                    await writer.wait_closed()
            del self._connections[task]
            counts["open"] = len(self._connections)
            # Memory back to the system a moment after a group of clients has left.
            if self._trim is not None:
                self._trim.cancel()
            self._trim = self._loop.call_later(TRIM_DELAY_S, _give_back_memory)

    def _evict(self, task: asyncio.Task) -> None:
        """Ends a connection still in its handshake with HTTP 503, to make room."""
        writer = self._handshaking.pop(task)
        self._evicted.add(task)
        writer.write(_busy(f"over {MAX_HANDSHAKES} connections in their handshake"))
        writer.close()  # its read ends, and so its task

    async def _relay(self, request: bytes, client_reader: asyncio.StreamReader,
                     client_writer: asyncio.StreamWriter,
                     writers: list[asyncio.StreamWriter]) -> None:  # fmt: skip
        """One client's session: the handshake passed on, then bytes copied both ways until
        the SDK's side ends (or the client's, then the SDK's within the handshake timeout)."""
        request, renamed = _offer_sdk_name(request)
        backend_reader, backend_writer = await asyncio.open_connection(
            "127.0.0.1", self.backend_port, limit=HANDSHAKE_LIMIT
        )
        writers.append(backend_writer)
        backend_writer.write(request)
        response = await asyncio.wait_for(backend_reader.readuntil(b"\r\n\r\n"),
                                          self.handshake_timeout)  # fmt: skip
        client_writer.write(_answer_legacy_name(response) if renamed else response)
        # An extension the SDK agreed to may use RSV1 (permessage-deflate); it agrees to none.
        extensions = any(line.lower().startswith(b"sec-websocket-extensions:")
                         for line in _header_lines(response))  # fmt: skip
        frames = _ClientFrames(self.max_message, 0x40 if extensions else 0)
        upstream = asyncio.ensure_future(_pump_client(client_reader, backend_writer, frames))
        downstream = asyncio.ensure_future(_pump(backend_reader, client_writer))
        pumps = [upstream, downstream]
        try:
            # A connection ends with the SDK's side; where the client ends first, the SDK is
            # told (a half close) and its end awaited.
            done, _ = await asyncio.wait(pumps, return_when=asyncio.FIRST_COMPLETED)
            if downstream not in done and upstream.exception() is None:
                await asyncio.wait([downstream], timeout=self.handshake_timeout)
        finally:
            for pump in pumps:
                pump.cancel()
            results = await asyncio.gather(*pumps, return_exceptions=True)
            # A client gone or cut without its close frame: the SDK is told it went away
            # (1001) in a frame of the client's, and what it still sends until it closes is
            # read and dropped, rather than leaving it to log a reset or a broken pipe.
            if not frames.closed and frames.whole and not backend_writer.is_closing():
                backend_writer.write(GOING_AWAY)
                with contextlib.suppress(Exception):
                    await asyncio.wait_for(_discard(backend_reader), CLOSE_GRACE_S)
        for result in results:
            if isinstance(result, Exception) and not isinstance(result, asyncio.CancelledError):
                raise result


async def _pump(reader: asyncio.StreamReader, writer: asyncio.StreamWriter) -> None:
    """Copies reader to writer as bytes come, a read waiting while the writer holds more than
    its buffer limit; at the reader's end, half-closes the writer so that the other direction
    can finish its closing handshake."""
    while True:
        data = await reader.read(RELAY_CHUNK)
        if not data:
            break
        writer.write(data)
        await writer.drain()
    if writer.can_write_eof():
        writer.write_eof()


async def _discard(reader: asyncio.StreamReader) -> None:
    """Reads and drops until the end of the stream."""
    while await reader.read(RELAY_CHUNK):
        pass


async def _pump_client(reader: asyncio.StreamReader, writer: asyncio.StreamWriter,
                       frames: _ClientFrames) -> None:  # fmt: skip
    """_pump for what a client sends: its frames checked before they pass (_ClientFrames),
    and a frame begun but not whole within FRAME_TIMEOUT_S ends the connection."""
    while True:
        if frames.begun is None:
            data = await reader.read(RELAY_CHUNK)
        else:
            left = frames.begun + FRAME_TIMEOUT_S - time.monotonic()
            try:
                data = await asyncio.wait_for(reader.read(RELAY_CHUNK), max(left, 0.0))
            except asyncio.TimeoutError:
                raise _Refused("timed_out", "a frame not finished in time") from None
        if not data:
            break
        frames.feed(data)
        writer.write(data)
        frames.whole = frames.begun is None
        await writer.drain()
    if writer.can_write_eof():
        writer.write_eof()


def serve(world, cameras=None, **options) -> FoxgloveServer:
    """Starts serving a world live (see FoxgloveServer); stop it with ``server.stop()``."""
    return FoxgloveServer(world, cameras, **options).start()
