"""Stereo rigs, stereo frames and the disparity/depth conversions a dataset needs (the id
legend and segmentation colours are ``ambfplus.labels``).

Conventions (see the package docstring): camera poses are world-from-camera in the OpenCV frame
(x right, y down, z forward); pixel (row r, column c) is centred at (c + 0.5, r + 0.5).

A rig's right camera sits `baseline` metres along the left camera's +x, with the same orientation
(rectified). Disparity d = x_left - x_right (pixels). With principal points cx_left, cx_right and
dcx = cx_right - cx_left, a point at depth Z has d = f B / Z - dcx, so Z = f B / (d + dcx). A
parallel rig has dcx = 0; an off-axis rig moves the principal points apart by dcx = f B / Z0 so
that points at the working distance Z0 have zero disparity and the two views overlap there.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Protocol

import numpy as np

from ._core import Camera, World
from .transforms import make_pose

PASSES = ("rgb", "depth", "label", "instance")


class _View(Protocol):
    """What a stereo pair's view offers: a live ``Frame`` or a recording's ``RecordedFrame``
    (for typing only; a pass that was not recorded is None)."""

    @property
    def intrinsics(self) -> np.ndarray: ...
    @property
    def pose(self) -> np.ndarray: ...
    @property
    def rgb(self) -> np.ndarray | None: ...
    @property
    def depth(self) -> np.ndarray | None: ...


@dataclass
class StereoFrame:
    """A left and a right frame taken at the same simulation time, with the rig's geometry."""

    left: _View  #: a live Frame or a RecordedFrame
    right: _View
    baseline: float  #: metres, from the two cameras' poses
    dcx: float  #: cx_right - cx_left, pixels

    @property
    def focal(self) -> float:
        return float(self.left.intrinsics[0, 0])

    @property
    def right_from_left(self) -> np.ndarray:
        """4x4 transform taking left-camera coordinates to right-camera coordinates."""
        return np.linalg.inv(self.right.pose) @ self.left.pose

    def disparity(self) -> np.ndarray:
        """The left image's disparity predicted from its depth (NaN where nothing was hit)."""
        return depth_to_disparity(self.left.depth, self.focal, self.baseline, self.dcx)


def depth_to_disparity(depth, focal: float, baseline: float, dcx: float = 0.0) -> np.ndarray:
    """d = f B / Z - dcx; NaN where depth is 0 (no hit)."""
    z = np.asarray(depth, dtype=np.float64)
    with np.errstate(divide="ignore"):
        d = focal * baseline / z - dcx
    return np.where(z > 0, d, np.nan)


def disparity_to_depth(disparity, focal: float, baseline: float, dcx: float = 0.0) -> np.ndarray:
    """Z = f B / (d + dcx); NaN where d + dcx <= 0."""
    d = np.asarray(disparity, dtype=np.float64) + dcx
    with np.errstate(divide="ignore", invalid="ignore"):
        z = focal * baseline / d
    return np.where(d > 0, z, np.nan)


# AMBF's camera frame (its point clouds): x back from the view direction, y right, z up.
_AMBF_FROM_OPENCV = np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])


def opencv_to_ambf(points) -> np.ndarray:
    """Camera-frame points from the OpenCV frame to AMBF's (x = -depth, y right, z up)."""
    return np.asarray(points, dtype=np.float64) @ _AMBF_FROM_OPENCV.T


def ambf_to_opencv(points) -> np.ndarray:
    """Camera-frame points from AMBF's frame (its DepthData clouds) to the OpenCV frame."""
    return np.asarray(points, dtype=np.float64) @ _AMBF_FROM_OPENCV


