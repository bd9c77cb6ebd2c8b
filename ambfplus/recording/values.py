"""The value rules of a recording, in one place: what ``validate`` checks and what the exports
refuse (or skip and count) besides the layout. A frame's depth is finite and >= 0 (0 where
nothing was hit), its time finite, its pose a rigid transform, its intrinsics a camera's (finite,
positive focal lengths, last row 0 0 1), its points finite, its labels in the label tables of the
legend's volumes, its instance ids in the legend and its voxel indices -1 or inside a volume. A
step log's numbers are finite and its ``*.pose`` columns rigid transforms."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# A rotation read back from float64 storage is orthonormal to rounding; one written from float32
# arithmetic to about 1e-6. Damage (a scale, a shear, a NaN) is far beyond either.
RIGID_TOLERANCE = 1e-5


def pose_problem(pose) -> str | None:
    """Why a 4x4 pose is not a rigid transform (``rigid``'s rule), or None."""
    pose = np.asarray(pose, dtype=float)
    if pose.shape != (4, 4):
        return f"a pose of shape {pose.shape}, not 4x4"
    if rigid(pose[None])[0]:
        return None
    if not np.isfinite(pose).all():
        return f"a pose holding {_non_finite(pose)}"
    if np.abs(pose[3] - (0.0, 0.0, 0.0, 1.0)).max() > RIGID_TOLERANCE:
        return f"a pose whose last row is {_short(pose[3])}, not 0 0 0 1"
    rotation = pose[:3, :3]
    error = float(np.abs(rotation.T @ rotation - np.eye(3)).max())
    what = "a reflection" if np.linalg.det(rotation) < 0 else f"off by {error:.3g}"
    return f"a pose whose rotation is not one ({what})"


def camera_intrinsics(ks: np.ndarray) -> np.ndarray:
    """Per K of an (N, 3, 3) array, whether it is a camera's: finite, fx and fy > 0, last row
    0 0 1."""
    ks = np.asarray(ks, dtype=float)
    good = np.isfinite(ks).all(axis=(1, 2)) & (ks[:, 0, 0] > 0) & (ks[:, 1, 1] > 0)
    return good & (np.abs(ks[:, 2] - (0.0, 0.0, 1.0)) <= 1e-12).all(axis=1)


def intrinsics_problem(k) -> str | None:
    """Why a 3x3 K is not a camera's (``camera_intrinsics``' rule), or None."""
    k = np.asarray(k, dtype=float)
    if k.shape != (3, 3) or not np.isfinite(k).all():
        return f"intrinsics {_short(k)} that are not a finite 3x3 matrix"
    if not camera_intrinsics(k[None])[0]:
        return f"intrinsics {_short(k)} with no positive focal lengths or a last row not 0 0 1"
    return None


def _non_finite(values: np.ndarray) -> str:
    nan = int(np.isnan(values).sum())
    inf = int(np.isinf(values).sum())
    parts = (f"{nan} NaN" if nan else "", f"{inf} infinite" if inf else "")
    return ", ".join(p for p in parts if p)


def _short(values) -> str:
    return np.array2string(np.asarray(values), precision=4, separator=" ", threshold=12)


def _pixel(mask: np.ndarray) -> str:
    row, column = np.argwhere(mask)[0][:2]
    return f"row {int(row)}, column {int(column)}"


@dataclass
class Rules:
    """The legend's ids, label ids and voxel counts a recording's values are checked against
    (``Rules.of(recording)``)."""

    ids: np.ndarray  # object ids in the legend, sorted
    labels: np.ndarray  # label ids of every volume in the legend, sorted (0 always allowed)
    voxels: int | None  # voxels of the largest volume, when the legend says its shape
    has_labels: bool = True
    skipped: dict = field(default_factory=dict)

    @classmethod
    def of(cls, recording) -> Rules:
        legend = recording.legend
        ids = np.array(sorted(int(i) for i in legend), dtype=np.int64)
        labels, voxels, has_labels = {0}, None, False
        for entry in legend.values():
            if entry.get("kind") != "volume":
                continue
            if "labels" in entry:
                has_labels = True
                labels.update(int(label) for label in entry["labels"])
            shape = entry.get("shape")
            if shape is None:
                shape = recording.metadata.get("volumes", {}).get(entry.get("name"), {})
                shape = shape.get("shape") if isinstance(shape, dict) else None
            if shape is not None:
                count = int(np.prod([int(n) for n in shape]))
                voxels = count if voxels is None else max(voxels, count)
        return cls(ids, np.array(sorted(labels), dtype=np.int64), voxels, has_labels)

    def frame_problems(self, frame, passes=None) -> list[str]:
        """What is wrong with a recorded frame's values (empty: nothing). `passes` limits the
        image passes looked at (default: every pass the frame has)."""
        problems = []
        time = float(frame.time)
        if not np.isfinite(time):
            problems.append(f"time {time}")
        for problem in (pose_problem(frame.pose), intrinsics_problem(frame.intrinsics)):
            if problem:
                problems.append(problem)
        names = passes if passes is not None else ("depth", "points", "label", "instance", "voxel")
        for name in names:
            image = getattr(frame, name, None)
            if image is None:
                continue
            problem = self.image_problem(name, np.asarray(image))
            if problem:
                problems.append(problem)
        return problems

    def image_problem(self, name: str, image: np.ndarray) -> str | None:
        """Why an image pass holds a value it may not, naming the first pixel, or None."""
        if name in ("depth", "points"):
            # The common case at memory speed: a sum is finite exactly when every value is
            # (metres do not overflow float32), and depth's minimum is not negative.
            if np.isfinite(image.sum(dtype=np.float64)) and (name != "depth" or image.min() >= 0):
                return None
            bad = ~np.isfinite(image)
            if name == "depth":
                bad |= image < 0
            else:
                bad = bad.any(axis=-1)
            if bad.any():
                first = image[tuple(np.argwhere(bad)[0][:2])]
                what = "finite and >= 0" if name == "depth" else "finite"
                count = int(bad.sum())
                return f"{name} {_short(first)} at {_pixel(bad)} ({count} pixels not {what})"
            return None
        if name == "label" and self.has_labels:
            return self._members("label", image, self.labels, "the legend's label tables")
        if name == "instance":
            return self._members("instance", image, np.union1d(self.ids, [0]), "the legend")
        if name == "voxel":
            bad = image < -1
            if self.voxels is not None:
                bad |= image >= self.voxels
            if bad.any():
                value = int(image[tuple(np.argwhere(bad)[0])])
                return f"voxel index {value} at {_pixel(bad)} outside the volume"
        return None

    @staticmethod
    def _members(name: str, image: np.ndarray, allowed: np.ndarray, where: str) -> str | None:
        if image.size == 0:
            return None
        low, high = int(image.min()), int(image.max())
        if low >= 0 and high < 1 << 20:  # a table lookup per pixel: no sort of the image
            table: np.ndarray = np.zeros(high + 1, dtype=bool)
            table[allowed[(allowed >= 0) & (allowed <= high)]] = True
            bad = ~table[image]
        else:
            bad = ~np.isin(image, allowed)
        if not bad.any():
            return None
        unknown = np.unique(image[bad])
        mask = image == unknown[0]
        return f"{name} {int(unknown[0])} at {_pixel(mask)} not in {where}" + (
            f" (and {unknown.size - 1} more ids)" if unknown.size > 1 else ""
        )


def _bad_step_column(column: str, values: np.ndarray) -> tuple[np.ndarray, str] | None:
    """A float step column's rows that break the rules and how ("not finite" first, then
    "not rigid" for a ``*.pose`` column), or None for a column the rules do not cover."""
    if values.dtype.kind != "f" or not len(values):
        return None
    flat = values.reshape(len(values), -1)
    bad = ~np.isfinite(flat).all(axis=1)
    if bad.any():
        return bad, "not finite"
    if column.endswith(".pose") and flat.shape[1] == 16:
        return ~rigid(flat.reshape(-1, 4, 4)), "not rigid"
    return bad, "not finite"


def step_problems(steps: dict) -> list[str]:
    """What is wrong with a step log's values: numbers that are not finite (naming the column,
    the row and the value) and ``*.pose`` columns that are not rigid transforms."""
    problems = []
    for column, values in steps.items():
        values = np.asarray(values)
        found = _bad_step_column(column, values)
        if found is None or not found[0].any():
            continue
        bad, how = found
        row = int(np.flatnonzero(bad)[0])
        if how == "not finite":
            what = f"holds {_short(values[row])}"
        else:
            what = f"is {pose_problem(values[row].reshape(4, 4))}"
        problems.append(f"steps/{column} row {row} {what} ({int(bad.sum())} rows {how})")
    return problems


def rigid(poses: np.ndarray) -> np.ndarray:
    """Per pose of an (N, 4, 4) array, whether it is a rigid transform (as pose_problem)."""
    poses = np.asarray(poses, dtype=float)
    finite = np.isfinite(poses).all(axis=(1, 2))
    poses = np.where(finite[:, None, None], poses, np.eye(4))
    last = np.abs(poses[:, 3] - (0.0, 0.0, 0.0, 1.0)).max(axis=1) <= RIGID_TOLERANCE
    rotation = poses[:, :3, :3]
    gram = np.einsum("nji,njk->nik", rotation, rotation) - np.eye(3)
    orthonormal = np.abs(gram).max(axis=(1, 2)) <= RIGID_TOLERANCE
    return finite & last & orthonormal & (np.linalg.det(rotation) > 0)


def bad_step_rows(steps: dict) -> np.ndarray:
    """Per row of a step log, whether it breaks the rules (the rows step_problems describes)."""
    rows = len(steps["step"]) if "step" in steps else 0
    bad: np.ndarray = np.zeros(rows, dtype=bool)
    for column, values in steps.items():
        values = np.asarray(values)
        if len(values) != rows:
            continue
        found = _bad_step_column(column, values)
        if found is not None:
            bad |= found[0]
    return bad


BAD_FRAMES = ("refuse", "skip")


class FrameGate:
    """What an export writes of a recording under the value rules: with ``bad_frames``
    "refuse" the first frame or step row that breaks them raises `error` (the export then
    leaves nothing); with "skip" such frames and rows are left out and counted. Times, poses,
    intrinsics and the step log are checked from their columns when the gate is made; a frame's
    images as the export reads them (``image_ok``, ``frame_ok``)."""

    def __init__(self, recording, bad_frames: str = "refuse", error: type = ValueError) -> None:
        if bad_frames not in BAD_FRAMES:
            raise error(f"bad_frames must be one of {', '.join(BAD_FRAMES)}, got {bad_frames!r}")
        self.path, self.error = recording.path, error
        self.skip = bad_frames == "skip"
        self.rules = Rules.of(recording)
        self.skipped_frames = 0
        self._skipped: set = set()
        self.bad_columns = {}
        for name, stream in recording.cameras.items():
            bad = self._column_rows(stream)
            if bad.any() and not self.skip:
                row = int(np.flatnonzero(bad)[0])
                frame = stream[row]
                self._refuse(
                    f"cameras/{name} frame {row}: {'; '.join(self.rules.frame_problems(frame, ()))}"
                )
            self.bad_columns[name] = bad
        steps = recording.steps
        self.bad_steps = bad_step_rows(steps) if steps else np.zeros(0, dtype=bool)
        if self.bad_steps.any() and not self.skip:
            self._refuse(step_problems(steps)[0])

    @staticmethod
    def _column_rows(stream) -> np.ndarray:
        times = np.asarray(stream.time[:], dtype=float)
        ks = np.asarray(stream.intrinsics[:], dtype=float).reshape(-1, 3, 3)
        poses = np.asarray(stream.pose[:], dtype=float).reshape(-1, 4, 4)
        return ~(np.isfinite(times) & camera_intrinsics(ks) & rigid(poses))

    def _refuse(self, what: str) -> None:
        raise self.error(
            f"{self.path}: {what}; nothing was exported (bad_frames='skip', --skip-bad-frames on "
            "the command line, leaves such frames out and counts them)"
        )

    def pose_ok(self, stream: str, index: int) -> bool:
        """Whether frame `index` of camera stream `stream` has a good time, pose and K."""
        bad = self.bad_columns.get(stream)
        return bad is None or not bad[index]

    def step_ok(self, row: int) -> bool:
        return not len(self.bad_steps) or not self.bad_steps[row]

    def image_ok(self, stream: str, index: int, name: str, image) -> bool:
        """Whether an image pass of a frame holds only allowed values (raises under
        "refuse"); a skipped frame is counted once."""
        if (stream, index) in self._skipped:
            return False
        problem = self.rules.image_problem(name, np.asarray(image))
        if problem is None:
            return True
        if not self.skip:
            self._refuse(f"cameras/{stream} frame {index}: {problem}")
        self._skipped.add((stream, index))
        self.skipped_frames += 1
        return False

    def frame_ok(self, stream: str, index: int, frame) -> bool:
        """Whether a frame (its columns, then each image pass it has) may be written."""
        if not self.pose_ok(stream, index):
            if (stream, index) not in self._skipped:
                self._skipped.add((stream, index))
                self.skipped_frames += 1
            return False
        for name in ("depth", "points", "label", "instance", "voxel"):
            image = getattr(frame, name, None)
            if image is not None and not self.image_ok(stream, index, name, image):
                return False
        return True

    def counts(self) -> dict:
        """What was skipped, for an export's details."""
        return {"skipped_frames": self.skipped_frames, "skipped_steps": int(self.bad_steps.sum())}
