"""The ``ambfplus`` command line: ``demo``, ``replay``, ``assess``, ``convert``, ``launch``,
``check-plugins``, ``validate``, ``export``, ``generate``, ``dataset info``, ``info``, ``doctor``
(and ``--cmake-dir``, the folder of the CMake package C++ plugins build against).

Each command is a module of this package: ``add_parser(commands)`` declares its options and
sets ``func``, the function that runs it.

Errors take one path, in ``main``: whatever a command raises becomes one line on stderr naming
the file or argument and what to do, with exit status 2 (``errors.describe``); a usage error is
one line with status 2 too. ``ambfplus --debug <command>`` shows the traceback instead. Status 1
stays a command's own verdict: it ran and the result failed (``validate``, ``replay``, ...).
"""

from __future__ import annotations

import argparse
import sys
from typing import NoReturn

from .._core import __version__
from ..plugin import cmake_dir
from . import (
    assess,
    check_plugins,
    convert,
    dataset,
    demo,
    doctor,
    errors,
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


class _Parser(argparse.ArgumentParser):
    """A parser whose usage errors are one line (with status 2, as argparse's): the error and
    where to read the usage."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    """The ``ambfplus`` command line's parser, every command with its options."""
    parser = _Parser(prog="ambfplus", description=__doc__.split("\n\n")[0])
    parser.add_argument("--version", action="version", version=f"ambfplus {__version__}")
    parser.add_argument(
        "--cmake-dir",
        action=_PrintCmakeDir,
        help="print the folder of ambfplusConfig.cmake (for -Dambfplus_DIR=...) and exit",
    )
    parser.add_argument(
        "--debug",
        action="store_true",
        help="let an error end the command with its traceback (default: one line, status 2)",
    )
    commands = parser.add_subparsers(dest="command", required=True)
    for command in COMMANDS:
        command.add_parser(commands)
    _list_inputs(commands)
    return parser


def _list_inputs(commands: argparse._SubParsersAction) -> None:
    """Sets ``_inputs`` of each command: the arguments its user must give (positional ones and
    required options), in order, and ``_defaults``, every option's default; an error message
    that names no argument given is prefixed with the first input (``errors.line``)."""
    for sub in commands.choices.values():
        nested = [a for a in sub._actions if isinstance(a, argparse._SubParsersAction)]
        for action in nested:
            _list_inputs(action)
        if not nested:
            inputs = [a.dest for a in sub._actions if not a.option_strings or a.required]
            defaults = {a.dest: a.default for a in sub._actions if a.option_strings}
            sub.set_defaults(_inputs=tuple(inputs), _defaults=defaults)


def main(argv: list[str] | None = None) -> int:
    """Runs the ``ambfplus`` command with these arguments (default: the command line's); the
    exit status: 0 done, 1 the command's result is a failure, 2 an error (one line on stderr),
    130 interrupted."""
    args = build_parser().parse_args(argv)
    if args.debug:
        return args.func(args)
    try:
        return args.func(args)
    except SystemExit as stop:
        if not isinstance(stop.code, str):  # a status: the command chose it
            raise
        return errors.report(args, stop.code)
    except KeyboardInterrupt:
        print(f"{errors.command_name(args)}: interrupted", file=sys.stderr)
        return 130
    except Exception as error:  # noqa: BLE001 - the one place every command's errors end
        return errors.report(args, error)
