"""``validate(path)``: checks that a recording is consistent with itself and with the conventions
(``ambfplus validate PATH`` on the command line)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..stereo import disparity_agreement
from .hdf5 import check_global_heaps
from .reader import DAMAGE, CameraStream, Recording, RigStream, open_recording
from .schema import RecordingError, find_parts, glob_escape
from .values import Rules, step_problems

POINTS_RELATIVE_TOLERANCE = 1e-4
BASELINE_TOLERANCE_M = 1e-6
# Block matching on rendered bone: textured points needed, the largest median error of a pair
# (smooth bone gives some wrong matches), and how close the recovered baseline must be.
DISPARITY_MIN_POINTS = 50
DISPARITY_MEDIAN_PX = 2.0
DISPARITY_BASELINE_REL = 0.02
DCX_TOLERANCE_PX = 1e-6


@dataclass
class Check:
    """One check: ``status`` is "pass", "fail", "skip" (does not apply) or "warn" (passes)."""

    name: str
    status: str
    detail: str = ""
    numbers: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return self.status != "fail"


@dataclass
class ValidationReport:
    """The checks run on one recording; ``ok`` when none failed."""

    path: Path
    checks: list[Check]

    @property
    def ok(self) -> bool:
        return all(check.passed for check in self.checks)

    @property
    def failed(self) -> list[Check]:
        return [check for check in self.checks if not check.passed]

    def __str__(self) -> str:
        lines = [f"{self.path}:"]
        for check in self.checks:
            numbers = ", ".join(f"{k}={_short(v)}" for k, v in check.numbers.items())
            text = f"  {check.status.upper():4}  {check.name}"
            text += f": {check.detail}" if check.detail else ""
            text += f" ({numbers})" if numbers else ""
            lines.append(text)
        failed = len(self.failed)
        lines.append(f"{'OK' if self.ok else 'FAILED'}: {len(self.checks)} checks, {failed} failed")
        return "\n".join(lines)

    def to_dict(self) -> dict:
        return {
            "path": str(self.path),
            "ok": self.ok,
            "checks": [
                {"name": c.name, "status": c.status, "detail": c.detail, "numbers": c.numbers}
                for c in self.checks
            ],
        }


def _short(value) -> str:
    return f"{value:.3g}" if isinstance(value, float) else str(value)


def validate(path, match_images: bool = True) -> ValidationReport:
    """Opens the recording and checks it: lengths, increasing steps and times, depth against
    points, rig geometry, removed labels against the legend, removed voxels not seen later.
    `match_images` also block-matches three stereo pairs against their depth and baseline (the
    costliest check: about as much CPU as rendering the recording took). Before it opens the
    recording, it checks the global heaps of every file (see ``ambfplus.recording.hdf5``)."""
    path = Path(path)
    try:
        heaps = _heaps_check(path)
        recording = open_recording(path)
    except (RecordingError, OSError) as error:
        return ValidationReport(path, [Check("open", "fail", str(error))])
    with recording:
        checks = [_open_check(recording), heaps, _leftover_check(path)]
        checks.append(_metadata_check(recording))
        try:
            rules = Rules.of(recording)
            for name, stream in recording.cameras.items():
                checks += _stream_checks(f"cameras/{name}", stream)
                checks.append(_values_check(f"cameras/{name}", stream, rules))
            for name, rig in recording.rigs.items():
                checks += _rig_checks(f"rigs/{name}", rig, match_images)
            checks += _steps_checks(recording.steps)
            checks += _removed_checks(recording)
            checks += _log_order_checks(recording)
            for name, stream in recording.cameras.items():
                checks.append(_removed_visibility_check(f"cameras/{name}", stream, recording))
        except (RecordingError, *DAMAGE) as error:
            # Data that cannot be read or does not have the layout's shapes and types.
            checks.append(Check("read", "fail", f"{type(error).__name__}: {error}"))
    return ValidationReport(path, checks)


def _open_check(recording: Recording) -> Check:
    numbers = {"parts": len(recording.parts), "version": recording.version}
    if recording.complete:
        return Check("open", "pass", "head and parts agree", numbers)
    return Check(
        "open",
        "warn",
        "the recorder did not close (interrupted): the parts hold everything up to its last "
        "flush; ambfplus.recording.repair(path) completes the head",
        numbers,
    )


def _heaps_check(path: Path) -> Check:
    """Every file's global heap collections walked as libhdf5 walks them (raises a
    RecordingError naming the file and collection that would make libhdf5 loop)."""
    files = [path] + [part for _, part in find_parts(path)]
    collections = sum(check_global_heaps(file) for file in files)
    numbers = {"files": len(files), "collections": collections}
    return Check("global heaps", "pass", "every collection ends where it says it does", numbers)


def _equal_lengths(name: str, columns: dict) -> Check:
    lengths = {column: len(data) for column, data in columns.items()}
    if len(set(lengths.values())) <= 1:
        return Check(f"{name}: equal lengths", "pass", "", {"rows": next(iter(lengths.values()))})
    return Check(f"{name}: equal lengths", "fail", f"dataset lengths differ: {lengths}")


def _increasing(name: str, values: np.ndarray, strictly: bool = True) -> Check:
    """Strictly (or weakly) increasing values; names the first row that breaks it."""
    values = np.asarray(values)
    steps = np.diff(values)
    bad = np.flatnonzero(steps <= 0 if strictly else steps < 0)
    what = "increases strictly" if strictly else "never decreases"
    title = f"{name} {what}"
    if bad.size == 0:
        return Check(title, "pass", "", {"rows": len(values)})
    i = int(bad[0]) + 1
    return Check(
        title,
        "fail",
        f"row {i} has {values[i]!r} after {values[i - 1]!r}",
        {"rows": len(values), "violations": int(bad.size)},
    )


def _stream_checks(name: str, stream: CameraStream) -> list[Check]:
    checks = [
        _equal_lengths(name, stream.columns),
        _increasing(f"{name}/step", stream.step[:]),
        _increasing(f"{name}/time", stream.time[:]),
    ]
    if "points" in stream.passes and "depth" in stream.passes:
        checks.append(_points_check(name, stream))
    return checks


def pixel_rays(intrinsics: np.ndarray, height: int, width: int) -> np.ndarray:
    """Camera-frame rays (z = 1) through pixel centres (c + 0.5, r + 0.5), (H, W, 3)."""
    cols, rows = np.meshgrid(np.arange(width) + 0.5, np.arange(height) + 0.5)
    k = np.asarray(intrinsics, dtype=np.float64)
    x = (cols - k[0, 2]) / k[0, 0]
    y = (rows - k[1, 2]) / k[1, 1]
    return np.stack([x, y, np.ones_like(x)], axis=-1)


def _points_check(name: str, stream: CameraStream) -> Check:
    """points = depth * K^-1 [c + 0.5, r + 0.5, 1] in every frame, to a relative 1e-4."""
    worst, bad_pixels, first_bad = 0.0, 0, None
    for i in range(len(stream)):
        depth = stream.depth[i].astype(np.float64)
        expected = depth[..., None] * pixel_rays(stream.intrinsics[i], *depth.shape)
        error = np.linalg.norm(stream.points[i] - expected, axis=-1)
        scale = np.linalg.norm(expected, axis=-1)
        relative = error / np.maximum(scale, 1e-12)
        relative[scale == 0] = np.where(error[scale == 0] > 0, np.inf, 0.0)
        worst = max(worst, float(relative.max(initial=0.0)))
        bad = int(np.count_nonzero(relative > POINTS_RELATIVE_TOLERANCE))
        bad_pixels += bad
        if bad and first_bad is None:
            first_bad = i
    numbers = {"frames": len(stream), "max_relative_error": worst}
    title = f"{name}: points agree with depth"
    if bad_pixels == 0:
        return Check(title, "pass", f"within {POINTS_RELATIVE_TOLERANCE:g} relative", numbers)
    detail = f"{bad_pixels} pixels off by more than {POINTS_RELATIVE_TOLERANCE:g}, first in frame"
    return Check(title, "fail", f"{detail} {first_bad}", {**numbers, "bad_pixels": bad_pixels})


def _rig_checks(name: str, rig: RigStream, match_images: bool = True) -> list[Check]:
    checks = [_equal_lengths(name, rig.columns), _increasing(f"{name}/step", rig.step[:])]
    left, right = rig.left_index[:], rig.right_index[:]
    if len(left) and (
        left.min() < 0
        or right.min() < 0
        or left.max() >= len(rig.left)
        or right.max() >= len(rig.right)
    ):
        checks.append(Check(f"{name}: frame indices", "fail", "a pair points past its streams"))
        return checks
    checks.append(Check(f"{name}: frame indices", "pass", "", {"pairs": len(left)}))
    checks.append(_views_paired_check(name, rig, left, right))
    checks.append(_pair_steps_check(name, rig, left, right))
    checks += _rig_geometry_checks(name, rig, left, right)
    if match_images:
        checks.append(_disparity_check(name, rig))
    return checks


def _disparity_check(name: str, rig: RigStream) -> Check:
    """On the first, middle and last pairs: block matching between the images agrees with the
    disparity their depth and baseline predict, and gives back the baseline."""
    title = f"{name}: disparity from depth and baseline matches the images"
    if len(rig) == 0 or not {"rgb", "depth"} <= set(rig.left.passes):
        return Check(title, "skip", "needs pairs with rgb and depth")
    pairs = sorted({0, len(rig) // 2, len(rig) - 1})
    results = [(i, disparity_agreement(rig[i])) for i in pairs]
    used = [(i, r) for i, r in results if r["points"] >= DISPARITY_MIN_POINTS]
    if not used:
        return Check(title, "skip", "too little texture to match")
    median = max(r["median_error"] for _, r in used)
    baseline_error = max(abs(r["baseline"] - rig.baseline[i]) / rig.baseline[i] for i, r in used)
    numbers = {
        "pairs": len(used),
        "points": sum(r["points"] for _, r in used),
        "median_error_px": median,
        "baseline_error": baseline_error,
    }
    if median <= DISPARITY_MEDIAN_PX and baseline_error <= DISPARITY_BASELINE_REL:
        return Check(title, "pass", f"median within {DISPARITY_MEDIAN_PX} px", numbers)
    return Check(
        title,
        "fail",
        f"median error {median:.2f} px (<= {DISPARITY_MEDIAN_PX}), baseline off by "
        f"{baseline_error:.1%} (<= {DISPARITY_BASELINE_REL:.0%})",
        numbers,
    )


def _views_paired_check(name: str, rig: RigStream, left, right) -> Check:
    """The rig's two streams hold the same number of frames and every frame is in a pair: a
    view without its other half means a pair was cut (a recording interrupted inside it)."""
    title = f"{name}: both views of every pair recorded"
    counts = {"left": len(rig.left), "right": len(rig.right), "pairs": len(left)}
    unpaired = {
        "left": len(rig.left) - len(np.unique(left)),
        "right": len(rig.right) - len(np.unique(right)),
    }
    if counts["left"] == counts["right"] and not any(unpaired.values()):
        return Check(title, "pass", "", counts)
    detail = (
        f"stream {rig.left.name} has {counts['left']} frames and {rig.right.name} "
        f"{counts['right']} for {counts['pairs']} pairs ({unpaired['left']} and "
        f"{unpaired['right']} frames in no pair): a stereo pair was cut"
    )
    return Check(
        title, "fail", detail, {**counts, **{f"unpaired_{k}": v for k, v in unpaired.items()}}
    )


def leftover_files(path: Path) -> list[Path]:
    """Unfinished files a recorder that did not close left beside ``path``: its last part's
    ``.partNNNN.tmp`` and a head being rewritten (``.tmp``). Readers ignore them."""
    escaped = glob_escape(path.name)
    found = list(path.parent.glob(escaped + ".part*.tmp")) + list(
        path.parent.glob(escaped + ".tmp")
    )
    return sorted(found)


def _leftover_check(path: Path) -> Check:
    found = leftover_files(path)
    if not found:
        return Check("no unfinished files", "pass")
    names = ", ".join(p.name for p in found)
    return Check(
        "no unfinished files",
        "warn",
        f"{names}: left by a recorder that did not close; readers ignore them and "
        "ambfplus.recording.repair(path) removes them",
        {"files": len(found)},
    )


# Small per-frame columns are read whole and indexed in memory (one read per part).
def _pair_steps_check(name: str, rig: RigStream, left, right) -> Check:
    steps = rig.step[:]
    same = (rig.left.step[:][left] == steps) & (rig.right.step[:][right] == steps)
    if len(steps) == 0 or same.all():
        return Check(f"{name}: views share the pair's step", "pass", "", {"pairs": len(steps)})
    i = int(np.flatnonzero(~same)[0])
    return Check(f"{name}: views share the pair's step", "fail", f"pair {i} differs")


def _rig_geometry_checks(name: str, rig: RigStream, left, right) -> list[Check]:
    """Baseline = distance between the poses; dcx = cx_right - cx_left."""
    if len(left) == 0:
        return []
    left_t = rig.left.pose[:][left][:, :3, 3]
    right_t = rig.right.pose[:][right][:, :3, 3]
    baseline_error = np.abs(np.linalg.norm(right_t - left_t, axis=1) - rig.baseline[:])
    cx_difference = rig.right.intrinsics[:][right][:, 0, 2] - rig.left.intrinsics[:][left][:, 0, 2]
    dcx_error = np.abs(cx_difference - rig.dcx[:])
    return [
        _tolerance_check(
            f"{name}: baseline = distance between poses", baseline_error, BASELINE_TOLERANCE_M, "m"
        ),
        _tolerance_check(f"{name}: dcx = cx_right - cx_left", dcx_error, DCX_TOLERANCE_PX, "px"),
    ]


def _tolerance_check(title: str, errors: np.ndarray, tolerance: float, unit: str) -> Check:
    worst = float(errors.max(initial=0.0))
    numbers = {"max_error": worst, "tolerance": tolerance}
    if worst <= tolerance:
        return Check(title, "pass", f"within {tolerance:g} {unit}", numbers)
    i = int(np.argmax(errors))
    return Check(title, "fail", f"pair {i} is off by {worst:.3g} {unit}", numbers)


def _steps_checks(steps: dict) -> list[Check]:
    if not steps:
        return [Check("steps", "skip", "no steps recorded")]
    problems = step_problems(steps)
    values = Check(
        "steps: values finite, poses rigid",
        "fail" if problems else "pass",
        "; ".join(problems),
        {"columns": len(steps)},
    )
    return [
        _equal_lengths("steps", steps),
        _increasing("steps/step", steps["step"]),
        _increasing("steps/time", steps["time"]),
        values,
    ]


def _metadata_check(recording: Recording) -> Check:
    """The head's metadata: stored (a recorder always writes it, {} when given none) and a JSON
    object; a session's says which scene it recorded (what replay rebuilds)."""
    title = "metadata"
    if not recording.metadata_stored:
        detail = "the head holds no metadata attribute, which every recorder writes: damaged"
        return Check(title, "fail", detail)
    if not isinstance(recording.metadata, dict):
        detail = f"the head's metadata is {type(recording.metadata).__name__}, not a JSON object"
        return Check(title, "fail", detail)
    scene = "scene" in recording.metadata
    detail = "" if scene else "no scene: a recording replay cannot rebuild (not a session's)"
    return Check(title, "pass", detail, {"keys": len(recording.metadata)})