class StereoRig:
    """Two cameras a baseline apart along the left camera's x axis, captured together.

    ``StereoRig(world, "rig", baseline=0.065, width=640, height=480, fov_y=...)`` makes cameras
    ``rig_left`` and ``rig_right``; ``working_distance`` (metres) makes it off-axis;
    ``background`` (RGB 0..1) is what both show where nothing is hit, and
    ``principal_point_offset`` (pixels) moves both principal points alike; ``shadows``,
    ``antialiasing`` (1 = off to 4, see ``Camera.antialiasing``) and ``looks`` (volumes' ambient
    occlusion, bone texture and wet highlights) change both cameras' rgb pass only
    (``Camera.shadows``, ``Camera.antialiasing``, ``Camera.looks``). Move it with
    ``look_at`` or ``pose`` (the left camera's). ``StereoRig.from_cameras(left, right)`` wraps two
    existing cameras (e.g. an ADF file's stereoL and stereoR), keeping their poses.
    """

    def __init__(
        self,
        world: World,
        name: str,
        baseline: float = 0.065,
        width: int = 640,
        height: int = 480,
        fov_y: float = 0.4,
        near: float = 0.01,
        far: float = 10.0,
        working_distance: float | None = None,
        background=(0.0, 0.0, 0.0),
        principal_point_offset=(0.0, 0.0),
        shadows: bool = False,
        antialiasing: int = 1,
        looks: bool = False,
    ) -> None:
        if not baseline > 0:
            raise ValueError(f"baseline must be > 0 m, got {baseline}")
        options: dict[str, Any] = {
            "fov_y": fov_y,
            "near": near,
            "far": far,
            "background": list(background),
            "shadows": shadows,
            "antialiasing": antialiasing,
            "looks": looks,
        }
        left = world.add_camera(f"{name}_left", width, height, **options)
        right = world.add_camera(f"{name}_right", width, height, **options)
        offset = np.eye(4)
        offset[0, 3] = baseline
        right.attach_to(left, offset)
        self.left, self.right = left, right
        self.name = name
        self._offset = offset
        self.principal_point_offset = tuple(float(v) for v in principal_point_offset)
        self.set_working_distance(working_distance)

    @classmethod
    def from_cameras(cls, left: Camera, right: Camera) -> StereoRig:
        rig = cls.__new__(cls)
        rig.left, rig.right, rig.name = left, right, left.name
        rig.principal_point_offset = (0.0, 0.0)
        rig._offset = np.linalg.inv(left.pose) @ right.pose
        if abs(rig._offset[0, 3]) <= 0 or not np.allclose(
            rig._offset[:3, :3], np.eye(3), atol=1e-6
        ):
            raise ValueError(
                f"{left.name} and {right.name} are not a rectified pair: the right camera must "
                "have the left one's orientation and sit along its x axis"
            )
        return rig

    @property
    def baseline(self) -> float:
        """Metres between the optical centres."""
        return float(np.linalg.norm((np.linalg.inv(self.left.pose) @ self.right.pose)[:3, 3]))

    @property
    def dcx(self) -> float:
        """cx_right - cx_left, pixels (0 for a parallel rig)."""
        return float(self.right.principal_point[0] - self.left.principal_point[0])

    def set_working_distance(self, distance: float | None) -> None:
        """Off-axis: points at this depth get zero disparity (None: parallel again). Both
        principal points also move by ``principal_point_offset`` (pixels; the same for both
        views, so the pair stays rectified)."""
        w, h = self.left.width, self.left.height
        dx, dy = self.principal_point_offset
        shift = 0.0
        if distance is not None:
            if not distance > 0:
                raise ValueError(f"working distance must be > 0 m, got {distance}")
            shift = self.left.intrinsics[0, 0] * self.baseline / distance / 2
        self.left.principal_point = (w / 2 - shift + dx, h / 2 + dy)
        self.right.principal_point = (w / 2 + shift + dx, h / 2 + dy)

    @property
    def pose(self) -> np.ndarray:
        return self.left.pose

    @pose.setter
    def pose(self, value) -> None:
        self.left.pose = value
        self.right.pose = np.asarray(value) @ self._offset

    def look_at(self, eye, target, up=(0.0, 0.0, 1.0)) -> None:
        """Places the left camera at eye looking at target (the right one follows)."""
        self.left.look_at(eye, target, up)
        self.right.pose = self.left.pose @ self._offset

    def aim(self, eye, target, up=(0.0, 0.0, 1.0)) -> None:
        """Places the rig's midpoint at eye, both cameras looking along target - eye (an
        off-axis rig then sees a target at its working distance at both images' centres)."""
        self.look_at(eye, target, up)
        self.pose = self.left.pose @ make_pose((-self.baseline / 2, 0.0, 0.0))

    def capture(self, passes=PASSES, poses=None) -> StereoFrame:
        """Both views at the same simulation time."""
        self.right.pose = self.left.pose @ self._offset
        left = self.left.capture(passes=list(passes), poses=poses)
        right = self.right.capture(passes=list(passes), poses=poses)
        return StereoFrame(left, right, self.baseline, self.dcx)


