"""The status line: what it shows (``Status``) and its overlay image with the warning."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

# How close a critical structure may come before the status warns, metres.
WARN_DISTANCE = 0.002


def level_of(distance_mm: float, margin_mm: float) -> str:
    """A protected structure's warning level: "clear", "near" (within twice its margin) or
    "inside" its margin."""
    if not math.isfinite(distance_mm) or distance_mm > 2 * margin_mm:
        return "clear"
    return "inside" if distance_mm <= margin_mm else "near"


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
    # With --task: the task's live metrics.
    task: str = ""
    elapsed_s: float = 0.0
    force_n: float = 0.0
    nearest: str = ""
    nearest_mm: float = math.inf
    nearest_margin_mm: float = 0.0
    violations: int = 0
    # Every protected structure: {"name", "mm" (None when gone), "margin_mm", "level"}.
    structures: list = field(default_factory=list)
    fixtures: str = ""  # "on", "off" (Ctrl+G) or "" (none)
    sound: str = ""  # "on", "muted" (Ctrl+M) or "" (no sound)

    @property
    def level(self) -> str:
        """The nearest protected structure's level (level_of)."""
        return level_of(self.nearest_mm, self.nearest_margin_mm)

    def task_line(self) -> str:
        if not self.task:
            return ""
        near = (f"{self.nearest} {self.nearest_mm:.1f} mm (margin {self.nearest_margin_mm:g})"
                if math.isfinite(self.nearest_mm) else "no structure near")  # fmt: skip
        return (f"{self.task} | {self.elapsed_s:.0f} s | force {self.force_n:.1f} N | {near} | "
                f"violations {self.violations}")  # fmt: skip

    def lines(self) -> list[str]:
        burr = f"burr {self.burr_mm:g} mm {'ON' if self.spinning else 'off'}"
        critical = (
            f"nearest critical: {self.critical} {self.critical_mm:.1f} mm"
            if math.isfinite(self.critical_mm)
            else "no critical structure"
        )
        rates = f"graphics {self.fps:.1f} fps | physics {self.physics_hz:.0f} Hz"
        extra = "".join(
            f" | {name} {value}"
            for name, value in (("fixtures", self.fixtures), ("sound", self.sound))
            if value
        )
        return [f"{burr} | {self.mode} | {critical} | {rates}{extra}"] + (
            [self.task_line()] if self.task else []
        )


def draw_overlay(status: Status, width: int, height: int) -> np.ndarray:
    """An RGBA image of the status line (top left) and the warning (centred, red)."""
    from PIL import Image, ImageDraw

    image = Image.new("RGBA", (width, height), (0, 0, 0, 0))
    draw = ImageDraw.Draw(image)
    font = _font(16)
    y: float = 8
    colours = {"clear": (120, 230, 120, 255), "near": (255, 200, 60, 255),
               "inside": (255, 90, 90, 255)}  # fmt: skip
    for line in status.lines():
        box = draw.textbbox((10, y), line, font=font)
        draw.rectangle((box[0] - 4, box[1] - 3, box[2] + 4, box[3] + 3), fill=(0, 0, 0, 140))
        task = bool(status.task) and line == status.task_line()
        colour = colours[status.level] if task else (255, 255, 255, 255)
        draw.text((10, y), line, font=font, fill=colour)
        y = box[3] + 8
        if task:  # the force bar: 0..10 N, red past the task's excess force
            width_n = 24
            draw.rectangle((10, y, 10 + 10 * width_n, y + 8), outline=(255, 255, 255, 200))
            filled = min(status.force_n, 10.0) * width_n
            draw.rectangle((10, y, 10 + filled, y + 8), fill=colour)
            y += 16
            # Each protected structure in its own level's colour.
            x: float = 10
            for s in status.structures:
                mm = "gone" if s["mm"] is None else f"{s['mm']:.1f} mm"
                text = f"{s['name']} {mm}"
                box = draw.textbbox((x, y), text, font=font)
                draw.rectangle((box[0] - 4, box[1] - 3, box[2] + 4, box[3] + 3),
                               fill=(0, 0, 0, 140))  # fmt: skip
                draw.text((x, y), text, font=font, fill=colours[s["level"]])
                x = box[2] + 16
            if status.structures:
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
