"""One stereo training sample from a captured or recorded pair: the images, the targets and the
rig's geometry, as PyTorch tensors (see ``ambfplus.learning`` for the keys)."""

from __future__ import annotations

import numpy as np
import torch

from .targets import stereo_targets

#: Passes a sample needs in both views.
REQUIRED_PASSES = ("rgb", "depth")
#: Passes a sample carries when the pair has them.
OPTIONAL_PASSES = ("segmentation", "instance", "label")


def _view_image(view, name: str, where: str) -> np.ndarray:
    image = getattr(view, name, None)
    if image is None:
        raise ValueError(
            f"{where}: the {getattr(view, 'camera', 'camera')} view has no '{name}' image; a "
            f"stereo sample needs {' and '.join(REQUIRED_PASSES)} in both views"
        )
    return np.asarray(image)


def _chw(rgb: np.ndarray) -> torch.Tensor:
    """uint8 HxWx3 -> float32 3xHxW in 0..1 (a new tensor, never a view of engine memory)."""
    return torch.from_numpy(np.ascontiguousarray(rgb.transpose(2, 0, 1))).float().div_(255.0)


def stereo_sample(pair, where: str = "stereo pair") -> dict[str, torch.Tensor]:
    """The sample of a ``StereoFrame`` (live ``Frame`` views or ``RecordedFrame`` views).
    `where` names the pair's origin in error messages."""
    left_rgb = _view_image(pair.left, "rgb", where)
    right_rgb = _view_image(pair.right, "rgb", where)
    left_depth = _view_image(pair.left, "depth", where).astype(np.float32, copy=True)
    right_depth = _view_image(pair.right, "depth", where)
    focal, baseline, dcx = float(pair.focal), float(pair.baseline), float(pair.dcx)
    targets = stereo_targets(left_depth, right_depth, focal, baseline, dcx)
    sample = {
        "left": _chw(left_rgb),
        "right": _chw(right_rgb),
        "disparity": torch.from_numpy(targets["disparity"]),
        "depth": torch.from_numpy(left_depth),
        "valid": torch.from_numpy(targets["valid"]),
        "occlusion": torch.from_numpy(targets["occlusion"]),
        "baseline": torch.tensor(baseline, dtype=torch.float32),
        "focal": torch.tensor(focal, dtype=torch.float32),
        "dcx": torch.tensor(dcx, dtype=torch.float32),
        "intrinsics": torch.from_numpy(np.array(pair.left.intrinsics, dtype=np.float64)),
        "left_pose": torch.from_numpy(np.array(pair.left.pose, dtype=np.float64)),
        "right_pose": torch.from_numpy(np.array(pair.right.pose, dtype=np.float64)),
        "time": torch.tensor(float(pair.left.time), dtype=torch.float64),
        "step": torch.tensor(int(pair.left.step), dtype=torch.int64),
    }
    segmentation = getattr(pair.left, "segmentation", None)
    if segmentation is not None:
        seg = np.ascontiguousarray(np.asarray(segmentation).transpose(2, 0, 1))
        sample["segmentation"] = torch.from_numpy(seg.copy())
    for name in ("instance", "label"):
        image = getattr(pair.left, name, None)
        if image is not None:
            # uint16 labels become int32: PyTorch's uint16 supports few operations.
            sample[name] = torch.from_numpy(np.asarray(image).astype(np.int32, copy=True))
    return sample


#: Sample entries that are images, (C, H, W) or (H, W).
IMAGE_KEYS = (
    "left", "right", "segmentation", "disparity", "depth", "valid", "occlusion", "instance", "label"
)  # fmt: skip


def crop_sample(sample: dict, top: int, left: int, height: int, width: int) -> dict:
    """The same window of both views. Disparities are unchanged (both images move alike) but a
    pixel whose match now falls outside the right crop becomes occluded; the intrinsics' principal
    point moves with the window."""
    full_height, full_width = sample["disparity"].shape[-2:]
    if not (0 <= top and top + height <= full_height and 0 <= left and left + width <= full_width):
        raise ValueError(
            f"crop {width}x{height} at (row {top}, column {left}) does not fit a "
            f"{full_width}x{full_height} sample"
        )
    out = dict(sample)
    rows, cols = slice(top, top + height), slice(left, left + width)
    for key in IMAGE_KEYS:
        if key in out:
            out[key] = sample[key][..., rows, cols].contiguous()
    x_right = torch.arange(width, dtype=torch.float32) + 0.5 - out["disparity"]
    outside = (x_right < 0) | (x_right >= width)
    out["occlusion"] = out["occlusion"] | (out["valid"] & outside)
    if "intrinsics" in out:
        k = sample["intrinsics"].clone()
        k[0, 2] -= left
        k[1, 2] -= top
        out["intrinsics"] = k
    return out
