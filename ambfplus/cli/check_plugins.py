"""``ambfplus check-plugins``: load plugin files in probe processes."""

from __future__ import annotations

import argparse

from .._core import PluginError
from .values import number


def add_parser(commands) -> None:
    """Declares ``ambfplus check-plugins``, its options and the function that runs it."""
    check = commands.add_parser(
        "check-plugins",
        help="load plugin files in probe processes (their static initialisers run there, not "
        "here); exit 1 if any crashes, hangs or fails",
    )
    check.add_argument("plugins", nargs="+", help="plugin files (.so, .py) or names")
    check.add_argument(
        "--timeout", type=number(0, above=True), default=60.0, help="seconds a probe may take"
    )
    check.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Loads each plugin file in a probe process; exit code 1 if any is refused."""
    from ..plugin import probe_plugin

    refused = 0
    for plugin in args.plugins:
        try:
            result = probe_plugin(plugin, timeout=args.timeout)
        except PluginError as error:
            print(error)
            refused += 1
            continue
        print(result.message)
        refused += not result.ok
    return 1 if refused else 0
