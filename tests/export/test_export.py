"""Exports of a recorded drilling session (ambfplus.export): MCAP and rosbag2 read back by two
other libraries than their writer, the original system's HDF5 layout read by a checker written
from the reference note, COCO masks decoded back to the instance images, datasets, bad input."""

from __future__ import annotations

import hashlib
import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest

import ambfplus
from ambfplus.recording import Recorder, open_recording
from ambfplus.scenes import drilling_phantom, orbit_view, record_session

pytest.importorskip("mcap_ros2", reason='needs pip install "ambfplus[export]"')
pytest.importorskip("rosbags", reason='needs pip install "ambfplus[export]"')
pytest.importorskip("pycocotools", reason='needs pip install "ambfplus[export]"')

from helpers.rays import pixel_rays  # noqa: E402
from mcap.reader import make_reader  # noqa: E402
from mcap_ros2.decoder import DecoderFactory  # noqa: E402
from rosbags.highlevel import AnyReader  # noqa: E402
from rosbags.typesys import Stores, get_typestore  # noqa: E402

from ambfplus.export import ExportError, MissingExtra, export  # noqa: E402

# pycocotools 2.0.11 warns under NumPy 2 when decoding; the masks are right.
pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


def drilling_session(path: Path, seed: int = 0, seconds: float = 0.8):
    """A short session at 160x120 with the paper's off-axis rig: the burr plunges into the bone
    while the rig circles; a stereo frame every 100 steps."""
    scene = drilling_phantom(resolution=64, seed=seed, width=160, height=120)
    r = scene.drill.burr_radius
    surface = scene.drill.volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))["position"]
    down = surface[2] + r - 0.002 - scene.drill.goal[2, 3]
    device = ambfplus.ScriptedDevice()
    device.set_waypoints([
        {"time": 0.0, "position": (0, 0, 0)},
        {"time": 0.2, "position": (0, 0, down + 0.004), "buttons": 1},
        {"time": 0.6, "position": (0, 0, down), "buttons": 1},
        {"time": 0.8, "position": (0.003, 0.002, down), "buttons": 1},
    ])  # fmt: skip
    return record_session(scene, path, device, seconds=seconds, capture_every=100,
                          camera_motion=orbit_view)  # fmt: skip


# A recording made from plain arrays, no rendering: 8x6 stereo frames at steps 10, 20, 30, a
# step log of the drill (pose, force, burr) at every step 1..30 and three removed voxels.
TINY_LEGEND = {
    1: {"name": "anatomy", "kind": "volume", "model": "ear", "shape": [10, 10, 10],
        "dimensions": [0.01, 0.01, 0.01], "voxel_size": [0.001, 0.001, 0.001],
        "pose": np.eye(4).tolist(), "labels": {1: {"name": "Bone", "color": [230, 220, 200]},
                                              3: {"name": "Facial_Nerve", "color": [250, 5, 9]}}},
    2: {"name": "ball", "kind": "body", "model": "tools", "color": [10, 20, 30]},
    3: {"name": "drill", "kind": "drill", "model": "tools", "burr_diameters": [0.006, 0.004]},
}  # fmt: skip
TINY_STEPS = np.arange(1, 31)


def tiny_frame(camera: str, step: int, focal: float = 6.0, x: float = 0.0) -> dict:
    rng = np.random.default_rng(step * 7 + len(camera))
    pose = np.eye(4)
    pose[0, 3] = x
    return {
        "camera": camera, "time": step * 1e-3, "step": step, "pose": pose,
        "intrinsics": np.array([[focal, 0, 4.0], [0, focal, 3.0], [0, 0, 1]]),
        "rgb": rng.integers(0, 256, (6, 8, 3), dtype=np.uint8),
        "depth": rng.uniform(0.2, 0.3, (6, 8)).astype(np.float32),
        "label": rng.choice(np.array([0, 1, 3], np.uint16), (6, 8)),  # the legend's labels
        "instance": rng.choice(np.array([0, 1, 2], np.int32), (6, 8)),
        "segmentation": rng.integers(0, 256, (6, 8, 3), dtype=np.uint8),
    }  # fmt: skip


def tiny_recording(
    path: Path,
    *,
    baselines=(0.065, 0.065, 0.065),
    focals=(6.0, 6.0, 6.0),
    passes=None,
    legend=TINY_LEGEND,
    burr=None,
    unpaired_right=False,
) -> Path:
    """A small stereo recording written with the Recorder from plain arrays (no rendering):
    each frame's baseline and left focal length as given; ``burr`` the drill's burr index at
    each step; ``unpaired_right`` adds a right-camera frame that belongs to no stereo pair."""
    from types import SimpleNamespace

    path.parent.mkdir(parents=True, exist_ok=True)
    with Recorder(path) as recorder:
        recorder.set_legend(legend)
        for index, (baseline, focal) in enumerate(zip(baselines, focals)):
            step = 10 * (index + 1)
            pair = SimpleNamespace(left=tiny_frame("rig_left", step, focal),
                                   right=tiny_frame("rig_right", step, 6.0, baseline),
                                   baseline=baseline, dcx=0.0)  # fmt: skip
            recorder.add_stereo("rig", pair, passes=passes)
        if unpaired_right:
            recorder.add_frame("rig_right", tiny_frame("rig_right", 35), passes=passes)
        n = len(TINY_STEPS)
        poses = np.tile(np.eye(4), (n, 1, 1))
        poses[:, :3, 3] = np.column_stack([TINY_STEPS * 1e-4, -TINY_STEPS * 2e-4, TINY_STEPS * 0])
        angles = TINY_STEPS * 0.05
        poses[:, 0, 0], poses[:, 0, 1] = np.cos(angles), -np.sin(angles)
        poses[:, 1, 0], poses[:, 1, 1] = np.sin(angles), np.cos(angles)
        recorder.add_steps({
            "step": TINY_STEPS, "time": TINY_STEPS * 1e-3, "drill.pose": poses,
            "drill.force": np.column_stack([TINY_STEPS * 0.1, TINY_STEPS * -0.2, TINY_STEPS * 0.3]),
            "drill.burr": np.zeros(n, np.int64) if burr is None else np.asarray(burr, np.int64),
        })  # fmt: skip
        recorder.add_removed({"step": np.array([5, 5, 22]), "label": np.array([1, 1, 3]),
                              "voxel": np.array([[1, 2, 3], [1, 2, 4], [5, 5, 5]])},
                             volume="anatomy")  # fmt: skip
    return path


def tree(folder: Path) -> dict:
    """Every path under a folder with its bytes (None for folders): what 'nothing changed'
    compares."""
    return {str(p.relative_to(folder)): (p.read_bytes() if p.is_file() else None)
            for p in sorted(folder.rglob("*"))}  # fmt: skip


@pytest.fixture(scope="module")
def session(tmp_path_factory):
    path = tmp_path_factory.mktemp("session") / "s.h5"
    summary = drilling_session(path)
    assert summary["voxels_removed"] > 0 and summary["frames"] == 8
    return path


@pytest.fixture(scope="module")
def exported(session, tmp_path_factory):
    """The session exported to MCAP and to rosbag2."""
    folder = tmp_path_factory.mktemp("ros")
    export(session, folder / "s.mcap", "mcap", progress=False)
    export(session, folder / "bag", "rosbag2", progress=False)
    return folder / "s.mcap", folder / "bag"


def read_with_mcap(path: Path) -> list[tuple[str, str, int, object]]:
    """(topic, type, log time, message) of every message, decoded by mcap-ros2-support."""
    if path.is_dir():
        path = next(path.glob("*.mcap"))
    out = []
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            out.append((channel.topic, schema.name, message.log_time, decoded))
    return out


def read_with_rosbags(path: Path) -> list[tuple[str, str, int, object]]:
    """The same, read and deserialised by rosbags."""
    store = get_typestore(Stores.ROS2_JAZZY)
    out = []
    with AnyReader([path], default_typestore=store) as reader:
        for connection, timestamp, raw in reader.messages():
            out.append((connection.topic, connection.msgtype, timestamp,
                        reader.deserialize(raw, connection.msgtype)))  # fmt: skip
    return sorted(out, key=lambda m: m[2])


def exported_image(stream, pass_name: str, index: int) -> np.ndarray:
    """A recorded pass as the ROS exports write it by default: depth NaN where nothing was
    hit (REP 118; recorded as 0), the other passes unchanged."""
    image = getattr(stream, pass_name)[index]
    return np.where(image > 0, image, np.float32(np.nan)) if pass_name == "depth" else image


def same_image(got: np.ndarray, expected: np.ndarray) -> bool:
    """Equal arrays, NaN equal to NaN (depth), dtypes too."""
    return got.dtype == expected.dtype and np.array_equal(
        got, expected, equal_nan=expected.dtype.kind == "f"
    )


def stamp_ns(message) -> int:
    return message.header.stamp.sec * 10**9 + message.header.stamp.nanosec


