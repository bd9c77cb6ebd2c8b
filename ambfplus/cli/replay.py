"""``ambfplus replay``: re-simulate a recording from its device readings, optionally
re-rendering it with another rig."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def add_parser(commands) -> None:
    """Declares ``ambfplus replay``, its options and the function that runs it."""
    replay = commands.add_parser(
        "replay",
        help="re-simulate a recording from its device readings (same removal log?) and "
        "optionally re-render it with another rig",
    )
    replay.add_argument("recording", type=Path)
    replay.add_argument("--out", type=Path, help="write the re-rendered session here")
    replay.add_argument("--baseline", type=float, help="another stereo baseline, metres")
    replay.add_argument("--width", type=int)
    replay.add_argument("--height", type=int)
    replay.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Re-simulates a recording from its device readings, optionally re-rendering it."""
    from ..scenes import replay

    report = replay(
        args.recording,
        out=args.out,
        baseline=args.baseline,
        width=args.width,
        height=args.height,
        progress=lambda line: print("  " + line, flush=True),
    )
    print(
        json.dumps(
            {
                "steps": report.steps,
                "frames": report.frames,
                "voxels_removed": report.voxels_removed,
                "removal_identical": report.removal_identical,
                "forces_identical": report.forces_identical,
                "images_identical": report.images_identical,
                "output": str(report.output) if report.output else None,
            },
            indent=2,
        )
    )
    same = report.removal_identical and report.forces_identical
    return 0 if same and report.images_identical in (None, report.frames) else 1
