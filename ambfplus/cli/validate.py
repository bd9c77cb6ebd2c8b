"""``ambfplus validate``: check a recording or a dataset folder."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from ..dataset.check import DatasetReport
    from ..recording.validation import ValidationReport


def add_parser(commands) -> None:
    """Declares ``ambfplus validate``, its options and the function that runs it."""
    validate = commands.add_parser(
        "validate",
        help="check a recording (ambfplus.recording) or a dataset folder (its manifest and "
        "every shard); exit 1 if any check fails",
    )
    validate.add_argument(
        "recording", type=Path, help="a recording's head file (name.h5) or a dataset folder"
    )
    validate.add_argument("--json", action="store_true", help="print the report as JSON")
    validate.add_argument(
        "--no-image-matching",
        action="store_true",
        help="skip block matching the stereo pairs against depth and baseline (the costliest "
        "check)",
    )
    validate.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Checks a recording or a dataset folder; exit code 0 only when every check passes."""
    report: DatasetReport | ValidationReport
    if not args.recording.exists():
        # Nothing to check is a usage error (status 2), not a failed check (status 1).
        raise FileNotFoundError(2, "no such recording or dataset folder", str(args.recording))
    if args.recording.is_dir():
        from ..dataset import validate_dataset

        report = validate_dataset(args.recording, match_images=not args.no_image_matching)
    else:
        from ..recording import validate

        report = validate(args.recording, match_images=not args.no_image_matching)
    print(json.dumps(report.to_dict(), indent=2) if args.json else report)
    return 0 if report.ok else 1
