"""The status line: what it shows (``Status``) and its overlay image with the warning."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# How close a critical structure may come before the status warns, metres.
WARN_DISTANCE = 0.002


@dataclass
class Status:
    """What the status line shows, kept up to date by the session."""

    burr_mm: float = 0.0
    spinning: bool = False
    mode: str = "keyboard"
    critical: str = ""
    critical_mm: float = math.inf
    warning: str = ""
    fps: float = 0.0
    physics_hz: float = 0.0
    physics_p99_ms: float = 0.0
    physics_max_ms: float = 0.0
    cpu_s_per_frame: float = 0.0
    frames: int = 0
    drill_position: list = field(default_factory=list)

    def lines(self) -> list[str]:
        burr = f"burr {self.burr_mm:g} mm {'ON' if self.spinning else 'off'}"
        critical = (
            f"nearest critical: {self.critical} {self.critical_mm:.1f} mm"
            if math.isfinite(self.critical_mm)
            else "no critical structure"
        )
        rates = f"graphics {self.fps:.1f} fps | physics {self.physics_hz:.0f} Hz"
        return [f"{burr} | {self.mode} | {critical} | {rates}"]


def draw_overlay(status: Status, width: int, height: int) -> np.ndarray:
    """An RGBA image of the status line (top left) and the warning (centred, red)."""
    from PIL import Image, ImageDraw

    image = Image.new("RGBA", (width, height), (0, 0, 0, 0))
    draw = ImageDraw.Draw(image)
    font = _font(16)
    y: float = 8
    for line in status.lines():
        box = draw.textbbox((10, y), line, font=font)
        draw.rectangle((box[0] - 4, box[1] - 3, box[2] + 4, box[3] + 3), fill=(0, 0, 0, 140))
        draw.text((10, y), line, font=font, fill=(255, 255, 255, 255))
        y = box[3] + 8
    if status.warning:
        big = _font(28)
        box = draw.textbbox((0, 0), status.warning, font=big)
        x = (width - (box[2] - box[0])) // 2
        top = height // 2 - 20
        draw.rectangle((x - 10, top - 8, x + box[2] - box[0] + 10, top + box[3] - box[1] + 12),
                       fill=(150, 0, 0, 170))  # fmt: skip
        draw.text((x, top), status.warning, font=big, fill=(255, 255, 255, 255))
    return np.asarray(image)


_fonts: dict = {}


def _font(size: int):
    from PIL import ImageFont

    if size not in _fonts:
        try:
            _fonts[size] = ImageFont.load_default(size)
        except TypeError:  # Pillow < 10.1 has one bitmap size
            _fonts[size] = ImageFont.load_default()
    return _fonts[size]
