"""The names of AMBF's Python client (``ambf_client``), in-process and without ROS.

A script written for AMBF's client runs with no edit once the simulator it talks to is chosen::

    import ambfplus
    from ambfplus import ambf_client

    sim = ambfplus.Simulator.from_launch("launch.yaml", models=[12])
    ambf_client.use_simulator(sim)              # Client() talks to sim from now on
    ambf_client.install_alias()                  # `import ambf_client` finds this module
    # ... then the unmodified script:
    from ambf_client import Client
    client = Client()
    client.connect()
    base = client.get_obj_handle("Mold_A")
    base.set_joint_pos(0, 0.5)                  # by index (AMBF's order) or by name

Time passes in one of two ways (``docs/reference/ambf-client.md``):

- **lock-step** (the default): the simulation steps only when the script says so:
  ``WorldHandle.update()`` (``set_num_step_skips`` steps each), ``Client.step(n)``, or the
  ``sleep()`` of a rate from ``Client.create_rate(hz)``.
- **real time** (``realtime=True``): a thread steps the world in step with the wall clock from
  ``connect()`` to ``clean_up()``, so a script that sleeps sees time pass, as with AMBF's
  asynchronous client. ``WorldHandle.enable_throttling(True)`` pauses the thread and hands the
  clock to ``update()``, as AMBF's throttling does.

Every public method of AMBF's client types is in ``COVERAGE``: implemented over the engine, a
no-op (ROS plumbing with nothing to do in-process), not applied (raises ``NotImplementedError``
saying why), or an ambfplus extension. Differences from AMBF, by design: commands act at once,
not at the next ROS message; ``set_pos``/``set_rpy``/``set_pose`` place an object directly (AMBF
drives a body there with its controller) and zero a body's velocity; a bad joint index or name
raises (``IndexError``/``KeyError``) where AMBF prints and returns None.
"""

from __future__ import annotations

import sys
import threading
import time
import types
from dataclasses import dataclass, field
from typing import Any, Union

import numpy as np

from ._core import ConstraintActuator, Joint, ProximitySensor, RigidBody, Simulator
from .transforms import rpy_matrix

JointRef = Union[int, str]

__all__ = [
    "COVERAGE",
    "Client",
    "WorldHandle",
    "GenericHandle",
    "ObjectHandle",
    "GhostHandle",
    "CameraHandle",
    "LightHandle",
    "SensorHandle",
    "ActuatorHandle",
    "VehicleHandle",
    "Point",
    "Quaternion",
    "Pose",
    "Header",
    "Rate",
    "use_simulator",
    "install_alias",
    "coverage_markdown",
]


# ROS message look-alikes: the fields AMBF's client returns, with no ROS.
@dataclass
class Point:
    """geometry_msgs/Point's (and Vector3's) fields."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0

    def __iter__(self):
        return iter((self.x, self.y, self.z))


Vector3 = Point


@dataclass
class Quaternion:
    """geometry_msgs/Quaternion's fields."""

    x: float = 0.0
    y: float = 0.0
    z: float = 0.0
    w: float = 1.0

    def __iter__(self):
        return iter((self.x, self.y, self.z, self.w))


@dataclass
class Pose:
    """geometry_msgs/Pose's fields."""

    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class Wrench:
    """geometry_msgs/Wrench's fields."""

    force: Vector3 = field(default_factory=Vector3)
    torque: Vector3 = field(default_factory=Vector3)


@dataclass
class Twist:
    """geometry_msgs/Twist's fields."""

    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class Header:
    """std_msgs/Header's fields: stamp is the simulation time (s), seq the step index."""

    seq: int
    stamp: float
    frame_id: str


# Rotations: AMBF's fixed-axis roll, pitch, yaw (R = Rz(y) Ry(p) Rx(r)); quaternions (x, y, z, w).
def _rpy(rotation: np.ndarray) -> list:
    pitch = float(np.arcsin(np.clip(-rotation[2, 0], -1.0, 1.0)))
    roll = float(np.arctan2(rotation[2, 1], rotation[2, 2]))
    yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    return [roll, pitch, yaw]


