"""Makes the site's images from the installed package (run from the repository root):

    python docs/images/make_images.py [FIXTURES]

demo_montage.png and demo_passes.png come from `ambfplus demo`; launcher.png is a screenshot
of `ambfplus-launch` showing the original drilling scene (FIXTURES/volumetric_drilling, default
../shared/fixtures) on a virtual display (Xvfb, xdotool, xwd), the drill moved 6 mm into the
view with the burr spinning.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from PIL import Image

ROOT = Path(__file__).resolve().parents[2]
IMAGES = ROOT / "docs" / "images"
# The launcher tests' X11 helpers (tests/x11.py, or tests/helpers/x11.py once tests are grouped).
sys.path[:0] = [str(ROOT / "tests" / "helpers"), str(ROOT / "tests")]

from x11 import finish, launch, screenshot, window_origin, xdo  # noqa: E402


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


def launcher_image(work: Path, fixtures: Path) -> None:
    read, write = os.pipe()
    server = subprocess.Popen(
        ["Xvfb", "-displayfd", str(write), "-screen", "0", "1920x1080x24", "-nolisten", "tcp"],
        pass_fds=(write,),
    )
    os.close(write)
    display = ":" + os.read(read, 16).decode().strip()
    try:
        launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
        process, _, window = launch(display, work, launch_file, 20)
        xdo(display, "key", "--delay", "200", *(["ctrl+i"] * 6), "space")
        time.sleep(4.0)
        screen = screenshot(display)
        left, top = window_origin(display, window)
        finish(process)
    finally:
        server.terminate()
        server.wait()
    window_image = Image.fromarray(screen[top : top + 540, left : left + 1536])
    window_image.save(IMAGES / "launcher.png", optimize=True)


if __name__ == "__main__":
    fixtures = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT.parent / "shared" / "fixtures"
    with tempfile.TemporaryDirectory() as work:
        demo_images(Path(work))
        launcher_image(Path(work), fixtures)
