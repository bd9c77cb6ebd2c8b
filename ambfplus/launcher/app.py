"""Running ``ambfplus-launch``: headless, or in a window."""

from __future__ import annotations

import argparse
import sys
import time

from .options import parse_args
from .session import LaunchSession
from .window import run_window


def main(argv: list[str] | None = None) -> int:
    """Runs ``ambfplus-launch`` with these arguments (default: the command line's); the exit
    status."""
    args, plugin_args = parse_args(argv)
    if not args.show_gui:
        return run_headless(args, plugin_args)
    try:
        import glfw
    except ImportError:
        print("ambfplus-launch needs GLFW for its window: pip install 'ambfplus[gui]' (or run "
              "headless with -g false)", file=sys.stderr)  # fmt: skip
        return 2
    if not glfw.init():
        print("ambfplus-launch: GLFW cannot open a display (is DISPLAY set? run headless with "
              "-g false)", file=sys.stderr)  # fmt: skip
        return 2
    try:
        return run_window(glfw, args, plugin_args)
    finally:
        glfw.terminate()


def run_headless(args: argparse.Namespace, plugin_args: list[str]) -> int:
    """The real-time session without a window (until --seconds or Ctrl+C)."""
    session = LaunchSession(args, plugin_args)
    started = time.perf_counter()
    try:
        with session.loop:
            print(f"ambfplus-launch: headless; physics: {session.loop.scheduling}", flush=True)
            session.start_live()
            while args.seconds is None or time.perf_counter() - started < args.seconds:
                time.sleep(0.1)
                session.drain()
    except KeyboardInterrupt:
        pass
    finally:
        session.stop_live()
        session.drain()
        session.finish()
    return 0