def image_array(message) -> np.ndarray:
    dtypes = {"rgb8": (np.uint8, 3), "32FC1": (np.float32, 1), "16UC1": (np.uint16, 1),
              "32SC1": (np.int32, 1)}  # fmt: skip
    dtype, channels = dtypes[message.encoding]
    assert message.is_bigendian == 0
    data = np.frombuffer(bytes(message.data), dtype=np.uint8)
    rows = data.reshape(message.height, message.step)
    pixels = rows[:, : message.width * channels * np.dtype(dtype).itemsize]
    shape = (message.height, message.width) + ((channels,) if channels > 1 else ())
    return np.ascontiguousarray(pixels).view(dtype).reshape(shape)


def transform_matrix(t) -> np.ndarray:
    """A TransformStamped's transform as a 4x4 matrix (its own quaternion formula)."""
    q = t.transform.rotation
    x, y, z, w = q.x, q.y, q.z, q.w
    rotation = np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip
    pose = np.eye(4)
    pose[:3, :3] = rotation
    v = t.transform.translation
    pose[:3, 3] = (v.x, v.y, v.z)
    return pose


def lookup(transforms: dict, frame: str, time: int) -> np.ndarray:
    """world-from-frame at a time, composing the transforms up to 'world'."""
    pose = np.eye(4)
    while frame != "world":
        parent, matrix = transforms[(frame, time)] if (frame, time) in transforms else (
            transforms[(frame, 0)]
        )  # fmt: skip
        pose = matrix @ pose
        frame = parent
    return pose


@pytest.mark.parametrize("reader", [read_with_mcap, read_with_rosbags])
@pytest.mark.parametrize("which", ["mcap", "rosbag2"])
def test_ros_exports_read_back_equal_to_the_recording(session, exported, reader, which):
    path = exported[0] if which == "mcap" else exported[1]
    messages = reader(path)
    by_topic: dict[str, list] = {}
    for topic, msgtype, log_time, message in messages:
        by_topic.setdefault(topic, []).append((msgtype, log_time, message))
        if hasattr(message, "header"):
            assert stamp_ns(message) == log_time  # stamps are the simulation time
    with open_recording(session) as rec:
        rig = rec.rigs["rig"]
        assert abs(rig.dcx[0]) > 10  # the off-axis rig
        steps = rec.steps
        # Images, depth and labels equal the recording's arrays, frame by frame.
        for name, stream in rec.cameras.items():
            times = [int(round(t * 1e9)) for t in stream.time[:]]
            for pass_name, suffix in (("rgb", "image_rect_color"), ("depth", "depth/image_rect"),
                                      ("label", "label/image"), ("instance", "instance/image"),
                                      ("voxel", "voxel/image"),
                                      ("segmentation", "segmentation/image")):  # fmt: skip
                got = by_topic[f"/{name}/{suffix}"]
                assert [t for _, t, _ in got] == times
                for index, (msgtype, _, message) in enumerate(got):
                    assert msgtype == "sensor_msgs/msg/Image"
                    assert message.header.frame_id == f"{stream.camera}_optical_frame"
                    expected = exported_image(stream, pass_name, index)
                    assert same_image(image_array(message), expected), (name, pass_name)
            assert len(by_topic[f"/{name}/camera_info"]) == len(by_topic[f"/{name}/points"]) \
                == len(stream)  # fmt: skip
        # Counts: TF at every step and at every frame time, a wrench every step, removal
        # messages at every step that removed voxels.
        frame_times = {int(round(t * 1e9)) for s in rec.cameras.values() for t in s.time[:]}
        assert len(by_topic["/tf"]) == len(steps["step"]) + len(frame_times)
        assert [t for _, t, _ in by_topic["/drill/wrench"]] == [
            int(round(t * 1e9)) for t in steps["time"]
        ]
        for (_, _, message), force in zip(by_topic["/drill/wrench"], steps["drill.force"]):
            f = message.wrench.force
            assert (f.x, f.y, f.z) == tuple(force)
        removed = rec.removed
        assert len(by_topic["/drilling/removed_voxels"]) == len(np.unique(removed["step"]))
        clouds = by_topic["/drilling/removed_voxels"]
        ijk = np.concatenate([cloud_fields(m, ("i", "j", "k")) for _, _, m in clouds])
        assert np.array_equal(ijk, removed["voxel"])
        labels = np.concatenate([cloud_fields(m, ("label",))[:, 0] for _, _, m in clouds])
        assert np.array_equal(labels, removed["label"])
        check_calibration(rec, by_topic)
        check_tf(rec, by_topic)
        check_point_clouds(rec, by_topic)


def cloud_fields(message, names) -> np.ndarray:
    """Columns of a PointCloud2, read through its own field table."""
    types = {7: np.float32, 5: np.int32, 4: np.uint16}
    fields = {f.name: f for f in message.fields}
    data = np.frombuffer(bytes(message.data), np.uint8).reshape(-1, message.point_step)
    columns = []
    for name in names:
        f = fields[name]
        dtype = np.dtype(types[f.datatype])
        raw = np.ascontiguousarray(data[:, f.offset : f.offset + dtype.itemsize])
        columns.append(raw.view(dtype)[:, 0].astype(np.float64))
    return np.stack(columns, axis=1)


def check_calibration(rec, by_topic) -> None:
    """CameraInfo's K and P put the recording's points at their pixels (ROS's convention:
    pixel centres at integers), both eyes, through the off-axis rig's shifted right P."""
    rig = rec.rigs["rig"]
    worst = 0.0
    for i in range(len(rig)):
        pair = rig[i]
        left, right = pair.left, pair.right
        info_l = by_topic[f"/{rig.left.name}/camera_info"][int(rig.left_index[i])][2]
        info_r = by_topic[f"/{rig.right.name}/camera_info"][int(rig.right_index[i])][2]
        k_l, p_l = np.reshape(info_l.k, (3, 3)), np.reshape(info_l.p, (3, 4))
        k_r, p_r = np.reshape(info_r.k, (3, 3)), np.reshape(info_r.p, (3, 4))
        assert info_l.distortion_model == "plumb_bob" and not np.any(info_l.d)
        assert p_r[0, 3] == pytest.approx(-k_r[0, 0] * pair.baseline)
        rows, cols = np.nonzero(left.depth > 0)
        rays = pixel_rays(left.intrinsics, left.height, left.width)[rows, cols]
        x_left = rays * left.depth[rows, cols, None].astype(np.float64)
        # Left: K and P take the point back to the pixel it was seen at (integer centres).
        for matrix in (k_l, p_l[:, :3]):
            uvw = x_left @ matrix.T
            u, v = uvw[:, 0] / uvw[:, 2], uvw[:, 1] / uvw[:, 2]
            worst = max(worst, np.abs(u - cols).max(), np.abs(v - rows).max())
        # Right: where the right camera's pose and intrinsics (ambfplus convention) see it,
        # less half a pixel; both P (from the left frame) and K (from the right frame).
        world = x_left @ left.pose[:3, :3].T + left.pose[:3, 3]
        inverse = np.linalg.inv(right.pose)
        x_right = world @ inverse[:3, :3].T + inverse[:3, 3]
        k = right.intrinsics
        u_expected = k[0, 0] * x_right[:, 0] / x_right[:, 2] + k[0, 2] - 0.5
        v_expected = k[1, 1] * x_right[:, 1] / x_right[:, 2] + k[1, 2] - 0.5
        homogeneous = np.column_stack([x_left, np.ones(len(x_left))])
        uvw = homogeneous @ p_r.T
        worst = max(worst, np.abs(uvw[:, 0] / uvw[:, 2] - u_expected).max(),
                    np.abs(uvw[:, 1] / uvw[:, 2] - v_expected).max())  # fmt: skip
        uvw = x_right @ k_r.T
        worst = max(worst, np.abs(uvw[:, 0] / uvw[:, 2] - u_expected).max())
    assert worst <= 0.05, worst


def check_tf(rec, by_topic) -> None:
    """/tf and /tf_static compose to the recorded poses of cameras, drill and bodies."""
    transforms = {}
    for topic in ("/tf", "/tf_static"):
        for _, _, message in by_topic[topic]:
            for t in message.transforms:
                transforms[(t.child_frame_id, stamp_ns(t))] = (t.header.frame_id,
                                                               transform_matrix(t))  # fmt: skip
    worst = 0.0
    for stream in rec.cameras.values():
        for time, pose in zip(stream.time[:], stream.pose[:]):
            got = lookup(transforms, f"{stream.camera}_optical_frame", int(round(time * 1e9)))
            worst = max(worst, np.abs(got - pose).max())
    steps = rec.steps
    for body in ("drill", "burr", "shaft", "handle"):
        for time, pose in zip(steps["time"][::37], steps[f"{body}.pose"][::37]):
            worst = max(
                worst, np.abs(lookup(transforms, body, int(round(time * 1e9))) - pose).max()
            )
    volume = next(e for e in rec.legend.values() if e["kind"] == "volume")
    assert np.abs(lookup(transforms, volume["name"], 0) - np.array(volume["pose"])).max() <= 1e-9
    assert worst <= 1e-9, worst


