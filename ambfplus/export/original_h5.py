"""A recording in the original system's HDF5 layout (volumetric_drilling's data_record v3), so
that analysis scripts written for it read it. The layout is the one in
``shared/reference/original-recording.md``, section 5.2.

Files: ``OUT/YYYYmmdd_HHMMSS.hdf5``, a new file every ``chunk_size`` (500) camera samples,
named by the recording's start time plus the simulation time of the file's first sample (a
second later than the previous file's name where two would fall in the same second).
Each holds::

    metadata_v3/camera_intrinsic     float64 3x3   the left camera's K (ambfplus's cx, cy)
    metadata_v3/camera_extrinsic     int64 4x4     T_cv_ambf (AMBF camera axes -> OpenCV)
    metadata_v3/README               string
    metadata_v3/baseline             float64       metres (with a stereo rig)
    metadata_v3/voxel_volume         float64       mm^3 (attribute units), with a volume
    vision_data/intermittent_data/                 empty
    vision_data/continuous_data/time               float64 (N,) simulation seconds
      l_img, r_img, segm                           uint8 (N, H, W, 3) BGR
      depth                                        float16 (N, H, W) metres, OpenCV z
      pose_<object>                                float64 (N, 7) x y z qx qy qz qw, T_world_obj
    physics_data/intermittent_data/voxels_removed/ voxel_time_stamp (G,), voxel_removed (M, 4)
                                                   [group, i, j, k], voxel_color (M, 5)
                                                   [group, r, g, b, a] 0-255, README
    physics_data/intermittent_data/burr_change/    burr_size int64 (K,) mm, time_stamp (K,)
    physics_data/intermittent_data/drill_force_feedback/  wrench (K, 6), time_stamp (K,)
    physics_data/continuous_data/high_frequency_poses/<object>_pose/  time_stamp (P,), pose (P, 7)
    ambfplus/                                      what the layout cannot say (see below)

Objects take the original's names: the drill is ``mastoidectomy_drill``, the rig's left camera
``main_camera`` and the drilled volume ``mastoidectomy_volume`` (``names=`` changes or adds
names); other logged bodies keep theirs. Camera poses are the AMBF camera body's
(T_world_cv @ T_cv_ambf), as the original records them, so that its extrinsic applies.

The original's conventions are kept where scripts depend on them: BGR images, float16 depth,
[x, y, z, qx, qy, qz, qw] poses, gzip, files of 500 samples, groups left out where empty, the
``group`` column of voxels_removed restarting at 0 in every file (concatenating files needs an
offset, as with the original's), voxel_removed holding voxel indices (as the original's
plugin publishes them) and the constant int64 extrinsic. Its known defects are not reproduced:
positions, depth, baseline and voxel volume are in metres (no 0.049 scale factor, so the README's
claim of metres is true); high-frequency poses are written once per physics step (not twice)
and stamped with simulation time (not the wall clock at receipt); the volume's pose is its
real one (not always volume_171's); the first burr is written at the first step (the original
only writes changes); the wrench's torque is 0 (the original copies the force into it); the
baseline is written only with a stereo rig.

The group ``ambfplus`` adds what v3 cannot hold: ``camera_intrinsic_right`` and ``dcx`` (an
off-axis rig's right principal point), ``volume_dimensions`` (m) and ``volume_voxel_count``,
which with ``pose_mastoidectomy_volume`` place a voxel index (i, j, k) in the world at
R ((i, j, k) + 0.5) * D / n - D / 2) + t, ``sample_step`` and ``voxel_step``, and attributes
with the software version, the source, the conventions and the names used.
"""

from __future__ import annotations

import json
from datetime import datetime, timedelta, timezone
from pathlib import Path

import numpy as np

from ..labels import legend_index
from ..recording.values import FrameGate
from ._common import ExportError, StepClock, export_conventions, pose_vector

