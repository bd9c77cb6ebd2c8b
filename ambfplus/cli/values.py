"""Argument types that check a value's range as argparse reads it, so that a value a command
cannot honour is a one-line usage error (status 2) before anything runs."""

from __future__ import annotations

import argparse
import math


def within(low: int, high: int):
    """An argparse type: an integer in [low, high], else a one-line usage error saying so."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer, got {text!r}") from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"expected {low}..{high}, got {value}")
        return value

    return parse


def number(low: float, high: float = math.inf, *, above: bool = False):
    """An argparse type: a finite number >= `low` (> `low` when `above`) and <= `high`."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
        if value < low or (above and value == low) or value > high:
            bounds = f"{'>' if above else '>='} {low:g}"
            bounds += f" and <= {high:g}" if math.isfinite(high) else ""
            raise argparse.ArgumentTypeError(f"expected a number {bounds}, got {text!r}")
        return value

    return parse
