"""A recording as ROS 2 messages, written to MCAP (``mcap`` + ``mcap-ros2-support``) or to a
rosbag2 folder with MCAP storage (``rosbags``). Both hold the same topics and messages.

Topics (``S`` is a camera stream, e.g. ``rig_left``; ``D`` a drill; ``V`` the drilled volume):

==============================  ===========================  ==================================
topic                           type                         content
==============================  ===========================  ==================================
``/S/image_rect_color``         sensor_msgs/Image            rgb8
``/S/depth/image_rect``         sensor_msgs/Image            32FC1, metres along the optical
                                                             axis, NaN where nothing was hit
                                                             (REP 118; ``depth_no_hit="zero"``
                                                             keeps the recording's 0)
``/S/label/image``              sensor_msgs/Image            16UC1 anatomy label ids (0 = none)
``/S/instance/image``           sensor_msgs/Image            32SC1 object ids (0 = background)
``/S/voxel/image``              sensor_msgs/Image            32SC1 voxel index, -1 = none
``/S/segmentation/image``       sensor_msgs/Image            rgb8 flat segmentation colours
``/S/.../compressed``           sensor_msgs/CompressedImage  ``image_topics="compressed"`` (in-
                                                             stead of the raw ones) or "both":
                                                             each image topic's PNG (rgb8,
                                                             16UC1) or TIFF (32-bit) form,
                                                             lossless; JPEG for rgb as an option
                                                             (``ambfplus.export.images``)
``/S/camera_info``,             sensor_msgs/CameraInfo       K, P in ROS's pixel convention,
``/S/<pass>/camera_info``                                    beside every image topic (depth,
                                                             label, instance, voxel,
                                                             segmentation): the same message
``/S/points``                   sensor_msgs/PointCloud2      organised, optical frame: x y z
                                                             (float32, NaN where no hit), rgb
                                                             (packed float32), instance (int32),
                                                             label (uint16)
``/tf``                         tf2_msgs/TFMessage           world -> ``<camera>_link`` (at
                                                             their frames), bodies and drills
                                                             (every step)
``/tf_static``                  tf2_msgs/TFMessage           world -> volumes; ``<camera>_link``
                                                             -> ``<camera>_optical_frame``
``/D/wrench``                   geometry_msgs/WrenchStamped  force fed back to the device (N),
                                                             world axes; torque 0
``/drilling/removed_voxels``    sensor_msgs/PointCloud2      voxels removed in a step: x y z
                                                             (centres, volume frame V), i j k,
                                                             label
``/drilling/events``            diagnostic_msgs/             critical-structure events of a
                                DiagnosticArray              step (name, label, voxel, step)
==============================  ===========================  ==================================

Conventions: header stamps and log times are simulation time (nanoseconds since the session
started, not Unix time) by default; ``stamp="wall"`` adds the recording's wall-clock start (its
``created`` time), so that stamps are Unix time. A camera has a body frame ``<camera>_link``
(REP 103: x forward, y left, z up), posed in the world, and its child the optical frame
``<camera>_optical_frame`` (x right, y down, z forward), which stamps its images. Other frames
are named after their objects (``tf_frame``: the legend's name under its namespace, if any).
Every channel states its ``offered_qos_profiles`` as rosbag2 writes them: ``/tf_static``
reliable and transient local (latched), the others reliable and volatile. Message definitions
are ROS 2 Jazzy's (``ros_distro: jazzy``; the same for these types since Humble).
CameraInfo follows ROS: pixel centres at integer coordinates, so
``cx_ros = cx - 0.5`` and ``cy_ros = cy - 0.5`` from ambfplus's intrinsics (which centre pixel
(r, c) at (c + 0.5, r + 0.5)); R is the identity (views are rectified), no distortion; a
stereo rig's right camera has P[0, 3] = Tx = -fx * baseline and its own, shifted principal
point for an off-axis rig, so P projects points of the left optical frame into the right image.
"""

from __future__ import annotations

import functools
import heapq
import io
import json
import posixpath
from collections.abc import Iterator
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np

from .. import __version__
from ..labels import legend_index, object_key
from ..recording.values import FrameGate
from ._common import (
    LINK_FROM_OPTICAL,
    ExportError,
    StepClock,
    camera_frames,
    export_conventions,
    link_pose,
    nanoseconds,
    quaternion_xyzw,
    require,
    tf_frame,
)
from .images import COMPRESSED_IMAGE, check_image_options, compressed_image_message

WORLD = "world"
TYPESTORE = "ROS2_JAZZY"  # the message definitions (ROS 2 Jazzy's; unchanged since Humble)
ROS_DISTRO = "jazzy"  # what the files say they hold, as rosbag2 writes it
DEPTH_NO_HIT = ("nan", "zero")
STAMPS = ("sim", "wall")

# pass -> (topic suffix, ROS encoding)
IMAGE_TOPICS = {
    "rgb": ("image_rect_color", "rgb8"),
    "depth": ("depth/image_rect", "32FC1"),
    "label": ("label/image", "16UC1"),
    "instance": ("instance/image", "32SC1"),
    "voxel": ("voxel/image", "32SC1"),
    "segmentation": ("segmentation/image", "rgb8"),
}
IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
POINT_CLOUD = "sensor_msgs/msg/PointCloud2"
TF = "tf2_msgs/msg/TFMessage"
WRENCH = "geometry_msgs/msg/WrenchStamped"
DIAGNOSTICS = "diagnostic_msgs/msg/DiagnosticArray"
# sensor_msgs/PointField datatypes
FLOAT32, INT32, UINT16 = 7, 5, 4
DIAGNOSTIC_WARN, DIAGNOSTIC_ERROR = 1, 2


