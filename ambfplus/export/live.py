"""A world served live over the Foxglove WebSocket protocol (the Foxglove SDK's server), so that
Foxglove, or any client of the protocol, watches a headless session from another machine or
process.

    from ambfplus.export.live import FoxgloveServer
    with ambfplus.RealTimeLoop(world), FoxgloveServer(world, [camera], rate=10.0) as server:
        ...  # ws://127.0.0.1:8765 (server.url); server.stats.summary() says what it sent

It publishes, as ROS 2 messages (CDR, ``ros2msg`` schemas: the same types and conventions as
the ``mcap`` export), only on channels a client subscribed to, from two threads of its own:

- at ``rate`` Hz of wall time (10 by default; ticks it misses are skipped, never caught up in a
  burst): ``/tf`` (tf2_msgs/TFMessage: world -> each camera's optical frame, the drill, its
  bodies and the volumes), ``/<camera>/camera_info`` (K and P in ROS's pixel convention),
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
"""

from __future__ import annotations

import threading
import time
from collections import deque
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ._common import frame_name, nanoseconds, require
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


def _durations() -> deque:
    return deque(maxlen=TIMINGS_KEPT)


@dataclass
class LiveStats:
    """What the server did: state ticks run and skipped, messages sent, images sent, and
    durations of the last ticks and image rounds (a capture of every subscribed camera)."""

    ticks: int = 0
    skipped: int = 0
    messages: int = 0
    images: int = 0
    image_rounds: int = 0
    image_seconds: float = 0.0  # wall time with an image subscriber
    tick_seconds: deque = field(default_factory=_durations)
    round_seconds: deque = field(default_factory=_durations)

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
                "image_round_ms_max": float(rounds.max() * 1e3)}  # fmt: skip


class FoxgloveServer:
    """Serves ``world`` live (see the module docstring): ``cameras`` (default: all of the
    world's) and its first drill (or ``drill``), the state at ``rate`` Hz and images at up to
    ``image_rate`` Hz (default ``rate``), on ``host``:``port`` (0: any free port).
    ``start()``/``stop()`` or a ``with`` block."""

    def __init__(self, world, cameras=None, *, drill=None, rate: float = 10.0,
                 image_rate: float | None = None, host: str = "127.0.0.1",
                 port: int = DEFAULT_PORT, depth: bool = False,
                 name: str = "ambfplus") -> None:  # fmt: skip
        self._foxglove = require("foxglove", "foxglove")
        require("foxglove", "rosbags.typesys")
        image_rate = rate if image_rate is None else image_rate
        for what, value in (("rate", rate), ("image_rate", image_rate)):
            if not value > 0:
                raise ValueError(f"{what} must be > 0 Hz, got {value}")
        self.world = world
        self.cameras = list(world.cameras if cameras is None else cameras)
        drills = list(world.drills)
        self.drill = drill if drill is not None else (drills[0] if drills else None)
        self.rate, self.image_rate = float(rate), float(image_rate)
        self.host, self.requested_port, self.depth, self.name = host, port, depth, name
        self.stats = LiveStats()
        self._store = typestore()
        self._server = None
        self._threads: list[threading.Thread] = []
        self._stop = threading.Event()
        self._errors: list[BaseException] = []
        # Objects whose pose /tf carries, chosen once.
        self._posed_objects = [o for o in world.objects if o.kind in ("body", "volume", "drill")]
        self._posed = [o.name for o in self._posed_objects]
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
            self._channel(f"/{self.drill.name}/wrench", WRENCH)
            self._channel(f"/{self.drill.name}/critical", DIAGNOSTICS)
        try:
            self._server = fox.start_server(name=self.name, host=self.host,
                                            port=self.requested_port, context=self._context,
                                            message_backlog_size=64)  # fmt: skip
        except Exception as error:  # the SDK raises RuntimeError for a port in use
            raise RuntimeError(
                f"the Foxglove server cannot listen on {self.host}:{self.requested_port}: {error}"
            ) from None
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
        if self._server is not None:
            self._server.stop()
            self._server = None
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
        return self._server.port if self._server is not None else self.requested_port

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
            frame = camera.capture(passes=passes, poses=True)
            t = nanoseconds(frame.time)
            frame_id = frame_name(camera.name, "camera")
            if self._wanted("/tf"):  # first, so a client has the pose when the image comes
                poses = frame.poses
                transforms = [transform(t, WORLD, n, poses[n]) for n in self._posed if n in poses]
                transforms.append(transform(t, WORLD, frame_id, frame.pose))
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
            topics += [f"/{self.drill.name}/wrench", f"/{self.drill.name}/critical"]
        if not any(self._wanted(topic) for topic in topics):
            return
        state = self._snapshot()
        t = nanoseconds(state["time"])
        transforms = [transform(t, WORLD, child, pose) for child, pose in state["poses"]]
        for camera in self.cameras:
            frame_id = frame_name(camera.name, "camera")
            pose, intrinsics = state["cameras"][camera.name]
            transforms.append(transform(t, WORLD, frame_id, pose))
            info_topic = f"/{camera.name}/camera_info"
            if self._wanted(info_topic):
                self._send(info_topic, t, camera_info(t, frame_id, camera.width, camera.height,
                                                      intrinsics))  # fmt: skip
        if self._wanted("/tf"):
            self._send("/tf", t, {"transforms": transforms})
        if self.drill is None:
            return
        wrench_topic = f"/{self.drill.name}/wrench"
        if self._wanted(wrench_topic):
            f = state["force"]
            self._send(wrench_topic, t, {
                "header": header(t, WORLD),
                "wrench": {"force": {"x": f[0], "y": f[1], "z": f[2]},
                           "torque": {"x": 0.0, "y": 0.0, "z": 0.0}},
            })  # fmt: skip
        critical_topic = f"/{self.drill.name}/critical"
        if self._wanted(critical_topic):
            self._send(critical_topic, t, self._critical(t, state))

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
            "poses": [(name, s["pose"]) for name, s in zip(self._posed, states)],
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
                "hardware_id": self.drill.name,
                "values": [{"key": "distance_m", "value": repr(float(distance))}],
            })  # fmt: skip
        return {"header": header(t, self.drill.name), "status": statuses}


def serve(world, cameras=None, **options) -> FoxgloveServer:
    """Starts serving a world live (see FoxgloveServer); stop it with ``server.stop()``."""
    return FoxgloveServer(world, cameras, **options).start()
