"""A scripted drill for tests of the phantom scene."""

from __future__ import annotations

import ambfplus


def plunge_and_cut(scene) -> ambfplus.ScriptedDevice:
    """A device that plunges the scene's drill 2 mm into the bone under the volume's top (burr
    on from 0.2 s, at depth by 0.8 s) and cuts 5 mm sideways by 1.4 s, backwards and upwards
    (-x, +y): into the mastoid, away from the ear canal, which the drill may not cut."""
    drill = scene.drill
    surface = drill.volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))["position"]
    down = surface[2] + drill.burr_radius - 0.002 - drill.goal[2, 3]
    device = ambfplus.ScriptedDevice()
    device.set_waypoints(
        [
            {"time": 0.0, "position": (0, 0, 0)},
            {"time": 0.2, "position": (0, 0, down + 0.004), "buttons": 1},
            {"time": 0.8, "position": (0, 0, down), "buttons": 1},
            {"time": 1.4, "position": (-0.004, 0.003, down), "buttons": 1},
        ]
    )
    return device
