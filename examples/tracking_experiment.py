"""The paper's tracking experiment on the built-in phantom: stereo visual odometry on a
moving-camera sequence and on a moving-drill sequence, against the true camera poses.

    python examples/tracking_experiment.py OUT             # full size: 500 frames each
    python examples/tracking_experiment.py OUT --small     # seconds: CI size
    python examples/tracking_experiment.py OUT --recordings DEPTH_OUT   # reuse the sequences
                                                   # examples/stereo_depth_experiment.py made

The tracker is a plain stereo visual odometry, not ORB-SLAM3 (no map optimisation, loop closing
or bundle adjustment): in every frame, OpenCV ORB features of the left and right views, on the
anatomy only (the drill and the background are masked out with the recorded instance image), are
matched along rows and triangulated with the rig (Z = f B / (d + dcx)). Each frame's left
features are matched to a keyframe's and the camera's motion from the keyframe is found by PnP
with RANSAC, refined on the inliers. Two variants: frame to frame (the previous frame is the
keyframe: the issue's method, and the one closest to the paper's numbers), and keyframes (a frame
becomes the next keyframe only when it keeps too few of the current one's points: less drift).
The first frame starts at its true pose (the anatomy's frame is what the camera is tracked
against).

Errors, mean +- std over frames (the paper's Table 1 reports mean +- std of errors):
- trajectory: the tracked camera pose of every frame against the true one, from the common first
  frame (no other alignment), translation in mm and rotation in degrees;
- relative: every frame-to-frame motion against the true motion.
Frames where PnP finds fewer than MIN_INLIERS inliers count as tracking failures; they keep the
previous pose and become the next keyframe.

Writes OUT/tracking.json, OUT/tracking.md and OUT/trajectory_<sequence>_<method>.csv.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import cv2
import numpy as np

from ambfplus.learning.sequences import MOVING_CAMERA, MOVING_DRILL, ensure_sequence
from ambfplus.recording import open_recording

ORB_FEATURES = 3000
# The rig stays about 250 mm from the anatomy: a shallow pyramid keeps keypoints precise.
ORB_LEVELS = 3
MAX_HAMMING = 64  # descriptor distance beyond which two ORB features never match
RATIO = 0.8  # Lowe's ratio test
ROW_TOLERANCE = 1.5  # px, left-right matches lie on the same row (rectified rig)
MIN_INLIERS = 12
# Tracking against keyframes: a new one when inliers fall below this share of the keyframe's first.
KEYFRAME_SHARE = 0.6
METHODS = (("frame to frame", None), ("keyframes", KEYFRAME_SHARE))
PNP_REPROJECTION_PX = 1.5
SEQUENCES = (("moving camera", MOVING_CAMERA), ("moving drill", MOVING_DRILL))


def parse_args(argv) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="output folder")
    parser.add_argument("--small", action="store_true", help="CI size: 20 frames at 320x240")
    parser.add_argument("--frames", type=int, help="frames per sequence (default 500)")
    parser.add_argument("--width", type=int, help="image width (default 640)")
    parser.add_argument("--height", type=int, help="image height (default 480)")
    parser.add_argument("--resolution", type=int, help="phantom voxels per side (default 128)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--recordings", type=Path, help="folder of the sequences (default OUT)")
    args = parser.parse_args(argv)
    small = {"frames": 20, "width": 320, "height": 240, "resolution": 96}
    full = {"frames": 500, "width": 640, "height": 480, "resolution": 128}
    for key, value in (small if args.small else full).items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    args.recordings = args.recordings or args.out
    return args


def anatomy_ids(legend: dict) -> list[int]:
    """Object ids of the volumes (the anatomy) in a recording's legend."""
    ids = [i for i, entry in legend.items() if entry.get("kind") == "volume"]
    if not ids:
        raise ValueError("the recording's legend lists no volume: nothing to track against")
    return ids


def camera_matrix(intrinsics: np.ndarray) -> np.ndarray:
    """Our intrinsics centre pixels at c + 0.5; OpenCV centres them on integers."""
    k = np.array(intrinsics, dtype=np.float64)
    k[0, 2] -= 0.5
    k[1, 2] -= 0.5
    return k


