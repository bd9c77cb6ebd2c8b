"""A world served live over the Foxglove WebSocket protocol (the Foxglove SDK's server), so that
Foxglove, or any client of the protocol, watches a headless session from another machine or
process.

    from ambfplus.export.live import FoxgloveServer
    with ambfplus.RealTimeLoop(world), FoxgloveServer(world, [camera], rate=10.0) as server:
        ...  # ws://127.0.0.1:8765 (server.url)

The server's own thread wakes ``rate`` times per second of wall time (10 Hz by default;
deadlines it misses are skipped, never caught up in a burst) and publishes, as ROS 2 messages
(CDR, ``ros2msg`` schemas: the same types and conventions as the ``mcap`` export), only on
channels a client subscribed to:

- ``/<camera>/image_rect_color`` (sensor_msgs/Image rgb8; ``depth=True`` adds
  ``/<camera>/depth/image_rect``, 32FC1 metres) and ``/<camera>/camera_info`` (K and P in ROS's
  pixel convention) for each camera;
- ``/tf`` (tf2_msgs/TFMessage): world -> each camera's optical frame, the drill, its bodies and
  the volumes;
- ``/<drill>/wrench`` (geometry_msgs/WrenchStamped): the force fed back to the device, world
  axes;
- ``/<drill>/critical`` (diagnostic_msgs/DiagnosticArray): every critical structure's distance
  from the burr, nearest first (level WARN under 2 mm, ERROR at 0).

Stamps are simulation time. The physics loop (``ambfplus.RealTimeLoop``) never waits for the
server's Python: images are captured as any other thread captures (the engine holds the world's
lock only to copy what it draws, with the poses TF needs), the drill's force and distances are
two reads under the lock, and encoding and sending happen off the lock; a slow client loses
its oldest messages (the SDK's per-client backlog), it never stalls the publisher. It listens
on 127.0.0.1 unless ``host`` says otherwise. Needs ``pip install "ambfplus[foxglove]"``.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass, field

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


@dataclass
class LiveStats:
    """What the server did: ticks run and skipped, messages sent, seconds per tick."""

    ticks: int = 0
    skipped: int = 0
    messages: int = 0
    tick_seconds: list = field(default_factory=list)

    def summary(self) -> dict:
        t = np.asarray(self.tick_seconds[-1000:]) if self.tick_seconds else np.zeros(1)
        return {"ticks": self.ticks, "skipped": self.skipped, "messages": self.messages,
                "tick_ms_median": float(np.median(t) * 1e3),
                "tick_ms_max": float(t.max() * 1e3)}  # fmt: skip


class FoxgloveServer:
    """Serves ``world`` live (see the module docstring): ``cameras`` (default: all of the
    world's), its first drill (or ``drill``) at ``rate`` Hz on ``host``:``port`` (0: any free
    port). ``start()``/``stop()`` or a ``with`` block."""

    def __init__(self, world, cameras=None, *, drill=None, rate: float = 10.0,
                 host: str = "127.0.0.1", port: int = DEFAULT_PORT, depth: bool = False,
                 name: str = "ambfplus") -> None:  # fmt: skip
        self._foxglove = require("foxglove", "foxglove")
        require("foxglove", "rosbags.typesys")
        if not rate > 0:
            raise ValueError(f"rate must be > 0 Hz, got {rate}")
        self.world = world
        self.cameras = list(world.cameras if cameras is None else cameras)
        drills = list(world.drills)
        self.drill = drill if drill is not None else (drills[0] if drills else None)
        self.rate = float(rate)
        self.host, self.requested_port, self.depth, self.name = host, port, depth, name
        self.stats = LiveStats()
        self._store = typestore()
        self._server = None
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()
        self._error: BaseException | None = None
        # Objects whose pose /tf carries, chosen once.
        self._posed_objects = [o for o in world.objects if o.kind in ("body", "volume", "drill")]
        self._posed = [o.name for o in self._posed_objects]

    # Life cycle -------------------------------------------------------------------------------

    def start(self) -> FoxgloveServer:
        fox = self._foxglove
        self._context = fox.Context()
        self._channels, self._msgtypes = {}, {}
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
        self._thread = threading.Thread(target=self._run, name="foxglove-live", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        if self._server is not None:
            self._server.stop()
            self._server = None
        for channel in getattr(self, "_channels", {}).values():
            channel.close()
        if self._error is not None:
            error, self._error = self._error, None
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
        text, _ = self._store.generate_msgdef(msgtype, ros_version=2)
        schema = fox.Schema(name=msgtype, encoding="ros2msg", data=text.encode())
        self._channels[topic] = fox.Channel(topic, schema=schema, message_encoding="cdr",
                                            context=self._context)  # fmt: skip
        self._msgtypes[topic] = msgtype

    # Publishing -------------------------------------------------------------------------------

    def _run(self) -> None:
        period = 1.0 / self.rate
        deadline = time.perf_counter()
        try:
            while not self._stop.is_set():
                started = time.perf_counter()
                self.publish()
                self.stats.ticks += 1
                self.stats.tick_seconds.append(time.perf_counter() - started)
                deadline += period
                now = time.perf_counter()
                if now > deadline:  # late: skip the missed ticks instead of bursting
                    missed = int((now - deadline) / period) + 1
                    self.stats.skipped += missed
                    deadline += missed * period
                self._stop.wait(max(0.0, deadline - time.perf_counter()))
        except BaseException as error:  # reported by stop()
            self._error = error

    def _wanted(self, topic: str) -> bool:
        channel = self._channels.get(topic)
        return channel is not None and channel.has_sinks()

    def _send(self, topic: str, time_ns: int, body: dict) -> None:
        msgtype = self._msgtypes[topic]
        message = for_rosbags(self._store, body, msgtype)
        data = bytes(self._store.serialize_cdr(message, msgtype))
        self._channels[topic].log(data, log_time=time_ns)
        self.stats.messages += 1

    def publish(self) -> None:
        """One tick: images (with the poses the engine copied for them), the drill's state,
        then encoding and sending, all off the world's lock but for two reads."""
        frames = {}
        for camera in self.cameras:
            passes = [p for p, topic in (("rgb", f"/{camera.name}/image_rect_color"),
                                         ("depth", f"/{camera.name}/depth/image_rect"))
                      if (p == "rgb" or self.depth) and self._wanted(topic)]  # fmt: skip
            if passes:
                frames[camera.name] = camera.capture(passes=passes, poses=True)
        state = self._snapshot(frames)
        t = nanoseconds(state["time"])
        transforms = [transform(t, WORLD, child, pose) for child, pose in state["poses"]]
        for camera in self.cameras:
            frame_id = frame_name(camera.name, "camera")
            frame = frames.get(camera.name)
            if frame is not None:
                frame_time = nanoseconds(frame.time)
                for pass_name, topic, encoding in (
                    ("rgb", f"/{camera.name}/image_rect_color", "rgb8"),
                    ("depth", f"/{camera.name}/depth/image_rect", "32FC1"),
                ):  # fmt: skip
                    image = getattr(frame, pass_name, None)
                    if image is not None:
                        body = image_message(frame_time, frame_id, image, encoding)
                        self._send(topic, frame_time, body)
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

    def _snapshot(self, frames: dict) -> dict:
        """The state this tick publishes. With a captured frame, its time and the poses the
        engine copied for it under the lock (no Python runs under the world's lock, where a
        thread that lost the GIL would hold the physics thread up); else a few reads under the
        lock. The drill's force and distances are two reads under the lock."""
        world, drill = self.world, self.drill
        frame = next(iter(frames.values()), None)
        if frame is not None:
            poses = frame.poses
            state = {
                "time": frame.time,
                "poses": [(n, poses[n]) for n in self._posed if n in poses],
                "cameras": {
                    c.name: (
                        frames[c.name].pose if c.name in frames else poses[c.name],
                        c.intrinsics,
                    )
                    for c in self.cameras
                },  # fmt: skip
            }
        else:
            with world.lock():
                state = {
                    "time": world.time,
                    "poses": [(o.name, o.pose) for o in self._posed_objects],
                    "cameras": {c.name: (c.pose, c.intrinsics) for c in self.cameras},
                }
        if drill is not None:
            with world.lock():
                force, distances = drill.force, drill.critical_distances
            state["force"] = [float(v) for v in force]
            state["distances"] = distances
        return state

    def _critical(self, t: int, state: dict) -> dict:
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