def check_point_clouds(rec, by_topic) -> None:
    stream = rec.cameras["rig_left"]
    frame = stream[3]
    message = by_topic["/rig_left/points"][3][2]
    assert (message.height, message.width) == (frame.height, frame.width)
    xyz = cloud_fields(message, ("x", "y", "z")).reshape(frame.height, frame.width, 3)
    hit = frame.depth > 0
    assert np.isnan(xyz[~hit]).all() and not np.isnan(xyz[hit]).any()
    rays = pixel_rays(frame.intrinsics, frame.height, frame.width)
    expected = rays[hit] * frame.depth[hit, None]
    assert np.abs(xyz[hit] - expected).max() <= 1e-6
    labels = cloud_fields(message, ("label", "instance"))
    assert np.array_equal(labels[:, 0], frame.label.reshape(-1))
    assert np.array_equal(labels[:, 1], frame.instance.reshape(-1))
    # rgb, PCL's packed 0x00RRGGBB in a float32 field, is the recording's rgb at each point's
    # pixel, in both eyes and every frame.
    for name, stream in rec.cameras.items():
        for index, (_, _, message) in enumerate(by_topic[f"/{name}/points"]):
            rgb = cloud_rgb(message).reshape(message.height, message.width, 3)
            assert np.array_equal(rgb, stream.rgb[index]), (name, index)


def cloud_rgb(message) -> np.ndarray:
    """The rgb field of a PointCloud2 unpacked to (N, 3) uint8, through its field table."""
    field = next(f for f in message.fields if f.name == "rgb")
    assert field.datatype == 7 and field.count == 1  # FLOAT32, as PCL packs it
    data = np.frombuffer(bytes(message.data), np.uint8).reshape(-1, message.point_step)
    packed = np.ascontiguousarray(data[:, field.offset : field.offset + 4]).view("<u4")[:, 0]
    assert not (packed >> 24).any()
    return np.stack([(packed >> 16) & 255, (packed >> 8) & 255, packed & 255], 1).astype(np.uint8)


def test_ros_exports_state_their_conventions(exported):
    mcap_path, bag = exported
    with open(mcap_path, "rb") as f:
        metadata = {m.name: m.metadata for m in make_reader(f).iter_metadata()}["ambfplus"]
    assert metadata["ambfplus_version"] == ambfplus.__version__
    assert "simulation time" in metadata["time"] and "metres" in metadata["units"]
    assert "cx_ros = cx_ambfplus - 0.5" in metadata["pixel_convention"]
    assert json.loads(metadata["frames"])["rig_left_optical_frame"].startswith("optical")
    text = (bag / "metadata.yaml").read_text()
    assert "ambfplus.ambfplus_version" in text and "storage_identifier: mcap" in text
    # /tf_static is latched, as ROS 2 players expect.
    assert "durability: transient_local" in text


IMAGE_NAMESPACES = ("", "/depth", "/label", "/instance", "/voxel", "/segmentation")


@pytest.mark.parametrize("which", ["mcap", "rosbag2"])
def test_ros_exports_follow_ros_conventions(session, exported, which):
    """Depth is NaN where nothing was hit (REP 118); a camera_info sits beside every image
    topic with the camera's K and P; each camera has a <camera>_link body frame (REP 103) in
    /tf whose latched child is the optical frame the images are stamped with."""
    messages = read_with_rosbags(exported[0] if which == "mcap" else exported[1])
    by_topic: dict[str, list] = {}
    for topic, _, _, message in messages:
        by_topic.setdefault(topic, []).append(message)
    with open_recording(session) as rec:
        for name, stream in rec.cameras.items():
            optical, link = f"{stream.camera}_optical_frame", f"{stream.camera}_link"
            depth = np.stack([image_array(m) for m in by_topic[f"/{name}/depth/image_rect"]])
            recorded = stream.depth[:]
            assert (recorded == 0).any() and (recorded > 0).any()  # both kinds of pixel
            assert np.array_equal(np.isnan(depth), recorded == 0)
            assert np.array_equal(depth[recorded > 0], recorded[recorded > 0])
            infos = {ns: by_topic[f"/{name}{ns}/camera_info"] for ns in IMAGE_NAMESPACES}
            for ns, got in infos.items():
                assert len(got) == len(stream), (name, ns)
                for index, (info, first) in enumerate(zip(got, infos[""])):
                    assert info.header.frame_id == optical
                    assert stamp_ns(info) == int(round(stream.time[index] * 1e9))
                    assert np.array_equal(info.k, first.k) and np.array_equal(info.p, first.p)
                    k = np.reshape(info.k, (3, 3))
                    assert k[0, 0] == pytest.approx(stream.intrinsics[index][0, 0])
            # TF: world -> link at every frame, link -> optical latched, no world -> optical.
            dynamic = [t for m in by_topic["/tf"] for t in m.transforms]
            assert not [t for t in dynamic if t.child_frame_id == optical]
            links = [t for t in dynamic if t.child_frame_id == link]
            assert [stamp_ns(t) for t in links] == [int(round(x * 1e9)) for x in stream.time]
            assert {t.header.frame_id for t in links} == {"world"}
            static = [
                t for t in by_topic["/tf_static"][0].transforms if t.child_frame_id == optical
            ]
            assert len(static) == 1 and static[0].header.frame_id == link
            q = static[0].transform.rotation
            assert (q.x, q.y, q.z, q.w) == pytest.approx((-0.5, 0.5, -0.5, 0.5))
            for t, pose in zip(links, stream.pose[:]):
                world_link = transform_matrix(t)
                # REP 103 body axes: x forward (the optical z), y left (-x), z up (-y).
                assert world_link[:3, 0] == pytest.approx(pose[:3, 2], abs=1e-9)
                assert world_link[:3, 1] == pytest.approx(-pose[:3, 0], abs=1e-9)
                assert world_link[:3, 2] == pytest.approx(-pose[:3, 1], abs=1e-9)
                assert world_link[:3, 3] == pytest.approx(pose[:3, 3], abs=1e-12)
        # The drill and the volume are frames named after their objects.
        volume = next(e["name"] for e in rec.legend.values() if e["kind"] == "volume")
        assert {t.child_frame_id for t in by_topic["/tf_static"][0].transforms} >= {volume}
        assert "drill" in {t.child_frame_id for t in by_topic["/tf"][-1].transforms}
        assert {m.header.frame_id for m in by_topic["/drilling/removed_voxels"]} == {volume}


def qos_of(text: str) -> list[dict]:
    import yaml

    profiles = yaml.safe_load(text)
    assert isinstance(profiles, list) and len(profiles) == 1, text
    return profiles


def test_ros_exports_state_qos_distro_and_rosbag2_names(exported):
    """Every MCAP channel offers its QoS as rosbag2 writes it (/tf_static transient local,
    the others volatile, all reliable), the same in the rosbag2 folder; both files say
    ros_distro jazzy; the folder holds <name>_0.mcap and metadata.yaml, which points to it."""
    import yaml

    mcap_path, bag = exported
    assert sorted(p.name for p in bag.iterdir()) == ["bag_0.mcap", "metadata.yaml"]
    info = yaml.safe_load((bag / "metadata.yaml").read_text())["rosbag2_bagfile_information"]
    assert info["ros_distro"] == "jazzy" and info["version"] == 9
    assert info["relative_file_paths"] == ["bag_0.mcap"]
    assert [f["path"] for f in info["files"]] == ["bag_0.mcap"]
    in_yaml = {t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
               for t in info["topics_with_message_count"]}  # fmt: skip
    for path in (mcap_path, bag / "bag_0.mcap"):
        with open(path, "rb") as f:
            reader = make_reader(f)
            channels = reader.get_summary().channels.values()
            metadata = {m.name: m.metadata for m in reader.iter_metadata()}
        assert {c.topic for c in channels} == set(in_yaml)
        for channel in channels:
            (profile,) = qos_of(channel.metadata["offered_qos_profiles"])
            latched = channel.topic == "/tf_static"
            assert profile["reliability"] == "reliable", channel.topic
            assert profile["durability"] == ("transient_local" if latched else "volatile")
            assert profile["history"] == "keep_last" and profile["depth"] == (1 if latched else 10)
            assert in_yaml[channel.topic] == [profile], channel.topic  # MCAP and rosbag2 agree
        if path == mcap_path:
            assert metadata["ambfplus"]["ros_distro"] == "jazzy"
        else:
            embedded = yaml.safe_load(metadata["rosbag2"]["serialized_metadata"])
            assert embedded["ros_distro"] == "jazzy"
            assert embedded["relative_file_paths"] == ["bag_0.mcap"]