def _values_check(name: str, stream: CameraStream, rules: Rules) -> Check:
    """Every frame's values (see ``ambfplus.recording.values``); names the first bad frame."""
    title = f"{name}: frame values"
    bad, first = 0, ""
    for i in range(len(stream)):
        problems = rules.frame_problems(stream[i])
        if problems:
            bad += 1
            if not first:
                first = f"frame {i} (step {int(stream.step[i])}): {'; '.join(problems)}"
    if bad:
        return Check(title, "fail", first + (f"; {bad} frames in all" if bad > 1 else ""),
                     {"frames": len(stream), "bad_frames": bad})  # fmt: skip
    return Check(title, "pass", "depth, poses, intrinsics, ids in range", {"frames": len(stream)})


def _log_order_checks(recording: Recording) -> list[Check]:
    checks = []
    if len(recording.removed["step"]):
        checks.append(_increasing("removed/step", recording.removed["step"], strictly=False))
    if recording.events:
        steps = [event["step"] for event in recording.events]
        checks.append(_increasing("events/step", np.array(steps), strictly=False))
    return checks


def removed_volume(recording: Recording) -> tuple[int, dict] | None:
    """The legend entry (id, entry) of the volume the removed log refers to: the one it names,
    or the legend's only volume."""
    volumes = {i: e for i, e in recording.legend.items() if e.get("kind") == "volume"}
    name = recording.removed["volume"]
    if name is not None:
        matches = [(i, e) for i, e in volumes.items() if e.get("name") == name]
        return matches[0] if matches else None
    return next(iter(volumes.items())) if len(volumes) == 1 else None