CHUNK_SIZE = 500
# The original's constant extrinsic: AMBF camera axes (x back, y right, z up; its clouds) to
# OpenCV's.
T_CV_AMBF = np.array([[0, 1, 0, 0], [0, 0, -1, 0], [-1, 0, 0, 0], [0, 0, 0, 1]], dtype=np.int64)
README = (
    "All position information is in meters unless specified otherwise.\n"
    "Quaternion is a list in the order of [qx, qy, qz, qw].\n"
    "Poses are defined to be T_world_obj.\n"
    "Depth in CV convention (corrected by extrinsic, T_cv_ambf).\n"
    "Written by ambfplus {version} from the recording {source} (simulation time in seconds; "
    "see the group 'ambfplus' for what this layout cannot hold).\n"
)
VOXEL_README = (
    "voxel_removed rows are [group, i, j, k]: the volume's voxel indices; voxel_color rows are "
    "[group, r, g, b, a] in 0-255. A group is the voxels removed in one physics step, stamped "
    "by voxel_time_stamp[group]. Groups restart at 0 in every file.\n"
)
# The ambfplus group's attributes that describe the layout and its camera poses.
LAYOUT_NOTE = "volumetric_drilling data_record v3 (metadata_v3, vision_data, physics_data)"
CAMERA_POSES_NOTE = (
    "pose_main_camera and camera high-frequency poses are "
    "T_world_ambf_camera = T_world_cv @ T_cv_ambf (camera_extrinsic)"
)
DEFAULT_NAMES = {"drill": "mastoidectomy_drill", "camera": "main_camera",
                 "volume": "mastoidectomy_volume"}  # fmt: skip


