"""pose_logger: a Python plugin that writes the positions of bodies to ``<name>.csv`` in the
working directory every 0.1 s of simulation time, and logs objects as they arrive.

At world or simulator scope it follows every body of the world, at model scope the model's
bodies, at object scope its own body. Declare it in an ADF file::

    plugins:
    - {name: poses, filename: pose_logger.py, path: ../pose_logger}

or load it from Python: ``world.load_plugin("plugins/pose_logger/pose_logger.py")``.
"""

from __future__ import annotations

import csv
import logging
from pathlib import Path

import ambfplus

log = logging.getLogger("ambfplus.plugins.pose_logger")

# Simulation seconds between rows.
INTERVAL = 0.1


class PoseLogger(ambfplus.Plugin):
    def init(self) -> int:
        self.path = Path.cwd() / f"{self.name}.csv"
        self.file = self.path.open("w", newline="")
        self.rows = csv.writer(self.file)
        self.rows.writerow(["time", "step", "body", "x", "y", "z"])
        self.every = max(1, round(INTERVAL / self.world.time_step))
        log.info("%s (%s scope): writing body positions to %s", self.name, self.scope, self.path)
        return 1

    def bodies(self) -> list:
        # Handles are looked up each time, never kept: a kept handle would keep the simulator
        # alive (see ambfplus.plugin).
        if self.object is not None:
            return [self.object] if self.object.kind == "body" else []
        objects = self.model.objects if self.model is not None else self.world.objects
        return [o for o in objects if o.kind == "body"]

    def physics_update(self, dt: float) -> None:
        world = self.world
        if world.step_index % self.every:
            return
        for body in self.bodies():
            x, y, z = body.pose[:3, 3]
            self.rows.writerow(
                [
                    f"{world.time:.4f}",
                    world.step_index,
                    body.name,
                    f"{x:.6f}",
                    f"{y:.6f}",
                    f"{z:.6f}",
                ]
            )

    def on_object_added(self, obj) -> None:
        log.info("%s: %s '%s' added", self.name, obj.kind, obj.name)

    def reset(self) -> None:
        self.file.flush()

    def close(self) -> None:
        self.file.close()
        log.info("%s: wrote %s", self.name, self.path)
