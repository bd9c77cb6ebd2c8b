"""The ``ambfplus`` command line: ``demo``, ``replay``, ``assess``, ``convert``, ``launch``,
``check-plugins``, ``validate``, ``export``, ``generate``, ``dataset info``, ``info``, ``doctor``
(and ``--cmake-dir``, the folder of the CMake package C++ plugins build against).

Each command is a module of this package: ``add_parser(commands)`` declares its options and
sets ``func``, the function that runs it.
"""

from __future__ import annotations

import argparse

from .._core import __version__
from ..plugin import cmake_dir
from . import (
    assess,
    check_plugins,
    convert,
    dataset,
    demo,
    doctor,
    export,
    generate,
    info,
    launch,
    replay,
    validate,
)

# In the order ``ambfplus --help`` lists them.
COMMANDS = (demo, replay, assess, convert, launch, check_plugins, validate, export, generate,
            dataset, info, doctor)  # fmt: skip


class _PrintCmakeDir(argparse.Action):
    """--cmake-dir: prints the folder and exits, as --version does."""

    def __init__(self, option_strings, dest, **kwargs):
        super().__init__(option_strings, dest, nargs=0, default=argparse.SUPPRESS, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print(cmake_dir())
        parser.exit()


def build_parser() -> argparse.ArgumentParser:
    """The ``ambfplus`` command line's parser, every command with its options."""
    parser = argparse.ArgumentParser(prog="ambfplus", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"ambfplus {__version__}")
    parser.add_argument(
        "--cmake-dir",
        action=_PrintCmakeDir,
        help="print the folder of ambfplusConfig.cmake (for -Dambfplus_DIR=...) and exit",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(commands)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Runs the ``ambfplus`` command with these arguments (default: the command line's); the
    exit status."""
    args = build_parser().parse_args(argv)
    return args.func(args)
