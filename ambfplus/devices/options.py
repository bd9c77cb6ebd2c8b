"""Input devices from AMBF's input-device files.

``read_input_devices(file)`` gives each device's settings as AMBF's files write them;
``input_device_options(entry, world)`` turns one into the options of ``add_input_device``:

- ``workspace scaling`` -> ``workspace_scale`` (world metres per device metre);
- ``button mapping``: ``a1`` -> ``drill_button`` (the burr spins while held), ``a2`` ->
  ``clutch_button`` (the device moves alone while held), ``next mode`` -> ``burr_button`` (the
  next burr); a missing or negative index means no button;
- ``max force`` (N, when given) -> ``max_force``;
- the first of ``pair cameras`` that is in the world -> ``reference`` (device motion follows its
  image axes: x right, y up, z towards the viewer).

``haptic gain`` is left out: AMBF applies it to its own multibody controllers, and the drilling
simulator sends the drill's force to the device unscaled, as ambfplus does.
"""

from __future__ import annotations

from typing import Any

from .._core import World

_BUTTONS = {"a1": "drill_button", "a2": "clutch_button", "next mode": "burr_button"}


def input_device_options(entry: dict[str, Any], world: World | None = None) -> dict[str, Any]:
    """add_input_device options from an entry of ``read_input_devices`` (see the module)."""
    options: dict[str, Any] = {"workspace_scale": float(entry.get("workspace_scaling", 1.0))}
    buttons = entry.get("buttons", {})
    for key, option in _BUTTONS.items():
        index = int(buttons.get(key, -1))
        options[option] = index if index >= 0 else -1
    if float(entry.get("max_force", 0.0)) > 0:
        options["max_force"] = float(entry["max_force"])
    if world is not None:
        for name in entry.get("pair_cameras", []):
            if name in world:
                options["reference"] = world[name]
                break
    return options
