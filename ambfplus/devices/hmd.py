"""Head-mounted displays: OpenHMD's devices (its null device without hardware), and the eye
cameras of an OpenXR session.

``OpenHMD()`` opens the first head-mounted display OpenHMD finds, else its null HMD, through
Debian's ``libopenhmd0`` (ctypes, nothing to compile). It gives the head's orientation, the
interpupillary distance, each eye's resolution and projection, and the lens distortion
(PanoTools model). On the null device ``set_rotation`` scripts the head.

``HmdView(world, hmd, base)`` makes two eye cameras riding on a base camera: each is the base
camera turned by the head's orientation and moved half the IPD along the head's x axis, with
the eye's resolution, focal length and principal point from OpenHMD's projection. ``update()``
follows the head; ``lens()`` gives the distortion a ``Window`` applies when it shows them side
by side.

For an OpenXR runtime's headset, ``ambfplus.OpenXrSession`` runs the session (its error says
why where there is no runtime or headset; the launcher then falls back to OpenHMD), and
``XrView(world, base)`` keeps two eye cameras where the session's eyes are: each is the base
camera moved by the eye's pose in the session's LOCAL space (whose origin is the head's at the
start), with the eye's asymmetric field of view as square pixels (its height the swapchain
image's, times ``scale``) and an off-axis principal point.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import math

import numpy as np

# openhmd.h's values (Debian's libopenhmd 0.3).
_ROTATION_QUAT = 1
_LEFT_PROJECTION, _RIGHT_PROJECTION = 4, 5
_SCREEN_WIDTH_M, _SCREEN_HEIGHT_M = 7, 8
_LENS_SEPARATION, _LENS_HEIGHT = 9, 10
_EYE_IPD = 15
_DISTORTION_K, _ABERRATION_K = 20, 21
_RESOLUTION_X, _RESOLUTION_Y, _DEVICE_CLASS = 0, 1, 2
_PRODUCT, _PATH = 1, 2
_CLASS_HMD = 0
# OpenHMD's eye and head frames are OpenGL's (x right, y up, z backwards); cameras are OpenCV's.
_GL_FROM_CV = np.diag([1.0, -1.0, -1.0])


class HmdError(RuntimeError):
    """OpenHMD is missing, or a device could not be opened or read."""


def _library() -> ctypes.CDLL:
    name = ctypes.util.find_library("openhmd") or "libopenhmd.so.0"
    try:
        lib = ctypes.CDLL(name)
    except OSError as error:
        raise HmdError(
            f"OpenHMD is not installed ({error}); on Debian: apt-get install libopenhmd0"
        ) from None
    lib.ohmd_ctx_create.restype = ctypes.c_void_p
    lib.ohmd_ctx_destroy.argtypes = [ctypes.c_void_p]
    lib.ohmd_ctx_probe.argtypes = [ctypes.c_void_p]
    lib.ohmd_ctx_update.argtypes = [ctypes.c_void_p]
    lib.ohmd_list_gets.restype = ctypes.c_char_p
    lib.ohmd_list_gets.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int]
    lib.ohmd_list_geti.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_int,
                                   ctypes.POINTER(ctypes.c_int)]  # fmt: skip
    lib.ohmd_list_open_device.restype = ctypes.c_void_p
    lib.ohmd_list_open_device.argtypes = [ctypes.c_void_p, ctypes.c_int]
    lib.ohmd_close_device.argtypes = [ctypes.c_void_p]
    for name in ("ohmd_device_getf", "ohmd_device_setf"):
        getattr(lib, name).argtypes = [ctypes.c_void_p, ctypes.c_int,
                                       ctypes.POINTER(ctypes.c_float)]  # fmt: skip
    lib.ohmd_device_geti.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.POINTER(ctypes.c_int)]
    return lib


class OpenHMD:
    """The first head-mounted display OpenHMD finds; its null HMD when there is none (or with
    null=True)."""

    def __init__(self, null: bool = False) -> None:
        self._lib = _library()
        self._ctx = self._lib.ohmd_ctx_create()
        if not self._ctx:
            raise HmdError("OpenHMD could not create a context")
        count = self._lib.ohmd_ctx_probe(self._ctx)
        hmds = []
        for i in range(count):
            kind = ctypes.c_int(-1)
            self._lib.ohmd_list_geti(self._ctx, i, _DEVICE_CLASS, ctypes.byref(kind))
            product = (self._lib.ohmd_list_gets(self._ctx, i, _PRODUCT) or b"").decode()
            path = (self._lib.ohmd_list_gets(self._ctx, i, _PATH) or b"").decode()
            if kind.value == _CLASS_HMD:
                hmds.append((i, product, path))
        # OpenHMD's virtual devices (its null HMD, its "External Device" fed by the caller)
        # have no path; hardware has its USB path.
        real = [h for h in hmds if h[2] not in ("", "(none)")]
        nulls = [h for h in hmds if "null" in h[1].lower()]
        choice = (nulls if null else real or nulls) or []
        if not choice:
            self.close()
            raise HmdError(f"OpenHMD found no head-mounted display among {count} device(s)")
        index, self.name, _ = choice[0]
        self.null = "null" in self.name.lower()
        self._device = self._lib.ohmd_list_open_device(self._ctx, index)
        if not self._device:
            self.close()
            raise HmdError(f"OpenHMD could not open {self.name}")

    def _getf(self, what: int, count: int) -> np.ndarray:
        values = (ctypes.c_float * count)()
        if self._lib.ohmd_device_getf(self._device, what, values) != 0:
            raise HmdError(f"{self.name}: OpenHMD has no value {what}")
        return np.array(values[:], dtype=np.float64)

    def _geti(self, what: int) -> int:
        value = ctypes.c_int()
        self._lib.ohmd_device_geti(self._device, what, ctypes.byref(value))
        return value.value

    @property
    def rotation(self) -> np.ndarray:
        """The head's orientation, quaternion (x, y, z, w) in OpenHMD's (OpenGL's) frame."""
        self._lib.ohmd_ctx_update(self._ctx)
        q = self._getf(_ROTATION_QUAT, 4)
        return q / np.linalg.norm(q) if np.linalg.norm(q) > 0 else np.array([0, 0, 0, 1.0])

    def set_rotation(self, quaternion) -> None:
        """Sets the head's orientation (x, y, z, w): scripts the null device's head."""
        q = np.asarray(quaternion, dtype=np.float64)
        q = q / np.linalg.norm(q)
        values = (ctypes.c_float * 4)(*q)
        if self._lib.ohmd_device_setf(self._device, _ROTATION_QUAT, values) != 0:
            raise HmdError(f"{self.name}: its orientation cannot be set")

    @property
    def ipd(self) -> float:
        """Interpupillary distance, metres."""
        return float(self._getf(_EYE_IPD, 1)[0])

    @property
    def eye_resolution(self) -> tuple[int, int]:
        """Each eye's pixels: half the screen's width, its height."""
        return self._geti(_RESOLUTION_X) // 2, self._geti(_RESOLUTION_Y)

    def eye_intrinsics(self, eye: str) -> tuple[float, float, float]:
        """(focal length, cx, cy) in pixels of the eye's image (row 0 at the top), from
        OpenHMD's OpenGL projection of that eye."""
        p = self._getf(_LEFT_PROJECTION if eye == "left" else _RIGHT_PROJECTION, 16)
        p = p.reshape(4, 4).T  # column-major
        width, height = self.eye_resolution
        return (
            p[1, 1] * height / 2,
            width / 2 * (1 - p[0, 2]),
            height / 2 * (1 + p[1, 2]),
        )

    def lens(self) -> dict:
        """The lens distortion a window applies to each eye's image: PanoTools coefficients
        (a, b, c, d), chromatic aberration (r, g, b), and each eye's lens centre as a fraction
        of its viewport (x from the left, y from the bottom) with the normalising radius
        (fraction of the viewport's width: the centre's distance to the eye's outer edge)."""
        width, height = self._getf(_SCREEN_WIDTH_M, 1)[0] / 2, self._getf(_SCREEN_HEIGHT_M, 1)[0]
        separation = self._getf(_LENS_SEPARATION, 1)[0]
        lens_y = self._getf(_LENS_HEIGHT, 1)[0]
        left_x = width - separation / 2  # the left lens, from the left eye's outer edge
        return {
            "k": self._getf(_DISTORTION_K, 4).tolist(),
            "aberration": self._getf(_ABERRATION_K, 3).tolist(),
            "centres": [(left_x / width, lens_y / height), (1 - left_x / width, lens_y / height)],
            "radius": left_x / width,
            "aspect": width / height,
        }

    def close(self) -> None:
        if getattr(self, "_device", None):
            self._lib.ohmd_close_device(self._device)
            self._device = None
        if getattr(self, "_ctx", None):
            self._lib.ohmd_ctx_destroy(self._ctx)
            self._ctx = None

    def __enter__(self) -> OpenHMD:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def quaternion_matrix(q) -> np.ndarray:
    """3x3 rotation of a quaternion (x, y, z, w)."""
    x, y, z, w = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


class HmdView:
    """Two eye cameras for an HMD riding on a base camera, following the head (update())."""

    def __init__(self, world, hmd: OpenHMD, base, name: str = "hmd", scale: float = 1.0):
        self.hmd, self.base, self.world = hmd, base, world
        width, height = (max(1, int(round(v * scale))) for v in hmd.eye_resolution)
        self.cameras = []
        for eye in ("left", "right"):
            focal, cx, cy = (v * scale for v in hmd.eye_intrinsics(eye))
            fov_y = 2 * math.atan(height / (2 * focal))
            camera = world.add_camera(f"{name}_{eye}", width, height, fov_y=fov_y,
                                      near=base.near, far=base.far, shadows=base.shadows,
                                      antialiasing=base.antialiasing,
                                      looks=base.looks)  # fmt: skip
            camera.principal_point = (cx, cy)
            self.cameras.append(camera)
        self.update()

    def eye_poses(self, rotation=None) -> list[np.ndarray]:
        """World-from-eye poses (OpenCV frame) for a head orientation (x, y, z, w; now if
        None): the base camera turned by the head, each eye half the IPD along the head's x."""
        q = self.hmd.rotation if rotation is None else rotation
        head = np.eye(4)
        head[:3, :3] = _GL_FROM_CV @ quaternion_matrix(q) @ _GL_FROM_CV
        poses = []
        for side in (-1.0, 1.0):
            eye = np.eye(4)
            eye[0, 3] = side * self.hmd.ipd / 2
            poses.append(self.base.pose @ head @ eye)
        return poses

    def update(self) -> None:
        """The eyes where the head now looks."""
        for camera, pose in zip(self.cameras, self.eye_poses()):
            camera.pose = pose

    def lens(self) -> dict:
        return self.hmd.lens()


def xr_eye_geometry(fov, size, scale: float = 1.0) -> tuple[int, int, float, float, float]:
    """(width, height, fov_y, cx, cy) of a camera with square pixels covering an OpenXR eye's
    field of view (angles left, right, up, down in radians; left and down negative) for a
    swapchain image of size (width, height), its height times scale."""
    left, right, up, down = (math.tan(a) for a in fov)
    if not (right > left and up > down):
        raise ValueError(f"an eye's field of view must open right and up, got {list(fov)}")
    height = max(1, int(round(size[1] * scale)))
    focal = height / (up - down)
    width = max(1, int(round(focal * (right - left))))
    return width, height, 2 * math.atan(height / (2 * focal)), -left * focal, up * focal


class XrView:
    """Two eye cameras riding on a base camera where an OpenXR session's eyes are (update()
    each frame with wait_frame()'s eyes). The cameras exist after the first update."""

    def __init__(self, world, base, name: str = "openxr", scale: float = 1.0):
        self.world, self.base, self.name, self.scale = world, base, name, scale
        self.cameras: list = []
        self._made = 0

    def update(self, eyes: list[dict]) -> list:
        """Places the eye cameras (made, or made again when an eye's image changes size) and
        returns them, left then right."""
        with self.world.lock():
            shapes = [xr_eye_geometry(e["fov"], e["size"], self.scale) for e in eyes]
            if [(c.width, c.height) for c in self.cameras] != [g[:2] for g in shapes]:
                self._made += 1
                suffix = "" if self._made == 1 else f"_{self._made}"
                self.cameras = [
                    self.world.add_camera(
                        f"{self.name}_{side}{suffix}",
                        g[0],
                        g[1],
                        fov_y=g[2],
                        near=self.base.near,
                        far=self.base.far,
                        shadows=self.base.shadows,
                        antialiasing=self.base.antialiasing,
                        looks=self.base.looks,
                    )  # fmt: skip
                    for side, g in zip(("left", "right"), shapes)
                ]
            for camera, eye, g in zip(self.cameras, eyes, shapes):
                camera.fov_y = g[2]
                camera.principal_point = g[3:]
                camera.pose = self.base.pose @ np.asarray(eye["pose"])
        return self.cameras