@dataclass(order=True)
class Message:
    """One message to write: when (ns of simulation time), where and what (a dict tree whose
    arrays are NumPy arrays, converted for each writer)."""

    time: int
    order: int
    topic: str = field(compare=False)
    msgtype: str = field(compare=False)
    body: dict = field(compare=False)


def header(time_ns: int, frame: str) -> dict:
    return {"stamp": {"sec": time_ns // 10**9, "nanosec": time_ns % 10**9}, "frame_id": frame}


def image_message(time_ns: int, frame: str, array: np.ndarray, encoding: str) -> dict:
    """A sensor_msgs/Image of an (H, W) or (H, W, C) array, little-endian."""
    array = np.ascontiguousarray(array)
    height, width = array.shape[:2]
    return {
        "header": header(time_ns, frame),
        "height": height,
        "width": width,
        "encoding": encoding,
        "is_bigendian": 0,
        "step": array.strides[0],
        "data": array.reshape(-1).view(np.uint8),
    }


def ros_intrinsics(intrinsics: np.ndarray) -> np.ndarray:
    """ambfplus's K (pixel centres at +0.5) as ROS's K (pixel centres at integers)."""
    k = np.array(intrinsics, dtype=np.float64)
    k[0, 2] -= 0.5
    k[1, 2] -= 0.5
    return k


def camera_info(time_ns, frame, width, height, intrinsics, tx: float = 0.0) -> dict:
    """A sensor_msgs/CameraInfo: rectified, no distortion; tx = -fx * baseline for the right
    camera of a stereo pair (0 otherwise)."""
    k = ros_intrinsics(intrinsics)
    p = np.zeros((3, 4))
    p[:, :3] = k
    p[0, 3] = tx
    return {
        "header": header(time_ns, frame),
        "height": int(height),
        "width": int(width),
        "distortion_model": "plumb_bob",
        "d": np.zeros(5),
        "k": k.reshape(-1),
        "r": np.eye(3).reshape(-1),
        "p": p.reshape(-1),
        "binning_x": 0,
        "binning_y": 0,
        "roi": {"x_offset": 0, "y_offset": 0, "height": 0, "width": 0, "do_rectify": False},
    }


def transform(time_ns: int, parent: str, child: str, pose: np.ndarray) -> dict:
    """A geometry_msgs/TransformStamped: child's pose in parent (parent-from-child)."""
    q = quaternion_xyzw(pose[:3, :3])
    t = pose[:3, 3]
    return {
        "header": header(time_ns, parent),
        "child_frame_id": child,
        "transform": {
            "translation": {"x": float(t[0]), "y": float(t[1]), "z": float(t[2])},
            "rotation": {"x": float(q[0]), "y": float(q[1]), "z": float(q[2]), "w": float(q[3])},
        },
    }


def point_cloud(time_ns: int, frame: str, columns: dict, height: int, width: int) -> dict:
    """A sensor_msgs/PointCloud2 from named columns (x, y, z, rgb, instance, label; each of
    height * width values), packed in that order."""
    kinds = {"x": ("<f4", FLOAT32), "y": ("<f4", FLOAT32), "z": ("<f4", FLOAT32),
             "rgb": ("<f4", FLOAT32), "i": ("<i4", INT32), "j": ("<i4", INT32),
             "k": ("<i4", INT32), "instance": ("<i4", INT32), "label": ("<u2", UINT16)}  # fmt: skip
    names = [n for n in kinds if n in columns]
    dtype: np.dtype = np.dtype([(n, kinds[n][0]) for n in names])
    offsets = {n: dtype.fields[n][1] for n in names} if dtype.fields else {}
    packed = np.empty(height * width, dtype=dtype)
    fields = []
    for name in names:
        packed[name] = np.asarray(columns[name]).reshape(-1)
        fields.append({"name": name, "offset": offsets[name],
                       "datatype": kinds[name][1], "count": 1})  # fmt: skip
    has_nan = any(np.isnan(packed[n]).any() for n in ("x", "y", "z") if n in names)
    return {
        "header": header(time_ns, frame),
        "height": height,
        "width": width,
        "fields": fields,
        "is_bigendian": False,
        "point_step": dtype.itemsize,
        "row_step": dtype.itemsize * width,
        "data": packed.view(np.uint8),
        "is_dense": not has_nan,
    }


def packed_rgb(rgb: np.ndarray) -> np.ndarray:
    """RGB uint8 (..., 3) as PCL's packed float32 (0x00RRGGBB reinterpreted)."""
    rgb = rgb.astype(np.uint32)
    packed = (rgb[..., 0] << 16) | (rgb[..., 1] << 8) | rgb[..., 2]
    return packed.view(np.float32)


def camera_points(frame) -> np.ndarray:
    """(H, W, 3) camera-frame points of a recorded frame: its points pass where recorded, else
    depth back-projected through its intrinsics (pixel centres at +0.5); NaN where no hit."""
    depth = np.asarray(frame.depth, dtype=np.float32)
    if frame.points is not None:
        points = np.array(frame.points, dtype=np.float32)
    else:
        rays = _rays(depth.shape, tuple(np.asarray(frame.intrinsics).ravel()))
        points = rays * depth[..., None]
    points[depth <= 0] = np.nan
    return points


@functools.lru_cache(maxsize=8)
def _rays(shape: tuple[int, int], k: tuple) -> np.ndarray:
    """(H, W, 3) float32 rays (z = 1) through the pixel centres (c + 0.5, r + 0.5)."""
    h, w = shape
    x = ((np.arange(w) + 0.5 - k[2]) / k[0]).astype(np.float32)
    y = ((np.arange(h) + 0.5 - k[5]) / k[4]).astype(np.float32)
    rays = np.ones((h, w, 3), np.float32)
    rays[..., 0] = x[None, :]
    rays[..., 1] = y[:, None]
    rays.setflags(write=False)
    return rays


def check_ros_options(depth_no_hit: str, stamp: str) -> None:
    """Raises ExportError for a depth_no_hit or stamp that is not one of the known values."""
    if depth_no_hit not in DEPTH_NO_HIT:
        raise ExportError(f"depth_no_hit (--depth-no-hit) is one of {', '.join(DEPTH_NO_HIT)}, "
                          f"not {depth_no_hit!r}")  # fmt: skip
    if stamp not in STAMPS:
        raise ExportError(f"stamp (--stamp) is one of {', '.join(STAMPS)}, not {stamp!r}")


def wall_clock_start(recording) -> int:
    """The recording's wall-clock start (its ``created`` attribute, ISO 8601; UTC where it
    names no zone) as integer nanoseconds since the Unix epoch."""
    created = recording.created
    try:
        when = datetime.fromisoformat(str(created))
    except ValueError:
        when = None
    if not created or when is None:
        raise ExportError(f"{recording.path}: stamp 'wall' (--stamp wall) needs the recording's "
                          f"wall-clock start, an ISO 8601 'created' time; it has {created!r}: "
                          "export with stamp 'sim'")  # fmt: skip
    if when.tzinfo is None:
        when = when.replace(tzinfo=timezone.utc)
    since = when - datetime(1970, 1, 1, tzinfo=timezone.utc)
    return (since.days * 86400 + since.seconds) * 10**9 + since.microseconds * 1000


def info_topics(stream: str, passes) -> list[str]:
    """The CameraInfo topics of a stream: ``/S/camera_info`` and one beside every other image
    topic (``/S/depth/camera_info`` beside ``/S/depth/image_rect``), as image_transport pairs
    them."""
    topics = [f"/{stream}/camera_info"]
    for pass_name in passes:
        if pass_name in IMAGE_TOPICS:
            topic = posixpath.join(posixpath.dirname(f"/{stream}/{IMAGE_TOPICS[pass_name][0]}"),
                                   "camera_info")  # fmt: skip
            if topic not in topics:
                topics.append(topic)
    return topics


def depth_with_nan(depth: np.ndarray) -> np.ndarray:
    """A depth image with NaN where nothing was hit (recorded as 0), as REP 118 asks."""
    depth = np.asarray(depth, dtype=np.float32)
    return np.where(depth > 0, depth, np.float32(np.nan))


def qos_profiles(topic: str) -> list:
    """The offered QoS of a topic, as rosbags' Qos: /tf_static latched (reliable, transient
    local, keep last 1), the others reliable, volatile, keep last 10."""
    interfaces = require("export", "rosbags.interfaces")
    latched = topic == "/tf_static"
    zero = interfaces.QosTime(0, 0)
    return [interfaces.Qos(
        interfaces.QosHistory.KEEP_LAST, 1 if latched else 10,
        interfaces.QosReliability.RELIABLE,
        interfaces.QosDurability.TRANSIENT_LOCAL if latched else interfaces.QosDurability.VOLATILE,
        zero, zero, interfaces.QosLiveliness.AUTOMATIC, zero, False,
    )]  # fmt: skip


def qos_yaml(topic: str) -> str:
    """The ``offered_qos_profiles`` text of a topic, as rosbag2 (format 9) and rosbags write
    it into an MCAP channel's metadata."""
    metadata, yaml = require("export", "rosbags.rosbag2.metadata", "ruamel.yaml")
    stream = io.StringIO()
    dumper = yaml.YAML(typ="safe")
    dumper.default_flow_style = False
    dumper.dump(metadata.dump_qos_v9(qos_profiles(topic)), stream)
    return stream.getvalue().strip()


class RosExport:
    """Turns a recording into time-ordered ROS 2 messages (see the module docstring)."""

    def __init__(self, recording, *, point_clouds: bool = True, image_topics: str = "raw",
                 rgb_codec: str = "png", jpeg_quality: int = 90, depth_no_hit: str = "nan",
                 stamp: str = "sim", bad_frames: str = "refuse") -> None:  # fmt: skip
        check_image_options(image_topics, rgb_codec, jpeg_quality)
        check_ros_options(depth_no_hit, stamp)
        self.rec = recording
        self.gate = FrameGate(recording, bad_frames, ExportError)
        self.depth_no_hit, self.stamp = depth_no_hit, stamp
        # ns added to simulation time: the recording's wall-clock start for stamp "wall".
        self.offset = wall_clock_start(recording) if stamp == "wall" else 0
        self.point_clouds = point_clouds
        self.raw_images = image_topics in ("raw", "both")
        self.compressed_images = image_topics in ("compressed", "both")
        self.rgb_codec, self.jpeg_quality = rgb_codec, jpeg_quality
        self.clock = StepClock(recording)
        self.legend = recording.legend
        self.names = legend_index(self.legend)
        self.warnings: list[str] = []
        self._stereo = self._stereo_partners()
        self._check()

    # What is in it ---------------------------------------------------------------------------

    def _check(self) -> None:
        for name, stream in self.rec.cameras.items():
            if "depth" not in stream.passes and self.point_clouds:
                self.warnings.append(f"stream {name} has no depth: no point cloud for it")
        removed = self.rec.removed
        for entry in self.legend.values():
            name = entry.get("name")
            if entry.get("kind") == "volume" and "pose" not in entry:
                self.warnings.append(f"the legend has no pose of volume {name}: no transform "
                                     "from world to it")  # fmt: skip
        if len(removed["step"]) and self._volume_geometry(removed["volume"]) is None:
            raise ExportError(
                f"{self.rec.path}: the removal log's volume {removed['volume']!r} has no "
                "dimensions and shape in the legend, so its voxels cannot be placed (record "
                "with Recorder.set_legend(world))"
            )

    def _stereo_partners(self) -> dict:
        """stream -> (left stream, rig name) for the right stream of each rig, with the
        baseline of each of its frames."""
        partners = {}
        for rig_name, rig in self.rec.rigs.items():
            right = rig.right.name
            baselines = np.full(len(rig.right), np.nan)
            baselines[np.asarray(rig.right_index[:], dtype=np.int64)] = rig.baseline[:]
            partners[right] = (rig.left.name, rig_name, baselines)
        return partners

    def _volume_geometry(self, name):
        entry = self.names.get(name)
        if not entry or "dimensions" not in entry or "shape" not in entry:
            return None
        return np.asarray(entry["dimensions"], float), np.asarray(entry["shape"], int)

    def _frame(self, name: str) -> str:
        """The TF frame of a legend object: its key where the legend gives one (an object under
        a namespace: ``psm1/baselink``), else its name under the legend's namespace, if any."""
        entry = self.names.get(name) or {}
        if entry.get("key"):
            return tf_frame(entry["key"])
        return tf_frame(name, entry.get("namespace") or "")

    def _camera_frames(self, stream) -> tuple[str, str]:
        """(body, optical) frames of a stream's camera."""
        entry = self.names.get(stream.camera) or {}
        return camera_frames(stream.camera, entry.get("namespace") or "")

    def _camera_frame(self, stream) -> str:
        return self._camera_frames(stream)[1]

    def _ns(self, seconds) -> int:
        """A stamp and log time (ns) of a simulation time (s): see ``stamp``."""
        return nanoseconds(seconds) + self.offset

    def _pose_columns(self) -> dict[str, np.ndarray]:
        """Step-log pose columns of objects other than recorded cameras: name -> (N, 4, 4)."""
        filmed = {object_key(self.names, s.camera) for s in self.rec.cameras.values()}
        out = {}
        for column, values in self.rec.steps.items():
            if not column.endswith(".pose") or values.ndim != 3 or values.shape[1:] != (4, 4):
                continue
            name = column[: -len(".pose")]
            if object_key(self.names, name) in filmed:
                continue  # cameras are placed where their frames were taken
            out[name] = values
        return out

    def _kind(self, name: str) -> str:
        return (self.names.get(name) or {}).get("kind", "body")

    def topics(self) -> dict[str, str]:
        """topic -> message type, for everything this export writes."""
        out = {}
        for name, stream in self.rec.cameras.items():
            for pass_name in stream.passes:
                if pass_name in IMAGE_TOPICS:
                    topic = f"/{name}/{IMAGE_TOPICS[pass_name][0]}"
                    if self.raw_images:
                        out[topic] = IMAGE
                    if self.compressed_images:
                        out[f"{topic}/compressed"] = COMPRESSED_IMAGE
            for topic in info_topics(name, stream.passes):
                out[topic] = CAMERA_INFO
            if self.point_clouds and "depth" in stream.passes:
                out[f"/{name}/points"] = POINT_CLOUD
        if self.rec.cameras or self._pose_columns():
            out["/tf"] = TF
        if self.rec.cameras or self._static_poses():
            out["/tf_static"] = TF
        for drill in self._drills():
            out[f"/{drill}/wrench"] = WRENCH
        if len(self.rec.removed["step"]):
            out["/drilling/removed_voxels"] = POINT_CLOUD
        if self.rec.events:
            out["/drilling/events"] = DIAGNOSTICS
        return out

    def _drills(self) -> list[str]:
        steps = self.rec.steps
        return [
            n for n in dict.fromkeys(e.get("key") or e.get("name") for e in self.legend.values())
            if self._kind(n) == "drill" and f"{n}.force" in steps
        ]  # fmt: skip

    def _static_poses(self) -> dict[str, np.ndarray]:
        """Volumes whose pose the legend holds and the step log does not: fixed."""
        logged = self._pose_columns()
        return {
            key: np.asarray(entry["pose"], dtype=np.float64)
            for entry in self.legend.values()
            if entry.get("kind") == "volume" and "pose" in entry
            and (key := entry.get("key") or entry.get("name")) not in logged
        }  # fmt: skip

    def describe(self) -> dict:
        """The export's own metadata: conventions, topics, frames, legend, warnings."""
        topics = self.topics()
        frames = {WORLD: "the simulation's world frame (right-handed, z up)"}
        for s in self.rec.cameras.values():
            link, optical = self._camera_frames(s)
            frames[link] = (f"body frame of camera {s.camera} (REP 103 axes: x forward, y "
                            "left, z up), posed in the world")  # fmt: skip
            frames[optical] = (f"optical frame of camera {s.camera} (OpenCV axes: x right, y "
                               f"down, z forward), child of {link}; stamps its images")  # fmt: skip
        frames.update({self._frame(n): f"{self._kind(n)} {n}" for n in self._pose_columns()})
        frames.update({
            self._frame(n): f"volume {n} (centred on its grid; voxel (i, j, k) centre at "
            "(i + 0.5) s - D / 2 along x, y, z)"
            for n in self._static_poses()
        })  # fmt: skip
        return {
            **export_conventions(self.rec),
            "message_definitions": f"ROS 2 {ROS_DISTRO} ({TYPESTORE} type store of rosbags)",
            "ros_distro": ROS_DISTRO,
            "time_stamps": self._stamp_description(),
            "qos": "offered_qos_profiles on every topic: /tf_static reliable, transient local "
            "(latched), keep last 1; the others reliable, volatile, keep last 10",
            "pixel_convention": "CameraInfo K and P centre pixels on integers (ROS, OpenCV): "
            "cx_ros = cx_ambfplus - 0.5, cy_ros = cy_ambfplus - 0.5",
            "stereo": "the right camera's P has Tx = -fx * baseline and its own principal "
            "point (shifted for an off-axis rig); P maps left-optical-frame points to right "
            "pixels",
            "encodings": "rgb8 colour and segmentation; 32FC1 depth in metres ("
            + ("NaN = no hit, REP 118" if self.depth_no_hit == "nan" else "0 = no hit")
            + "); 16UC1 label ids; 32SC1 instance ids and voxel indices (-1 = none)",
            "camera_info": "sensor_msgs/CameraInfo beside every image topic of a camera (the "
            "same K, P, frame and stamp)",
            "compressed_images": self._compressed_description(),
            "point_clouds": "organised, optical frame, NaN where nothing was hit; rgb packed "
            "0x00RRGGBB as float32",
            "wrench": "the force the drill feeds back to the device (N), world axes; torque 0",
            "topics": json.dumps(topics, sort_keys=True),
            "frames": json.dumps(frames, sort_keys=True),
            "legend": json.dumps({str(k): v for k, v in self.legend.items()}, sort_keys=True),
            "recording_metadata": json.dumps(self.rec.metadata, sort_keys=True, default=str),
            "warnings": json.dumps(self.warnings),
        }

    def _stamp_description(self) -> str:
        if self.stamp == "wall":
            return (f"header stamps and log times are Unix time in nanoseconds: the recording's "
                    f"wall-clock start ({self.rec.created}) plus simulation time")  # fmt: skip
        return ("header stamps and log times are simulation time in nanoseconds since the "
                "session started (not Unix time)")  # fmt: skip

    def _compressed_description(self) -> str:
        if not self.compressed_images:
            return "none (raw sensor_msgs/Image topics only)"
        rgb = ("JPEG, quality " + str(self.jpeg_quality) + " (lossy)" if self.rgb_codec == "jpeg"
               else "PNG (lossless)")  # fmt: skip
        return (
            "sensor_msgs/CompressedImage on <image topic>/compressed, format 'ORIG_PIXFMT; "
            f"CODEC compressed [PIXFMT]' as image_transport's compressed plugin: rgb {rgb}; "
            "segmentation PNG and 16UC1 labels 16-bit PNG (lossless); 32FC1 depth and 32SC1 "
            "ids 32-bit TIFF with deflate (lossless)"
        )

    def frames(self) -> int:
        """Frames written (once written: those skipped for their values are not)."""
        return sum(len(s) for s in self.rec.cameras.values()) - self.gate.skipped_frames

    # The messages ----------------------------------------------------------------------------

    def messages(self) -> Iterator[Message]:
        """Every message, in order of simulation time."""
        sources = [self._camera_messages(s) for s in self.rec.cameras.values()]
        sources += [self._camera_tf(), self._step_tf(), self._static_tf(), self._wrenches(),
                    self._removed(), self._events()]  # fmt: skip
        return heapq.merge(*sources)

    def _camera_messages(self, stream) -> Iterator[Message]:
        frame_id = self._camera_frame(stream)
        partner = self._stereo.get(stream.name)
        infos = info_topics(stream.name, stream.passes)
        for index in range(len(stream)):
            frame = stream[index]
            if not self.gate.frame_ok(stream.name, index, frame):
                continue
            t = self._ns(frame.time)
            for pass_name in stream.passes:
                if pass_name not in IMAGE_TOPICS:
                    continue
                suffix, encoding = IMAGE_TOPICS[pass_name]
                topic, image = f"/{stream.name}/{suffix}", getattr(frame, pass_name)
                if pass_name == "depth" and self.depth_no_hit == "nan":
                    image = depth_with_nan(image)
                if self.raw_images:
                    yield Message(t, 1, topic, IMAGE, image_message(t, frame_id, image, encoding))
                if self.compressed_images:
                    codec = self.rgb_codec if pass_name == "rgb" else "png"
                    body = compressed_image_message(header(t, frame_id), image, encoding, codec,
                                                    self.jpeg_quality)  # fmt: skip
                    yield Message(t, 1, f"{topic}/compressed", COMPRESSED_IMAGE, body)
            tx = 0.0
            if partner is not None:
                baseline = partner[2][index]
                if np.isnan(baseline):
                    raise ExportError(
                        f"{self.rec.path}: frame {index} of {stream.name} (the right camera of "
                        f"rig {partner[1]}) belongs to no stereo pair; its P has no baseline"
                    )
                tx = -frame.intrinsics[0, 0] * baseline
            body = camera_info(t, frame_id, frame.width, frame.height, frame.intrinsics, tx)
            for topic in infos:
                yield Message(t, 1, topic, CAMERA_INFO, body)
            if self.point_clouds and frame.depth is not None:
                yield Message(t, 1, f"/{stream.name}/points", POINT_CLOUD,
                              self._cloud(t, frame_id, frame))  # fmt: skip

    def _cloud(self, t: int, frame_id: str, frame) -> dict:
        points = camera_points(frame)
        h, w = points.shape[:2]
        columns = {"x": points[..., 0], "y": points[..., 1], "z": points[..., 2]}
        if frame.rgb is not None:
            columns["rgb"] = packed_rgb(frame.rgb)
        if frame.instance is not None:
            columns["instance"] = frame.instance
        if frame.label is not None:
            columns["label"] = frame.label
        return point_cloud(t, frame_id, columns, h, w)

    def _camera_tf(self) -> Iterator[Message]:
        """world -> each camera's body frame at the times its frames were taken (one message
        per time, holding every camera filmed then); its optical frame is on /tf_static."""
        by_time: dict[int, list] = {}
        for stream in self.rec.cameras.values():
            times, poses = stream.time[:], stream.pose[:]
            link = self._camera_frames(stream)[0]
            for index, (time, pose) in enumerate(zip(times, poses)):
                if self.gate.pose_ok(stream.name, index):
                    by_time.setdefault(self._ns(time), []).append((link, link_pose(pose)))
        for t in sorted(by_time):
            transforms = [transform(t, WORLD, child, pose) for child, pose in by_time[t]]
            yield Message(t, 0, "/tf", TF, {"transforms": transforms})

    def _step_tf(self) -> Iterator[Message]:
        columns = self._pose_columns()
        if not columns:
            return
        steps = self.rec.steps
        times = steps["time"]
        names = sorted(columns)
        frames = [self._frame(n) for n in names]
        for row in range(len(times)):
            if not self.gate.step_ok(row):
                continue
            t = self._ns(times[row])
            transforms = [
                transform(t, WORLD, frame, columns[n][row]) for n, frame in zip(names, frames)
            ]
            yield Message(t, 0, "/tf", TF, {"transforms": transforms})

    def _static_tf(self) -> Iterator[Message]:
        """One latched message at the start: world -> fixed volumes, and each camera's body
        frame -> its optical frame."""
        t = self._ns(0.0)
        transforms = [transform(t, WORLD, self._frame(name), pose)
                      for name, pose in sorted(self._static_poses().items())]  # fmt: skip
        for stream in self.rec.cameras.values():
            link, optical = self._camera_frames(stream)
            transforms.append(transform(t, link, optical, LINK_FROM_OPTICAL))
        if transforms:
            yield Message(t, 0, "/tf_static", TF, {"transforms": transforms})

    def _wrenches(self) -> Iterator[Message]:
        steps = self.rec.steps
        drills = self._drills()
        if not drills:
            return
        times = steps["time"]
        forces = {d: steps[f"{d}.force"] for d in drills}
        for row in range(len(times)):
            if not self.gate.step_ok(row):
                continue
            t = self._ns(times[row])
            for drill in drills:
                f = forces[drill][row]
                body = {
                    "header": header(t, WORLD),
                    "wrench": {
                        "force": {"x": float(f[0]), "y": float(f[1]), "z": float(f[2])},
                        "torque": {"x": 0.0, "y": 0.0, "z": 0.0},
                    },
                }
                yield Message(t, 2, f"/{drill}/wrench", WRENCH, body)

    def _removed(self) -> Iterator[Message]:
        removed = self.rec.removed
        if not len(removed["step"]):
            return
        volume = removed["volume"]
        dimensions, shape = self._volume_geometry(volume)
        size = dimensions / shape
        steps = removed["step"]
        bounds = np.flatnonzero(np.diff(steps)) + 1
        starts, stops = np.r_[0, bounds], np.r_[bounds, len(steps)]
        times = self.clock(steps[starts])
        for start, stop, time in zip(starts, stops, times):
            voxels = removed["voxel"][start:stop].astype(np.int64)
            centres = (voxels + 0.5) * size - dimensions / 2
            columns = {"x": centres[:, 0], "y": centres[:, 1], "z": centres[:, 2],
                       "i": voxels[:, 0], "j": voxels[:, 1], "k": voxels[:, 2],
                       "label": removed["label"][start:stop]}  # fmt: skip
            t = self._ns(time)
            cloud = point_cloud(t, self._frame(volume), columns, 1, stop - start)
            yield Message(t, 3, "/drilling/removed_voxels", POINT_CLOUD, cloud)

    def _events(self) -> Iterator[Message]:
        events = self.rec.events
        if not events:
            return
        volume = self.rec.removed["volume"]
        labels = (self.names.get(volume) or {}).get("labels", {})
        by_step: dict[int, list] = {}
        for event in events:
            by_step.setdefault(event["step"], []).append(event)
        for step in sorted(by_step):
            t = self._ns(float(self.clock([step])[0]))
            statuses = []
            for event in by_step[step]:
                name = (labels.get(event["label"]) or {}).get("name", f"label {event['label']}")
                voxel = event["voxel"]
                statuses.append({
                    "level": DIAGNOSTIC_ERROR if event["kind"] == "critical" else DIAGNOSTIC_WARN,
                    "name": event["kind"],
                    "message": f"{event['kind']}: {name} (label {event['label']}) at voxel "
                    f"{tuple(voxel)}",
                    "hardware_id": volume or "",
                    "values": [{"key": k, "value": str(v)} for k, v in (
                        ("step", step), ("kind", event["kind"]), ("label", event["label"]),
                        ("label_name", name), ("voxel_i", voxel[0]), ("voxel_j", voxel[1]),
                        ("voxel_k", voxel[2]))],
                })  # fmt: skip
            yield Message(t, 4, "/drilling/events", DIAGNOSTICS,
                          {"header": header(t, self._frame(volume) if volume else WORLD),
                           "status": statuses})  # fmt: skip


# Writers --------------------------------------------------------------------------------------


def typestore():
    """rosbags' type store of the message definitions used here."""
    typesys = require("export", "rosbags.typesys")
    return typesys.get_typestore(getattr(typesys.Stores, TYPESTORE))


_NUMPY_TYPES = {"bool": np.bool_, "byte": np.uint8, "char": np.uint8, "int8": np.int8,
                "uint8": np.uint8, "int16": np.int16, "uint16": np.uint16, "int32": np.int32,
                "uint32": np.uint32, "int64": np.int64, "uint64": np.uint64,
                "float32": np.float32, "float64": np.float64}  # fmt: skip


def for_rosbags(store, value, msgtype: str):
    """A message tree as a rosbags message object of the type store."""
    _, fields = store.fielddefs[msgtype]
    values = {}
    for name, (node, detail) in fields:
        raw = value.get(name) if isinstance(value, dict) else None
        values[name] = _rosbags_field(store, node.name, detail, raw)
    return store.types[msgtype](**values)


def _rosbags_field(store, node: str, detail, raw):
    if node == "BASE":
        kind = detail[0]
        if kind == "string":
            return "" if raw is None else str(raw)
        return _NUMPY_TYPES[kind](0 if raw is None else raw).item()
    if node == "NAME":
        return for_rosbags(store, raw or {}, detail)
    (inner, inner_detail), _ = detail
    if inner.name == "BASE" and inner_detail[0] != "string":
        dtype = _NUMPY_TYPES[inner_detail[0]]
        if raw is None:
            return np.empty(0, dtype)
        return np.frombuffer(raw, dtype) if isinstance(raw, bytes) else np.asarray(raw, dtype)
    return [_rosbags_field(store, inner.name, inner_detail, item) for item in (raw or [])]


class McapSink:
    """Writes messages to an MCAP file (``mcap``) as ROS 2 CDR (serialised by rosbags), with
    each channel's ``offered_qos_profiles`` and no empty summary group (no attachment index:
    the file holds no attachments)."""

    def __init__(self, path: Path, compression: str | None = "zstd") -> None:
        mcap_writer = require("export", "mcap.writer")
        kinds = {"zstd": "ZSTD", "lz4": "LZ4", None: "NONE"}
        if compression not in kinds:
            raise ExportError(f"MCAP compression is zstd, lz4 or None, not {compression!r}")
        indexes = mcap_writer.IndexType
        self._file = open(path, "wb")  # noqa: SIM115 (closed by close())
        self._writer = mcap_writer.Writer(
            self._file,
            chunk_size=4 * 1024 * 1024,
            compression=getattr(mcap_writer.CompressionType, kinds[compression]),
            index_types=indexes.CHUNK | indexes.MESSAGE | indexes.METADATA,
        )
        self._writer.start(profile="ros2", library=f"ambfplus {__version__} ({ROS_DISTRO})")
        self._store = typestore()
        self._schemas: dict[str, int] = {}
        self._channels: dict[str, int] = {}
        self._sequence: dict[str, int] = {}

    def _channel(self, topic: str, msgtype: str) -> int:
        channel = self._channels.get(topic)
        if channel is None:
            schema = self._schemas.get(msgtype)
            if schema is None:
                text, _ = self._store.generate_msgdef(msgtype, ros_version=2)
                schema = self._schemas[msgtype] = self._writer.register_schema(
                    msgtype, "ros2msg", text.encode()
                )
            channel = self._channels[topic] = self._writer.register_channel(
                topic, "cdr", schema, metadata={"offered_qos_profiles": qos_yaml(topic)}
            )
        return channel

    def write(self, message: Message) -> None:
        channel = self._channel(message.topic, message.msgtype)
        body = for_rosbags(self._store, message.body, message.msgtype)
        data = self._store.serialize_cdr(body, message.msgtype)
        sequence = self._sequence.get(message.topic, 0)
        self._sequence[message.topic] = sequence + 1
        self._writer.add_message(channel, log_time=message.time, data=bytes(data),
                                 publish_time=message.time, sequence=sequence)  # fmt: skip

    def close(self, metadata: dict[str, str]) -> None:
        try:
            self._writer.add_metadata("ambfplus", metadata)
            self._writer.finish()
        finally:
            self._file.close()

    def abort(self) -> None:
        self._file.close()


def _rosbag2_writer(rosbag2, path: Path, name: str):
    """rosbags' rosbag2 writer, naming its MCAP file ``<name>_0.mcap`` as ROS 2 does (rosbags
    names it after the folder, which is a temporary one here) and stating ``ros_distro``."""
    plugins = rosbag2.Writer.STORAGE_PLUGINS
    storage: Any = plugins[rosbag2.StoragePlugin.MCAP]

    class NamedStorage(storage):
        def __init__(self, folder: Path, compression) -> None:
            super().__init__(folder, compression)
            target: Path = folder / f"{name}_0.mcap"
            # Open for writing: the name changes, the file and its handle stay.
            Path(folder / f"{folder.name}.mcap").rename(target)
            self.path = target

        def close(self, version: int, metadata: str) -> None:
            super().close(version, with_ros_distro(metadata))

    class Writer(rosbag2.Writer):
        STORAGE_PLUGINS = {**plugins, rosbag2.StoragePlugin.MCAP: NamedStorage}

    return Writer(path, version=9, storage_plugin=rosbag2.StoragePlugin.MCAP)


def with_ros_distro(text: str, key: str | None = None) -> str:
    """rosbag2 metadata (YAML) with ``ros_distro`` set to ROS_DISTRO (under ``key`` where
    given); rosbags writes its own name there."""
    yaml = require("export", "ruamel.yaml")
    loader = yaml.YAML(typ="safe")
    loader.default_flow_style = False
    data = loader.load(text)
    (data[key] if key else data)["ros_distro"] = ROS_DISTRO
    stream = io.StringIO()
    loader.dump(data, stream)
    return stream.getvalue() if key else stream.getvalue().strip()


class Rosbag2Sink:
    """Writes messages to a rosbag2 folder as ROS 2 names its files (``metadata.yaml`` and
    ``<name>_0.mcap``, zstd chunks) with rosbags, which also serialises them (CDR)."""

    def __init__(self, path: Path, topics: dict[str, str], name: str | None = None) -> None:
        rosbag2 = require("export", "rosbags.rosbag2")
        self._store = typestore()
        self._path = path
        self._writer = _rosbag2_writer(rosbag2, path, name or path.name)
        self._writer.set_compression(rosbag2.CompressionMode.STORAGE,
                                     rosbag2.CompressionFormat.ZSTD)  # fmt: skip
        self._writer.open()
        self._connections = {
            topic: self._writer.add_connection(topic, msgtype, typestore=self._store,
                                               offered_qos_profiles=qos_profiles(topic))
            for topic, msgtype in topics.items()
        }  # fmt: skip

    def write(self, message: Message) -> None:
        body = for_rosbags(self._store, message.body, message.msgtype)
        data = self._store.serialize_cdr(body, message.msgtype)
        self._writer.write(self._connections[message.topic], message.time, data)

    def close(self, metadata: dict[str, str]) -> None:
        for key, value in metadata.items():
            self._writer.set_custom_data(f"ambfplus.{key}", value)
        self._writer.close()
        yaml_path = self._path / "metadata.yaml"
        yaml_path.write_text(with_ros_distro(yaml_path.read_text(), "rosbag2_bagfile_information"))

    def abort(self) -> None:
        self._writer.abort()


def write_ros(recording, out: Path, kind: str, bar, *, point_clouds: bool = True,
              compression: str | None = "zstd", image_topics: str = "raw",
              rgb_codec: str = "png", jpeg_quality: int = 90, depth_no_hit: str = "nan",
              stamp: str = "sim", bag_name: str | None = None,
              bad_frames: str = "refuse") -> dict:  # fmt: skip
    """Writes a recording as an MCAP file (kind "mcap") or a rosbag2 folder ("rosbag2") at
    ``out`` (a path that does not exist yet); returns counts per topic. ``image_topics``:
    "raw" (sensor_msgs/Image), "compressed" (sensor_msgs/CompressedImage; ``rgb_codec`` "png"
    or "jpeg" at ``jpeg_quality``) or "both". ``depth_no_hit``: "nan" (REP 118) or "zero"
    where depth saw nothing; ``stamp``: "sim" (simulation time) or "wall" (the recording's
    wall-clock start + simulation time). ``bag_name`` names a rosbag2 folder's data file
    (``<bag_name>_0.mcap``; the folder's name by default). ``bad_frames``: "refuse" (an
    ExportError at the first frame or step whose values break ``ambfplus.recording.values``'
    rules) or "skip" (left out and counted)."""
    export = RosExport(recording, point_clouds=point_clouds, image_topics=image_topics,
                       rgb_codec=rgb_codec, jpeg_quality=jpeg_quality,
                       depth_no_hit=depth_no_hit, stamp=stamp,
                       bad_frames=bad_frames)  # fmt: skip
    topics = export.topics()
    sink: McapSink | Rosbag2Sink
    if kind == "mcap":
        sink = McapSink(out, compression)
    else:
        sink = Rosbag2Sink(out, topics, bag_name)
    counts = {topic: 0 for topic in topics}
    frame_topics = {f"/{name}/camera_info" for name in recording.cameras}
    try:
        for message in export.messages():
            sink.write(message)
            counts[message.topic] += 1
            if message.topic in frame_topics:
                bar.update(1)
    except BaseException:
        sink.abort()
        raise
    sink.close(export.describe())
    return {"topics": topics, "messages": counts, "warnings": export.warnings,
            "frames": export.frames(), **export.gate.counts()}  # fmt: skip
