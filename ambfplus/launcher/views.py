"""What the window shows (``--stereo``): the camera, a stereo pair side by side, or a
head-mounted display's eyes (OpenHMD, OpenXR)."""

from __future__ import annotations

import argparse

import numpy as np

from .._core import OpenXrSession, RenderError, Window
from ..devices.hmd import HmdError, HmdView, OpenHMD, XrView
from ..stereo import StereoRig
from .session import LaunchSession


def _view_of(world, camera, width: int, height: int, name: str, x: float = 0.0):
    """A camera riding on `camera` (x metres along its x axis) with its optics at the window's
    size (a camera's own size is what it publishes; the window shows its view at the
    window's)."""
    offset = np.eye(4)
    offset[0, 3] = x
    with world.lock():
        view = world.add_camera(
            name,
            width,
            height,
            fov_y=camera.fov_y,
            near=camera.near,
            far=camera.far,
            shadows=camera.shadows,
            antialiasing=camera.antialiasing,
            looks=camera.looks,
        )
        view.attach_to(camera, offset)
        view.pose = camera.pose @ offset
    return view


class Views:
    """What the window shows (--stereo): the camera; a stereo pair riding on it, side by side; or
    a head-mounted display's eyes, turned by the head and seen through its lenses."""

    def __init__(self, session: LaunchSession, args: argparse.Namespace) -> None:
        self.world, self.camera = session.world, session.camera
        self.mode = args.stereo
        self.notes: list[str] = []
        self.hmd = None
        self.xr = None  # an OpenXR session
        self.xr_view: XrView | None = None
        if self.mode == "openxr":
            try:
                self.xr = OpenXrSession("ambfplus-launch")
                self.xr_view = XrView(self.world, self.camera, name=f"{self.camera.name}_xr")
                self.notes.append(f"OpenXR: {self.xr.system} on {self.xr.runtime}")
            except RenderError as error:
                self.notes.append(f"{error}; using OpenHMD")
                self.mode = "hmd"
        if self.mode == "hmd":
            try:
                self.hmd = OpenHMD()
                self.notes.append(f"head-mounted display: {self.hmd.name}")
            except HmdError as error:
                self.notes.append(f"{error}; showing side-by-side stereo instead")
                self.mode = "side-by-side"
        self.ipd = args.ipd if args.ipd is not None else self._default_ipd()
        if not self.ipd > 0:
            raise SystemExit(f"ambfplus-launch: --ipd must be > 0 m, got {self.ipd}")
        self.convergence = args.convergence
        self.look_distance = look_distance(session)
        self._views: dict[tuple[int, int], list] = {}
        self._hmd_views: dict[tuple[int, int], HmdView] = {}

    def _default_ipd(self) -> float:
        """The HMD's; else the baseline of the scene's stereo pair (stereoL and stereoR, as the
        original's drilling scene has); else 65 mm."""
        if self.hmd is not None:
            return self.hmd.ipd
        if "stereoL" in self.world and "stereoR" in self.world:
            try:
                return StereoRig.from_cameras(self.world["stereoL"], self.world["stereoR"]).baseline
            except ValueError:
                pass
        return 0.065

    def window_size(self, args: argparse.Namespace) -> tuple[int, int]:
        if self.xr is not None:
            # The eyes side by side, at most 1536 pixels wide.
            (w0, h0), (w1, _) = self.xr.eye_sizes
            shrink = min(1.0, 1536 / (w0 + w1))
            default = (int((w0 + w1) * shrink), int(h0 * shrink))
        elif self.hmd is not None:
            eye_width, eye_height = self.hmd.eye_resolution
            default = (2 * eye_width, eye_height)
        else:
            default = (1536, 540)
        return args.width or default[0], args.height or default[1]

    def lens(self) -> dict | None:
        return self.hmd.lens() if self.hmd is not None else None

    def show(self, window: Window, width: int, height: int, overlay=None) -> list[dict]:
        """Shows a frame: in the window, and with OpenXR in the headset (the window then mirrors
        the eyes without rendering them again). The frames shown, each with its step."""
        xr = self.xr
        if xr is not None:
            xr.poll_events()
            if xr.running:
                eyes = xr.wait_frame()
                cameras = []
                if eyes:
                    if self.xr_view is None:
                        raise RenderError("OpenXR: the session runs without its view")
                    cameras = self.xr_view.update(eyes)
                frames = xr.end_frame(cameras)
                if frames:
                    window.present(cameras, width, height, overlay, rendered=True)
                    return frames
        return window.present(self.cameras(width, height), width, height, overlay)

    def cameras(self, width: int, height: int) -> list:
        """The cameras shown left to right in a window of this size (made once per size); an
        HMD's eyes turned to where the head now looks; an OpenXR session's eyes as they were
        last (it is not running)."""
        if self.xr_view is not None and self.xr_view.cameras:
            return self.xr_view.cameras
        key = (width, height)
        if key not in self._views:
            self._views[key] = self._make(width, height, len(self._views))
        if key in self._hmd_views:
            with self.world.lock():
                self._hmd_views[key].update()
        return self._views[key]

    def _make(self, width: int, height: int, index: int) -> list:
        camera, world = self.camera, self.world
        name = f"{camera.name}_window{index}"
        if self.mode in ("off", "openxr"):
            return [_view_of(world, camera, width, height, name)]
        if self.mode == "hmd":
            hmd = self.hmd
            assert hmd is not None, "the mode stays 'hmd' only once the HMD opened"
            with world.lock():
                view = HmdView(world, hmd, camera, name=name,
                               scale=(width // 2) / hmd.eye_resolution[0])  # fmt: skip
            self._hmd_views[(width, height)] = view
            return view.cameras
        # Side by side: each eye half the window, half the IPD either side of the camera.
        left = _view_of(world, camera, width // 2, height, f"{name}_left", -self.ipd / 2)
        right = _view_of(world, camera, width - width // 2, height, f"{name}_right", self.ipd / 2)
        convergence = self.look_distance if self.convergence is None else self.convergence
        if convergence > 0:
            with world.lock():
                StereoRig.from_cameras(left, right).set_working_distance(convergence)
        return [left, right]

    def describe(self, width: int, height: int) -> dict:
        """The views' geometry, for the status file: mode, IPD, each eye's focal length and
        principal point, and (side by side) the zero-disparity depth."""
        cameras = (self.xr_view.cameras if self.xr_view is not None else None) or (
            self._views.get((width, height)) or self.cameras(width, height)
        )
        out = {"mode": self.mode, "ipd": self.ipd, "views": len(cameras)}
        if self.hmd is not None:
            out["hmd"] = self.hmd.name
            out["head"] = [float(v) for v in self.hmd.rotation]
        if self.xr is not None:
            out["openxr"] = {"runtime": self.xr.runtime, "system": self.xr.system,
                             "state": self.xr.state, "frames": self.xr.frames}  # fmt: skip
            if len(cameras) == 2:  # the eyes' distance, as the runtime places them
                out["ipd"] = float(np.linalg.norm(cameras[1].pose[:3, 3] - cameras[0].pose[:3, 3]))
        out["eyes"] = [
            {
                "name": c.name,
                "size": [c.width, c.height],
                "focal": float(c.intrinsics[0, 0]),
                "principal_point": [float(v) for v in c.principal_point],
            }
            for c in cameras
        ]
        if self.mode == "side-by-side":
            out["convergence"] = self.look_distance if self.convergence is None else (
                self.convergence
            )  # fmt: skip
        return out


def look_distance(session: LaunchSession) -> float:
    """How far the camera looks: to the first volume surface on its axis, else 0.3 m."""
    pose = session.camera.pose
    for volume in session.world.volumes:
        hit = volume.raycast(pose[:3, 3], pose[:3, 2])
        if hit is not None:
            return float(hit["distance"])
    return 0.3
