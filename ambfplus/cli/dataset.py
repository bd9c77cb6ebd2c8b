"""``ambfplus dataset info``: what a dataset folder holds."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def add_parser(commands) -> None:
    """Declares ``ambfplus dataset info``, its options and the function that runs it."""
    dataset = commands.add_parser("dataset", help="dataset folders: info")
    dataset_commands = dataset.add_subparsers(dest="dataset_command", required=True)
    info = dataset_commands.add_parser(
        "info", help="counts by anatomy, scenario and label of a dataset folder"
    )
    info.add_argument("folder", type=Path)
    info.add_argument("--json", action="store_true", help="print JSON")
    info.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """``dataset info DIR``: counts by anatomy, scenario and label."""
    from ..dataset import dataset_info, format_info

    info = dataset_info(args.folder)
    print(json.dumps(info, indent=2) if args.json else format_info(info))
    return 0