def _quaternion(rotation: np.ndarray) -> Quaternion:
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    if trace > 0:
        s = 2.0 * np.sqrt(trace + 1.0)
        q = (
            (m[2, 1] - m[1, 2]) / s,
            (m[0, 2] - m[2, 0]) / s,
            (m[1, 0] - m[0, 1]) / s,
            0.25 * s,
        )
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = (0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * np.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = ((m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * np.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s, (m[1, 0] - m[0, 1]) / s)
    return Quaternion(*(float(v) for v in q))


def _rotation(quat: Any) -> np.ndarray:
    """A rotation matrix from a quaternion given as (x, y, z, w) or with those fields."""
    if all(hasattr(quat, a) for a in "xyzw"):
        quat = (quat.x, quat.y, quat.z, quat.w)
    x, y, z, w = (float(v) for v in quat)
    n = np.sqrt(x * x + y * y + z * z + w * w)
    if n == 0.0:
        raise ValueError("a rotation's quaternion must not be zero")
    x, y, z, w = x / n, y / n, z / n, w / n
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def _matrix(pose: Any) -> np.ndarray:
    """A 4x4 pose from a Pose-like (position, orientation) or a 4x4 array."""
    if hasattr(pose, "position") and hasattr(pose, "orientation"):
        matrix = np.eye(4)
        p = pose.position
        matrix[:3, 3] = (float(p.x), float(p.y), float(p.z))
        matrix[:3, :3] = _rotation(pose.orientation)
        return matrix
    matrix = np.asarray(pose, dtype=float)
    if matrix.shape != (4, 4):
        raise ValueError(f"a pose is a Pose (position, orientation) or a 4x4 array, not {pose!r}")
    return matrix


def _vector(value: Any) -> tuple:
    if all(hasattr(value, a) for a in "xyz"):
        return (float(value.x), float(value.y), float(value.z))
    x, y, z = (float(v) for v in value)
    return (x, y, z)


_default: dict = {"simulator": None, "realtime": False}


def use_simulator(simulator: Simulator | None, *, realtime: bool = False) -> None:
    """Makes ``Client()`` with no simulator talk to this one (None forgets it).

    This is how a script written for AMBF, which calls ``Client()``, runs with no edit: the
    program that loads the scene names it here first. ``realtime`` is the default mode of those
    clients (a thread steps the world with the wall clock; else lock-step)."""
    _default["simulator"] = simulator
    _default["realtime"] = bool(realtime)


def install_alias() -> types.ModuleType:
    """Registers this module as ``ambf_client`` so that ``from ambf_client import Client`` works.

    Wheels install a top-level ``ambf_client`` module that does the same; this serves a source
    tree or any other install."""
    module = sys.modules[__name__]
    sys.modules["ambf_client"] = module
    return module


class Rate:
    """A loop rate (``Client.create_rate``): ``sleep()`` keeps a loop at ``hz``.

    In real-time mode it sleeps on the wall clock (as ROS's rate does); in lock-step mode it
    steps the simulation by one period instead, so a loop paced by a rate advances time."""

    def __init__(self, client: Client, hz: float) -> None:
        if not hz > 0:
            raise ValueError(f"a rate is a positive frequency in Hz, not {hz!r}")
        self._client = client
        self._period = 1.0 / float(hz)
        self._next = time.perf_counter() + self._period

    def sleep(self) -> None:
        if self._client._realtime:
            wait = self._next - time.perf_counter()
            if wait > 0:
                time.sleep(wait)
            self._next = max(self._next + self._period, time.perf_counter())
        else:
            dt = self._client._sim.world.time_step
            self._client.step(max(1, int(round(self._period / dt))))


class Client:
    """AMBF's ``Client`` over an in-process simulator.

    ``Client()`` talks to the simulator given to ``use_simulator``; ``simulator=`` names one
    directly. ``realtime`` (default: that of ``use_simulator``, else False) chooses the mode."""

    def __init__(
        self,
        client_name: str = "ambf_client",
        simulator: Simulator | None = None,
        realtime: bool | None = None,
    ) -> None:
        if simulator is None:
            simulator = _default["simulator"]
        if simulator is None:
            raise ValueError(
                "Client needs the simulator it talks to: call "
                "ambfplus.ambf_client.use_simulator(sim) first, or give Client(simulator=sim), "
                "e.g. sim = ambfplus.Simulator.from_launch('launch.yaml', models=[...])"
            )
        self.name = client_name
        self._sim: Simulator = simulator
        self._lock = threading.RLock()
        self._realtime = bool(_default["realtime"] if realtime is None else realtime)
        self._thread: threading.Thread | None = None
        self._running = False
        self._throttled = threading.Event()
        self._shutdown = False
        self._handles: dict = {}
        self._initial_poses: dict = {}
        self._world_handle: WorldHandle | None = None
        self._remember_poses()

    def _remember_poses(self) -> None:
        """The bodies' poses when the client was made: what ``reset_bodies`` restores."""
        for body in self._sim.world.bodies:
            if not isinstance(getattr(body, "attached_to", None), RigidBody):
                self._initial_poses[body.id] = (body, body.pose.copy())

    # Connection: nothing to connect to in-process; connect starts the real-time thread.
    def create_objs_from_rostopics(self, publish_rate: float | None = None) -> None:
        """No-op: the objects are the simulator's, found by name on request."""

    def connect(self, default_publish_rate: float = 120) -> bool:
        """Starts the real-time thread in real-time mode; True."""
        self._shutdown = False
        self.start()
        return True

    def refresh(self) -> None:
        """Stops and restarts the client (handles are made anew)."""
        self.clean_up()
        self.connect()

    def start(self) -> None:
        """Starts the real-time thread (real-time mode only; AMBF starts its publishers)."""
        if self._realtime and self._thread is None:
            self._running = True
            self._thread = threading.Thread(target=self._run, name="ambfplus-realtime", daemon=True)
            self._thread.start()

    def clean_up(self) -> None:
        """Stops the real-time thread and forgets the handles."""
        self._running = False
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        self._handles.clear()
        self._shutdown = True

    def _run(self) -> None:
        world = self._sim.world
        start, sim_start = time.perf_counter(), world.time
        while self._running:
            if self._throttled.is_set():
                # Throttled: update() owns the clock; on release, time runs on from now.
                time.sleep(0.001)
                start, sim_start = time.perf_counter(), world.time
                continue
            behind = (time.perf_counter() - start) - (world.time - sim_start)
            if behind > 0:
                with self._lock:
                    self._sim.step(max(1, min(int(behind / world.time_step), 50)))
            else:
                time.sleep(min(-behind, 0.005))

    def step(self, n: int = 1) -> None:
        """Advances the simulation by n fixed steps (lock-step; in place of waiting for ROS)."""
        with self._lock:
            self._sim.step(n)

    # Lookup.
    def get_common_namespace(self) -> str:
        return self._sim.world.namespace

    def get_world_handle(self) -> WorldHandle:
        if self._world_handle is None:
            self._world_handle = WorldHandle(self)
        return self._world_handle

    def _keyed(self) -> dict:
        """The objects AMBF's client lists, by its keys: the namespace below /ambf/env/ and the
        name (``psm1/baselink``), the bare name in the root namespace (joints have no topic)."""
        return {o.key: o for o in self._sim.world.objects if o.kind != "joint"}

    def get_obj_names(self) -> list:
        return list(self._keyed())

    def get_obj_handle(self, a_name: str):
        """The handle of the object a name refers to, as AMBF's client finds it: a key; else the
        one key that holds the name (``psm1/base`` finds ``psm1/baselink``; several: a message
        listing them, and None); else the engine's own names (a full name ``/ambf/env/...``,
        an ADF block ``BODY l1``). None with a message when nothing matches."""
        keyed = self._keyed()
        obj = keyed.get(a_name)
        if obj is None:
            found = [key for key in keyed if a_name in key]
            if len(found) > 1:
                print(f"ambfplus.ambf_client: '{a_name}' matches {len(found)} objects "
                      f"({', '.join(found)}): name one of them")  # fmt: skip
                return None
            if found:
                obj = keyed[found[0]]
        if obj is None:
            try:
                obj = self._sim.world.get(a_name)
            except KeyError as error:
                print(f"ambfplus.ambf_client: {error.args[0]}")
                return None
        handle = self._handles.get(obj.id)
        if handle is None:
            handle = _handle_for(self, obj)
            self._handles[obj.id] = handle
        return handle

    def get_obj_pose(self, a_name: str):
        """The pose (x, y, z, roll, pitch, yaw) of the named object, or None."""
        handle = self.get_obj_handle(a_name)
        return None if handle is None else handle.get_pose()

    def set_obj_cmd(self, a_name: str, fx, fy, fz, nx, ny, nz) -> None:
        """A wrench on the named body (``wrench_command``)."""
        handle = self.get_obj_handle(a_name)
        if not isinstance(handle, ObjectHandle):
            raise KeyError(f"'{a_name}' is not a rigid body")
        handle.wrench_command(fx, fy, fz, nx, ny, nz)

    # ROS plumbing.
    def print_active_topics(self) -> None:
        """Prints the objects' names (in-process there are no topics)."""
        print(self.get_obj_names())

    def print_summary(self) -> None:
        names = self.get_obj_names()
        print(f"ambfplus client '{self.name}': {len(names)} objects")
        for name in names:
            print(name)

    def set_publish_rate(self, rate: float) -> None:
        """No-op: there is no publisher; commands act at once."""

    def is_shutdown(self) -> bool:
        """True after clean_up (AMBF: whether ROS shut down)."""
        return self._shutdown

    def get_time(self) -> float:
        """Wall-clock seconds, as ROS's clock gives them without simulated time."""
        return time.time()

    def create_rate(self, rate: float) -> Rate:
        return Rate(self, rate)

    def get_ral(self):
        raise NotImplementedError(
            "get_ral: ambfplus's client has no ROS abstraction layer (there is no ROS in-process)"
        )


class WorldHandle:
    """AMBF's world handle: stepping, time and reset."""

    def __init__(self, client: Client) -> None:
        self._client = client
        self._skips = 1
        self._name = "World"

    # WatchDog (ROS command expiry): nothing expires in-process.
    def acknowledge_wd(self) -> None:
        """No-op."""

    def is_wd_expired(self) -> bool:
        return False

    def console_print(self, class_name: str) -> None:
        """No-op."""

    def set_active(self) -> None:
        """No-op: every handle is live."""

    def is_active(self) -> bool:
        return True

    def ros_cb(self, data) -> None:
        """No-op: the state is read from the engine."""

    def run_publisher(self) -> None:
        """No-op: commands act at once."""

    def clear_cmd(self) -> None:
        """Ends throttling (what AMBF's watchdog does when the client goes quiet)."""
        self.enable_throttling(False)

    def enable_throttling(self, data: bool) -> None:
        """Real-time mode: True pauses the thread and lets update() step; False resumes it.
        Lock-step mode: nothing to do (the script already owns the clock)."""
        if data:
            self._client._throttled.set()
        else:
            self._client._throttled.clear()

    def set_num_step_skips(self, n: int) -> None:
        if n <= 0 or n > 100:
            raise ValueError(f"set_num_step_skips: n is 1 to 100, not {n!r}")
        self._skips = int(n)

    def update(self) -> None:
        """Steps the simulation n_skip_steps steps, except in real-time mode while not throttled
        (there the thread keeps time, as AMBF's free-running simulator does)."""
        client = self._client
        if client._realtime and client._thread is not None and not client._throttled.is_set():
            return
        client.step(self._skips)

    def set_name(self, name: str) -> None:
        self._name = name

    def get_name(self) -> str:
        return self._name

    def reset(self) -> None:
        """Resets the bodies, the volumes' removed voxels and the plugins (time runs on)."""
        world = self._client._sim.world
        with self._client._lock:
            self._reset_bodies()
            for volume in world.volumes:
                volume.reset()
            world.reset_plugins()

    def reset_bodies(self) -> None:
        """Puts every body back at its pose when the client was made, at rest."""
        with self._client._lock:
            self._reset_bodies()

    def _reset_bodies(self) -> None:
        for body, pose in self._client._initial_poses.values():
            body.pose = pose
            if body.dynamic:
                body.linear_velocity = (0.0, 0.0, 0.0)
                body.angular_velocity = (0.0, 0.0, 0.0)

    # Extensions (not in AMBF's world handle).
    def get_sim_time(self) -> float:
        return self._client._sim.world.time

    def get_sim_step(self) -> int:
        return self._client._sim.world.step_index


class GenericHandle:
    """AMBF's ``BaseObject``: name, pose and the state header of any object."""

    def __init__(self, client: Client, obj) -> None:
        self._client = client
        self._obj = obj
        self._name = obj.qualified_name or obj.name
        self._pose_cmd: np.ndarray | None = None

    # WatchDog and ROS plumbing: nothing to do in-process.
    def acknowledge_wd(self) -> None:
        """No-op."""

    def is_wd_expired(self) -> bool:
        return False

    def console_print(self, class_name: str) -> None:
        """No-op."""

    def ros_cb(self, data) -> None:
        """No-op: the state is read from the engine."""

    def run_publisher(self) -> None:
        """No-op: commands act at once."""

    def set_active(self) -> None:
        """No-op: every handle is live."""

    def is_active(self) -> bool:
        return True

    # State.
    def get_name(self) -> str:
        return self._name

    def set_name(self, name: str) -> None:
        """Renames the handle (as in AMBF, the object keeps its name)."""
        self._name = name

    def get_identifier(self) -> str:
        return self._obj.identifier or self._obj.name

    def get_sim_step(self) -> int:
        return self._client._sim.world.step_index

    def _parent(self):
        attached = getattr(self._obj, "attached_to", None)
        if attached is not None and hasattr(attached, "pose"):
            return attached
        for joint in self._client._sim.world.joints:
            if joint.child is self._obj:
                return joint.parent
        return None

    def get_parent_name(self) -> str:
        parent = self._parent()
        return "" if parent is None else parent.name

    def _children(self) -> list:
        return []

    def get_children_names(self) -> list:
        return [c.name for c in self._children()]

    def get_num_of_children(self) -> int:
        return len(self._children())

    def get_pos(self) -> Point:
        return Point(*(float(v) for v in self._obj.pose[:3, 3]))

    def get_rot(self) -> Quaternion:
        return _quaternion(self._obj.pose[:3, :3])

    def get_rpy(self) -> list:
        return _rpy(self._obj.pose[:3, :3])

    def get_pose(self) -> list:
        """[x, y, z, roll, pitch, yaw] in the world frame."""
        pose = self._obj.pose
        return [float(v) for v in pose[:3, 3]] + _rpy(pose[:3, :3])

    def get_pos_command(self) -> Point:
        pose = self._obj.pose if self._pose_cmd is None else self._pose_cmd
        return Point(*(float(v) for v in pose[:3, 3]))

    def get_rot_command(self) -> Quaternion:
        pose = self._obj.pose if self._pose_cmd is None else self._pose_cmd
        return _quaternion(pose[:3, :3])

    def get_msg_header(self) -> Header:
        world = self._client._sim.world
        return Header(world.step_index, world.time, self.get_parent_name() or world.name)

    def get_msg_time_stamp(self) -> float:
        return self.get_msg_header().stamp

    def get_msg_seq_num(self) -> int:
        return self.get_msg_header().seq

    def get_msg_frame_id(self) -> str:
        return self.get_msg_header().frame_id

    # Placing the object.
    def _commanded(self) -> np.ndarray:
        return (self._obj.pose if self._pose_cmd is None else self._pose_cmd).copy()

    def set_pos(self, px: float, py: float, pz: float) -> None:
        pose = self._commanded()
        pose[:3, 3] = (px, py, pz)
        self.set_pose(pose)

    def set_rpy(self, roll: float, pitch: float, yaw: float) -> None:
        pose = self._commanded()
        pose[:3, :3] = rpy_matrix((roll, pitch, yaw))
        self.set_pose(pose)

    def set_rot(self, quat) -> None:
        """Orientation from a quaternion (x, y, z, w)."""
        pose = self._commanded()
        pose[:3, :3] = _rotation(quat)
        self.set_pose(pose)

    def set_pose(self, pose) -> None:
        """Places the object at a Pose (position, orientation quaternion) or a 4x4 pose."""
        matrix = _matrix(pose)
        with self._client._lock:
            self._place(matrix)
        self._pose_cmd = matrix

    def _place(self, pose: np.ndarray) -> None:
        self._obj.pose = pose


class ObjectHandle(GenericHandle):
    """AMBF's ``RigidBody`` (and the older ``Object``): a body, with the joints below it in
    AMBF's order."""

    def __init__(self, client: Client, body: RigidBody) -> None:
        super().__init__(client, body)
        self._body = body
        self._wrench = Wrench()
        self._twist_cmd: Twist | None = None
        self._publish = {"children": True, "joint_names": True, "joint_positions": True}

    def _place(self, pose: np.ndarray) -> None:
        self._body.pose = pose
        self._body.linear_velocity = (0.0, 0.0, 0.0)
        self._body.angular_velocity = (0.0, 0.0, 0.0)

    def _children(self) -> list:
        return [j.child for j in self._joints()]

    # Motion.
    def get_linear_vel(self) -> Point:
        return Point(*(float(v) for v in self._body.linear_velocity))

    def get_angular_vel(self) -> Point:
        return Point(*(float(v) for v in self._body.angular_velocity))

    def get_inertia(self) -> Vector3:
        return Vector3(*(float(v) for v in self._body.inertia))

    def get_mass(self) -> float:
        return self._body.mass

    def set_force(self, fx: float, fy: float, fz: float) -> None:
        self.set_wrench(Wrench(Vector3(fx, fy, fz), self._wrench.torque))

    def set_torque(self, nx: float, ny: float, nz: float) -> None:
        self.set_wrench(Wrench(self._wrench.force, Vector3(nx, ny, nz)))

    def set_wrench(self, wrench, torque=None) -> None:
        """A Wrench (force, torque), or a force and a torque, in the world frame."""
        if torque is not None:
            wrench = Wrench(Vector3(*_vector(wrench)), Vector3(*_vector(torque)))
        force, moment = _vector(wrench.force), _vector(wrench.torque)
        with self._client._lock:
            self._body.force = force
            self._body.torque = moment
        self._wrench = Wrench(Vector3(*force), Vector3(*moment))

    def wrench_command(self, fx, fy, fz, nx, ny, nz) -> None:
        self.set_wrench(Wrench(Vector3(fx, fy, fz), Vector3(nx, ny, nz)))

    def get_force_command(self) -> Vector3:
        return self._wrench.force

    def get_torque_command(self) -> Vector3:
        return self._wrench.torque

    def set_linear_vel(self, vx: float, vy: float, vz: float) -> None:
        self.set_twist(Twist(Vector3(vx, vy, vz), self.get_angular_velocity_command()))

    def set_angular_vel(self, ax: float, ay: float, az: float) -> None:
        self.set_twist(Twist(self.get_linear_velocity_command(), Vector3(ax, ay, az)))

    def set_twist(self, twist) -> None:
        """Sets the body's linear and angular velocity (world frame) now."""
        linear, angular = _vector(twist.linear), _vector(twist.angular)
        with self._client._lock:
            self._body.linear_velocity = linear
            self._body.angular_velocity = angular
        self._twist_cmd = Twist(Vector3(*linear), Vector3(*angular))

    def velocity_command(self, vx, vy, vz, ax, ay, az) -> None:
        self.set_twist(Twist(Vector3(vx, vy, vz), Vector3(ax, ay, az)))

    def get_linear_velocity_command(self) -> Vector3:
        return self.get_linear_vel() if self._twist_cmd is None else self._twist_cmd.linear

    def get_angular_velocity_command(self) -> Vector3:
        return self.get_angular_vel() if self._twist_cmd is None else self._twist_cmd.angular

    def pose_command(self, px, py, pz, roll, pitch, yaw, *jnt_cmds) -> None:
        """Places the body; the angles compose as AMBF's command does (R = Rx(yaw) Ry(pitch)
        Rz(roll)); joint commands are ignored, as AMBF's rigid body ignores them."""
        pose = np.eye(4)
        pose[:3, :3] = (
            rpy_matrix((yaw, 0.0, 0.0))
            @ rpy_matrix((0.0, pitch, 0.0))
            @ rpy_matrix((0.0, 0.0, roll))
        )
        pose[:3, 3] = (px, py, pz)
        self.set_pose(pose)

    # What AMBF's state messages carry: always all of it in-process.
    def get_publish_children_name_flag(self) -> bool:
        return self._publish["children"]

    def get_publish_joint_names_flag(self) -> bool:
        return self._publish["joint_names"]

    def get_publish_joint_positions_flag(self) -> bool:
        return self._publish["joint_positions"]

    def set_publish_children_names_flag(self, state: bool) -> None:
        """Kept, with no effect: children names are always available."""
        self._publish["children"] = bool(state)

    def set_publish_joint_names_flag(self, state: bool) -> None:
        """Kept, with no effect: joint names are always available."""
        self._publish["joint_names"] = bool(state)

    def set_publish_joint_positions_flag(self, state: bool) -> None:
        """Kept, with no effect: joint positions are always available."""
        self._publish["joint_positions"] = bool(state)

    # Joints, by index (AMBF's order) or by name.
    def _joints(self) -> list:
        return self._body.joints

    def _joint(self, ref: JointRef) -> Joint:
        joints = self._joints()
        if isinstance(ref, str):
            for j in joints:
                if j.name == ref:
                    return j
            raise KeyError(
                f"{self._body.name} has no joint named '{ref}'; its joints: "
                f"{[j.name for j in joints]}"
            )
        if not 0 <= ref < len(joints):
            raise IndexError(
                f"{self._body.name} has {len(joints)} joints; index {ref} is out of range"
            )
        return joints[ref]

    def is_joint_idx_valid(self, joint_idx: int) -> bool:
        return isinstance(joint_idx, int) and 0 <= joint_idx < len(self._joints())

    def get_joint_idx_from_name(self, joint_name: str):
        """The joint's index, or None."""
        names = self.get_joint_names()
        return names.index(joint_name) if joint_name in names else None

    def get_joint_name_from_idx(self, joint_idx: int):
        """The joint's name, or None."""
        return self._joints()[joint_idx].name if self.is_joint_idx_valid(joint_idx) else None

    def get_num_joints(self) -> int:
        return len(self._joints())

    def get_joint_names(self) -> list:
        return [j.name for j in self._joints()]

    def resize_joint_cmd_array(self, req_len: int) -> bool:
        """Whether the body has that many joints (there is no command array to size)."""
        return req_len <= len(self._joints())

    def set_joint_pos(self, joint_name_or_idx: JointRef, p: float) -> None:
        with self._client._lock:
            self._joint(joint_name_or_idx).set_position(float(p))

    def set_joint_vel(self, joint_name_or_idx: JointRef, v: float) -> None:
        with self._client._lock:
            self._joint(joint_name_or_idx).set_velocity(float(v))

    def set_joint_effort(self, joint_name_or_idx: JointRef, f: float) -> None:
        with self._client._lock:
            self._joint(joint_name_or_idx).set_effort(float(f))

    def _pairs(self, values, index_list) -> list:
        """(joint index, value) pairs: index_list[i] gets values[i]; an empty or mismatched
        index_list means values for joints 0, 1, ..."""
        values = list(values)
        indices = list(index_list or [])
        if not indices or len(indices) != len(values):
            indices = list(range(len(values)))
        return list(zip(indices, values))

    def set_multiple_joint_pos(self, p_list, index_list) -> None:
        for idx, p in self._pairs(p_list, index_list):
            self.set_joint_pos(idx, p)

    def set_multiple_joint_vel(self, v_list, index_list) -> None:
        for idx, v in self._pairs(v_list, index_list):
            self.set_joint_vel(idx, v)

    def set_multiple_joint_effort(self, f_list, index_list) -> None:
        for idx, f in self._pairs(f_list, index_list):
            self.set_joint_effort(idx, f)

    def get_joint_pos(self, joint_name_or_idx: JointRef) -> float:
        return self._joint(joint_name_or_idx).position

    def get_joint_vel(self, joint_name_or_idx: JointRef) -> float:
        return self._joint(joint_name_or_idx).velocity

    def get_joint_effort(self, joint_name_or_idx: JointRef) -> float:
        return self._joint(joint_name_or_idx).effort

    def get_all_joint_pos(self) -> list:
        return [j.position for j in self._joints()]

    def get_all_joint_vel(self) -> list:
        return [j.velocity for j in self._joints()]

    def get_all_joint_effort(self) -> list:
        return [j.effort for j in self._joints()]


class GhostHandle(GenericHandle):
    """A ghost object: a body that collides with nothing and senses what overlaps it."""

    def get_sensed_objects(self) -> list:
        """The names of the bodies overlapping the ghost after the last step."""
        return [b.name for b in self._obj.overlapping]


class CameraHandle(GenericHandle):
    """AMBF's ``Camera``: the base object's names (render with ambfplus's capture)."""


class LightHandle(GenericHandle):
    """AMBF's ``Light``: the base object's names."""


class SensorHandle(GenericHandle):
    """AMBF's ``Sensor`` over a proximity sensor: one element per ray."""

    def _sensor(self) -> ProximitySensor:
        return self._obj

    def _hit(self, idx: int) -> dict:
        hits = self._sensor().hits
        if not 0 <= idx < len(hits):
            raise IndexError(f"{self._obj.name} has {len(hits)} rays; index {idx} is out of range")
        return hits[idx]

    def get_count(self) -> int:
        return self._sensor().ray_count

    def is_triggered(self, idx: int) -> bool:
        return bool(self._hit(idx)["triggered"])

    def get_range(self, idx: int) -> float:
        self._hit(idx)
        return self._sensor().range

    def get_measurement(self, idx: int) -> float:
        """How near the hit is, normalised: 1 at the ray's start, 0 at its end or on a miss."""
        hit = self._hit(idx)
        return 1.0 - float(hit["fraction"]) if hit["triggered"] else 0.0

    def get_all_measurements(self) -> list:
        return [self.get_measurement(i) for i in range(self.get_count())]

    def get_sensed_object(self, idx: int) -> str:
        """The name of the body the ray hits, or ''."""
        body = self._hit(idx)["body"]
        return "" if body is None else body.name

    def get_parent(self) -> str:
        return self._sensor().parent.name

    def get_pose(self) -> Pose:  # type: ignore[override]
        """The sensor's world pose as a Pose (AMBF's sensor returns the message itself)."""
        pose = self._obj.pose
        return Pose(Point(*(float(v) for v in pose[:3, 3])), _quaternion(pose[:3, :3]))


class ActuatorHandle(GenericHandle):
    """AMBF's ``Actuator`` over a constraint actuator (a grasp)."""

    def _actuator(self) -> ConstraintActuator:
        return self._obj

    def actuate(self, obj_name: str, pose=None) -> None:
        """Holds the named body: where it is now, or with the actuator at pose (a Pose or 4x4)
        in the body's frame."""
        body = self._client._sim.world.get(obj_name)
        if not isinstance(body, RigidBody):
            raise KeyError(f"actuate: '{obj_name}' is not a rigid body")
        with self._client._lock:
            self._actuator().actuate(body, None if pose is None else _matrix(pose))

    def actuate_from_sensor_data(self, sensor_identifer: str) -> None:
        """Holds what the named sensor (the nearest triggered ray's body) or ghost senses, other
        than the actuator's own body; does nothing when it senses nothing else."""
        sensor = self._client._sim.world.get(sensor_identifer)
        holder = self._actuator().parent

        def graspable(body) -> bool:
            return isinstance(body, RigidBody) and body is not holder

        body = None
        if isinstance(sensor, ProximitySensor):
            hits = sorted(
                (h for h in sensor.hits if h["triggered"] and graspable(h["body"])),
                key=lambda h: h["distance"],
            )
            body = hits[0]["body"] if hits else None
        elif isinstance(sensor, RigidBody) and sensor.is_ghost:
            overlapping = [b for b in sensor.overlapping if graspable(b)]
            body = overlapping[0] if overlapping else None
        else:
            raise KeyError(f"actuate_from_sensor_data: '{sensor_identifer}' is not a sensor")
        if body is not None:
            with self._client._lock:
                self._actuator().actuate(body)

    def deactuate(self) -> None:
        with self._client._lock:
            self._actuator().deactuate()


_NO_VEHICLES = (
    "ambfplus has no vehicles: AMBF's VEHICLE blocks (wheeled bodies with raycast suspension) "
    "are not loaded"
)


class VehicleHandle(GenericHandle):
    """AMBF's ``Vehicle``: kept so that the names exist; the engine has no vehicles."""

    def _not_applied(self, name: str):
        raise NotImplementedError(f"{name}: {_NO_VEHICLES}")

    def get_wheel_count(self) -> int:
        return self._not_applied("get_wheel_count")

    def check_wheel_count(self, idx: int) -> bool:
        return self._not_applied("check_wheel_count")

    def initialize_wheel_cmds(self) -> None:
        self._not_applied("initialize_wheel_cmds")

    def set_steered_wheel_indices(self, indices) -> None:
        self._not_applied("set_steered_wheel_indices")

    def set_powered_wheel_indices(self, indices) -> None:
        self._not_applied("set_powered_wheel_indices")

    def set_vehicle_steering(self, val: float) -> None:
        self._not_applied("set_vehicle_steering")

    def set_vehicle_steering_ackerman(self, val: float) -> None:
        self._not_applied("set_vehicle_steering_ackerman")

    def set_vehicle_power(self, val: float) -> None:
        self._not_applied("set_vehicle_power")

    def set_vehicle_brake(self, val: float) -> None:
        self._not_applied("set_vehicle_brake")

    def set_wheel_steering(self, idx: int, val: float) -> None:
        self._not_applied("set_wheel_steering")

    def set_wheel_power(self, idx: int, val: float) -> None:
        self._not_applied("set_wheel_power")

    def set_wheel_brake(self, idx: int, val: float) -> None:
        self._not_applied("set_wheel_brake")


def _handle_for(client: Client, obj) -> GenericHandle:
    if isinstance(obj, RigidBody):
        return GhostHandle(client, obj) if obj.is_ghost else ObjectHandle(client, obj)
    kinds = {
        "camera": CameraHandle,
        "light": LightHandle,
        "sensor": SensorHandle,
        "actuator": ActuatorHandle,
    }
    if obj.kind == "sensor" and not isinstance(obj, ProximitySensor):
        return GenericHandle(client, obj)
    return kinds.get(obj.kind, GenericHandle)(client, obj)


# The audit: every public method of AMBF's client types (its Python client, ambf_client/python,
# and the older ambf_comm scripts), keyed "<AMBF type>.<method>", with what ambfplus does:
# implemented, no-op (ROS plumbing with nothing to do in-process), not applied (raises
# NotImplementedError saying why), or extension (ambfplus's own, not in AMBF's client).
# A type's handle has its own methods and those of its AMBF base types (AMBF_BASES).
_I, _N, _X, _E = "implemented", "no-op", "not applied", "extension"
_ROS = "ROS plumbing: nothing to do in-process"

AMBF_BASES = {
    "Client": (),
    "World": ("WatchDog",),
    "BaseObject": ("WatchDog",),
    "RigidBody": ("BaseObject", "WatchDog"),
    "GhostObject": ("BaseObject", "WatchDog"),
    "Camera": ("BaseObject", "WatchDog"),
    "Light": ("BaseObject", "WatchDog"),
    "Sensor": ("BaseObject", "WatchDog"),
    "Actuator": ("BaseObject", "WatchDog"),
    "Vehicle": ("BaseObject", "WatchDog"),
}

# The handle class that stands for each AMBF type (WatchDog is only ever a base).
HANDLES = {
    "Client": Client,
    "World": WorldHandle,
    "BaseObject": GenericHandle,
    "RigidBody": ObjectHandle,
    "GhostObject": GhostHandle,
    "Camera": CameraHandle,
    "Light": LightHandle,
    "Sensor": SensorHandle,
    "Actuator": ActuatorHandle,
    "Vehicle": VehicleHandle,
}

COVERAGE: dict = {
    # Client
    "Client.create_objs_from_rostopics": (_N, "objects are the simulator's, found on request"),
    "Client.connect": (_I, "starts the real-time thread in real-time mode"),
    "Client.refresh": (_I, "clean_up, then connect"),
    "Client.start": (_I, "starts the real-time thread (AMBF: its publishers)"),
    "Client.get_common_namespace": (_I, "the world's namespace"),
    "Client.get_world_handle": (_I, ""),
    "Client.get_obj_names": (_I, "AMBF's keys: namespace below /ambf/env/ + name, no joints"),
    "Client.get_obj_handle": (
        _I,
        "AMBF's lookup: a key, else the one key holding the name (several: a message, None), "
        "else a full name or ADF block",
    ),
    "Client.get_obj_pose": (_I, "the handle's get_pose (AMBF's returns an absent attribute)"),
    "Client.set_obj_cmd": (_I, "wrench_command on the named body"),
    "Client.print_active_topics": (_I, "prints the object names (there are no topics)"),
    "Client.print_summary": (_I, ""),
    "Client.clean_up": (_I, "stops the real-time thread"),
    "Client.set_publish_rate": (_N, "no publisher: commands act at once"),
    "Client.is_shutdown": (_I, "True after clean_up"),
    "Client.get_time": (_I, "wall-clock seconds, as ROS's clock without simulated time"),
    "Client.create_rate": (_I, "real time: sleeps; lock-step: steps one period"),
    "Client.get_ral": (_X, "no ROS abstraction layer in-process"),
    "Client.step": (_E, "lock-step: advance n steps"),
    # WatchDog (base of the world and of every object)
    "WatchDog.acknowledge_wd": (_N, "commands do not expire in-process"),
    "WatchDog.is_wd_expired": (_N, "always False"),
    "WatchDog.console_print": (_N, _ROS),
    # World
    "World.set_active": (_N, _ROS),
    "World.is_active": (_N, "always True"),
    "World.ros_cb": (_N, _ROS),
    "World.run_publisher": (_N, _ROS),
    "World.enable_throttling": (_I, "real time: pauses the thread, update() steps"),
    "World.set_num_step_skips": (_I, "steps per update(), 1 to 100"),
    "World.update": (_I, "steps n skip steps (not while the real-time thread runs free)"),
    "World.clear_cmd": (_I, "ends throttling"),
    "World.set_name": (_I, ""),
    "World.get_name": (_I, ""),
    "World.reset": (_I, "bodies, volumes and plugins reset; time runs on"),
    "World.reset_bodies": (_I, "poses when the client was made, at rest"),
    "World.get_sim_time": (_E, "simulation time (s)"),
    "World.get_sim_step": (_E, "step index"),
    # BaseObject (base of every object)
    "BaseObject.ros_cb": (_N, _ROS),
    "BaseObject.run_publisher": (_N, _ROS),
    "BaseObject.set_active": (_N, _ROS),
    "BaseObject.is_active": (_N, "always True"),
    "BaseObject.get_sim_step": (_I, "the world's step index"),
    "BaseObject.get_num_of_children": (_I, "bodies below a body's joints; 0 for others"),
    "BaseObject.get_children_names": (_I, "bodies below a body's joints; [] for others"),
    "BaseObject.get_pos": (_I, "world frame"),
    "BaseObject.get_rot": (_I, "quaternion (x, y, z, w), world frame"),
    "BaseObject.get_rpy": (_I, "fixed-axis roll, pitch, yaw"),
    "BaseObject.get_pose": (_I, "[x, y, z, roll, pitch, yaw]"),
    "BaseObject.get_pos_command": (_I, "last set_pos/set_pose, else the state"),
    "BaseObject.get_rot_command": (_I, "last set_rpy/set_rot/set_pose, else the state"),
    "BaseObject.get_identifier": (_I, "the ADF block ('BODY l1'), else the name"),
    "BaseObject.get_name": (_I, "the qualified name"),
    "BaseObject.get_parent_name": (_I, "the object it rides on, or a body's parent joint's"),
    "BaseObject.get_msg_header": (_I, "stamp: simulation time; seq: step index"),
    "BaseObject.get_msg_time_stamp": (_I, "simulation time (s)"),
    "BaseObject.get_msg_seq_num": (_I, "step index"),
    "BaseObject.get_msg_frame_id": (_I, "the parent's name, else the world's"),
    "BaseObject.set_name": (_I, "renames the handle only, as in AMBF"),
    "BaseObject.set_pos": (_I, "placed directly (AMBF: its controller drives it there)"),
    "BaseObject.set_rpy": (_I, "placed directly"),
    "BaseObject.set_rot": (_I, "quaternion (x, y, z, w); placed directly"),
    "BaseObject.set_pose": (_I, "a Pose or a 4x4; placed directly"),
    # RigidBody (and ambf_comm's older Object, whose methods are a subset of these)
    "RigidBody.is_joint_idx_valid": (_I, ""),
    "RigidBody.get_linear_vel": (_I, "world frame"),
    "RigidBody.get_angular_vel": (_I, "world frame"),
    "RigidBody.get_joint_idx_from_name": (_I, "None when absent"),
    "RigidBody.get_joint_name_from_idx": (_I, "None when out of range"),
    "RigidBody.get_joint_pos": (_I, "index or name; raises on a bad one"),
    "RigidBody.get_joint_vel": (_I, "index or name"),
    "RigidBody.get_joint_effort": (_I, "index or name"),
    "RigidBody.get_all_joint_pos": (_I, "AMBF's joint order"),
    "RigidBody.get_all_joint_vel": (_I, ""),
    "RigidBody.get_all_joint_effort": (_I, ""),
    "RigidBody.get_num_joints": (_I, ""),
    "RigidBody.get_joint_names": (_I, ""),
    "RigidBody.get_force_command": (_I, "last commanded force"),
    "RigidBody.get_torque_command": (_I, "last commanded torque"),
    "RigidBody.get_linear_velocity_command": (_I, "last commanded, else the state"),
    "RigidBody.get_angular_velocity_command": (_I, "last commanded, else the state"),
    "RigidBody.get_publish_children_name_flag": (_N, "everything is always available"),
    "RigidBody.get_publish_joint_names_flag": (_N, "everything is always available"),
    "RigidBody.get_publish_joint_positions_flag": (_N, "everything is always available"),
    "RigidBody.set_publish_children_names_flag": (_N, "everything is always available"),
    "RigidBody.set_publish_joint_names_flag": (_N, "everything is always available"),
    "RigidBody.set_publish_joint_positions_flag": (_N, "everything is always available"),
    "RigidBody.get_inertia": (_I, "principal inertia (Vector3)"),
    "RigidBody.set_force": (_I, "world frame; keeps the last torque"),
    "RigidBody.set_torque": (_I, "world frame; keeps the last force"),
    "RigidBody.set_wrench": (_I, "a Wrench, or a force and a torque"),
    "RigidBody.wrench_command": (_I, ""),
    "RigidBody.set_linear_vel": (_I, "sets the velocity now (AMBF: its controller)"),
    "RigidBody.set_angular_vel": (_I, "sets the velocity now"),
    "RigidBody.set_twist": (_I, "sets the velocities now"),
    "RigidBody.velocity_command": (_I, "sets the velocities now"),
    "RigidBody.pose_command": (_I, "AMBF's angle order; joint commands ignored, as in AMBF"),
    "RigidBody.resize_joint_cmd_array": (_N, "no command array; True when the joints exist"),
    "RigidBody.set_joint_pos": (_I, "the joint's position controller"),
    "RigidBody.set_multiple_joint_pos": (_I, "index_list[i] gets p_list[i]"),
    "RigidBody.set_joint_vel": (_I, "the joint's velocity command"),
    "RigidBody.set_multiple_joint_vel": (_I, "index_list[i] gets v_list[i]"),
    "RigidBody.set_joint_effort": (_I, "the joint's effort"),
    "RigidBody.set_multiple_joint_effort": (_I, "index_list[i] gets f_list[i]"),
    "RigidBody.get_mass": (_E, "kg"),
    # GhostObject (AMBF 2's ghost client was not available to audit: base names plus this)
    "GhostObject.get_sensed_objects": (_E, "names of the bodies overlapping it"),
    # Camera, Light: the base object's names only (AMBF's types add none).
    # Sensor
    "Sensor.get_count": (_I, "rays"),
    "Sensor.is_triggered": (_I, "per ray"),
    "Sensor.get_range": (_I, "the sensor's range (m)"),
    "Sensor.get_measurement": (_I, "1 - hit fraction; 0 on a miss"),
    "Sensor.get_all_measurements": (_I, ""),
    "Sensor.get_sensed_object": (_I, "the hit body's name, or ''"),
    "Sensor.get_parent": (_I, "the parent body's name"),
    "Sensor.get_pose": (_I, "a Pose (AMBF's sensor returns the message)"),
    # Actuator
    "Actuator.actuate": (_I, "holds the named body; pose: offset in its frame"),
    "Actuator.actuate_from_sensor_data": (_I, "what a proximity sensor or ghost senses"),
    "Actuator.deactuate": (_I, ""),
    # Vehicle
    "Vehicle.get_wheel_count": (_X, _NO_VEHICLES),
    "Vehicle.check_wheel_count": (_X, _NO_VEHICLES),
    "Vehicle.set_steered_wheel_indices": (_X, _NO_VEHICLES),
    "Vehicle.initialize_wheel_cmds": (_X, _NO_VEHICLES),
    "Vehicle.set_powered_wheel_indices": (_X, _NO_VEHICLES),
    "Vehicle.set_vehicle_steering": (_X, _NO_VEHICLES),
    "Vehicle.set_vehicle_steering_ackerman": (_X, _NO_VEHICLES),
    "Vehicle.set_vehicle_power": (_X, _NO_VEHICLES),
    "Vehicle.set_vehicle_brake": (_X, _NO_VEHICLES),
    "Vehicle.set_wheel_steering": (_X, _NO_VEHICLES),
    "Vehicle.set_wheel_power": (_X, _NO_VEHICLES),
    "Vehicle.set_wheel_brake": (_X, _NO_VEHICLES),
}


def public_methods(cls: type) -> set:
    """The public methods of a handle class (its own and inherited)."""
    return {name for name in dir(cls) if not name.startswith("_") and callable(getattr(cls, name))}


def expected_methods(ambf_type: str) -> set:
    """The methods COVERAGE gives the handle of an AMBF type (its own and its bases')."""
    types_ = (ambf_type, *AMBF_BASES[ambf_type])
    return {key.split(".", 1)[1] for key in COVERAGE if key.split(".", 1)[0] in types_}


def coverage_markdown() -> str:
    """The coverage table as Markdown (docs/reference/ambf-client.md holds this text)."""
    lines = ["| AMBF method | ambfplus | note |", "|---|---|---|"]
    for key, (status, note) in COVERAGE.items():
        lines.append(f"| `{key}` | {status} | {note} |")
    counts = {s: sum(1 for v in COVERAGE.values() if v[0] == s) for s in (_I, _N, _X, _E)}
    lines.append("")
    lines.append(
        f"{len(COVERAGE)} methods: {counts[_I]} implemented, {counts[_N]} no-op, "
        f"{counts[_X]} not applied, {counts[_E]} ambfplus extensions."
    )
    return "\n".join(lines) + "\n"
