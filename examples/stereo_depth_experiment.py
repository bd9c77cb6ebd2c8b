"""The paper's depth experiment on the built-in phantom: train a small STTR-style stereo transformer
from scratch on a moving-camera sequence and test it on a moving-drill sequence, beside OpenCV's
semi-global block matching (SGBM) on the same frames.

    python examples/stereo_depth_experiment.py OUT            # full size: 500 + 500 frames
    python examples/stereo_depth_experiment.py OUT --small    # minutes: CI size

Full size follows the paper: the rig of ``ambfplus.scenes.drilling_phantom`` (65 mm baseline,
f = 1135 px at 640x480, off-axis with zero disparity at 250 mm), 500 training frames of the rig
circling the untouched phantom while the drill rests, 500 test frames of a still rig watching the
drill plunge into the bone. Training runs for a wall-clock budget (40 minutes by default) on
random 224x320 crops around the anatomy; testing uses the whole 640x480 frames.

Metrics, over the test pixels that hit something and are visible in both views ("visible"), and
over all pixels that hit something ("all"): depth L1 (mm), end-point error (EPE, px) and bad-1px
(share of pixels off by more than one pixel). SGBM's invalid pixels are filled along rows from
their nearest valid neighbours (the farther of the two) for the full-density comparison; its raw
density and its errors on the pixels it kept are reported too.

Writes OUT/results.json, OUT/results.md, OUT/learning_curve.csv, OUT/depth_error.png (left view,
true depth, the model's and SGBM's depth and their errors for the middle test frame),
OUT/model.pt and the two recordings (reused by a later run with the same settings, e.g. by
examples/tracking_experiment.py --recordings OUT).
"""

from __future__ import annotations

import os

# Idle PyTorch threads sleep instead of spinning: on a shared CPU a spinning thread takes the
# core its partner needs, and training slows several times over.
os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

import argparse  # noqa: E402
import json  # noqa: E402
import math  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402
import torch  # noqa: E402

import ambfplus  # noqa: E402
from ambfplus.learning import (  # noqa: E402
    RecordingStereoDataset,
    StereoTransformer,
    disparity_metrics,
    fill_invalid_along_rows,
    make_loader,
    stereo_loss,
)
from ambfplus.learning.metrics import pool  # noqa: E402
from ambfplus.learning.samples import crop_sample  # noqa: E402
from ambfplus.learning.sequences import MOVING_CAMERA, MOVING_DRILL, ensure_sequence  # noqa: E402

# SGBM's fixed parameters (blockSize 5, OpenCV's recommended smoothness penalties for 3
# channels); the disparity range comes from the rig (see sgbm_range).
SGBM_BLOCK = 5
SGBM_PARAMETERS = {
    "blockSize": SGBM_BLOCK,
    "P1": 8 * 3 * SGBM_BLOCK**2,
    "P2": 32 * 3 * SGBM_BLOCK**2,
    "disp12MaxDiff": 1,
    "preFilterCap": 63,
    "uniquenessRatio": 10,
    "speckleWindowSize": 100,
    "speckleRange": 2,
    "mode": cv2.STEREO_SGBM_MODE_SGBM_3WAY,
}
# Depths SGBM searches (m): the anatomy lies at 210-290 mm from the rig, the drill's shaft nearer.
SGBM_DEPTHS = (0.15, 0.35)


