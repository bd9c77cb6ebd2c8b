"""Learning from the simulator: PyTorch datasets of stereo samples, rendered in the loop or read
from recordings, and a small STTR-style stereo network.

    from ambfplus.learning import SimulatorStereoDataset, RecordingStereoDataset, make_loader

    data = SimulatorStereoDataset(samples=2000, scenario="mixed", width=320, height=240)
    for batch in make_loader(data, batch_size=4, num_workers=2):  # spawned workers
        batch["left"], batch["right"], batch["disparity"], batch["valid"], batch["occlusion"]

A sample is a dict of tensors (left view; H x W images):

- ``left``, ``right``: float32 (3, H, W) RGB in 0..1;
- ``disparity``: float32 (H, W) pixels, d = x_left - x_right = f B / Z - dcx (negative beyond
  an off-axis rig's working distance), 0 where ``valid`` is False;
- ``depth``: float32 (H, W) metres along the optical axis, 0 where nothing was hit;
- ``valid``: bool (H, W), the pixel hit something (its disparity is defined);
- ``occlusion``: bool (H, W), a valid pixel the right camera does not see (hidden behind
  something nearer, or outside the right image), found from the right view's depth;
- ``segmentation`` uint8 (3, H, W), ``instance`` int32 (H, W) object ids, ``label`` int32
  (H, W) anatomy labels (each when captured or recorded);
- ``baseline`` (m), ``focal`` (px), ``dcx`` (px, cx_right - cx_left): float32 scalars;
  ``intrinsics`` float64 (3, 3) of the left camera (pixel centres at c + 0.5);
  ``left_pose``, ``right_pose`` float64 (4, 4) world-from-camera (OpenCV frame);
  ``time`` float64 (s) and ``step`` int64.

Fork safety: nothing renders or opens a file before iteration, in the process that iterates,
and ``make_loader`` spawns its workers: a forked worker would inherit the parent's EGL context,
which the engine refuses to use (``RenderError``). Scripts that use workers need the usual
``if __name__ == "__main__":`` guard of the spawn start method.

PyTorch is an optional extra: ``pip install ambfplus[torch]``.
"""

try:
    import torch  # noqa: F401
except ImportError as _error:  # pragma: no cover - exercised in a subprocess by the tests
    raise ImportError(
        "ambfplus.learning needs PyTorch, an optional extra: pip install 'ambfplus[torch]' "
        "(for the CPU-only build, first: pip install torch --index-url "
        "https://download.pytorch.org/whl/cpu)"
    ) from _error

from ..scenes import CameraPath, DrillScript
from .datasets import RecordingStereoDataset, SimulatorStereoDataset, make_loader
from .metrics import disparity_metrics, fill_invalid_along_rows
from .samples import crop_sample, stereo_sample
from .stereo_transformer import StereoTransformer, stereo_loss
from .targets import depth_from_disparity, disparity_from_depth, occlusion_mask, stereo_targets

__all__ = [
    "CameraPath",
    "crop_sample",
    "depth_from_disparity",
    "disparity_from_depth",
    "disparity_metrics",
    "DrillScript",
    "fill_invalid_along_rows",
    "make_loader",
    "occlusion_mask",
    "RecordingStereoDataset",
    "SimulatorStereoDataset",
    "stereo_loss",
    "stereo_sample",
    "stereo_targets",
    "StereoTransformer",
]