def block_match(left, right, rows, cols, dmin, dmax, half=10) -> np.ndarray:
    """Disparity at each (row, col) of the left image: zero-mean normalised correlation of a
    (2 half + 1)^2 window along the same row of the right image, refined to sub-pixel by a
    parabola. NaN where the window has no texture or the best match is at the search's edge."""
    gray_l = left.astype(np.float64).mean(axis=2)
    gray_r = right.astype(np.float64).mean(axis=2)
    side = 2 * half + 1
    out = np.full(len(rows), np.nan)
    for k, (r, c) in enumerate(zip(rows, cols)):
        patch = gray_l[r - half : r + half + 1, c - half : c + half + 1]
        if patch.std() < 5:
            continue
        lo, hi = max(c - dmax, half), min(c - dmin, gray_r.shape[1] - half - 1)
        if hi - lo < 3:
            continue
        strip = gray_r[r - half : r + half + 1, lo - half : hi + half + 1]
        windows = np.lib.stride_tricks.sliding_window_view(strip, (side, side))[0]
        z = (patch - patch.mean()) / patch.std()
        mean = windows.mean(axis=(1, 2), keepdims=True)
        std = windows.std(axis=(1, 2), keepdims=True) + 1e-9
        cost = -(((windows - mean) / std) * z).sum(axis=(1, 2))
        i = int(np.argmin(cost))
        if i == 0 or i == len(cost) - 1:
            continue
        a, b, e = cost[i - 1], cost[i], cost[i + 1]
        out[k] = c - (lo + i + 0.5 * (a - e) / (a - 2 * b + e))
    return out


def disparity_agreement(stereo: StereoFrame, step: int = 8, margin: int = 20) -> dict:
    """Block matching on a grid of the left image (every `step` pixels, `margin` from the
    border) against the disparity the left depth and the rig predict. Returns the textured,
    non-occluded points used, the median and 95th percentile of |measured - predicted| (px), and
    the baseline recovered from the measured disparities, B = (d + dcx) Z / f (m)."""
    left, right = stereo.left, stereo.right
    if left.depth is None:
        raise ValueError("disparity_agreement needs the left view's depth pass")
    height, width = left.depth.shape
    predicted = stereo.disparity()
    rows, cols = (
        g.ravel()
        for g in np.meshgrid(
            np.arange(margin, height - margin, step), np.arange(margin, width - margin, step)
        )
    )
    keep = ~np.isnan(predicted[rows, cols])
    rows, cols = rows[keep], cols[keep]
    out = {"points": 0, "median_error": np.nan, "p95_error": np.nan, "baseline": np.nan}
    if len(rows) == 0:
        return out
    d = predicted[rows, cols]
    measured = block_match(
        left.rgb, right.rgb, rows, cols, int(d.min()) - 20, int(d.max()) + 20, half=margin // 2
    )
    ok = ~np.isnan(measured) & (cols - d > margin - 5) & (cols - d < width - margin + 5)
    if not ok.any():
        return out
    error = np.abs(measured[ok] - d[ok])
    z = np.asarray(left.depth)[rows[ok], cols[ok]]
    return {
        "points": int(ok.sum()),
        "median_error": float(np.median(error)),
        "p95_error": float(np.percentile(error, 95)),
        "baseline": float(np.median((measured[ok] + stereo.dcx) * z / stereo.focal)),
    }