def test_mcap_summary_passes_the_specs_checks(exported):
    """The MCAP summary as the specification (and `mcap doctor`) checks it: every summary
    offset names a non-empty group holding only records of its opcode, the statistics count
    the channels, schemas, chunks and messages that are there, and no attachment index is
    written for a file without attachments."""
    from mcap.records import Attachment, AttachmentIndex, SummaryOffset
    from mcap.stream_reader import StreamReader

    for path in (exported[0], exported[1] / "bag_0.mcap"):
        data = path.read_bytes()
        with open(path, "rb") as f:
            records = list(StreamReader(f, skip_magic=False).records)
        offsets = [r for r in records if isinstance(r, SummaryOffset)]
        assert offsets and all(o.group_length > 0 for o in offsets), offsets
        for offset in offsets:
            group = data[offset.group_start : offset.group_start + offset.group_length]
            position = 0
            while position < len(group):
                assert group[position] == offset.group_opcode, (path.name, offset)
                length = int.from_bytes(group[position + 1 : position + 9], "little")
                position += 9 + length
            assert position == len(group)
        assert not [r for r in records if isinstance(r, (Attachment, AttachmentIndex))]
        with open(path, "rb") as f:
            reader = make_reader(f)
            summary = reader.get_summary()
            messages = sum(1 for _ in reader.iter_messages())
        stats = summary.statistics
        assert stats.message_count == messages == sum(stats.channel_message_counts.values())
        assert stats.channel_count == len(summary.channels) > 0
        assert stats.schema_count == len(summary.schemas) > 0
        assert stats.chunk_count == len(summary.chunk_indexes) > 0
        assert stats.attachment_count == 0


def test_ros_exports_take_wall_stamps_and_zero_depth(session, tmp_path):
    """--stamp wall: every stamp and log time is the recording's wall-clock start (its
    created time) plus the simulation time; --depth-no-hit zero keeps the recorded 0."""
    from datetime import datetime

    with open_recording(session) as rec:
        start = int(round(datetime.fromisoformat(rec.created).timestamp() * 1e6)) * 1000
        frame_times = [int(round(t * 1e9)) for t in rec.cameras["rig_left"].time[:]]
        depth = rec.cameras["rig_left"].depth[:]
        step_times = [int(round(t * 1e9)) for t in rec.steps["time"]]
    assert start > 1.7e18  # after 2023: Unix time
    completed = run_cli(tmp_path, str(session), "--to", "rosbag2", str(tmp_path / "wall"),
                        "--stamp", "wall", "--depth-no-hit", "zero", "--no-points",
                        "--quiet")  # fmt: skip
    assert completed.returncode == 0, completed.stderr
    export(session, tmp_path / "wall.mcap", "mcap", stamp="wall", depth_no_hit="zero",
           point_clouds=False, progress=False)  # fmt: skip
    for path in (tmp_path / "wall", tmp_path / "wall.mcap"):
        for reader in (read_with_rosbags, read_with_mcap):
            by_topic: dict[str, list] = {}
            for topic, _, log_time, message in reader(path):
                by_topic.setdefault(topic, []).append((log_time, message))
                if hasattr(message, "header"):
                    assert stamp_ns(message) == log_time
            images = by_topic["/rig_left/depth/image_rect"]
            assert [t for t, _ in images] == [start + t for t in frame_times]
            assert [t for t, _ in by_topic["/drill/wrench"]] == [start + t for t in step_times]
            static = by_topic["/tf_static"][0][1].transforms
            assert {stamp_ns(t) for t in static} == {start}
            got = np.stack([image_array(m) for _, m in images])
            assert np.array_equal(got, depth) and not np.isnan(got).any()
    info = (tmp_path / "wall" / "metadata.yaml").read_text()
    assert f"nanoseconds_since_epoch: {start}" in info
    assert sorted(p.name for p in (tmp_path / "wall").iterdir()) == ["metadata.yaml",
                                                                      "wall_0.mcap"]  # fmt: skip


def test_ros_options_are_checked(session, tmp_path):
    cases = [
        ({"depth_no_hit": "inf"}, "depth_no_hit (--depth-no-hit) is one of nan, zero, not 'inf'"),
        ({"stamp": "utc"}, "stamp (--stamp) is one of sim, wall, not 'utc'"),
    ]
    for options, message in cases:
        for to in ("mcap", "rosbag2"):
            with pytest.raises(ExportError, match=re.escape(message)):
                export(session, tmp_path / "x", to, progress=False, **options)
            assert list(tmp_path.iterdir()) == []
    completed = run_cli(tmp_path, str(session), "--to", "mcap", str(tmp_path / "x.mcap"),
                        "--stamp", "utc")  # fmt: skip
    assert completed.returncode != 0 and "--stamp" in completed.stderr
    assert "'utc'" in completed.stderr and "sim" in completed.stderr
    # A recording whose created time is no date cannot be stamped with wall-clock time.
    path = tmp_path / "undated.h5"
    with Recorder(path, created="yesterday") as recorder:
        recorder.set_legend(TINY_LEGEND)
        recorder.add_frame("cam", tiny_frame("cam", 10))
    with pytest.raises(ExportError, match=r"stamp 'wall' \(--stamp wall\) needs .*'yesterday'"):
        export(path, tmp_path / "u.mcap", "mcap", stamp="wall", progress=False)
    assert not (tmp_path / "u.mcap").exists()
    assert export(path, tmp_path / "u.mcap", "mcap", progress=False).frames == 1


def test_events_become_diagnostics(tmp_path):
    """A critical-structure event of the removal log reaches /drilling/events with its label's
    name (a recording made with the Recorder directly)."""
    scene = drilling_phantom(resolution=32, width=64, height=48)
    path = tmp_path / "events.h5"
    with Recorder(path) as recorder:
        recorder.set_legend(scene.world)
        scene.world.step(5)
        recorder.add_stereo("rig", scene.rig.capture(("rgb", "depth")))
        # Label 10 is the facial nerve (the original system's ids).
        recorder.add_events([{"step": 5, "kind": "critical", "label": 10, "voxel": (4, 5, 6)}])
        recorder.add_removed({"step": np.array([5]), "voxel": np.array([[4, 5, 6]]),
                              "label": np.array([10])}, volume="anatomy")  # fmt: skip
    export(path, tmp_path / "e.mcap", "mcap", progress=False)
    events = [m for m in read_with_mcap(tmp_path / "e.mcap") if m[0] == "/drilling/events"]
    assert len(events) == 1
    status = events[0][3].status[0]
    values = {v.key: v.value for v in status.values}
    assert status.level == 2 and "Facial_Nerve" in status.message
    assert values["label_name"] == "Facial_Nerve" and values["voxel_j"] == "5"


# The original system's layout ------------------------------------------------------------------

# From shared/reference/original-recording.md, section 5.2: path -> (dtype, shape pattern);
# N samples, G voxel groups, M voxels, K events, P high-frequency poses; () is a scalar.
ORIGINAL_LAYOUT = {
    "metadata_v3/camera_intrinsic": ("float64", (3, 3)),
    "metadata_v3/camera_extrinsic": ("int64", (4, 4)),
    "metadata_v3/README": ("string", ()),
    "metadata_v3/baseline": ("float64", ()),
    "metadata_v3/voxel_volume": ("float64", ()),
    "vision_data/continuous_data/time": ("float64", ("N",)),
    "vision_data/continuous_data/l_img": ("uint8", ("N", "H", "W", 3)),
    "vision_data/continuous_data/r_img": ("uint8", ("N", "H", "W", 3)),
    "vision_data/continuous_data/segm": ("uint8", ("N", "H", "W", 3)),
    "vision_data/continuous_data/depth": ("float16", ("N", "H", "W")),
    "vision_data/continuous_data/pose_mastoidectomy_drill": ("float64", ("N", 7)),
    "vision_data/continuous_data/pose_main_camera": ("float64", ("N", 7)),
    "vision_data/continuous_data/pose_mastoidectomy_volume": ("float64", ("N", 7)),
    "physics_data/intermittent_data/voxels_removed/voxel_time_stamp": ("float64", ("G",)),
    "physics_data/intermittent_data/voxels_removed/voxel_removed": ("float64", ("M", 4)),
    "physics_data/intermittent_data/voxels_removed/voxel_color": ("float64", ("M", 5)),
    "physics_data/intermittent_data/voxels_removed/README": ("string", ()),
    "physics_data/intermittent_data/burr_change/burr_size": ("int64", ("K",)),
    "physics_data/intermittent_data/burr_change/time_stamp": ("float64", ("K",)),
    "physics_data/intermittent_data/drill_force_feedback/wrench": ("float64", ("F", 6)),
    "physics_data/intermittent_data/drill_force_feedback/time_stamp": ("float64", ("F",)),
}
T_CV_AMBF = np.array([[0, 1, 0, 0], [0, 0, -1, 0], [-1, 0, 0, 0], [0, 0, 0, 1]])


def quaternion_matrix(q) -> np.ndarray:
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])  # fmt: skip


