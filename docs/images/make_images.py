"""Makes the site's images from the installed package (run from the repository root):

    python docs/images/make_images.py

demo_montage.png and demo_passes.png come from `ambfplus demo`.
"""

from __future__ import annotations

import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "images"
# The launcher tests' X11 helpers (tests/x11.py, or tests/helpers/x11.py once tests are grouped).
sys.path[:0] = [str(ROOT / "tests" / "helpers"), str(ROOT / "tests")]


def demo_images(work: Path) -> None:
    out = work / "demo_out"
    subprocess.run(["ambfplus", "demo", "--out", str(out)], check=True, cwd=work)
    shutil.copy(out / "montage.png", IMAGES / "demo_montage.png")
    # rgb, depth, label and segmentation of the last frame, cropped around the anatomy.
    views = ["rgb", "depth_preview", "label_preview", "segmentation"]
    size, gap, box = 300, 4, (120, 20, 480, 380)
    strip = Image.new("RGB", (len(views) * (size + gap) - gap, size), (255, 255, 255))
    for k, name in enumerate(views):
        view = Image.open(out / f"{name}.png").convert("RGB").crop(box)
        strip.paste(view.resize((size, size), Image.LANCZOS), (k * (size + gap), 0))
    strip.save(IMAGES / "demo_passes.png", optimize=True)


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as work:
        demo_images(Path(work))