def parse_args(argv) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path, help="output folder")
    small_help = "CI size: 20 frames each at 160x120, 30 training iterations"
    parser.add_argument("--small", action="store_true", help=small_help)
    parser.add_argument("--frames", type=int, help="frames per sequence (default 500)")
    parser.add_argument("--width", type=int, help="image width (default 640)")
    parser.add_argument("--height", type=int, help="image height (default 480)")
    parser.add_argument("--resolution", type=int, help="phantom voxels per side (default 128)")
    parser.add_argument("--train-minutes", type=float, help="training budget (default 40)")
    parser.add_argument("--iterations", type=int, help="train this many steps (no time budget)")
    crop_help = "training crop (default 224 320; whole frames with --small)"
    parser.add_argument("--crop", type=int, nargs=2, metavar=("H", "W"), help=crop_help)
    parser.add_argument("--batch", type=int, default=2)
    parser.add_argument("--lr", type=float, default=4e-4)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--threads", type=int, help="PyTorch threads (default: PyTorch's choice)")
    parser.add_argument("--recordings", type=Path, help="folder of the sequences (default OUT)")
    args = parser.parse_args(argv)
    small = {"frames": 20, "width": 160, "height": 120, "resolution": 64, "iterations": 30}
    full = {"frames": 500, "width": 640, "height": 480, "resolution": 128, "train_minutes": 40.0}
    for key, value in (small if args.small else full).items():
        if getattr(args, key) is None:
            setattr(args, key, value)
    if args.crop is None:
        args.crop = (args.height, args.width) if args.small else (224, 320)
    if args.width % 4 or args.height % 4 or args.crop[0] % 4 or args.crop[1] % 4:
        parser.error("image and crop sizes must be multiples of 4 (the network's feature stride)")
    if args.crop[0] > args.height or args.crop[1] > args.width:
        parser.error(f"crop {args.crop} is larger than the {args.height}x{args.width} images")
    args.recordings = args.recordings or args.out
    return args


def record_sequences(args) -> tuple[Path, Path]:
    """The training (moving camera) and testing (moving drill) recordings, made if needed."""
    args.recordings.mkdir(parents=True, exist_ok=True)
    options = {
        "frames": args.frames, "width": args.width, "height": args.height,
        "resolution": args.resolution, "seed": args.seed,
    }  # fmt: skip
    paths = []
    for kind, name in ((MOVING_CAMERA, "moving_camera.h5"), (MOVING_DRILL, "moving_drill.h5")):
        path = args.recordings / name
        started = time.perf_counter()
        if ensure_sequence(path, kind, **options):
            print(f"recorded {kind}: {path} ({time.perf_counter() - started:.0f} s)", flush=True)
        else:
            print(f"reusing {kind}: {path}", flush=True)
        paths.append(path)
    return paths[0], paths[1]


class AnatomyCrop:
    """A random training window centred near a random pixel that hit the anatomy or drill."""

    def __init__(self, height: int, width: int, seed: int) -> None:
        self.height, self.width = height, width
        self.rng = np.random.default_rng(seed)

    def __call__(self, sample: dict) -> dict:
        full_height, full_width = sample["valid"].shape
        rows, cols = np.nonzero(sample["valid"].numpy())
        if len(rows):
            k = self.rng.integers(len(rows))
            centre = rows[k], cols[k]
        else:
            centre = full_height // 2, full_width // 2
        top = int(np.clip(centre[0] - self.height // 2, 0, full_height - self.height))
        left = int(np.clip(centre[1] - self.width // 2, 0, full_width - self.width))
        return crop_sample(sample, top, left, self.height, self.width)


def learning_rate(base: float, progress: float, warmup: float = 0.03) -> float:
    """Linear warm-up, then a cosine decay to zero at progress 1."""
    if progress < warmup:
        return base * (0.1 + 0.9 * progress / warmup)
    return base * 0.5 * (1 + math.cos(math.pi * min(1.0, (progress - warmup) / (1 - warmup))))


def train(model, train_path: Path, args) -> dict:
    """Trains on random crops of the training sequence until the iteration count or the time
    budget is reached; returns the history and the time and CPU it took."""
    crop = AnatomyCrop(*args.crop, seed=args.seed)
    data = RecordingStereoDataset(train_path, transform=crop)
    loader = make_loader(
        data, batch_size=args.batch, shuffle=True, drop_last=True,
        generator=torch.Generator().manual_seed(args.seed),
    )  # fmt: skip
    optimiser = torch.optim.AdamW(model.parameters(), lr=args.lr, weight_decay=1e-4)
    budget = None if args.iterations else args.train_minutes * 60.0
    history, iteration, epoch = [], 0, 0
    wall0, cpu0 = time.perf_counter(), time.process_time()
    model.train()

    def progress() -> float:
        if budget is None:
            return iteration / args.iterations
        return (time.perf_counter() - wall0) / budget

    while progress() < 1.0:
        for batch in loader:
            if progress() >= 1.0:
                break
            lr = learning_rate(args.lr, progress())
            for group in optimiser.param_groups:
                group["lr"] = lr
            outputs = model(batch["left"], batch["right"])
            loss, terms = stereo_loss(outputs, batch)
            optimiser.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(model.parameters(), 1.0)
            optimiser.step()
            iteration += 1
            history.append({"iteration": iteration, "epoch": epoch, "lr": lr,
                            "loss": loss.item(), **terms})  # fmt: skip
            if iteration % 50 == 0 or iteration == 1:
                elapsed = time.perf_counter() - wall0
                line = f"loss {loss.item():.3f}, disparity L1 {terms['l1']:.3f} px"
                print(
                    f"  iteration {iteration} (epoch {epoch}, {elapsed:.0f} s): {line}", flush=True
                )
        epoch += 1
    data.close()
    return {
        "history": history,
        "iterations": iteration,
        "epochs": iteration * args.batch / len(data),
        "wall_seconds": time.perf_counter() - wall0,
        "cpu_seconds": time.process_time() - cpu0,
    }


def sgbm_range(focal: float, baseline: float, dcx: float) -> tuple[int, int]:
    """(minDisparity, numDisparities) covering SGBM_DEPTHS, in OpenCV's steps of 16."""
    near, far = SGBM_DEPTHS
    lowest = math.floor((focal * baseline / far - dcx) / 16) * 16
    highest = focal * baseline / near - dcx
    return lowest, int(math.ceil((highest - lowest) / 16) * 16)


def sgbm_disparity(left_rgb, right_rgb, focal, baseline, dcx) -> tuple[np.ndarray, np.ndarray]:
    """SGBM's disparity (px, our convention x_left - x_right, which is OpenCV's) and where it is
    valid. The images are padded with black columns so that the whole search range stays inside
    them: SGBM leaves the columns it cannot search invalid."""
    lowest, count = sgbm_range(focal, baseline, dcx)
    pad_left, pad_right = max(0, lowest + count), max(0, -lowest)
    matcher = cv2.StereoSGBM_create(minDisparity=lowest, numDisparities=count, **SGBM_PARAMETERS)

    def padded(image):
        return cv2.copyMakeBorder(
            np.ascontiguousarray(image), 0, 0, pad_left, pad_right, cv2.BORDER_CONSTANT, value=0
        )

    raw = matcher.compute(padded(left_rgb), padded(right_rgb))
    raw = raw[:, pad_left : raw.shape[1] - pad_right]
    valid = raw > (lowest - 1) * 16
    return raw.astype(np.float32) / 16.0, valid


@torch.no_grad()
def model_disparity(model, sample: dict) -> np.ndarray:
    model.eval()
    out = model(sample["left"][None], sample["right"][None])
    return out["disparity"][0].numpy()


def evaluate(model, test_path: Path) -> dict:
    """Both methods on every test frame; pooled metrics and the middle frame's images."""
    data = RecordingStereoDataset(test_path)
    per = {name: [] for name in ("model", "sgbm_filled", "sgbm_raw")}
    per_all = {name: [] for name in ("model", "sgbm_filled")}
    density = {"visible": [0, 0], "all": [0, 0]}
    middle, seconds = {}, {"model": 0.0, "sgbm": 0.0}
    for i in range(len(data)):
        s = data[i]
        truth = s["disparity"].numpy()
        valid = s["valid"].numpy()
        visible = valid & ~s["occlusion"].numpy()
        geometry = float(s["focal"]), float(s["baseline"]), float(s["dcx"])
        t0 = time.process_time()
        predicted = model_disparity(model, s)
        t1 = time.process_time()
        left = (s["left"].numpy().transpose(1, 2, 0) * 255).round().astype(np.uint8)
        right = (s["right"].numpy().transpose(1, 2, 0) * 255).round().astype(np.uint8)
        sgbm, sgbm_valid = sgbm_disparity(left, right, *geometry)
        filled = fill_invalid_along_rows(sgbm, ~sgbm_valid)
        seconds["model"] += t1 - t0
        seconds["sgbm"] += time.process_time() - t1
        per["model"].append(disparity_metrics(predicted, truth, visible, *geometry))
        per["sgbm_filled"].append(disparity_metrics(filled, truth, visible, *geometry))
        per["sgbm_raw"].append(disparity_metrics(sgbm, truth, visible & sgbm_valid, *geometry))
        per_all["model"].append(disparity_metrics(predicted, truth, valid, *geometry))
        per_all["sgbm_filled"].append(disparity_metrics(filled, truth, valid, *geometry))
        for key, mask in (("visible", visible), ("all", valid)):
            density[key][0] += int((mask & sgbm_valid).sum())
            density[key][1] += int(mask.sum())
        if i == len(data) // 2:
            middle = {"left": left, "truth": truth, "valid": valid, "model": predicted,
                      "sgbm": filled, "geometry": geometry}  # fmt: skip
    data.close()
    frames = len(data)
    return {
        "frames": frames,
        "visible": {name: _rounded(pool(m)) for name, m in per.items()},
        "all": {name: _rounded(pool(m)) for name, m in per_all.items()},
        "sgbm_density": {k: round(v[0] / max(v[1], 1), 4) for k, v in density.items()},
        "cpu_seconds_per_frame": {k: round(v / max(frames, 1), 4) for k, v in seconds.items()},
        "middle": middle,
    }


def _rounded(metrics: dict) -> dict:
    return {
        "depth_l1_mm": round(metrics["depth_l1_mm"], 4),
        "epe_px": round(metrics["epe"], 4),
        "bad1": round(metrics["bad1"], 4),
        "pixels": int(metrics["pixels"]),
    }


def colourise(values: np.ndarray, valid: np.ndarray, lo: float, hi: float) -> np.ndarray:
    """Values in [lo, hi] as a dark-blue-to-yellow ramp; black where not valid."""
    t = np.clip((values - lo) / max(hi - lo, 1e-12), 0, 1)
    stops = np.array([0.0, 0.5, 1.0])
    colours = np.array([[20, 20, 90], [200, 60, 90], [250, 230, 60]], float)
    rgb = np.stack([np.interp(t, stops, colours[:, c]) for c in range(3)], axis=-1)
    return np.where(valid[..., None], rgb, 0).astype(np.uint8)


def depth_error_image(middle: dict) -> np.ndarray:
    """Top: left view, true depth, the model's depth, SGBM's depth (230-280 mm). Bottom: their
    absolute depth errors (0 to 5 mm)."""
    from ambfplus.learning import depth_from_disparity

    valid = middle["valid"]
    truth = depth_from_disparity(middle["truth"], *middle["geometry"]) * 1000
    depths = [
        depth_from_disparity(middle[k], *middle["geometry"]) * 1000 for k in ("model", "sgbm")
    ]
    zs = truth[valid]
    lo, hi = (float(zs.min()), float(zs.max())) if zs.size else (0.0, 1.0)
    top = [middle["left"], colourise(truth, valid, lo, hi)]
    top += [colourise(d, valid, lo, hi) for d in depths]
    blank = np.zeros_like(middle["left"])
    bottom = [blank, blank] + [colourise(np.abs(d - truth), valid, 0.0, 5.0) for d in depths]
    return np.concatenate([np.concatenate(top, axis=1), np.concatenate(bottom, axis=1)], axis=0)


def write_report(out: Path, args, training: dict, results: dict) -> dict:
    middle = results.pop("middle")
    if middle:
        ambfplus.write_image(str(out / "depth_error.png"), depth_error_image(middle))
    with open(out / "learning_curve.csv", "w") as f:
        keys = list(training["history"][0]) if training["history"] else []
        f.write(",".join(keys) + "\n")
        for row in training["history"]:
            f.write(",".join(f"{row[k]:.6g}" for k in keys) + "\n")
    lowest, count = sgbm_range(*middle["geometry"]) if middle else (None, None)
    report = {
        "config": {
            "frames": args.frames, "width": args.width, "height": args.height,
            "resolution": args.resolution, "crop": list(args.crop), "batch": args.batch,
            "lr": args.lr, "seed": args.seed, "small": args.small,
            "threads": torch.get_num_threads(),
            "train_minutes": None if args.iterations else args.train_minutes,
        },
        "training": {k: (round(v, 3) if isinstance(v, float) else v)
                     for k, v in training.items() if k != "history"},
        "sgbm": {"minDisparity": lowest, "numDisparities": count, **SGBM_PARAMETERS,
                 "depths_searched_m": SGBM_DEPTHS},
        "test": results,
        "renderer": ambfplus.gl_info()["renderer"],
        "torch": torch.__version__,
        "opencv": cv2.__version__,
    }  # fmt: skip
    (out / "results.json").write_text(json.dumps(report, indent=2))
    (out / "results.md").write_text(markdown_table(report))
    return report


def markdown_table(report: dict) -> str:
    visible, everything = report["test"]["visible"], report["test"]["all"]
    rows = [
        ("STTR-style model", visible["model"], everything["model"]),
        ("SGBM, filled along rows", visible["sgbm_filled"], everything["sgbm_filled"]),
        ("SGBM, raw (its valid pixels only)", visible["sgbm_raw"], None),
    ]
    lines = [
        "| method | depth L1 (mm) | EPE (px) | bad-1px | depth L1, all hits (mm) |",
        "|---|---|---|---|---|",
    ]
    for name, v, a in rows:
        tail = f"{a['depth_l1_mm']:.3f}" if a else "-"
        lines.append(
            f"| {name} | {v['depth_l1_mm']:.3f} | {v['epe_px']:.3f} | {v['bad1']:.3f} | {tail} |"
        )
    t = report["training"]
    density = report["test"]["sgbm_density"]
    lines += [
        "",
        f"Test frames: {report['test']['frames']} (visible pixels: hit and seen by both views). "
        f"SGBM raw density: {density['visible']:.3f} of visible pixels, {density['all']:.3f} "
        "of all hits.",
        f"Training: {t['iterations']} iterations ({t['epochs']:.2f} epochs) in "
        f"{t['wall_seconds'] / 60:.1f} min wall, {t['cpu_seconds'] / 60:.1f} min CPU.",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    args = parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    torch.manual_seed(args.seed)
    # Denormal floats (tiny matching probabilities) cost a CPU dozens of times more.
    torch.set_flush_denormal(True)
    if args.threads:
        torch.set_num_threads(args.threads)
    train_path, test_path = record_sequences(args)
    model = StereoTransformer(channels=48, layers=4)
    budget = f"{args.iterations} iterations" if args.iterations else f"{args.train_minutes} min"
    print(f"training on {train_path.name} ({budget}, crops {args.crop[0]}x{args.crop[1]})")
    training = train(model, train_path, args)
    torch.save(model.state_dict(), args.out / "model.pt")
    print(f"testing on {test_path.name}", flush=True)
    results = evaluate(model, test_path)
    report = write_report(args.out, args, training, results)
    print((args.out / "results.md").read_text())
    print(f"wrote {args.out}: results.json, results.md, learning_curve.csv, depth_error.png")
    return 0 if report["test"]["visible"]["model"]["pixels"] > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
