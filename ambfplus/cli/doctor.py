"""``ambfplus doctor``: what the engine finds on this machine (``ambfplus.doctor``)."""

from __future__ import annotations

import argparse


def add_parser(commands) -> None:
    """Declares ``ambfplus doctor``, its options and the function that runs it."""
    doctor = commands.add_parser(
        "doctor",
        help="what the engine finds on this machine (renderer, EGL devices and drivers, optional "
        "libraries, extras) and what to install for what is missing; exits 1 if it cannot render",
    )
    doctor.add_argument("--json", action="store_true", help="print the checks as JSON")
    doctor.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the checks and prints them; 1 if the engine cannot render."""
    from ..doctor import main as doctor

    return doctor(as_json=args.json)
