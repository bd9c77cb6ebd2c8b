"""The scripted scenarios moved to ``ambfplus.scenarios`` (they need NumPy only, and dataset
generation uses them without PyTorch); this name stays for existing imports."""

from ..scenarios import DRILL_AREA, CameraPath, DrillScript

__all__ = ["CameraPath", "DRILL_AREA", "DrillScript"]
