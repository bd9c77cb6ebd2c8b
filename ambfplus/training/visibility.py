"""Burr visibility: whether the burr could be seen in the surgeon's view, by a depth test of the
burr against that camera's depth image at the frame's step.

The burr (a sphere) is visible in a frame where, at some pixel its silhouette covers, the first
surface the camera sees is not in front of the burr: the depth there is at least the depth of
the burr's nearest point less a tolerance (the burr itself, or something behind it). With the
frame's anatomy labels (the `label` pass), only anatomy hides the burr, so the drill's own shaft
in front of it does not; without them, anything between the camera and the whole burr hides it.
"""

from __future__ import annotations

import numpy as np

# How far in front of the burr's nearest point a surface may lie and still count as the burr
# (depth images are float32 and the burr is tessellated): metres.
DEPTH_TOLERANCE = 0.0003


def burr_visible(
    depth: np.ndarray,
    intrinsics: np.ndarray,
    camera_pose: np.ndarray,
    centre,
    radius: float,
    tolerance: float = DEPTH_TOLERANCE,
    label: np.ndarray | None = None,
) -> bool:
    """Whether a burr of `radius` at `centre` (world, metres) is visible in a depth image
    (H x W metres, 0 where nothing was hit) taken by a camera with `intrinsics` (3x3, pixel
    centres at half-integers) at `camera_pose` (4x4 world from the OpenCV camera frame);
    `label`: the frame's anatomy labels (0 where no anatomy), so that only anatomy hides."""
    camera_from_world = np.linalg.inv(np.asarray(camera_pose, float))
    x, y, z = camera_from_world[:3, :3] @ np.asarray(centre, float) + camera_from_world[:3, 3]
    if z <= radius:
        return False
    k = np.asarray(intrinsics, float)
    u, v = k[0, 0] * x / z + k[0, 2], k[1, 1] * y / z + k[1, 2]
    r = k[1, 1] * radius / z  # the silhouette's radius, pixels
    height, width = depth.shape
    cols = np.arange(max(0, int(np.floor(u - r))), min(width, int(np.ceil(u + r)) + 1))
    rows = np.arange(max(0, int(np.floor(v - r))), min(height, int(np.ceil(v + r)) + 1))
    if not len(cols) or not len(rows):
        return False
    # Pixels whose centres fall inside the silhouette (at least the pixel under the centre).
    cc, rr = np.meshgrid(cols, rows)
    inside = (cc + 0.5 - u) ** 2 + (rr + 0.5 - v) ** 2 <= max(r, 0.71) ** 2
    seen = depth[rr[inside], cc[inside]]
    front = z - radius - tolerance
    hides = (seen > 0) & (seen < front)
    if label is not None:
        hides &= label[rr[inside], cc[inside]] > 0
    return bool(np.any(~hides))


def visibility(
    frame_steps,
    intrinsics,
    camera_poses,
    depth,
    steps: dict,
    drill: str,
    burr_radii,
    cutting,
    label=None,
):
    """The fraction of cutting time in which the burr was visible, from the surgeon camera's
    recorded frames: their steps, intrinsics (N, 3, 3) and poses (N, 4, 4), and `depth(i)`
    giving frame i's depth image (read only for frames that stand for some cutting), and
    `label(i)` its anatomy labels where they were recorded (None otherwise). Each frame
    stands for the ticks from its step to the next frame's; `cutting` and `burr_radii` are per
    row of the step log. Returns None without frames."""
    step_index = np.asarray(steps["step"], np.int64)
    poses = np.asarray(steps[f"{drill}.pose"], float).reshape(-1, 4, 4)
    frame_steps = np.asarray(frame_steps, np.int64)
    if not len(frame_steps) or not len(step_index):
        return None
    rows = np.minimum(np.searchsorted(step_index, frame_steps), len(step_index) - 1)
    bounds = np.append(rows, len(step_index))
    weights = np.add.reduceat(np.asarray(cutting, bool).astype(np.int64), bounds[:-1])
    weights[bounds[:-1] >= bounds[1:]] = 0
    seen_time = total_time = 0.0
    visible = judged = 0
    for i in np.flatnonzero(weights):
        image = depth(int(i))
        if image is None:
            return None
        row = int(rows[i])
        labels = label(int(i)) if label is not None else None
        seen = burr_visible(
            image,
            intrinsics[i],
            camera_poses[i],
            poses[row][:3, 3],
            float(burr_radii[row]),
            label=labels,
        )
        judged += 1
        visible += seen
        total_time += float(weights[i])
        seen_time += float(weights[i]) * seen
    return {
        "fraction": seen_time / total_time if total_time > 0 else None,
        "frames": int(judged),
        "visible_frames": int(visible),
    }