def read_original(folder: Path) -> dict:
    """An independent reader of the v3 layout, from the reference note: checks every file's
    names, dtypes and shapes and concatenates the files (offsetting the voxel groups, which
    restart at 0 in every file)."""
    files = sorted(folder.glob("*.hdf5"))
    assert files and all(len(f.stem) == 15 and f.stem[8] == "_" for f in files)
    out = {"depth": [], "l_img": [], "r_img": [], "segm": [], "time": [], "voxels": [],
           "voxel_color": [], "voxel_time": [], "drill": [], "camera": [], "volume": [],
           "burr_size": [], "burr_time": [], "wrench": [], "wrench_time": []}  # fmt: skip
    high_frequency: dict[str, list] = {}
    for path in files:
        with h5py.File(path, "r") as f:
            assert "vision_data/intermittent_data" in f
            sizes = {"N": len(f["vision_data/continuous_data/time"])}
            sizes["H"], sizes["W"] = f["vision_data/continuous_data/depth"].shape[1:]
            for name, (dtype, pattern) in ORIGINAL_LAYOUT.items():
                if name not in f:
                    # Groups are left out where a file holds no such data.
                    assert "intermittent_data/" in name, f"{path.name}: {name} missing"
                    continue
                dataset = f[name]
                if dtype == "string":
                    assert h5py.check_string_dtype(dataset.dtype) and dataset.shape == ()
                    continue
                assert dataset.dtype == np.dtype(dtype), (name, dataset.dtype)
                shape = tuple(sizes.setdefault(p, dataset.shape[i]) if isinstance(p, str) else p
                              for i, p in enumerate(pattern))  # fmt: skip
                assert dataset.shape == shape, (name, dataset.shape, shape)
                if dataset.shape:
                    assert dataset.compression == "gzip", name
            assert f["metadata_v3/voxel_volume"].attrs["units"].startswith("mm^3")
            assert np.array_equal(f["metadata_v3/camera_extrinsic"][()], T_CV_AMBF)
            for name, group in f["physics_data/continuous_data/high_frequency_poses"].items():
                assert group["pose"].shape == (len(group["time_stamp"]), 7)
                high_frequency.setdefault(name, []).append(
                    (group["time_stamp"][()], group["pose"][()])
                )
            intermittent = f["physics_data/intermittent_data"]
            if "burr_change" in intermittent:
                out["burr_size"].append(intermittent["burr_change/burr_size"][()])
                out["burr_time"].append(intermittent["burr_change/time_stamp"][()])
            if "drill_force_feedback" in intermittent:
                out["wrench"].append(intermittent["drill_force_feedback/wrench"][()])
                out["wrench_time"].append(intermittent["drill_force_feedback/time_stamp"][()])
            data = f["vision_data/continuous_data"]
            for key in ("depth", "l_img", "r_img", "segm", "time"):
                out[key].append(data[key][()])
            out["drill"].append(data["pose_mastoidectomy_drill"][()])
            out["camera"].append(data["pose_main_camera"][()])
            out["volume"].append(data["pose_mastoidectomy_volume"][()])
            out["intrinsic"] = f["metadata_v3/camera_intrinsic"][()]
            out["baseline"] = f["metadata_v3/baseline"][()]
            out["voxel_volume"] = f["metadata_v3/voxel_volume"][()]
            out["dimensions"] = f["ambfplus/volume_dimensions"][()]
            out["count"] = f["ambfplus/volume_voxel_count"][()]
            if "physics_data/intermittent_data/voxels_removed" in f:
                group = f["physics_data/intermittent_data/voxels_removed"]
                rows = group["voxel_removed"][()]
                offset = sum(len(t) for t in out["voxel_time"])
                assert rows[0, 0] == 0  # restarts in every file
                out["voxels"].append(rows + [offset, 0, 0, 0])
                out["voxel_color"].append(group["voxel_color"][()] + [offset, 0, 0, 0, 0])
                out["voxel_time"].append(group["voxel_time_stamp"][()])
    out = {k: (np.concatenate(v) if isinstance(v, list) and v else v) for k, v in out.items()}
    # <object>_pose -> (time_stamp, pose) over all files.
    out["high_frequency"] = {
        name: (np.concatenate([t for t, _ in parts]), np.concatenate([p for _, p in parts]))
        for name, parts in high_frequency.items()
    }
    return out


def test_original_layout_is_read_by_an_independent_checker(session, tmp_path):
    out = tmp_path / "original"
    result = export(session, out, "original-h5", chunk_size=3, progress=False)
    assert len(result.details["files"]) == 3  # 8 samples, 3 per file
    data = read_original(out)
    with open_recording(session) as rec:
        rig = rec.rigs["rig"]
        left, right = rig.left, rig.right
        assert np.array_equal(data["l_img"][..., ::-1], left.rgb[:])  # BGR
        assert np.array_equal(data["r_img"][..., ::-1], right.rgb[:])
        assert np.array_equal(data["segm"][..., ::-1], left.segmentation[:])
        assert np.array_equal(data["time"], left.time[:])
        depth = left.depth[:]
        # float16 keeps 11 significant bits: within half a unit in the last place.
        tolerance = np.abs(np.spacing(depth.astype(np.float16)).astype(np.float32)) / 2
        assert (np.abs(data["depth"].astype(np.float32) - depth) <= tolerance + 1e-12).all()
        assert np.allclose(data["intrinsic"], left.intrinsics[0])
        assert data["baseline"] == pytest.approx(rig.baseline[0])
        # Poses [x, y, z, qx, qy, qz, qw]; the camera's is AMBF's camera body (extrinsic).
        for row, pose in zip(data["camera"], left.pose[:]):
            matrix = np.eye(4)
            matrix[:3, :3], matrix[:3, 3] = quaternion_matrix(row[3:]), row[:3]
            assert np.abs(matrix @ np.linalg.inv(T_CV_AMBF) - pose).max() <= 1e-9
        steps = rec.steps
        rows = np.searchsorted(steps["step"], left.step[:])
        for row, pose in zip(data["drill"], steps["drill.pose"][rows]):
            assert np.abs(quaternion_matrix(row[3:]) - pose[:3, :3]).max() <= 1e-9
            assert np.abs(row[:3] - pose[:3, 3]).max() <= 1e-12
        # Removed voxels in world coordinates, from the volume's pose, dimensions and count.
        removed = rec.removed
        volume = next(e for e in rec.legend.values() if e["name"] == removed["volume"])
        assert data["voxel_volume"] == pytest.approx(np.prod(volume["voxel_size"]) * 1e9)
        pose = data["volume"][0]
        size = data["dimensions"] / data["count"]
        local = (data["voxels"][:, 1:] + 0.5) * size - data["dimensions"] / 2
        world = local @ quaternion_matrix(pose[3:]).T + pose[:3]
        v = np.asarray(volume["pose"])
        expected_local = (removed["voxel"] + 0.5) * np.asarray(volume["voxel_size"]) - (
            np.asarray(volume["dimensions"]) / 2
        )  # fmt: skip
        expected = expected_local @ v[:3, :3].T + v[:3, 3]
        assert np.abs(world - expected).max() <= 1e-12
        groups = data["voxels"][:, 0].astype(int)
        assert np.array_equal(np.diff(groups) != 0, np.diff(removed["step"]) != 0)
        assert len(data["voxel_time"]) == len(np.unique(removed["step"]))
        check_original_physics(data, rec)


def pose_matrix(row) -> np.ndarray:
    """A [x, y, z, qx, qy, qz, qw] row as a 4x4 pose."""
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = quaternion_matrix(row[3:]), row[:3]
    return matrix


def check_original_physics(data: dict, rec) -> None:
    """The physics groups' values against the recording, as the reference note describes them
    less the defects the export does not reproduce: voxel colours [group, r, g, b, a] from the
    label table, burr sizes in mm where the burr changed (and the first), the drill's force at
    every step with a torque of 0, and every logged pose once per step at simulation time."""
    steps, removed, legend = rec.steps, rec.removed, rec.legend
    volume = next(e for e in legend.values() if e["name"] == removed["volume"])
    colour = data["voxel_color"]
    assert colour.shape == (len(removed["label"]), 5)
    assert np.array_equal(colour[:, 0], data["voxels"][:, 0])  # the same groups
    labels = volume["labels"]
    expected = np.array([labels[int(label)]["color"] for label in removed["label"]], float)
    assert np.array_equal(colour[:, 1:4], expected)
    assert (colour[:, 4] == 255).all()
    drill = next(e["name"] for e in legend.values() if e["kind"] == "drill")
    assert np.array_equal(data["wrench_time"], steps["time"])
    assert np.array_equal(data["wrench"][:, :3], steps[f"{drill}.force"])
    assert not data["wrench"][:, 3:].any()
    burr = steps[f"{drill}.burr"]
    changed = np.r_[True, burr[1:] != burr[:-1]]
    diameters = np.asarray(next(e for e in legend.values() if e["kind"] == "drill")[
        "burr_diameters"])  # fmt: skip
    assert data["burr_size"].dtype == np.int64
    assert np.array_equal(data["burr_size"], np.round(diameters[burr[changed]] * 1000))
    assert np.array_equal(data["burr_time"], steps["time"][changed])
    # High-frequency poses: the drill and the left camera under the original's names, the
    # camera as AMBF's camera body (the file's extrinsic applies), other bodies as they are.
    left = next(iter(rec.rigs.values())).left.camera
    names = {drill: "mastoidectomy_drill", left: "main_camera"}
    logged = [c.removesuffix(".pose") for c in steps if c.endswith(".pose")]
    assert set(data["high_frequency"]) == {f"{names.get(n, n)}_pose" for n in logged}
    for name in logged:
        times, rows = data["high_frequency"][f"{names.get(name, name)}_pose"]
        assert np.array_equal(times, steps["time"])  # once per step, simulation time
        to_ours = np.linalg.inv(T_CV_AMBF) if name == left else np.eye(4)
        got = np.array([pose_matrix(row) @ to_ours for row in rows])
        assert np.abs(got - steps[f"{name}.pose"]).max() <= 1e-9, name


