"""The names of AMBF's Python client (``ambf_client``), in-process and without ROS.

Scripts written for AMBF's client port by changing the import::

    from ambfplus.ambf_client import Client          # was: from ambf_client import Client

    sim = ambfplus.Simulator.from_launch("launch.yaml", models=[12])
    client = Client(simulator=sim)                     # was: Client()
    client.connect()
    base = client.get_obj_handle("Mold_A")
    base.set_joint_pos(0, 0.5)                        # by index (AMBF's order) or by name
    client.step(1000)                                 # or Client(..., realtime=True) + time.sleep

Differences from AMBF, by design: commands act at once, not at the next ROS message; time passes
only when the simulation steps (``client.step``, ``WorldHandle.update`` or a real-time thread
started with ``realtime=True``); ``set_pos``/``set_rpy`` place a body directly (AMBF drives it
there with the body's controller) and zero its velocity.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Union

import numpy as np

from ._core import Joint, RigidBody, Simulator
from .transforms import rpy_matrix

JointRef = Union[int, str]


@dataclass
class Point:
    """geometry_msgs/Point's fields."""

    x: float
    y: float
    z: float


def _rpy(rotation: np.ndarray) -> list:
    """Fixed-axis roll, pitch, yaw of a rotation (R = Rz(y) Ry(p) Rx(r))."""
    pitch = float(np.arcsin(np.clip(-rotation[2, 0], -1.0, 1.0)))
    roll = float(np.arctan2(rotation[2, 1], rotation[2, 2]))
    yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
    return [roll, pitch, yaw]


class Client:
    """AMBF's ``Client`` over an in-process simulator."""

    def __init__(
        self,
        client_name: str = "ambf_client",
        simulator: Simulator | None = None,
        realtime: bool = False,
    ) -> None:
        if simulator is None:
            raise ValueError(
                "Client needs the simulator it talks to: Client(simulator=sim), e.g. "
                "sim = ambfplus.Simulator.from_launch('launch.yaml', models=[...])"
            )
        self.name = client_name
        self._sim = simulator
        self._lock = threading.Lock()
        self._realtime = realtime
        self._thread: threading.Thread | None = None
        self._running = False

    # Connection (nothing to connect to in-process).
    def connect(self) -> bool:
        if self._realtime and self._thread is None:
            self._running = True
            self._thread = threading.Thread(target=self._run, name="ambfplus-realtime", daemon=True)
            self._thread.start()
        return True

    def create_objs_from_rostopics(self) -> None:
        pass

    def clean_up(self) -> None:
        self._running = False
        if self._thread is not None:
            self._thread.join()
            self._thread = None

    def _run(self) -> None:
        world = self._sim.world
        start = time.perf_counter()
        sim_start = world.time
        while self._running:
            behind = (time.perf_counter() - start) - (world.time - sim_start)
            if behind > 0:
                with self._lock:
                    self._sim.step(max(1, min(int(behind / world.time_step), 50)))
            else:
                time.sleep(min(-behind, 0.005))

    def step(self, n: int = 1) -> None:
        """Advances the simulation by n fixed steps (in place of waiting for ROS)."""
        with self._lock:
            self._sim.step(n)

    # Lookup.
    def get_obj_names(self) -> list:
        return [o.qualified_name or o.name for o in self._sim.world.objects]

    def get_obj_handle(self, name: str):
        """The handle of the object a name refers to (AMBF's lookup), or None with a message."""
        try:
            obj = self._sim.world.get(name)
        except KeyError as error:
            print(f"ambfplus.ambf_client: {error.args[0]}")
            return None
        if isinstance(obj, RigidBody):
            return ObjectHandle(self, obj)
        return GenericHandle(self, obj)

    def get_world_handle(self) -> WorldHandle:
        return WorldHandle(self)


class WorldHandle:
    """AMBF's world handle: stepping and time."""

    def __init__(self, client: Client) -> None:
        self._client = client
        self._skips = 1

    def enable_throttling(self, enable: bool) -> None:
        pass  # in-process the script always decides when time passes

    def set_num_step_skips(self, n: int) -> None:
        self._skips = max(1, int(n))

    def update(self) -> None:
        self._client.step(self._skips)

    def get_sim_time(self) -> float:
        return self._client._sim.world.time

    def reset_bodies(self) -> None:
        raise NotImplementedError("resetting bodies comes with the simulator's reset")


