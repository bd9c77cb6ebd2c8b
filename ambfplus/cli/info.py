"""``ambfplus info``: the version and the OpenGL device."""

from __future__ import annotations

import argparse
import json

from .._core import __version__, gl_info


def add_parser(commands) -> None:
    """Declares ``ambfplus info``, its options and the function that runs it."""
    info = commands.add_parser("info", help="print the version and the OpenGL device")
    info.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Prints the version and the OpenGL device as JSON."""
    print(json.dumps({"version": __version__, "gl": gl_info()}, indent=2))
    return 0