def test_original_layout_burr_changes_forces_and_poses_across_files(tmp_path):
    """A burr that changes twice, once as a file begins: each file writes the changes inside
    it (the first file the starting burr too); colours, forces and poses split over the files
    and concatenate back to the recording's."""
    # 4 mm from step 13, 6 mm again from step 20: the first step of the second file (its
    # samples start at step 20), where the change is seen only against the file before.
    burr = [0] * 12 + [1] * 7 + [0] * 11
    source = tiny_recording(tmp_path / "rec" / "t.h5", burr=burr)
    result = export(source, tmp_path / "original", "original-h5", chunk_size=1, progress=False)
    assert len(result.details["files"]) == 3
    data = read_original(tmp_path / "original")
    with open_recording(source) as rec:
        check_original_physics(data, rec)
    assert data["burr_size"].tolist() == [6, 4, 6]
    assert data["burr_time"].tolist() == (TINY_STEPS[[0, 12, 19]] * 1e-3).tolist()
    assert data["voxel_color"].tolist() == [[0, 230, 220, 200, 255], [0, 230, 220, 200, 255],
                                            [1, 250, 5, 9, 255]]  # fmt: skip
    assert len(data["wrench"]) == len(data["high_frequency"]["mastoidectomy_drill_pose"][0]) == 30


# COCO ------------------------------------------------------------------------------------------


def test_coco_masks_decode_to_the_instance_images(session, tmp_path):
    from pycocotools import mask as mask_utils
    from pycocotools.coco import COCO

    out = tmp_path / "coco"
    export(session, out, "coco", progress=False)
    with open_recording(session) as rec:
        legend = rec.legend
        label_names = {label["name"] for e in legend.values() if e["kind"] == "volume"
                       for label in e["labels"].values()}  # fmt: skip
        object_names = {e["name"] for e in legend.values() if e["kind"] == "body"}
        for name, stream in rec.cameras.items():
            coco = COCO(str(out / f"{name}.json"))
            categories = {c["id"]: c for c in coco.loadCats(coco.getCatIds())}
            # Objects, and the anatomy labels the frames show (no catch-all volume category).
            anatomy = {c["name"] for c in categories.values() if c["supercategory"] == "anatomy"}
            assert {c["name"] for c in categories.values()} - anatomy == object_names
            assert anatomy and anatomy <= label_names
            for index in range(len(stream)):
                frame = stream[index]
                image = coco.loadImgs(index + 1)[0]
                assert (out / image["file_name"]).is_file()
                instance = np.zeros_like(frame.instance)
                label = np.zeros_like(frame.label)
                for annotation in coco.loadAnns(coco.getAnnIds(imgIds=image["id"])):
                    mask = coco.annToMask(annotation).astype(bool)
                    assert mask.sum() == annotation["area"] > 0
                    assert not instance[mask].any()  # masks do not overlap
                    instance[mask] = annotation["instance_id"]
                    label[mask] = annotation["label_id"]
                    category = categories[annotation["category_id"]]
                    entry = legend[annotation["instance_id"]]
                    if annotation["label_id"]:
                        assert category["name"] == entry["labels"][annotation["label_id"]]["name"]
                    else:
                        assert category["name"] == entry["name"]
                    rle = annotation["segmentation"]
                    assert np.array_equal(mask_utils.decode(rle).astype(bool), mask)
                assert np.array_equal(instance, frame.instance)
                volume_pixels = np.isin(frame.instance, [i for i, e in legend.items()
                                                         if e["kind"] == "volume"])  # fmt: skip
                assert np.array_equal(label[volume_pixels], frame.label[volume_pixels])


# Datasets and bad input -------------------------------------------------------------------------