class OriginalLayout:
    """Plans and writes one recording in the v3 layout (see the module docstring)."""

    def __init__(self, recording, chunk_size: int = CHUNK_SIZE, names: dict | None = None,
                 bad_frames: str = "refuse"):  # fmt: skip
        if chunk_size < 1:
            raise ExportError(f"chunk_size must be >= 1, got {chunk_size}")
        self.rec = recording
        self.chunk_size = chunk_size
        self.warnings: list[str] = []
        self.legend_names = legend_index(recording.legend)
        self.clock = StepClock(recording)
        self.gate = FrameGate(recording, bad_frames, ExportError)
        self._choose_streams()
        self.names = self._names(names or {})
        self.steps = recording.steps
        if self.gate.skip:
            self._skip_bad()
        self._voxel_steps = None
        if len(recording.removed["step"]) and self._volume_geometry() is None:
            # v3 holds voxel indices, as the original's plugin publishes them, so they are
            # written; without the grid's geometry nothing places them in the world.
            self.warnings.append(
                f"the legend has no dimensions and shape of volume {self.volume_name()!r}: no "
                "voxel_volume, and voxel_removed's indices cannot be placed in the world"
            )

    # Planning --------------------------------------------------------------------------------

    def _choose_streams(self) -> None:
        rec = self.rec
        rig = None
        if rec.rigs:
            wanted = rec.metadata.get("rig")
            rig = rec.rigs.get(wanted) if wanted in rec.rigs else next(iter(rec.rigs.values()))
            if len(rec.rigs) > 1:
                self.warnings.append(f"several rigs; exported {rig.name} only")
        if rig is not None:
            self.left, self.right = rig.left, rig.right
            pairs = np.asarray(rig.left_index[:]), np.asarray(rig.right_index[:])
            baselines = np.asarray(rig.baseline[:])
            if len(baselines) and np.ptp(baselines) > 1e-9:
                raise ExportError(
                    f"{rec.path}: rig {rig.name}'s baseline changes during the recording "
                    f"({baselines.min():.6g} to {baselines.max():.6g} m); the original's layout "
                    "has one baseline"
                )
            self.baseline = float(baselines[0]) if len(baselines) else None
            self.samples = list(zip(*pairs))
            self.dcx = float(rig.dcx[0]) if len(baselines) else 0.0
        elif rec.cameras:
            self.left, self.right, self.baseline, self.dcx = (
                next(iter(rec.cameras.values())), None, None, 0.0,
            )  # fmt: skip
            self.samples = [(i, None) for i in range(len(self.left))]
            if len(rec.cameras) > 1:
                self.warnings.append(f"no stereo rig; exported camera stream {self.left.name}")
        else:
            self.left = self.right = self.baseline = None
            self.dcx, self.samples = 0.0, []
        for stream in (self.left, self.right):
            if stream is not None and len(stream):
                k = np.asarray(stream.intrinsics[:])
                if np.abs(k - k[0]).max() > 1e-9:
                    raise ExportError(
                        f"{rec.path}: camera stream {stream.name}'s intrinsics change during "
                        "the recording; the original's layout has one intrinsic matrix"
                    )

    def _names(self, names: dict) -> dict:
        """ambfplus object name -> the name it takes in the layout."""
        out = {}
        drills = [e.get("name") for e in self.rec.legend.values() if e.get("kind") == "drill"]
        if drills:
            out[drills[0]] = DEFAULT_NAMES["drill"]
        if self.left is not None:
            out[self.left.camera] = DEFAULT_NAMES["camera"]
        volume = self.volume_name()
        if volume is not None:
            out[volume] = DEFAULT_NAMES["volume"]
        out.update(names)
        return out

    def volume_name(self):
        removed = self.rec.removed.get("volume")
        if removed:
            return removed
        volumes = [e.get("name") for e in self.rec.legend.values() if e.get("kind") == "volume"]
        return volumes[0] if volumes else None

    def _skip_bad(self) -> None:
        """Leaves out the samples whose views break the value rules (their time, pose or K;
        the left view's depth, read here once more) and the step rows that do."""
        gate, kept = self.gate, []
        for sample in self.samples:
            views = [(s, int(r)) for s, r in zip((self.left, self.right), sample) if r is not None]
            if all(gate.pose_ok(s.name, r) for s, r in views) and (
                self.left.depth is None
                or gate.image_ok(
                    self.left.name, int(sample[0]), "depth", self.left.depth[int(sample[0])]
                )
            ):
                kept.append(sample)
        gate.skipped_frames = len(self.samples) - len(kept)
        self.samples = kept
        if gate.bad_steps.any():
            good = ~gate.bad_steps
            self.steps = {k: (v[good] if k != "volume" else v) for k, v in self.steps.items()}

    def chunks(self) -> list[tuple[int, int]]:
        n = len(self.samples)
        return [(a, min(a + self.chunk_size, n)) for a in range(0, max(n, 1), self.chunk_size)]

    def file_names(self) -> list[str]:
        try:
            start = datetime.fromisoformat(self.rec.created)
        except (TypeError, ValueError):
            start = datetime(1970, 1, 1, tzinfo=timezone.utc)
        names, last = [], None
        for a, _ in self.chunks():
            t = self._sample_time(a) if self.samples else 0.0
            when = (start + timedelta(seconds=float(t))).replace(microsecond=0)
            if last is not None and when <= last:
                # A file less than a second after the previous one is named a second later, so
                # that names stay unique and in order.
                when = last + timedelta(seconds=1)
            names.append(when.strftime("%Y%m%d_%H%M%S") + ".hdf5")
            last = when
        return names

    def _sample_time(self, index: int) -> float:
        return float(self.left.time[int(self.samples[index][0])])

    # Writing ---------------------------------------------------------------------------------

    def write(self, folder: Path, bar) -> dict:
        """Writes the files into ``folder`` (created); returns their names and counts."""
        import h5py

        folder.mkdir()
        chunks, names = self.chunks(), self.file_names()
        bounds = [self._sample_time(a) if self.samples else -np.inf for a, _ in chunks]
        bounds[0] = -np.inf
        bounds.append(np.inf)
        for index, ((a, b), name) in enumerate(zip(chunks, names)):
            with h5py.File(folder / name, "w") as f:
                self._metadata(f)
                self._vision(f, a, b, bar)
                self._physics(f, bounds[index], bounds[index + 1])
                self._extension(f, a, b)
        return {"files": names, "samples": len(self.samples), "frames": len(self.samples),
                "warnings": self.warnings, **self.gate.counts()}  # fmt: skip

    def _dataset(self, group, name: str, data, **attrs) -> None:
        data = np.asarray(data) if not isinstance(data, str) else data
        if isinstance(data, str) or data.ndim == 0:
            dataset = group.create_dataset(name, data=data)
        else:
            dataset = group.create_dataset(name, data=data, compression="gzip")
        for key, value in attrs.items():
            dataset.attrs[key] = value

    def _metadata(self, f) -> None:
        group = f.create_group("metadata_v3")
        if self.left is not None and len(self.left):
            self._dataset(group, "camera_intrinsic", np.asarray(self.left.intrinsics[0]))
        self._dataset(group, "camera_extrinsic", T_CV_AMBF)
        self._dataset(group, "README", README.format(version=export_conventions(self.rec)[
            "ambfplus_version"], source=self.rec.path.name))  # fmt: skip
        if self.baseline is not None:
            self._dataset(group, "baseline", np.float64(self.baseline))
        geometry = self._volume_geometry()
        if geometry is not None:
            dimensions, shape = geometry
            volume_mm3 = float(np.prod(dimensions / shape * 1000.0))
            self._dataset(group, "voxel_volume", np.float64(volume_mm3),
                          units="mm^3, millimeters cubed")  # fmt: skip

    def _volume_geometry(self):
        entry = self.legend_names.get(self.volume_name()) or {}
        if "dimensions" not in entry or "shape" not in entry:
            return None
        return np.asarray(entry["dimensions"], float), np.asarray(entry["shape"], float)

    def _vision(self, f, a: int, b: int, bar) -> None:
        f.create_group("vision_data/intermittent_data")
        group = f.create_group("vision_data/continuous_data")
        if not self.samples:
            return
        left_rows = [int(self.samples[i][0]) for i in range(a, b)]
        left = self.left
        self._dataset(group, "time", np.asarray(left.time[left_rows], dtype=np.float64))
        images = {"l_img": (left, "rgb", 0), "segm": (left, "segmentation", 0)}
        if self.right is not None:
            images["r_img"] = (self.right, "rgb", 1)
        datasets = []
        for name, (stream, pass_name, side) in images.items():
            column = stream.columns.get(pass_name)
            if column is None:
                self.warnings.append(f"stream {stream.name} has no {pass_name}: no {name}")
                continue
            datasets.append((name, column, side, lambda image: image[..., ::-1], np.uint8))
        if left.depth is not None:
            datasets.append(("depth", left.depth, 0, lambda d: d, np.float16))
        # One sample per chunk, written as read: a file of 500 full-size samples would not fit
        # in memory at once.
        for name, column, _, _, dtype in datasets:
            group.create_dataset(name, shape=(b - a,) + column.shape[1:], dtype=dtype,
                                 chunks=(1,) + column.shape[1:], compression="gzip")  # fmt: skip
        for i in range(a, b):
            for name, column, side, convert, _ in datasets:
                row = int(self.samples[i][side])
                image = np.asarray(column[row])
                if name == "depth":
                    self.gate.image_ok(left.name, row, "depth", image)  # refuses a bad one
                group[name][i - a] = convert(image)
            bar.update(1)
        for name, poses in self._sample_poses(left_rows).items():
            self._dataset(group, f"pose_{name}", poses)

    def _sample_poses(self, left_rows: list[int]) -> dict[str, np.ndarray]:
        """pose_<object> rows of the samples: the camera where its frame was taken, logged
        objects at the sample's step, the volume fixed."""
        left = self.left
        out = {self.names[left.camera]: np.array([
            pose_vector(pose @ T_CV_AMBF) for pose in left.pose[left_rows]])}  # fmt: skip
        steps = self.steps
        if "step" in steps:
            rows = np.searchsorted(steps["step"], np.asarray(left.step[left_rows]))
            rows = np.clip(rows, 0, len(steps["step"]) - 1)
            for name, column in self._logged_poses().items():
                if name == left.camera:
                    continue
                out[self.names.get(name, name)] = np.array([pose_vector(p) for p in column[rows]])
        volume = self.volume_name()
        entry = self.legend_names.get(volume) or {}
        if volume is not None and "pose" in entry and volume not in self._logged_poses():
            row = pose_vector(np.asarray(entry["pose"], dtype=np.float64))
            out[self.names[volume]] = np.tile(row, (len(left_rows), 1))
        elif volume is not None and volume not in self._logged_poses():
            note = f"the legend has no pose of volume {volume}: no pose_{self.names[volume]}"
            if note not in self.warnings:
                self.warnings.append(note)
        return out

    def _logged_poses(self) -> dict[str, np.ndarray]:
        out = {}
        for column, values in self.steps.items():
            if column.endswith(".pose") and values.ndim == 3 and values.shape[1:] == (4, 4):
                key = column[: -len(".pose")]
                entry = self.legend_names.get(key) or {}
                kind = entry.get("kind")
                # The original's layout names objects plainly (it had no namespaces): by the
                # declared name where one object has it, else by the key with '_' for '/'.
                name = entry.get("name") or key
                if self.legend_names.get(name) is not entry:
                    name = key.replace("/", "_")
                # Camera bodies in AMBF's camera axes, as the original's camera states are.
                out[name] = values @ T_CV_AMBF if kind == "camera" else values
        return out

    def _physics(self, f, t0: float, t1: float) -> None:
        steps = self.steps
        intermittent = f.create_group("physics_data/intermittent_data")
        self._voxels(intermittent, t0, t1)
        if "step" in steps:
            times = steps["time"]
            window = np.flatnonzero((times >= t0) & (times < t1))
            self._burr(intermittent, window)
            self._wrench(intermittent, window)
            poses = f.create_group("physics_data/continuous_data/high_frequency_poses")
            if len(window):
                for name, column in self._logged_poses().items():
                    group = poses.create_group(f"{self.names.get(name, name)}_pose")
                    self._dataset(group, "time_stamp", times[window])
                    self._dataset(group, "pose", np.array([pose_vector(p)
                                                           for p in column[window]]))  # fmt: skip
        else:
            f.create_group("physics_data/continuous_data")

    def _voxels(self, intermittent, t0: float, t1: float) -> None:
        removed = self.rec.removed
        steps = removed["step"]
        if not len(steps):
            return
        times = self.clock(steps)
        inside = np.flatnonzero((times >= t0) & (times < t1))
        if not len(inside):
            return  # the original leaves an empty group out
        steps, times = steps[inside], times[inside]
        voxels, labels = removed["voxel"][inside], removed["label"][inside]
        first = np.r_[True, np.diff(steps) != 0]
        group_index = np.cumsum(first) - 1
        entry = self.legend_names.get(removed["volume"]) or {}
        table = entry.get("labels", {})
        colours = np.zeros((int(labels.max()) + 1, 3))
        for label_id, label in table.items():
            if int(label_id) < len(colours):
                colours[int(label_id)] = label.get("color", (0, 0, 0))
        group = intermittent.create_group("voxels_removed")
        self._dataset(group, "voxel_time_stamp", times[first])
        self._dataset(group, "voxel_removed",
                      np.column_stack([group_index, voxels]).astype(np.float64))  # fmt: skip
        rgba = np.column_stack([colours[labels], np.full(len(labels), 255.0)])
        self._dataset(group, "voxel_color", np.column_stack([group_index, rgba]))
        self._dataset(group, "README", VOXEL_README)
        self._voxel_steps = steps[first]

    def _drill(self):
        return next((n for n, v in self.names.items() if v == DEFAULT_NAMES["drill"]), None)

    def _burr(self, intermittent, window: np.ndarray) -> None:
        drill = self._drill()
        column = self.steps.get(f"{drill}.burr") if drill else None
        diameters = (self.legend_names.get(drill) or {}).get("burr_diameters")
        if column is None or not len(window):
            return
        if diameters is None:
            self.warnings.append("the legend has no burr diameters: burr_change left out")
            return
        burr = column[window]
        whole = self.steps[f"{drill}.burr"]
        before = whole[window[0] - 1] if window[0] > 0 else None
        changed = np.r_[before is None or burr[0] != before, burr[1:] != burr[:-1]]
        if not changed.any():
            return
        sizes = np.round(np.asarray(diameters)[burr[changed]] * 1000).astype(np.int64)
        group = intermittent.create_group("burr_change")
        self._dataset(group, "burr_size", sizes)
        self._dataset(group, "time_stamp", self.steps["time"][window][changed])

    def _wrench(self, intermittent, window: np.ndarray) -> None:
        drill = self._drill()
        force = self.steps.get(f"{drill}.force") if drill else None
        if force is None or not len(window):
            return
        group = intermittent.create_group("drill_force_feedback")
        wrench = np.zeros((len(window), 6))
        wrench[:, :3] = force[window]
        self._dataset(group, "wrench", wrench)
        self._dataset(group, "time_stamp", self.steps["time"][window])

    def _extension(self, f, a: int, b: int) -> None:
        group = f.create_group("ambfplus")
        conventions = export_conventions(self.rec)
        for key, value in conventions.items():
            group.attrs[key] = value
        group.attrs["layout"] = LAYOUT_NOTE
        group.attrs["names"] = json.dumps({v: k for k, v in self.names.items()}, sort_keys=True)
        group.attrs["camera_poses"] = CAMERA_POSES_NOTE
        group.attrs["warnings"] = json.dumps(self.warnings)
        if self.right is not None and len(self.right):
            self._dataset(group, "camera_intrinsic_right", np.asarray(self.right.intrinsics[0]))
            self._dataset(group, "dcx", np.float64(self.dcx))
        geometry = self._volume_geometry()
        if geometry is not None:
            self._dataset(group, "volume_dimensions", geometry[0])
            self._dataset(group, "volume_voxel_count", geometry[1].astype(np.int64))
        if self.samples:
            rows = [int(self.samples[i][0]) for i in range(a, b)]
            self._dataset(group, "sample_step", np.asarray(self.left.step[rows], np.int64))
        steps = getattr(self, "_voxel_steps", None)
        if steps is not None and "voxels_removed" in f["physics_data/intermittent_data"]:
            self._dataset(group, "voxel_step", steps.astype(np.int64))
        self._voxel_steps = None


def write_original(recording, out: Path, bar, *, chunk_size: int = CHUNK_SIZE,
                   names: dict | None = None, bad_frames: str = "refuse") -> dict:  # fmt: skip
    """Writes a recording in the original's v3 layout into the folder ``out`` (which must not
    exist yet); returns the files written. ``bad_frames``: "refuse" or "skip" samples whose
    values break ``ambfplus.recording.values``' rules."""
    layout = OriginalLayout(recording, chunk_size=chunk_size, names=names, bad_frames=bad_frames)
    return layout.write(out, bar)
