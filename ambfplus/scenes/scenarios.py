"""Scripted scenarios for the built-in phantom scene (NumPy only): where the stereo rig looks and
what the drill does, drawn from a random generator so that every seed gives its own session.

- ``CameraPath``: the rig circling the phantom (or holding still) at about the working distance.
- ``DrillScript``: a scripted hand (a ``ScriptedDevice`` callback) that rests, or plunges the
  spinning burr into the bone at random sites, sweeps it sideways and pulls it back out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: The phantom's lateral face, where drilling happens (world x, y half-extent, metres).
DRILL_AREA = 0.010


@dataclass(frozen=True)
class CameraPath:
    """(eye, target) over time: a view from `distance` at an azimuth and elevation (degrees)
    that swing sinusoidally about their centres; zero amplitudes hold the camera still."""

    target: tuple[float, float, float] = (0.0, 0.0, 0.006)
    azimuth: float = -100.0
    azimuth_swing: float = 0.0
    azimuth_period: float = 8.0
    elevation: float = 55.0
    elevation_swing: float = 0.0
    elevation_period: float = 5.0
    distance: float = 0.25
    phase: float = 0.0

    def __call__(self, t: float) -> tuple[np.ndarray, np.ndarray]:
        azimuth = math.radians(
            self.azimuth
            + self.azimuth_swing * math.sin(2 * math.pi * t / self.azimuth_period + self.phase)
        )
        elevation = math.radians(
            self.elevation
            + self.elevation_swing
            * math.sin(2 * math.pi * t / self.elevation_period + 1.7 * self.phase)
        )
        direction = np.array(
            [
                math.cos(elevation) * math.cos(azimuth),
                math.cos(elevation) * math.sin(azimuth),
                math.sin(elevation),
            ]
        )
        target = np.asarray(self.target, dtype=float)
        return target + self.distance * direction, target

    @classmethod
    def random(
        cls,
        rng: np.random.Generator,
        moving: bool = True,
        target=(0.0, 0.0, 0.006),
        distance: tuple[float, float] = (0.23, 0.27),
    ) -> CameraPath:
        """A view of the lateral face from the surgeon's side, looking within 4 mm of `target`
        from between `distance` metres (default about 250 mm away, the paper's microscope),
        swinging by up to 35 degrees when `moving`."""
        jitter = rng.uniform(-0.004, 0.004, size=2)
        return cls(
            target=(float(target[0] + jitter[0]), float(target[1] + jitter[1]), float(target[2])),
            azimuth=float(rng.uniform(-130.0, -70.0)),
            azimuth_swing=float(rng.uniform(10.0, 35.0)) if moving else 0.0,
            azimuth_period=float(rng.uniform(4.0, 10.0)),
            elevation=float(rng.uniform(45.0, 70.0)),
            elevation_swing=float(rng.uniform(0.0, 10.0)) if moving else 0.0,
            elevation_period=float(rng.uniform(3.0, 8.0)),
            distance=float(rng.uniform(*distance)),
            phase=float(rng.uniform(0.0, 2 * math.pi)),
        )


class DrillScript:
    """A scripted hand for a ``ScriptedDevice`` callback (``device.set_callback(script)``):
    positions in the device frame (world axes, metres from the drill's start, as the built-in
    scene binds its device) and buttons (bit 0 spins the burr).

    It rests at the start until told to plunge: ``plunge(now, count)`` schedules `count` cycles,
    each over a random site of the lateral face whose surface the drill may cut (bone, not the
    ear canal): move above it, spin up, sink 1.5-3.5 mm into the bone, sweep 2-5 mm sideways,
    pull out. ``rest(now)`` brings the drill back to its start.
    ``busy_until`` is the time the last scheduled motion ends."""

    def __init__(self, volume, drill_start, burr_radius: float, rng: np.random.Generator):
        self.volume = volume
        self.start = np.asarray(drill_start, dtype=float)
        self.burr_radius = float(burr_radius)
        self.rng = rng
        self.waypoints: list[tuple[float, np.ndarray, int]] = [(0.0, np.zeros(3), 0)]
        self._removable = {label.id for label in volume.data.label_table if label.removable}

    @property
    def busy_until(self) -> float:
        return self.waypoints[-1][0]

    def __call__(self, t: float) -> dict:
        times = [w[0] for w in self.waypoints]
        i = int(np.searchsorted(times, t, side="right")) - 1
        if i < 0:
            return {"position": tuple(self.waypoints[0][1]), "buttons": self.waypoints[0][2]}
        if i >= len(self.waypoints) - 1:
            return {"position": tuple(self.waypoints[-1][1]), "buttons": self.waypoints[-1][2]}
        (t0, p0, buttons), (t1, p1, _) = self.waypoints[i], self.waypoints[i + 1]
        s = (t - t0) / (t1 - t0)
        # Buttons hold from a waypoint to the next, as ScriptedDevice waypoints do.
        return {"position": tuple(p0 + s * (p1 - p0)), "buttons": buttons}

    def _go(self, dt: float, where, buttons: int) -> None:
        self.waypoints.append((self.busy_until + dt, np.asarray(where, dtype=float), buttons))

    def _from(self, now: float) -> None:
        """Continues from where the hand is at `now` (drops any plan beyond it)."""
        here = self(now)
        self.waypoints = [w for w in self.waypoints if w[0] < now]
        self.waypoints.append((now, np.asarray(here["position"], float), here["buttons"]))

    def rest(self, now: float, seconds: float = 0.3) -> None:
        """Back to the start with the burr off."""
        self._from(now)
        self._go(seconds, np.zeros(3), 0)

    def plunge_until(self, end: float, now: float = 0.0) -> None:
        """Schedules plunge-and-sweep cycles from `now` (or the end of what is planned, if
        later) until the plan covers `end` seconds."""
        while self.busy_until < end:
            self.plunge(max(now, self.busy_until))

    def plunge(self, now: float, count: int = 1) -> None:
        """Schedules `count` plunge-and-sweep cycles at random sites."""
        self._from(now)
        for _ in range(count):
            x, y = self.rng.uniform(-DRILL_AREA, DRILL_AREA, size=2)
            hit = self.volume.raycast((x, y, 0.05), (0.0, 0.0, -1.0))
            if hit is None or hit["label"] not in self._removable:
                continue  # the burr cuts bone only (not the ear canal's skin, say)
            surface = float(hit["position"][2])
            above = np.array([x, y, surface + self.burr_radius + 0.003]) - self.start
            sink = self.rng.uniform(0.0015, 0.0035)
            down = np.array([x, y, surface + self.burr_radius - sink]) - self.start
            heading = self.rng.uniform(0.0, 2 * math.pi)
            sweep = self.rng.uniform(0.002, 0.005) * np.array(
                [math.cos(heading), math.sin(heading), 0.0]
            )
            for dt, where, buttons in (
                (0.4, above, 0),
                (0.2, above, 1),
                (float(self.rng.uniform(0.8, 1.6)), down, 1),
                (float(self.rng.uniform(0.6, 1.2)), down + sweep, 1),
                (0.3, above + sweep, 1),
            ):
                self._go(dt, where, buttons)