def _removed_checks(recording: Recording) -> list[Check]:
    removed = recording.removed
    if len(removed["step"]) == 0:
        return [Check("removed", "skip", "no removed voxels recorded")]
    checks = [_equal_lengths("removed", {k: v for k, v in removed.items() if k != "volume"})]
    found = removed_volume(recording)
    title = "removed/label: ids in the volume's label table"
    if found is None:
        what = removed["volume"] or "(unnamed; the legend has no single volume)"
        checks.append(Check(title, "fail", f"volume {what} is not in the legend"))
        return checks
    table = set(found[1].get("labels", {}))
    unknown = sorted(set(int(v) for v in np.unique(removed["label"])) - table)
    if unknown:
        detail = f"labels {unknown[:10]} are not in {found[1]['name']}'s table {sorted(table)}"
        checks.append(Check(title, "fail", detail, {"unknown_labels": len(unknown)}))
    else:
        checks.append(Check(title, "pass", "", {"voxels": len(removed["label"])}))
    shape = volume_shape(recording, found[1])
    if shape is not None:
        inside = np.all((removed["voxel"] >= 0) & (removed["voxel"] < np.array(shape)), axis=1)
        status = "pass" if inside.all() else "fail"
        detail = "" if inside.all() else f"{int((~inside).sum())} voxels outside {shape}"
        checks.append(Check("removed/voxel: inside the volume", status, detail))
    return checks


