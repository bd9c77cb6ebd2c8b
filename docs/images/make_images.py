"""Makes the site's images from the installed package (run from the repository root):

    python docs/images/make_images.py

demo_montage.png and demo_passes.png come from `ambfplus demo`; launcher.png is a window of
`ambfplus-launch` (on a virtual X display: Xvfb and xdotool) drilling the built-in phantom, written
as AMBF files (slice stack, model and launch file), with a task's status line and fixtures on;
phantom_vs_ear.png is the built-in phantom beside the original system's 256^3 segmented ear (the
shared fixture, read from ../shared/fixtures or AMBFPLUS_FIXTURES; only its rendering is kept),
both at 256^3 with their lateral surfaces up, under the same camera and lights.
"""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import textwrap
import time
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


FIXTURES = Path(os.environ.get("AMBFPLUS_FIXTURES", ROOT.parent / "shared" / "fixtures"))


def phantom_vs_ear() -> None:
    import numpy as np

    import ambfplus
    from ambfplus.transforms import make_pose

    ear_files = FIXTURES / "volumetric_drilling"
    ear = ambfplus.load_volume(
        ear_files / "ADF" / "volume_256.yaml", labels=ear_files / "labels.csv"
    )
    # The ear's pose in its launch file turns its lateral surface towards +x (where the drill
    # starts); a quarter turn about y then puts it up, as the phantom's.
    lateral_up = make_pose(rpy=(0.0, -np.pi / 2, 0.0)) @ make_pose(rpy=(1.57079, 1.4, 0.0))
    views = []
    for data, pose in ((ambfplus.phantom(256, 0, side="right"), np.eye(4)), (ear, lateral_up)):
        world = ambfplus.World()
        world.add_volume("anatomy", data, pose=pose)
        world.add_light("key", "directional", direction=(-0.3, 0.4, -1.0), intensity=0.8)
        world.add_light("fill", "point", position=(0.15, -0.2, 0.3), intensity=0.3)
        camera = world.add_camera("camera", 480, 480, 0.5, 0.01, 10.0, shadows=True,
                                  antialiasing=2, looks=True)  # fmt: skip
        camera.look_at(eye=(0.0, -0.06, 0.12), target=(0.0, 0.0, 0.004))
        views.append(np.asarray(camera.capture(passes=["rgb"]).rgb))
    Image.fromarray(np.concatenate(views, axis=1)).save(
        IMAGES / "phantom_vs_ear.png", optimize=True
    )


def launcher_image(work: Path) -> None:
    from x11 import screenshot, window_origin, xdo

    import ambfplus

    data = ambfplus.phantom(128)
    data.save_slice_stack(work / "ear")
    ambfplus.write_label_table(work / "ear" / "labels.csv", data.label_table)
    size = data.dimensions
    (work / "ear.yaml").write_text(
        textwrap.dedent(f"""
        volumes: [VOLUME ear]
        VOLUME ear:
          name: ear
          location:
            position: {{x: 0.0, y: 0.0, z: 0.0}}
            orientation: {{r: 0.0, p: 0.0, y: 0.0}}
          dimensions: {{x: {size[0]}, y: {size[1]}, z: {size[2]}}}
          images: {{path: ear/, prefix: plane, format: png, count: {data.shape[2]}}}
          labels: ear/labels.csv
        drills: [DRILL burr]
        DRILL burr:
          name: burr
          volume: VOLUME ear
          burr: 2
          location:
            position: {{x: 0.0, y: 0.0, z: 0.03}}
            orientation: {{r: 0.0, p: -1.5708, y: 0.0}}
        """)
    )
    (work / "world.yaml").write_text(
        textwrap.dedent("""
        lights: [light1]
        cameras: [main_camera]
        light1:
          name: light1
          location: {x: 0.1, y: -0.1, z: 0.3}
          direction: {x: -0.3, y: 0.3, z: -1.0}
          spot exponent: 0.3
          cutoff angle: 1.4
        main_camera:
          name: main_camera
          location: {x: 0.07, y: -0.11, z: 0.11}
          look at: {x: 0.0, y: 0.0, z: 0.005}
          up: {x: 0.0, y: 0.0, z: 1.0}
          clipping plane: {near: 0.001, far: 5.0}
          field view angle: 0.5
        """)
    )
    (work / "colors.yaml").write_text("Gray: {r: 128, g: 128, b: 128}\n")
    (work / "launch.yaml").write_text(
        "world config: world.yaml\ncolor config: colors.yaml\ninput devices config: devices.yaml\n"
        "multibody configs:\n  - ear.yaml\n"
    )
    (work / "task.yaml").write_text(
        textwrap.dedent("""
        version: 1
        name: Cortical mastoidectomy
        anatomy: {file: ear.yaml, labels: ear/labels.csv}
        target: {labels: [Bone]}
        protect:
          - {structure: Facial_Nerve, margin: 1.0}
          - {structure: Sinus_+_Dura, margin: 1.0}
        """)
    )
    display = ":77"
    xvfb = subprocess.Popen(["Xvfb", display, "-screen", "0", "1280x720x24", "-nolisten", "tcp"])
    try:
        time.sleep(1.0)
        env = {**os.environ, "DISPLAY": display}
        status = work / "status.json"
        process = subprocess.Popen(
            [sys.executable, "-m", "ambfplus.launcher", "launch.yaml", "-l", "0",
             "--width", "960", "--height", "540", "--seconds", "14", "--status", str(status),
             "--task", "task.yaml", "--fixtures"],
            env=env, cwd=work,
        )  # fmt: skip
        window = ""
        deadline = time.time() + 90
        while not window and time.time() < deadline:
            try:
                window = xdo(display, "search", "--name", "^ambfplus$").split()[0]
            except (subprocess.CalledProcessError, IndexError):
                time.sleep(0.3)
        while not status.exists() and time.time() < deadline:
            time.sleep(0.2)
        xdo(display, "windowfocus", "--sync", window)
        xdo(display, "key", "space")  # the burr on
        xdo(display, "key", "--delay", "20", "--repeat", "45", "ctrl+i")  # into the bone
        time.sleep(3.0)
        shot = screenshot(display)
        left, top = window_origin(display, window)
        Image.fromarray(shot[top : top + 540, left : left + 960]).save(
            IMAGES / "launcher.png", optimize=True
        )
        process.wait(timeout=90)
    finally:
        xvfb.terminate()


if __name__ == "__main__":
    with tempfile.TemporaryDirectory() as work:
        if "--launcher" not in sys.argv:
            demo_images(Path(work))
            phantom_vs_ear()
        launcher_image(Path(work))