class StereoFeatures:
    """ORB features of a left view with a 3D point (left camera frame) each, from their
    matches in the right view."""

    def __init__(self, orb, pair, anatomy: list[int]) -> None:
        kl, dl = detect(orb, pair.left, anatomy)
        kr, dr = detect(orb, pair.right, anatomy)
        self.keypoints = np.array([k.pt for k in kl], dtype=np.float64).reshape(-1, 2)
        self.descriptors = dl
        self.points = np.full((len(kl), 3), np.nan)
        if dl is None or dr is None or len(kr) == 0:
            return
        right_points = np.array([k.pt for k in kr], dtype=np.float64)
        k = camera_matrix(pair.left.intrinsics)
        f, b, dcx = k[0, 0], float(pair.baseline), float(pair.dcx)
        # Any disparity that puts the point between 0.1 m and 1 m in front of the rig.
        d_low, d_high = f * b / 1.0 - dcx, f * b / 0.1 - dcx
        d = self.keypoints[:, None, 0] - right_points[None, :, 0]
        same_row = np.abs(self.keypoints[:, None, 1] - right_points[None, :, 1]) <= ROW_TOLERANCE
        allowed = (same_row & (d >= d_low) & (d <= d_high)).astype(np.uint8)
        best, ok = match(dl, dr, allowed)
        disparity = d[np.arange(len(kl)), best]
        ok &= disparity + dcx > 0
        z = f * b / (disparity + dcx)
        u, v = self.keypoints[:, 0], self.keypoints[:, 1]
        points = np.stack([(u - k[0, 2]) * z / f, (v - k[1, 2]) * z / k[1, 1], z], axis=1)
        self.points[ok] = points[ok]


def detect(orb, view, anatomy: list[int]):
    """ORB keypoints and descriptors of a view, on pixels that see the anatomy."""
    gray = cv2.cvtColor(np.asarray(view.rgb), cv2.COLOR_RGB2GRAY)
    mask = np.isin(np.asarray(view.instance), anatomy).astype(np.uint8)
    return orb.detectAndCompute(gray, mask)


def match(query, train, allowed=None) -> tuple[np.ndarray, np.ndarray]:
    """For each query descriptor, the train descriptor nearest in Hamming distance (among the
    `allowed` pairs) and whether it is a match: close enough and clearly nearer than the second
    nearest (Lowe's ratio test)."""
    best = np.zeros(len(query), dtype=np.int64)
    ok = np.zeros(len(query), dtype=bool)
    matcher = cv2.BFMatcher(cv2.NORM_HAMMING)
    pairs = matcher.knnMatch(query, train, k=2, mask=allowed if allowed is not None else None)
    for candidates in pairs:
        if not candidates:
            continue
        first = candidates[0]
        second = candidates[1].distance if len(candidates) > 1 else np.inf
        best[first.queryIdx] = first.trainIdx
        ok[first.queryIdx] = first.distance <= MAX_HAMMING and first.distance < RATIO * second
    return best, ok


def motion_from(key: StereoFeatures, current: StereoFeatures, k: np.ndarray):
    """current-camera-from-key-camera (4x4) by PnP with RANSAC on the key's 3D points and the
    current left features, and the inlier count; None when tracking fails."""
    has_point = ~np.isnan(key.points[:, 0])
    if has_point.sum() < MIN_INLIERS or current.descriptors is None:
        return None, 0
    best, ok = match(key.descriptors[has_point], current.descriptors)
    if ok.sum() < MIN_INLIERS:
        return None, int(ok.sum())
    objects = key.points[has_point][ok]
    images = current.keypoints[best[ok]]
    found, rvec, tvec, inliers = cv2.solvePnPRansac(
        objects, images, k, None, iterationsCount=300, reprojectionError=PNP_REPROJECTION_PX,
        confidence=0.999, flags=cv2.SOLVEPNP_EPNP,
    )  # fmt: skip
    if not found or inliers is None or len(inliers) < MIN_INLIERS:
        return None, 0 if inliers is None else len(inliers)
    inliers = inliers[:, 0]
    rvec, tvec = cv2.solvePnPRefineLM(objects[inliers], images[inliers], k, None, rvec, tvec)
    motion = np.eye(4)
    motion[:3, :3] = cv2.Rodrigues(rvec)[0]
    motion[:3, 3] = tvec[:, 0]
    return motion, len(inliers)


def pose_error(estimate: np.ndarray, truth: np.ndarray) -> tuple[float, float]:
    """Translation (mm) and rotation (deg) of truth^-1 estimate."""
    error = np.linalg.inv(truth) @ estimate
    cos = np.clip((np.trace(error[:3, :3]) - 1) / 2, -1.0, 1.0)
    return float(np.linalg.norm(error[:3, 3]) * 1000), float(math.degrees(math.acos(cos)))


def track(path: Path, keyframe_share: float | None = None) -> dict:
    """Runs the odometry over a recording; returns estimated and true poses and statistics.
    Each frame is located against the current keyframe: frame to frame (every frame becomes the
    next keyframe) when `keyframe_share` is None, else a frame becomes the next keyframe only
    when fewer than that share of the keyframe's first inliers still match (the anatomy holds
    still, so a keyframe's points serve many frames without drifting)."""
    orb = cv2.ORB_create(nfeatures=ORB_FEATURES, fastThreshold=10, nlevels=ORB_LEVELS)
    with open_recording(path) as rec:
        anatomy = anatomy_ids(rec.legend)
        pairs = rec.rigs["rig"]
        truth, estimate, inliers, failures, keyframes = [], [], [], 0, 0
        key, key_pose, key_inliers = None, None, 0
        for i in range(len(pairs)):
            pair = pairs[i]
            current = StereoFeatures(orb, pair, anatomy)
            truth.append(np.asarray(pair.left.pose))
            if key is None:
                estimate.append(truth[0].copy())  # the first frame starts at its true pose
                key, key_pose, keyframes = current, truth[0].copy(), 1
                continue
            motion, count = motion_from(key, current, camera_matrix(pair.left.intrinsics))
            inliers.append(count)
            if motion is None:
                failures += 1
                estimate.append(estimate[-1].copy())  # lost: hold the last pose
            else:
                estimate.append(key_pose @ np.linalg.inv(motion))
                key_inliers = key_inliers or count
            if motion is None or keyframe_share is None or count < keyframe_share * key_inliers:
                key, key_pose, key_inliers = current, estimate[-1].copy(), 0
                keyframes += 1
    return {
        "truth": truth, "estimate": estimate, "inliers": inliers, "failures": failures,
        "keyframes": keyframes,
    }  # fmt: skip


