"""What moves the drill (``--device``, ``--pedal``): the keyboard, a network bridge or a joystick,
with the keyboard's and a pedal's buttons merged in."""

from __future__ import annotations

import argparse

from .._core import (
    AssetNotFound,
    Device,
    JoystickDevice,
    JoystickMapping,
    KeyboardDevice,
    MergedDevice,
    NetworkDevice,
)


def make_device(args: argparse.Namespace, keyboard: KeyboardDevice) -> tuple[Device, str]:
    """The device --device names (its buttons merged with the keyboard's and --pedal's), and
    how the status line names it."""
    kind, _, where = args.device.partition(":")
    if kind == "keyboard" and not where:
        pose: Device = keyboard
    elif kind == "network":
        try:
            pose = NetworkDevice(int(where) if where else 0)
        except ValueError as error:
            raise SystemExit(f"ambfplus-launch: --device {args.device}: {error}") from None
        except RuntimeError as error:
            raise SystemExit(f"ambfplus-launch: {error}") from None
        print(f"ambfplus-launch: network device on 127.0.0.1:{pose.port} (UDP)", flush=True)
        kind = f"network :{pose.port}"
    elif kind == "joystick":
        pose = _joystick(where or "/dev/input/js0")
    else:
        raise SystemExit(
            f"ambfplus-launch: --device is keyboard, network[:PORT] or joystick[:PATH], got "
            f"'{args.device}'"
        )
    buttons: list[Device] = [] if pose is keyboard else [keyboard]
    if args.pedal:
        buttons.append(_joystick(args.pedal, pedal_mapping(args.pedal_map)))
        kind += " + pedal"
    return (MergedDevice(pose, buttons) if buttons else pose), kind


def pedal_mapping(text: str) -> JoystickMapping:
    """--pedal-map: "drill=0,clutch=1,burr=2" (a role left out: no button); no axes."""
    roles = {"drill": -1, "clutch": -1, "burr": -1}
    for item in text.replace(" ", "").split(","):
        role, _, number = item.partition("=")
        if role not in roles or not number.lstrip("-").isdigit():
            raise SystemExit(
                f"ambfplus-launch: --pedal-map takes drill=N,clutch=N,burr=N, got '{text}'"
            )
        roles[role] = int(number)
    return JoystickMapping(**roles, axes=(-1, -1, -1))


def _joystick(path: str, mapping: JoystickMapping | None = None) -> JoystickDevice:
    try:
        return JoystickDevice(path, mapping or JoystickMapping())
    except AssetNotFound as error:
        raise SystemExit(f"ambfplus-launch: {error.strerror}") from None
