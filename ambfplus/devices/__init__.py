"""Input devices beyond the engine's own: options from AMBF's input-device files
(``options``), the network device's messages for bridges written in Python (``network``) and
head-mounted displays through OpenHMD or OpenXR (``hmd``)."""

from .options import input_device_options

__all__ = ["input_device_options"]
