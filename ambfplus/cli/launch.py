"""``ambfplus launch``: load an AMBF launch file headless (AMBF's -l / -a), step it and report
what loaded."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from .._core import Simulator
from .values import within

# A day of 1 ms steps.
MAX_STEPS = 86_400_000


def add_parser(commands) -> None:
    """Declares ``ambfplus launch``, its options and the function that runs it."""
    launch = commands.add_parser(
        "launch", help="load an AMBF launch file headless (AMBF's -l / -a), step it, report"
    )
    launch.add_argument("launch_file", type=Path)
    launch.add_argument("-l", type=indices, help="launch indices to load, e.g. 10,12")
    launch.add_argument("-a", help="more model files, comma separated")
    launch.add_argument("-i", type=indices, help="input devices to set up, e.g. 0,1")
    launch.add_argument("--ns", default="", help="namespace prefix")
    launch.add_argument("--steps", type=within(0, MAX_STEPS), default=1000,
                        help="1 ms steps to take (at most a day's)")  # fmt: skip
    launch.add_argument(
        "--strict", action="store_true", help="a model or plugin that fails is fatal"
    )
    launch.add_argument(
        "--plugins",
        help="simulator plugins to load after the launch file's, comma separated "
        "(libx.so, x.py, a path, or a name searched in AMBFPLUS_PLUGIN_PATH)",
    )
    launch.add_argument(
        "--check-plugins",
        action="store_true",
        help="load each --plugins file in a probe process first and refuse one whose probe "
        "crashes, hangs or fails",
    )
    launch.set_defaults(func=run)


def indices(text: str) -> list[int]:
    """AMBF's -l: "0,2, 5" -> [0, 2, 5]."""
    try:
        return [int(part) for part in text.replace(" ", "").split(",") if part]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected launch indices like 0,2 got '{text}'") from None


def run(args: argparse.Namespace) -> int:
    """Loads an AMBF launch file headless like AMBF's -l/-a, steps it, prints what loaded."""
    extra = [Path(p) for p in args.a.split(",") if p] if args.a else []
    plugins = [p for p in args.plugins.split(",") if p] if args.plugins else []
    if args.check_plugins:
        from ..plugin import check_plugin, resolve

        for plugin in plugins:
            if resolve(plugin) is not None:
                check_plugin(plugin)
    sim = Simulator.from_launch(
        args.launch_file,
        models=args.l,
        extra=extra,
        devices=args.i or [],
        strict=args.strict,
        namespace_prefix=args.ns,
        plugins=plugins,
    )
    sim.step(args.steps)
    report = sim.load_report
    summary = {
        "models": [m.name for m in report.models],
        "objects": {
            kind: sum(o.kind == kind for o in sim.world.objects)
            for kind in ("body", "joint", "camera", "light", "volume")
        },
        "plugins": [f"{p.name} ({p.language}, {p.scope})" for p in sim.world.plugins],
        "errors": [f"{f}: {m}" for f, m in report.errors],
        "warnings": len(report.warnings),
        "time": sim.world.time,
    }
    print(json.dumps(summary, indent=2))
    return 1 if report.errors else 0
