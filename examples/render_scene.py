"""Build a small scene from Python, render it headless, and use the frame as NumPy arrays.

python examples/render_scene.py [out_dir]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

import ambfplus


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    world = ambfplus.World()
    world.add_light("sun", "directional", direction=(-0.3, 0.2, -1.0))
    world.add_body("floor", "plane", mass=0, color=(0.3, 0.35, 0.4))
    world.add_body(
        "ball", "sphere", radius=0.05, pose=ambfplus.make_pose((0, 0, 0.05)), color=(0.9, 0.3, 0.2)
    )
    world.add_body(
        "post",
        "cylinder",
        radius=0.01,
        height=0.2,
        pose=ambfplus.make_pose((0.08, 0.05, 0.1)),
        color=(0.8, 0.8, 0.85),
    )
    camera = world.add_camera("camera", 640, 480, fov_y=0.7, near=0.01, far=10.0)
    camera.look_at(eye=(0.35, -0.25, 0.25), target=(0.0, 0.0, 0.05))

    frame = camera.capture()  # rgb and depth are views of the engine's buffers, not copies
    print(frame, "renderer:", ambfplus.gl_info()["renderer"])

    # Back-project every pixel with a hit into the world frame (pixel centres at +0.5).
    k = frame.intrinsics
    rows, cols = np.nonzero(frame.depth > 0)
    z = frame.depth[rows, cols].astype(np.float64)
    camera_points = np.stack(
        [(cols + 0.5 - k[0, 2]) / k[0, 0] * z, (rows + 0.5 - k[1, 2]) / k[1, 1] * z, z], axis=1
    )
    world_points = camera_points @ frame.pose[:3, :3].T + frame.pose[:3, 3]
    print(f"{len(world_points)} points; lowest z = {world_points[:, 2].min():.4f} m")

    # A preallocated buffer is filled in place: no allocation per frame.
    depth = np.zeros((camera.height, camera.width), np.float32)
    for _ in range(3):
        world.step(100)
        camera.capture(out={"depth": depth})
    print(f"depth at the image centre after {world.time:.2f} s: {depth[240, 320]:.4f} m")

    ambfplus.write_image(str(out / "example_rgb.png"), frame.rgb)
    depth_mm = np.round(frame.depth * 1000).astype(np.uint16)
    ambfplus.write_image(str(out / "example_depth_mm.png"), depth_mm)
    print("wrote", out / "example_rgb.png", "and", out / "example_depth_mm.png")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else Path("example_out"))