class GenericHandle:
    """A non-body object (camera, light, joint, ...): name and pose."""

    def __init__(self, client: Client, obj) -> None:
        self._client = client
        self._obj = obj

    def get_name(self) -> str:
        return self._obj.name

    def get_pos(self) -> Point:
        return Point(*(float(v) for v in self._obj.pose[:3, 3]))

    def get_rpy(self) -> list:
        return _rpy(self._obj.pose[:3, :3])

    def get_pose(self) -> np.ndarray:
        return self._obj.pose


class ObjectHandle(GenericHandle):
    """A rigid body, with the joints below it in AMBF's order."""

    def __init__(self, client: Client, body: RigidBody) -> None:
        super().__init__(client, body)
        self._body = body

    # Pose and motion.
    def set_pos(self, x: float, y: float, z: float) -> None:
        with self._client._lock:
            pose = self._body.pose
            pose[:3, 3] = (x, y, z)
            self._place(pose)

    def set_rpy(self, roll: float, pitch: float, yaw: float) -> None:
        with self._client._lock:
            pose = self._body.pose
            pose[:3, :3] = rpy_matrix((roll, pitch, yaw))
            self._place(pose)

    def set_pose(self, pose: np.ndarray) -> None:
        with self._client._lock:
            self._place(np.asarray(pose, dtype=float))

    def _place(self, pose: np.ndarray) -> None:
        self._body.pose = pose
        self._body.linear_velocity = (0.0, 0.0, 0.0)
        self._body.angular_velocity = (0.0, 0.0, 0.0)

    def get_linear_vel(self) -> Point:
        return Point(*(float(v) for v in self._body.linear_velocity))

    def get_angular_vel(self) -> Point:
        return Point(*(float(v) for v in self._body.angular_velocity))

    def set_force(self, fx: float, fy: float, fz: float) -> None:
        with self._client._lock:
            self._body.force = (fx, fy, fz)

    def set_torque(self, nx: float, ny: float, nz: float) -> None:
        with self._client._lock:
            self._body.torque = (nx, ny, nz)

    def set_wrench(self, force, torque) -> None:
        self.set_force(*force)
        self.set_torque(*torque)

    def get_mass(self) -> float:
        return self._body.mass

    def get_inertia(self) -> list:
        return [float(v) for v in self._body.inertia]

    # Joints, by index (AMBF's order) or by name.
    def _joints(self) -> list:
        return self._body.joints

    def _joint(self, ref: JointRef) -> Joint:
        joints = self._joints()
        if isinstance(ref, str):
            for j in joints:
                if j.name == ref:
                    return j
            raise KeyError(f"{self._body.name} has no joint named '{ref}'")
        if not 0 <= ref < len(joints):
            raise IndexError(
                f"{self._body.name} has {len(joints)} joints; index {ref} is out of range"
            )
        return joints[ref]

    def get_num_joints(self) -> int:
        return len(self._joints())

    def get_joint_names(self) -> list:
        return [j.name for j in self._joints()]

    def get_children_names(self) -> list:
        return [j.child.name for j in self._joints()]

    def get_num_of_children(self) -> int:
        return len(self.get_children_names())

    def set_joint_pos(self, joint: JointRef, pos: float) -> None:
        with self._client._lock:
            self._joint(joint).set_position(float(pos))

    def set_joint_vel(self, joint: JointRef, vel: float) -> None:
        with self._client._lock:
            self._joint(joint).set_velocity(float(vel))

    def set_joint_effort(self, joint: JointRef, effort: float) -> None:
        with self._client._lock:
            self._joint(joint).set_effort(float(effort))

    def get_joint_pos(self, joint: JointRef) -> float:
        return self._joint(joint).position

    def get_joint_vel(self, joint: JointRef) -> float:
        return self._joint(joint).velocity

    def get_joint_effort(self, joint: JointRef) -> float:
        return self._joint(joint).effort

    def get_all_joint_pos(self) -> list:
        return [j.position for j in self._joints()]

    def get_all_joint_vel(self) -> list:
        return [j.velocity for j in self._joints()]

    def get_all_joint_effort(self) -> list:
        return [j.effort for j in self._joints()]
