"""A launched session: the launch file loaded, its drill bound to the chosen device, its
real-time loop, and what it records or serves live."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .._core import KeyboardDevice, RealTimeLoop, Simulator, __version__
from .inputs import make_device
from .status import WARN_DISTANCE, Status, level_of

if TYPE_CHECKING:
    from ..export.live import FoxgloveServer
    from ..recording import Recorder


class LaunchSession:
    """A loaded launch file, its drill bound to a keyboard device, and its real-time loop."""

    def __init__(self, args: argparse.Namespace, plugin_args: list[str]) -> None:
        launch = args.launch or args.launch_file
        if launch is None:
            raise SystemExit("ambfplus-launch: give a launch file (positional or --launch_file)")
        extra = [Path(p) for p in args.load_multibody_files.split(",") if p] if (
            args.load_multibody_files
        ) else []  # fmt: skip
        # The original keeps its anatomy's names beside its launch file; the drilling plugin
        # reads them from --labels.
        labels = Path(launch).parent / "labels.csv"
        if "--labels" not in plugin_args and labels.is_file():
            plugin_args = plugin_args + ["--labels", str(labels.resolve())]
        self.sim = Simulator.from_launch(
            launch,
            models=args.load_multibodies,
            extra=extra,
            devices=args.load_devices or [],
            namespace_prefix=args.ns,
            time_step=1.0 / args.phx_frequency,
            plugins=[p for p in args.plugins.split(",") if p],
            arguments=plugin_args,
        )
        for file, message in self.sim.load_report.errors:
            print(f"error: {file}: {message}", file=sys.stderr)
        self.world = self.sim.world
        cameras = self.world.cameras
        if args.camera:
            self.camera = self.world[args.camera]
        elif cameras:
            self.camera = cameras[0]
        else:
            raise SystemExit(f"ambfplus-launch: {launch} has no camera to show")
        # What a trainee sees and a session records: shadows, anti-aliasing and the volumes'
        # looks on unless told otherwise (--shadows false, --antialiasing 1, --looks false);
        # ground-truth passes never change.
        for camera in cameras:
            camera.shadows = args.shadows
            camera.antialiasing = args.antialiasing
            camera.looks = args.looks
        self.drill = self.world.drills[0] if self.world.drills else None
        self.keyboard = KeyboardDevice()
        self.device, self.device_name = make_device(args, self.keyboard)
        self.binding = None
        self.spec = {
            "builder": "launch",
            "params": {
                "file": str(Path(launch).resolve()),
                "models": args.load_multibodies,
                "extra": [str(p.resolve()) for p in extra],
                "namespace_prefix": args.ns,
                "plugins": [p for p in args.plugins.split(",") if p],
                "arguments": plugin_args,
                "time_step": 1.0 / args.phx_frequency,
            },
        }
        self.device_options = {
            "reference": self.camera.key,
            "drill_button": 0,
            "clutch_button": 1,
            "burr_button": 2,
        }
        if self.drill is not None:
            options = dict(self.device_options, reference=self.camera)
            # Named "keyboard" whatever drives it: the name replay looks for (scenes.launch_scene).
            self.binding = self.world.add_input_device("keyboard", self.device, self.drill,
                                                       **options)  # fmt: skip
        self.initial_goal = self.drill.goal.copy() if self.drill is not None else None
        self.task, self.metrics = self._task(args)
        self.fixtures: list[dict] = self._fixtures(args)
        self.plan: str | None = self._plan(args)
        self.fixtures_on = bool(self.fixtures) or self.plan is not None
        self.sound = self._sound(args)
        self.report, self.metrics_path = args.report, args.metrics
        self.record_path = args.record
        if self.report is not None and self.record_path is None:
            self.record_path = self.report.with_suffix(".h5")
        self.started_time = self.world.time
        self.loop = RealTimeLoop(self.world, rate=args.phx_frequency)
        self.recorder: Recorder | None = None
        if self.record_path is not None:
            self.start_recording(self.record_path)
        self.live: FoxgloveServer | None = None
        self.live_options: dict[str, Any] | None = None
        if args.foxglove is not None:
            self.live_options = {"port": args.foxglove, "host": args.foxglove_host,
                                 "rate": args.foxglove_rate,
                                 "image_rate": args.foxglove_image_rate}  # fmt: skip

    def _task(self, args: argparse.Namespace):
        """--task: the task, checked against the launched anatomy, and its live metrics."""
        if args.task is None:
            if args.report is not None or args.metrics is not None:
                raise SystemExit("ambfplus-launch: --report and --metrics need --task")
            return None, None
        from .._core import ConfigError, live_metrics
        from ..training import load_task

        if self.drill is None:
            raise SystemExit(f"ambfplus-launch: --task: {args.launch or args.launch_file} has "
                             "no drill to measure")  # fmt: skip
        try:
            task = load_task(args.task)
            data = self.drill.volume.data
            if task.anatomy:
                import numpy as np

                expected = task.anatomy_data()
                if tuple(expected.shape) != tuple(data.shape) or not np.array_equal(
                    np.asarray(expected.labels), np.asarray(data.labels)
                ):
                    raise SystemExit(f"ambfplus-launch: --task: {task.source}: the task's "
                                     f"anatomy is not the launched volume "
                                     f"'{self.drill.volume.name}'")  # fmt: skip
            metrics = live_metrics(self.drill, protect=task.protect_config(data),
                                   target_mask=task.target_mask(data) if task.target else None,
                                   excess_force=task.excess_force)  # fmt: skip
        except (ConfigError, OSError) as error:
            raise SystemExit(f"ambfplus-launch: --task: {error}") from None
        return task, metrics

    def _fixtures(self, args: argparse.Namespace) -> list[dict]:
        """--fixtures: from a YAML file, or from --task's protected structures."""
        if args.fixtures is None:
            return []
        if self.drill is None:
            raise SystemExit("ambfplus-launch: --fixtures: the launch file has no drill")
        from .._core import ConfigError

        if args.fixtures == "task":
            if self.task is None:
                raise SystemExit("ambfplus-launch: --fixtures without a file needs --task")
            data = self.drill.volume.data
            names = {label.id: label.name for label in data.label_table}
            fixtures = [
                {"structure": names[i], "start": p.length + 0.001, "max_force": 1.5,
                 "stop": p.length / 2}
                for p in self.task.protect
                for i in self.task.label_ids(data, p)
            ]  # fmt: skip
        else:
            import yaml

            path = Path(args.fixtures)
            try:
                fixtures = yaml.safe_load(path.read_text())
            except (OSError, yaml.YAMLError) as error:
                raise SystemExit(f"ambfplus-launch: --fixtures {path}: {error}") from None
            if not isinstance(fixtures, list):
                raise SystemExit(f"ambfplus-launch: --fixtures {path}: expected a list of "
                                 "fixtures ({structure, start, max_force, stop})")  # fmt: skip
        try:
            self.drill.set_fixtures(fixtures)
        except (ConfigError, ValueError, TypeError) as error:
            raise SystemExit(f"ambfplus-launch: --fixtures: {error}") from None
        return list(self.drill.fixtures)

    # --plan: the stay-in-the-plan fixture and the follow-the-plan attraction (as the guidance
    # tests and benchmarks set them).
    PLAN_FIXTURE = {"start": 0.001, "max_force": 1.0, "stop": 0.0003}
    PLAN_FOLLOW = {"max_force": 0.6, "start": 0.002}

    def _plan(self, args: argparse.Namespace) -> str | None:
        """--plan stay / follow: guidance from --task's target region."""
        if args.plan is None:
            return None
        if self.task is None or self.drill is None:
            raise SystemExit("ambfplus-launch: --plan needs --task (its target region)")
        from .._core import ArgumentError, ConfigError

        try:
            target = self.task.target_mask(self.drill.volume.data)
        except (ConfigError, OSError, ValueError) as error:
            raise SystemExit(f"ambfplus-launch: --plan: {error}") from None
        if not target.any():
            raise SystemExit(f"ambfplus-launch: --plan: the task {self.task.name!r} has no "
                             "target voxel in the launched volume")  # fmt: skip
        try:
            self.drill.set_plan(target, **self.PLAN_FIXTURE)
            if args.plan == "follow":
                self.drill.follow_plan(**self.PLAN_FOLLOW)
        except (ArgumentError, ConfigError) as error:
            raise SystemExit(f"ambfplus-launch: --plan: {error}") from None
        return args.plan

    def toggle_fixtures(self) -> bool:
        """Ctrl+G: the fixtures and the plan's guidance off, or back on; whether they are on
        now."""
        if (not self.fixtures and self.plan is None) or self.drill is None:
            return False
        self.fixtures_on = not self.fixtures_on
        with self.world.lock():
            if self.fixtures:
                self.drill.set_fixtures([{**f, "enabled": f["enabled"] and self.fixtures_on}
                                         for f in self.fixtures])  # fmt: skip
            if self.plan is not None:
                self.drill.set_plan_enabled(self.fixtures_on)
                if self.plan == "follow":
                    self.drill.follow_plan(**self.PLAN_FOLLOW, enabled=self.fixtures_on)
        return self.fixtures_on

    def _sound(self, args: argparse.Namespace):
        """--audio / --mute: the drill's sound, beeping near the task's structures."""
        if not (args.audio or args.mute) or self.drill is None:
            return None
        from .._core import DrillSound

        warnings = None
        if self.task is not None:
            data = self.drill.volume.data
            names = {label.id: label.name for label in data.label_table}
            warnings = {
                names[i]: max(2 * p.length, 0.001)
                for p in self.task.protect
                for i in self.task.label_ids(data, p)
            }
        sound = DrillSound(self.drill, output="device", muted=args.mute, warnings=warnings)
        if sound.device_error:
            print(f"ambfplus-launch: no sound: {sound.device_error}", flush=True)
        return sound

    def toggle_mute(self) -> bool:
        """Ctrl+M: mutes or unmutes the drill's sound; whether it is muted now."""
        return self.sound.toggle_mute() if self.sound is not None else True

    def finish(self) -> None:
        """The session's end: the sound stopped, the recording closed, then --metrics and
        --report written."""
        if self.sound is not None:
            self.sound.close()
        if self.recorder is not None:
            self.recorder.close()
            self.recorder = None
        if self.metrics is None:
            return
        import json

        from ..fileio import write_text

        summary = self.metrics.summary()
        if self.metrics_path is not None:
            write_text(self.metrics_path, json.dumps(summary, indent=1) + "\n")
            print(f"ambfplus-launch: live metrics: {self.metrics_path}", flush=True)
        if self.report is not None:
            from ..training import assess

            result = assess(self.record_path, self.task)
            result.write_report(self.report)
            print(f"ambfplus-launch: debrief report: {self.report} (score "
                  f"{result.score:.0f} / 100)", flush=True)  # fmt: skip

    def start_live(self) -> None:
        """Starts the Foxglove live view (--foxglove), once the real-time loop runs."""
        if self.live_options is None:
            return
        from ..export import MissingExtra
        from ..export.live import FoxgloveServer

        try:
            self.live = FoxgloveServer(self.world, [self.camera], drill=self.drill,
                                       **self.live_options).start()  # fmt: skip
        except (MissingExtra, RuntimeError) as error:
            raise SystemExit(f"ambfplus-launch: --foxglove: {error}") from None
        print(f"ambfplus-launch: live view on {self.live.url}: TF, force and critical "
              f"structures at {self.live.rate:g} Hz, images at up to {self.live.image_rate:g} "
              "Hz as rendering allows (Foxglove: open a WebSocket connection)",
              flush=True)  # fmt: skip

    def stop_live(self) -> None:
        if self.live is not None:
            self.live.stop()
            self.live = None

    def start_recording(self, path: Path) -> None:
        from ..recording import Recorder

        logged = [self.camera] + ([self.drill, self.binding] if self.drill is not None else [])
        self.world.start_step_log(logged)
        meta = {
            "scene": self.spec,
            "device": {
                "name": "keyboard",
                "kind": type(self.device).__name__,
                "source": self.device_name,
                "options": self.device_options,
            },  # fmt: skip
            "camera": self.camera.name,
            "launcher": {"version": __version__},
        }
        self.recorder = Recorder(path, metadata=meta)
        self.recorder.set_legend(self.world)

    def drain(self) -> None:
        """Hands what the steps logged to the recorder."""
        if self.recorder is None:
            return
        from ..scenes import drain

        drain(self.world, self.drill, self.recorder)

    def _task_status(self, status: Status) -> None:
        import math

        import numpy as np

        assert self.task is not None and self.metrics is not None and self.drill is not None
        summary = self.metrics.summary()
        status.task = self.task.name
        status.elapsed_s = summary["total_time"]
        status.force_n = float(np.linalg.norm(self.drill.force))
        clearances = self.metrics.clearances()
        status.structures = [
            {
                "name": c["name"],
                "mm": None if c["distance"] is None else round(c["distance"] * 1000, 2),
                "margin_mm": c["margin"] * 1000,
                "level": "clear"
                if c["distance"] is None
                else level_of(c["distance"] * 1000, c["margin"] * 1000),
            }
            for c in clearances
        ]
        near = [c for c in clearances if c["distance"] is not None]
        if near:
            c = min(near, key=lambda c: c["distance"] - c["margin"])
            status.nearest, status.nearest_mm = c["name"], c["distance"] * 1000
            status.nearest_margin_mm = c["margin"] * 1000
        else:
            status.nearest, status.nearest_mm = "", math.inf
        status.violations = sum(
            s["contacts"] + (s["voxels_removed"] > 0) for s in summary["structures"]
        )

    def reset_volumes(self) -> None:
        with self.world.lock():
            for volume in self.world.volumes:
                volume.data.reset()

    def reset_world(self) -> None:
        """Volumes back to their start, the drill to its first pose, plugins reset."""
        with self.world.lock():
            for volume in self.world.volumes:
                volume.data.reset()
            if self.drill is not None:
                self.drill.goal = self.initial_goal
            self.world.reset_plugins()

    def status(self, status: Status, fps: float) -> Status:
        s = self.loop.stats
        status.fps = fps
        status.physics_hz = s["mean_rate"]
        status.physics_p99_ms = s["p99"] * 1e3
        status.physics_max_ms = s["max"] * 1e3
        if self.drill is None:
            status.mode = "no drill"
            return status
        assert self.binding is not None, "bound whenever there is a drill"
        status.mode = "clutch" if self.binding.clutched else self.device_name
        status.burr_mm = self.drill.burr_diameters[self.drill.burr] * 1000
        status.spinning = self.drill.on
        status.drill_position = self.drill.cursor_proxies[0].round(6).tolist()
        distances = self.drill.critical_distances
        if distances:
            name, distance = min(distances.items(), key=lambda kv: kv[1])
            status.critical, status.critical_mm = name, distance * 1000
        if self.metrics is not None:
            self._task_status(status)
        guided = self.fixtures or self.plan is not None
        status.fixtures = "on" if self.fixtures_on else ("off" if guided else "")
        status.sound = "" if self.sound is None else ("muted" if self.sound.muted else "on")
        events = self.drill.events
        cut = [e for e in events if e["kind"] == "critical"]
        if cut or status.critical_mm < WARN_DISTANCE * 1000:
            status.warning = f"WARNING! {status.critical} {status.critical_mm:.1f} mm"
        else:
            status.warning = ""
        return status