def statistics(tracked: dict) -> dict:
    truth, estimate = tracked["truth"], tracked["estimate"]
    trajectory = np.array([pose_error(e, t) for e, t in zip(estimate[1:], truth[1:])])
    relative = np.array(
        [
            pose_error(
                np.linalg.inv(estimate[i - 1]) @ estimate[i], np.linalg.inv(truth[i - 1]) @ truth[i]
            )  # fmt: skip
            for i in range(1, len(truth))
        ]
    )
    moved = [np.linalg.norm(truth[i][:3, 3] - truth[0][:3, 3]) * 1000 for i in range(len(truth))]

    def mean_std(values, column):
        return [round(float(values[:, column].mean()), 4), round(float(values[:, column].std()), 4)]

    return {
        "frames": len(truth),
        "trajectory_translation_mm": mean_std(trajectory, 0),
        "trajectory_rotation_deg": mean_std(trajectory, 1),
        "relative_translation_mm": mean_std(relative, 0),
        "relative_rotation_deg": mean_std(relative, 1),
        "final_translation_mm": round(float(trajectory[-1, 0]), 4),
        "tracking_failures": tracked["failures"],
        "keyframes": tracked["keyframes"],
        "median_inliers": float(np.median(tracked["inliers"])) if tracked["inliers"] else 0.0,
        "camera_travel_mm": round(float(max(moved)), 2),
    }


def write_trajectory(path: Path, tracked: dict) -> None:
    with open(path, "w") as f:
        f.write("frame,true_x,true_y,true_z,est_x,est_y,est_z\n")
        for i, (t, e) in enumerate(zip(tracked["truth"], tracked["estimate"])):
            values = [*t[:3, 3], *e[:3, 3]]
            f.write(f"{i}," + ",".join(f"{v:.6f}" for v in values) + "\n")


def markdown_table(results: dict) -> str:
    lines = [
        "| sequence, tracking | translation error (mm) | rotation error (deg) | relative "
        "translation (mm/frame) | relative rotation (deg/frame) | failures | keyframes |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in results.items():
        t, rot = r["trajectory_translation_mm"], r["trajectory_rotation_deg"]
        rt, rr = r["relative_translation_mm"], r["relative_rotation_deg"]
        lines.append(
            f"| {name} | {t[0]:.3f} +- {t[1]:.3f} | {rot[0]:.4f} +- {rot[1]:.4f} | "
            f"{rt[0]:.4f} +- {rt[1]:.4f} | {rr[0]:.5f} +- {rr[1]:.5f} | "
            f"{r['tracking_failures']}/{r['frames'] - 1} | {r['keyframes']} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    args.recordings.mkdir(parents=True, exist_ok=True)
    options = {
        "frames": args.frames, "width": args.width, "height": args.height,
        "resolution": args.resolution, "seed": args.seed,
    }  # fmt: skip
    results = {}
    for name, kind in SEQUENCES:
        path = args.recordings / f"{name.replace(' ', '_')}.h5"
        made = ensure_sequence(path, kind, **options)
        print(f"{'recorded' if made else 'reusing'} {name}: {path}", flush=True)
        for method, share in METHODS:
            tracked = track(path, share)
            slug = f"{name}_{method}".replace(" ", "_")
            write_trajectory(args.out / f"trajectory_{slug}.csv", tracked)
            results[f"{name}, {method}"] = statistics(tracked)
            print(f"  {name}, {method}: {results[f'{name}, {method}']}", flush=True)
    report = {"config": {**options, "small": args.small}, "sequences": results,
              "orb_features": ORB_FEATURES, "orb_levels": ORB_LEVELS, "min_inliers": MIN_INLIERS,
              "keyframe_share": KEYFRAME_SHARE,
              "pnp_reprojection_px": PNP_REPROJECTION_PX, "opencv": cv2.__version__}  # fmt: skip
    (args.out / "tracking.json").write_text(json.dumps(report, indent=2))
    (args.out / "tracking.md").write_text(markdown_table(results))
    print(markdown_table(results))
    return 0


if __name__ == "__main__":
    sys.exit(main())
