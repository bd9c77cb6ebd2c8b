"""The network device's messages, for bridges written in Python.

A bridge is a small program that owns a haptic device through its vendor's SDK (OpenHaptics,
Force Dimension, libnifalcon) and talks to ``ambfplus.NetworkDevice`` over UDP, so no SDK links
into the engine. Every step the engine answers the last pose it accepted with the force to
render. All fields are little-endian.

Pose, bridge to engine, exactly 80 bytes::

    offset  type        field
    0       4 bytes     magic "APDP"
    4       uint16      version (1)
    6       uint16      reserved (0)
    8       uint64      sequence number, increasing
    16      float64 x3  position, metres, device frame
    40      float64 x4  orientation quaternion x, y, z, w (unit within 1e-3)
    72      uint32      buttons (bit 0: the burr spins, 1: clutch, 2: next burr)
    76      uint32      reserved (0)

Force, engine to the sender of the last accepted pose, 48 bytes, after every step::

    0       4 bytes     magic "APDF"
    4       uint16      version (1)
    6       uint16      reserved (0)
    8       uint64      sequence number of the pose it answers
    16      float64     simulation time, seconds
    24      float64 x3  force to render, newtons, device frame

The engine rejects, counts by reason and otherwise ignores any datagram of another size, magic or
version, with a non-finite number, a position farther than its ``max_distance`` from the
origin, a quaternion that is not a rotation, or a sequence number not after the last accepted.
Readings are relative to the first accepted pose. This module needs only the standard library,
so a bridge on another machine can carry a copy of it.
"""

from __future__ import annotations

import math
import socket
import struct
from dataclasses import dataclass

POSE = struct.Struct("<4sHHQ3d4dII")
FORCE = struct.Struct("<4sHHQd3d")
VERSION = 1
assert POSE.size == 80 and FORCE.size == 48


def pack_pose(sequence: int, position, orientation=(0.0, 0.0, 0.0, 1.0), buttons: int = 0) -> bytes:
    """One pose datagram (orientation x, y, z, w)."""
    return POSE.pack(b"APDP", VERSION, 0, sequence, *position, *orientation, buttons, 0)


@dataclass
class Force:
    sequence: int  #: of the pose it answers
    time: float  #: simulation time, seconds
    force: tuple[float, float, float]  #: newtons, device frame

    @property
    def magnitude(self) -> float:
        return math.sqrt(sum(f * f for f in self.force))


def unpack_force(data: bytes) -> Force:
    """A force datagram; ValueError naming what is wrong with anything else."""
    if len(data) != FORCE.size:
        raise ValueError(f"a force message is {FORCE.size} bytes, got {len(data)}")
    magic, version, _, sequence, time, fx, fy, fz = FORCE.unpack(data)
    if magic != b"APDF" or version != VERSION:
        raise ValueError(f"not a version-{VERSION} force message (magic {magic!r}, {version})")
    return Force(sequence, time, (fx, fy, fz))


class Bridge:
    """The bridge's end: sends poses to an engine's NetworkDevice and collects its forces."""

    def __init__(self, port: int, host: str = "127.0.0.1") -> None:
        self.address = (host, port)
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.setblocking(False)
        self.sequence = 0
        self.forces: list[Force] = []

    def send(self, position, orientation=(0.0, 0.0, 0.0, 1.0), buttons: int = 0) -> None:
        self.sequence += 1
        self.socket.sendto(pack_pose(self.sequence, position, orientation, buttons), self.address)

    def receive(self) -> list[Force]:
        """The forces that have arrived since the last call (kept in ``forces`` too)."""
        new = []
        while True:
            try:
                data = self.socket.recv(4096)
            except BlockingIOError:
                break
            new.append(unpack_force(data))
        self.forces.extend(new)
        return new

    def close(self) -> None:
        self.socket.close()

    def __enter__(self) -> Bridge:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