def volume_shape(recording: Recording, entry: dict) -> tuple[int, ...] | None:
    """(nx, ny, nz) from the legend's volume entry, or from metadata["volumes"][name]."""
    shape = entry.get("shape")
    if shape is None:
        shape = recording.metadata.get("volumes", {}).get(entry.get("name"), {}).get("shape")
    return tuple(int(n) for n in shape) if shape is not None else None


def _removed_visibility_check(name: str, stream: CameraStream, recording: Recording) -> Check:
    """No pixel shows a label at a voxel that was removed before the frame's step."""
    title = f"{name}: removed voxels stay unseen"
    why_not = _visibility_skip_reason(stream, recording)
    if why_not:
        return Check(title, "skip", why_not)
    found = removed_volume(recording)
    assert found is not None, "_visibility_skip_reason found the volume in the legend"
    volume_id, entry = found
    shape = volume_shape(recording, entry)
    assert shape is not None, "_visibility_skip_reason found the volume's shape"
    nx, ny, _ = shape
    removed = recording.removed
    order = np.argsort(removed["step"], kind="stable")
    steps = removed["step"][order]
    voxels = removed["voxel"][order].astype(np.int64)
    linear = voxels[:, 0] + nx * (voxels[:, 1] + ny * voxels[:, 2])
    seen, first = 0, None
    for i in range(len(stream)):
        gone = linear[: np.searchsorted(steps, stream.step[i], side="left")]
        if gone.size == 0:
            continue
        shown = _voxels_showing_labels(stream, i, volume_id)
        count = int(np.count_nonzero(np.isin(shown, gone)))
        seen += count
        if count and first is None:
            first = i
    numbers = {"frames": len(stream), "removed": len(linear)}
    if seen == 0:
        return Check(title, "pass", "", numbers)
    detail = f"{seen} pixels show removed voxels, first in frame {first}"
    return Check(title, "fail", detail, {**numbers, "pixels": seen})


def _visibility_skip_reason(stream: CameraStream, recording: Recording) -> str:
    if "voxel" not in stream.passes or "label" not in stream.passes:
        return "needs the label and voxel passes"
    if len(recording.removed["step"]) == 0:
        return "no removed voxels recorded"
    found = removed_volume(recording)
    if found is None:
        return "the removed log's volume is not in the legend"
    if volume_shape(recording, found[1]) is None:
        return "the volume's shape is in neither the legend nor the metadata"
    return ""


def _voxels_showing_labels(stream: CameraStream, index: int, volume_id: int) -> np.ndarray:
    """Voxel indices of the pixels that show a label of the volume."""
    voxel = stream.voxel[index]
    mask = (voxel >= 0) & (stream.label[index] > 0)
    if "instance" in stream.passes:
        mask &= stream.instance[index] == volume_id
    return voxel[mask]