def make_dataset(folder: Path) -> list[dict]:
    """A dataset folder as ambfplus generate lays it out: two short recordings as shards and
    a manifest listing them with their checksums."""
    (folder / "shards").mkdir(parents=True)
    lines = []
    for episode in range(2):
        relative = f"shards/episode_{episode:06d}.h5"
        summary = drilling_session(folder / relative, seed=episode, seconds=0.3)
        digest = hashlib.sha256((folder / relative).read_bytes()).hexdigest()
        lines.append({"episode": episode, "seed": episode, "anatomy": "phantom",
                      "scenario": "drilling", "frames": 2 * summary["frames"],
                      "bytes": (folder / relative).stat().st_size, "sha256": digest,
                      "file": relative, "version": ambfplus.__version__})  # fmt: skip
    (folder / "manifest.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    (folder / "spec.yaml").write_text("episodes: 2\n")
    return lines


def test_a_dataset_exports_shard_by_shard_and_refuses_a_changed_shard(tmp_path):
    dataset = tmp_path / "data"
    lines = make_dataset(dataset)
    out = tmp_path / "out"
    results = export(dataset, out, "mcap", progress=False)
    assert [r.output for r in results] == [out / "shards" / f"episode_{e:06d}.mcap"
                                           for e in range(2)]  # fmt: skip
    index = [json.loads(x) for x in (out / "index.jsonl").read_text().splitlines()]
    assert [(x["episode"], x["file"], x["source_sha256"]) for x in index] == [
        (x["episode"], x["file"].replace(".h5", ".mcap"), x["sha256"]) for x in lines
    ]
    for line, result in zip(lines, results):
        assert result.frames == line["frames"]
        images = [m for m in read_with_mcap(result.output) if m[0] == "/rig_left/image_rect_color"]
        assert len(images) == line["frames"] // 2
    assert (out / "spec.yaml").is_file()
    # A shard whose bytes no longer match the manifest: nothing is exported.
    lines[1]["sha256"] = "0" * 64
    (dataset / "manifest.jsonl").write_text("".join(json.dumps(x) + "\n" for x in lines))
    with pytest.raises(ExportError, match="episode_000001.h5: its SHA-256 does not match"):
        export(dataset, tmp_path / "again", "rosbag2", progress=False)
    assert not (tmp_path / "again").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data", "out"]


def run_cli(cwd: Path, *args: str) -> subprocess.CompletedProcess:
    # Run away from the source folder, which would shadow the installed package.
    return subprocess.run([sys.executable, "-m", "ambfplus", "export", *args], cwd=cwd,
                          capture_output=True, text=True, timeout=120)  # fmt: skip


@pytest.mark.slow
def test_bad_input_gives_a_clear_error_and_writes_nothing(session, tmp_path):
    # A truncated recording: its head cut in half.
    truncated = tmp_path / "truncated.h5"
    data = session.read_bytes()
    truncated.write_bytes(data[: len(data) // 2])
    # A foreign HDF5 file.
    foreign = tmp_path / "foreign.h5"
    with h5py.File(foreign, "w") as f:
        f["data/l_img"] = np.zeros((2, 4, 4, 3), np.uint8)
    cases = [
        ((truncated, tmp_path / "a.mcap", "mcap"), f"{truncated}: not a readable HDF5 file"),
        ((foreign, tmp_path / "b", "coco"), f"{foreign}: not an ambfplus recording"),
        ((session, tmp_path / "c", "hdf5"), "unknown export format 'hdf5'; known: mcap"),
    ]
    for (source, out, to), message in cases:
        with pytest.raises(ValueError, match=message.replace("(", r"\(")):
            export(source, out, to, progress=False)
        completed = run_cli(tmp_path, str(source), "--to", to, str(out))
        assert completed.returncode == 2 and message in completed.stderr, completed.stderr
        assert not out.exists()
    # An existing output is kept unless --force.
    existing = tmp_path / "existing.mcap"
    existing.write_text("keep me")
    with pytest.raises(ExportError, match="exists; pass --force"):
        export(session, existing, "mcap", progress=False)
    completed = run_cli(tmp_path, str(session), "--to", "mcap", str(existing))
    assert completed.returncode == 2 and "exists; pass --force" in completed.stderr
    assert existing.read_text() == "keep me"
    completed = run_cli(tmp_path, str(session), "--to", "mcap", str(existing), "--force", "--quiet")
    assert completed.returncode == 0, completed.stderr
    assert json.loads(completed.stdout)["frames"] == 16
    assert existing.read_bytes()[:5] == b"\x89MCAP"
    # Nothing partial is left beside the outputs.
    assert not [p for p in tmp_path.iterdir() if ".tmp" in p.name]


# What a format cannot represent: the options of tiny_recording that make it, the formats that
# refuse it, one that takes it, and the refusal (after the recording's path).
NO_GEOMETRY = {**TINY_LEGEND, 1: {k: v for k, v in TINY_LEGEND[1].items()
                                  if k not in ("dimensions", "shape", "voxel_size")}}  # fmt: skip
REFUSALS = {
    "baseline changes": (
        {"baselines": (0.065, 0.065, 0.03)}, ["original-h5"], "mcap",
        "rig rig's baseline changes during the recording (0.03 to 0.065 m); the original's "
        "layout has one baseline",
    ),
    "intrinsics change": (
        {"focals": (6.0, 6.0, 7.0)}, ["original-h5"], "rosbag2",
        "camera stream rig_left's intrinsics change during the recording; the original's "
        "layout has one intrinsic matrix",
    ),
    "no instance pass": (
        {"passes": ("rgb", "depth", "label")}, ["coco"], "original-h5",
        "no camera stream has the 'instance' pass; COCO masks are made from instance images",
    ),
    "voxels without a grid": (
        {"legend": NO_GEOMETRY}, ["mcap", "rosbag2"], "coco",
        "the removal log's volume 'anatomy' has no dimensions and shape in the legend, so its "
        "voxels cannot be placed (record with Recorder.set_legend(world))",
    ),
    "a right frame out of any pair": (
        {"unpaired_right": True}, ["mcap", "rosbag2"], "original-h5",
        "frame 3 of rig_right (the right camera of rig rig) belongs to no stereo pair; its P "
        "has no baseline",
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", REFUSALS)
def test_what_a_format_cannot_represent_is_refused_and_nothing_written(tmp_path, case):
    options, formats, fine, message = REFUSALS[case]
    source = tiny_recording(tmp_path / "rec" / "t.h5", **options)
    out = tmp_path / "out"
    out.mkdir()
    for to in formats:
        target = out / ("x.mcap" if to == "mcap" else "x")
        with pytest.raises(ExportError) as refused:
            export(source, target, to, progress=False)
        assert str(refused.value) == f"{source}: {message}", to
        assert list(out.iterdir()) == [], to  # not the output, nor a temporary one
    # The same recording exports to a format that can hold it (MCAP has a CameraInfo per
    # frame; COCO needs no grid; original-h5 takes the stereo pairs and no instance images).
    assert export(source, out / ("fine.mcap" if fine == "mcap" else "fine"), fine,
                  progress=False).frames > 0  # fmt: skip


def test_original_layout_writes_voxels_it_cannot_place_with_a_warning(tmp_path):
    """v3 holds voxel indices, so a removal log whose volume has no grid geometry is written;
    the warning says that nothing places those voxels (unlike MCAP, which refuses them)."""
    source = tiny_recording(tmp_path / "rec" / "t.h5", legend=NO_GEOMETRY)
    result = export(source, tmp_path / "original", "original-h5", progress=False)
    warning = ("the legend has no dimensions and shape of volume 'anatomy': no voxel_volume, and "
               "voxel_removed's indices cannot be placed in the world")  # fmt: skip
    assert warning in result.details["warnings"]
    (path,) = (tmp_path / "original").glob("*.hdf5")
    with h5py.File(path, "r") as f:
        assert warning in json.loads(f["ambfplus"].attrs["warnings"])
        assert "voxel_volume" not in f["metadata_v3"] and "volume_dimensions" not in f["ambfplus"]
        rows = f["physics_data/intermittent_data/voxels_removed/voxel_removed"][()]
    assert rows.tolist() == [[0, 1, 2, 3], [0, 1, 2, 4], [1, 5, 5, 5]]


@pytest.mark.parametrize("to", ["rosbag2", "coco", "original-h5"])
def test_an_existing_output_folder_is_kept_unless_forced(tmp_path, to):
    """A folder output that exists is refused, from Python and the command line, and left as
    it was; --force replaces it whole with the export."""
    source = tiny_recording(tmp_path / "rec" / "t.h5")
    outputs = tmp_path / "outputs"
    out = outputs / "existing"
    (out / "inner").mkdir(parents=True)
    (out / "keep.txt").write_text("keep me")
    (out / "inner" / "data.bin").write_bytes(b"\x00\x01")
    before = tree(outputs)
    message = f"{out} exists; pass --force (force=True) to replace it"
    with pytest.raises(ExportError, match=re.escape(message)):
        export(source, out, to, progress=False)
    completed = run_cli(tmp_path, str(source), "--to", to, str(out))
    assert completed.returncode == 2 and message in completed.stderr, completed.stderr
    assert tree(outputs) == before
    completed = run_cli(tmp_path, str(source), "--to", to, str(out), "--force", "--quiet")
    assert completed.returncode == 0, completed.stderr
    assert json.loads(completed.stdout)["frames"] == (3 if to == "original-h5" else 6)
    assert [p.name for p in outputs.iterdir()] == ["existing"]  # nothing left beside it
    assert not (out / "keep.txt").exists() and not (out / "inner").exists()
    with open_recording(source) as rec:
        check_export_reads_back(to, out, rec)


def test_an_export_that_fails_midway_leaves_nothing(session, tmp_path, monkeypatch):
    from ambfplus.export import ros

    def broken(self, message):
        if message.topic == "/drill/wrench" and message.time > 4 * 10**8:
            raise OSError("disk full")
        self._writer.write(self._connections[message.topic], message.time, b"")

    monkeypatch.setattr(ros.Rosbag2Sink, "write", broken)
    with pytest.raises(OSError, match="disk full"):
        export(session, tmp_path / "bag", "rosbag2", progress=False)
    assert list(tmp_path.iterdir()) == []


def test_a_long_export_shows_a_progress_bar_of_frames(session, tmp_path, capsys):
    """progress=True: a tqdm bar on stderr named after the recording and the format, counting
    the frames written (every camera's for mcap, stereo pairs for original-h5) to the end;
    progress=False prints nothing."""
    pytest.importorskip("tqdm")
    export(session, tmp_path / "quiet.mcap", "mcap", point_clouds=False, progress=False)
    assert capsys.readouterr().err == ""
    for to, out, frames in (("mcap", "s.mcap", 16), ("original-h5", "original", 8)):
        export(session, tmp_path / out, to, progress=True)
        lines = capsys.readouterr().err.replace("\r", "\n").split("\n")
        final = [line for line in lines if line.strip()][-1]
        assert final.startswith(f"s.h5 -> {to}: 100%"), final
        assert f" {frames}/{frames} " in final and "frame" in final, final


def test_a_missing_extra_says_what_to_install(session, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "pycocotools.mask", None)
    with pytest.raises(MissingExtra, match=r'pip install "ambfplus\[export\]"'):
        export(session, tmp_path / "c", "coco", progress=False)
    assert not (tmp_path / "c").exists()


def test_copying_a_recording_keeps_its_parts_checkable(session, tmp_path):
    """The dataset checksum covers the head alone or the head and its parts."""
    from ambfplus.export import shard_digests

    copy = tmp_path / "copy"
    copy.mkdir()
    for path in session.parent.glob(session.name + "*"):
        shutil.copy(path, copy / path.name)
    head = copy / session.name
    digests = shard_digests(head)
    assert hashlib.sha256(head.read_bytes()).hexdigest() in digests and len(digests) == 2


# Compressed image topics ------------------------------------------------------------------------

PASS_TOPICS = {"rgb": "image_rect_color", "depth": "depth/image_rect", "label": "label/image",
               "instance": "instance/image", "voxel": "voxel/image",
               "segmentation": "segmentation/image"}  # fmt: skip


def decode_with_opencv(message) -> np.ndarray:
    """A CompressedImage's pixels decoded by OpenCV (not the Pillow that wrote them), in the
    raw encoding its format names (OpenCV hands colour images over as BGR)."""
    cv2 = pytest.importorskip("cv2", reason="decoding with another library needs OpenCV")
    image = cv2.imdecode(np.frombuffer(bytes(message.data), np.uint8), cv2.IMREAD_UNCHANGED)
    assert image is not None, message.format
    return image[..., ::-1] if image.ndim == 3 else image


@pytest.mark.parametrize("which", ["mcap", "rosbag2"])
def test_compressed_image_topics_round_trip(session, tmp_path, which):
    """image_topics="both": every raw image topic has a CompressedImage twin on
    <topic>/compressed; PNG and TIFF decode bit for bit to the recording's arrays, with both
    readers; JPEG rgb is close; "compressed" alone leaves the raw topics out."""
    from ambfplus.export.images import decode_image

    out = tmp_path / ("both.mcap" if which == "mcap" else "both")
    export(session, out, which, image_topics="both", point_clouds=False, progress=False)
    formats = {"rgb": "rgb8; png compressed bgr8", "depth": "32FC1; tiff compressed",
               "label": "16UC1; png compressed", "instance": "32SC1; tiff compressed",
               "voxel": "32SC1; tiff compressed",
               "segmentation": "rgb8; png compressed bgr8"}  # fmt: skip
    with open_recording(session) as rec:
        for reader in (read_with_mcap, read_with_rosbags):
            by_topic: dict[str, list] = {}
            for topic, msgtype, log_time, message in reader(out):
                by_topic.setdefault(topic, []).append((msgtype, log_time, message))
            for name, stream in rec.cameras.items():
                for pass_name, suffix in PASS_TOPICS.items():
                    raw = by_topic[f"/{name}/{suffix}"]
                    compressed = by_topic[f"/{name}/{suffix}/compressed"]
                    assert [t for _, t, _ in compressed] == [t for _, t, _ in raw]
                    for index, (msgtype, log_time, message) in enumerate(compressed):
                        assert msgtype == "sensor_msgs/msg/CompressedImage"
                        assert message.format == formats[pass_name]
                        assert stamp_ns(message) == log_time
                        assert message.header.frame_id == f"{stream.camera}_optical_frame"
                        expected = exported_image(stream, pass_name, index)
                        for decoded in (decode_with_opencv(message),
                                        decode_image(message.format, message.data)):  # fmt: skip
                            assert decoded.dtype == expected.dtype, (name, pass_name)
                            assert same_image(decoded, expected), (name, pass_name)
    # JPEG for rgb, compressed topics only; the rest stays lossless.
    jpeg = tmp_path / ("jpeg.mcap" if which == "mcap" else "jpeg")
    export(session, jpeg, which, image_topics="compressed", rgb_codec="jpeg", jpeg_quality=95,
           point_clouds=False, progress=False)  # fmt: skip
    topics = {}
    for topic, _, _, message in read_with_rosbags(jpeg):
        topics.setdefault(topic, []).append(message)
    assert not any(t.endswith(("/image_rect_color", "/image_rect", "/image")) for t in topics)
    with open_recording(session) as rec:
        for name, stream in rec.cameras.items():
            for index, message in enumerate(topics[f"/{name}/image_rect_color/compressed"]):
                assert message.format == "rgb8; jpeg compressed bgr8"
                assert bytes(message.data[:2]) == b"\xff\xd8"  # a JPEG stream
                error = decode_with_opencv(message).astype(float) - stream.rgb[index]
                psnr = 10 * np.log10(255.0**2 / np.mean(error**2))
                assert 30 < psnr < 100, psnr  # lossy, and close
            label = topics[f"/{name}/label/image/compressed"][0]
            assert np.array_equal(decode_with_opencv(label), stream.label[0])
        if which == "mcap":
            with open(jpeg, "rb") as f:
                metadata = {m.name: m.metadata for m in make_reader(f).iter_metadata()}
            assert "JPEG, quality 95" in metadata["ambfplus"]["compressed_images"]


def test_compressed_image_options_are_checked(session, tmp_path):
    cases = [
        ({"image_topics": "zipped"}, "image_topics is one of raw, compressed, both"),
        ({"rgb_codec": "webp"}, "the rgb codec is one of png, jpeg"),
        ({"jpeg_quality": 0}, "jpeg_quality is 1..100"),
        ({"rgb_codec": "png", "chunk_size": 3}, "the mcap export takes no option chunk_size"),
    ]
    for options, message in cases:
        with pytest.raises(ExportError, match=message):
            export(session, tmp_path / "x.mcap", "mcap", progress=False, **options)
        assert not (tmp_path / "x.mcap").exists()
    completed = run_cli(tmp_path, str(session), "--to", "rosbag2", str(tmp_path / "bag"),
                        "--image-topics", "compressed", "--rgb-codec", "jpeg", "--quiet",
                        "--verbose")  # fmt: skip
    assert completed.returncode == 0, completed.stderr
    topics = json.loads(completed.stdout)["topics"]
    assert topics["/rig_left/image_rect_color/compressed"] == "sensor_msgs/msg/CompressedImage"
    assert "/rig_left/image_rect_color" not in topics


# A dataset made by ambfplus generate -----------------------------------------------------------

GENERATED_SPEC = """\
version: 1
name: export-tiny
episodes: 3
seed: 11
capture: {every: 150, frames: 2, passes: [rgb, depth, label, instance, segmentation]}
anatomies: [{phantom: {resolution: 40, seed: 1}}]
scenarios: [{kind: drilling, frames: 3}, {kind: camera}]
rigs: [{resolution: [160, 120], baseline: 0.065, working_distance: 0.25}]
"""


@pytest.fixture(scope="module")
def generated(tmp_path_factory) -> Path:
    """Three tiny episodes made by `ambfplus generate` with 2 local workers."""
    folder = tmp_path_factory.mktemp("generated")
    (folder / "spec.yaml").write_text(GENERATED_SPEC)
    completed = subprocess.run(
        [sys.executable, "-m", "ambfplus", "generate", "spec.yaml", "--out", "data",
         "--workers", "2", "--quiet"],
        cwd=folder, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert completed.returncode == 0, completed.stderr
    return folder / "data"


def check_export_reads_back(to: str, output: Path, recording) -> None:
    """Reads an export of a shard back with the format's own readers (not the writers) and
    compares it with the shard."""
    streams = recording.cameras
    if to in ("mcap", "rosbag2"):
        for reader in (read_with_mcap, read_with_rosbags):
            by_topic: dict[str, list] = {}
            for topic, _, log_time, message in reader(output):
                by_topic.setdefault(topic, []).append((log_time, message))
            for name, stream in streams.items():
                times = [int(round(t * 1e9)) for t in stream.time[:]]
                for pass_name in stream.passes:
                    got = by_topic[f"/{name}/{PASS_TOPICS[pass_name]}"]
                    assert [t for t, _ in got] == times, (name, pass_name)
                    for index, (_, message) in enumerate(got):
                        expected = exported_image(stream, pass_name, index)
                        assert same_image(image_array(message), expected), (name, pass_name)
                assert len(by_topic[f"/{name}/camera_info"]) == len(stream)
            assert len(by_topic["/drill/wrench"]) == len(recording.steps["step"])
    elif to == "original-h5":
        data = read_original(output)
        rig = next(iter(recording.rigs.values()))
        assert np.array_equal(data["l_img"][..., ::-1], rig.left.rgb[:])  # BGR
        assert np.array_equal(data["r_img"][..., ::-1], rig.right.rgb[:])
        assert np.array_equal(data["segm"][..., ::-1], rig.left.segmentation[:])
        assert np.array_equal(data["time"], rig.left.time[:])
        depth = rig.left.depth[:]
        tolerance = np.abs(np.spacing(depth.astype(np.float16)).astype(np.float32)) / 2
        assert (np.abs(data["depth"].astype(np.float32) - depth) <= tolerance + 1e-12).all()
        assert data["baseline"] == pytest.approx(rig.baseline[0])
        removed = len(recording.removed["step"])
        assert len(data["voxels"]) == removed
    else:
        from pycocotools.coco import COCO

        for name, stream in streams.items():
            coco = COCO(str(output / f"{name}.json"))
            assert len(coco.getImgIds()) == len(stream)
            for index in range(len(stream)):
                image = coco.loadImgs(index + 1)[0]
                assert (output / image["file_name"]).is_file()
                instance = np.zeros_like(stream.instance[index])
                for annotation in coco.loadAnns(coco.getAnnIds(imgIds=image["id"])):
                    instance[coco.annToMask(annotation).astype(bool)] = annotation["instance_id"]
                assert np.array_equal(instance, stream.instance[index]), (name, index)


@pytest.mark.parametrize("to", ["mcap", "rosbag2", "original-h5", "coco"])
@pytest.mark.slow
def test_a_generated_dataset_exports_whole_or_shard_by_shard(generated, tmp_path, to):
    """A dataset folder made by `ambfplus generate` (shards with parts) exports to every
    format, all shards at once or one shard at a time, and reads back equal to its shards."""
    from ambfplus.dataset import read_manifest

    records = read_manifest(generated)[0]
    assert len(records) == 3 and all(r["parts"] for r in records)
    results = export(generated, tmp_path / "all", to, progress=False)
    assert len(results) == 3
    index = [json.loads(x) for x in (tmp_path / "all" / "index.jsonl").read_text().splitlines()]
    assert [(x["episode"], x["source_sha256"]) for x in index] == [
        (r["episode"], r["sha256"]) for r in records
    ]
    for record, result in zip(records, results):
        with open_recording(generated / record["file"]) as recording:
            assert recording.metadata["dataset"]["episode"] == record["episode"]
            check_export_reads_back(to, result.output, recording)
    # One shard on its own, by its head file (its part is found beside it).
    shard = generated / records[1]["file"]
    single = tmp_path / ("one.mcap" if to == "mcap" else "one")
    result = export(shard, single, to, progress=False)
    with open_recording(shard) as recording:
        check_export_reads_back(to, single, recording)
    assert result.frames == results[1].frames


def test_a_dataset_is_exported_by_its_folder_or_a_shards_head(generated, tmp_path):
    """What is not a shard's head or a dataset folder is refused, saying what to pass."""
    cases = [
        (generated / "shards", "it is inside the dataset folder"),
        (generated / "manifest.jsonl", "is a dataset's manifest: export its folder"),
        (
            next((generated / "shards").glob("*.part0001")),
            "one part of a recording; open its head file",
        ),  # fmt: skip
    ]
    for source, message in cases:
        with pytest.raises(ValueError, match=message):
            export(source, tmp_path / "out", "coco", progress=False)
        completed = run_cli(tmp_path, str(source), "--to", "coco", str(tmp_path / "out"))
        assert completed.returncode == 2 and message in completed.stderr, completed.stderr
        assert list(tmp_path.iterdir()) == []
    completed = run_cli(tmp_path, str(generated), "--to", "original-h5", str(tmp_path / "o"),
                        "--quiet")  # fmt: skip
    assert completed.returncode == 0, completed.stderr
    assert len(completed.stdout.splitlines()) == 3
    assert sorted(p.name for p in (tmp_path / "o" / "shards").iterdir()) == [
        f"episode_{e:06d}" for e in range(3)
    ]
