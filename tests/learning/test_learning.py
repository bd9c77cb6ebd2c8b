"""PyTorch adapters (ambfplus.learning): samples rendered in the loop and read from recordings,
their targets against the rig's geometry and an analytic occlusion, DataLoader workers that
never inherit the parent's EGL context, the stereo network, and the paper's two experiments as
runnable examples at CI size."""

from __future__ import annotations

import importlib.util
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest
from helpers import EXAMPLES  # noqa: E402

torch = pytest.importorskip(
    "torch", reason="ambfplus.learning needs PyTorch (pip install 'ambfplus[torch]')"
)

import ambfplus  # noqa: E402
from ambfplus.learning import (  # noqa: E402
    RecordingStereoDataset,
    SimulatorStereoDataset,
    StereoTransformer,
    disparity_metrics,
    fill_invalid_along_rows,
    make_loader,
    occlusion_mask,
    stereo_loss,
    stereo_sample,
)
from ambfplus.learning.samples import crop_sample  # noqa: E402
from ambfplus.learning.stereo_transformer import (  # noqa: E402
    log_optimal_transport,
    regress_disparity,
)
from ambfplus.stereo import StereoRig  # noqa: E402

# One thread: these networks are tiny, and spinning threads on a busy machine only slow them.
torch.set_num_threads(1)
SMALL = {"width": 96, "height": 72, "resolution": 48}


def run_python(code: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True, text=True, timeout=timeout, cwd="/",
    )  # fmt: skip


def test_importing_ambfplus_never_imports_torch():
    out = run_python(
        """
        import sys
        import ambfplus, ambfplus.scenes, ambfplus.recording, ambfplus.stereo, ambfplus.labels
        assert "torch" not in sys.modules, "ambfplus imported torch"
        print("ok")
        """
    )
    assert out.returncode == 0 and "ok" in out.stdout, out.stderr


def test_learning_without_torch_names_the_extra_and_the_cpu_build():
    out = run_python(
        """
        import sys
        sys.modules["torch"] = None  # as if PyTorch were not installed
        try:
            import ambfplus.learning
        except ImportError as error:
            print(error)
        else:
            raise SystemExit("imported without torch")
        """
    )
    assert out.returncode == 0, out.stderr
    assert "pip install 'ambfplus[torch]'" in out.stdout
    assert "download.pytorch.org/whl/cpu" in out.stdout


@pytest.fixture(scope="module")
def live_samples():
    """Three in-loop samples of each scenario, rendered in this process."""
    out = {}
    for scenario in ("camera", "drilling"):
        data = SimulatorStereoDataset(
            samples=3, scenario=scenario, episode_frames=3, capture_every=50, seed=3, **SMALL
        )
        out[scenario] = list(data)
    return out


def test_samples_have_the_documented_shapes_and_types(live_samples):
    sample = live_samples["drilling"][0]
    h, w = SMALL["height"], SMALL["width"]
    expected = {
        "left": (torch.float32, (3, h, w)), "right": (torch.float32, (3, h, w)),
        "disparity": (torch.float32, (h, w)), "depth": (torch.float32, (h, w)),
        "valid": (torch.bool, (h, w)), "occlusion": (torch.bool, (h, w)),
        "segmentation": (torch.uint8, (3, h, w)), "instance": (torch.int32, (h, w)),
        "label": (torch.int32, (h, w)), "baseline": (torch.float32, ()),
        "focal": (torch.float32, ()), "dcx": (torch.float32, ()),
        "intrinsics": (torch.float64, (3, 3)), "left_pose": (torch.float64, (4, 4)),
        "right_pose": (torch.float64, (4, 4)), "time": (torch.float64, ()),
        "step": (torch.int64, ()),
    }  # fmt: skip
    assert set(sample) == set(expected)
    for key, (dtype, shape) in expected.items():
        assert sample[key].dtype == dtype and tuple(sample[key].shape) == shape, key
    for key in ("left", "right"):
        assert 0.0 <= float(sample[key].min()) and float(sample[key].max()) <= 1.0
        assert float(sample[key].max()) > 0.5, "the phantom is lit"
    assert sample["step"] == 50 and sample["time"] == pytest.approx(0.05)


def test_disparity_agrees_with_depth_and_the_rig(live_samples):
    for sample in live_samples["camera"] + live_samples["drilling"]:
        f, b, dcx = (float(sample[k]) for k in ("focal", "baseline", "dcx"))
        valid, depth, d = sample["valid"], sample["depth"], sample["disparity"].double()
        assert valid.equal(depth > 0) and 0.05 < valid.float().mean() < 0.9
        assert (d[~valid] == 0).all()
        # Z = f B / (d + dcx) on every pixel with a hit.
        z = f * b / (d[valid] + dcx)
        torch.testing.assert_close(z, depth[valid].double(), rtol=1e-6, atol=0)
        # The rig: the paper's baseline and focal, off-axis at 250 mm.
        left, right = sample["left_pose"], sample["right_pose"]
        assert b == pytest.approx(float(torch.linalg.norm(left[:3, 3] - right[:3, 3])), rel=1e-6)
        assert b == pytest.approx(0.065) and f == pytest.approx(1135 * SMALL["height"] / 480)
        assert dcx == pytest.approx(f * b / 0.25, rel=1e-6)
        # Independently: carry each left pixel's point into the right camera and measure the
        # column it lands on there (the right principal point is dcx to the right).
        k = sample["intrinsics"]
        rows, cols = torch.nonzero(valid, as_tuple=True)
        zs = depth[rows, cols].double()
        x = ((cols + 0.5) - k[0, 2]) / k[0, 0] * zs
        y = ((rows + 0.5) - k[1, 2]) / k[1, 1] * zs
        world = left[:3, :3] @ torch.stack([x, y, zs]) + left[:3, 3:]
        in_right = right[:3, :3].T @ (world - right[:3, 3:])
        x_right = in_right[0] / in_right[2] * k[0, 0] + k[0, 2] + dcx
        torch.testing.assert_close(cols + 0.5 - x_right, d[rows, cols], atol=1e-3, rtol=0)


def test_segmentation_instance_and_label_describe_the_same_pixels(live_samples):
    sample = live_samples["drilling"][2]
    valid, instance, label = sample["valid"], sample["instance"], sample["label"]
    assert valid.equal(instance != 0), "every pixel with a hit shows an object"
    assert (label[~valid] == 0).all() and (label > 0).any()
    anatomy = torch.mode(instance[label > 0]).values
    assert (instance[label > 0] == anatomy).all(), "labels only where the anatomy is seen"
    assert (sample["segmentation"].sum(0)[valid] > 0).all()


def test_drilling_samples_change_the_anatomy_and_camera_samples_move_the_rig(live_samples):
    drilling, camera = live_samples["drilling"], live_samples["camera"]
    torch.testing.assert_close(drilling[0]["left_pose"], drilling[2]["left_pose"])
    assert not drilling[0]["depth"].equal(drilling[2]["depth"]), "the drill moved"
    moved = torch.linalg.norm(camera[0]["left_pose"][:3, 3] - camera[2]["left_pose"][:3, 3])
    assert moved > 0.002, "the rig swings during a camera episode"


def card_before_wall(card_distance: float = 0.2, wall_distance: float = 0.3):
    """A wall facing the paper's off-axis rig at 300 mm and a thin card 40 mm wide in front of
    it, captured at 320x240."""
    world = ambfplus.World()
    world.add_light("key", "directional", direction=(0, 0, -1))
    world.add_body("wall", "box", size=(1.0, 1.0, 0.01), mass=0,
                   pose=ambfplus.make_pose((0, 0, -0.005)))  # fmt: skip
    card_z = wall_distance - card_distance
    world.add_body("card", "box", size=(0.04, 0.04, 0.001), mass=0,
                   pose=ambfplus.make_pose((0, 0, card_z - 0.0005)))  # fmt: skip
    fov_y = 2 * np.arctan(120 / 567.5)  # f = 567.5 px at 320x240: the paper's at half size
    rig = StereoRig(world, "rig", baseline=0.065, width=320, height=240, fov_y=fov_y,
                    near=0.01, far=2.0, working_distance=0.25)  # fmt: skip
    rig.aim((0, 0, wall_distance), (0, 0, 0), up=(0, 1, 0))
    return rig.capture(("rgb", "depth", "instance"))


def test_occlusion_is_the_band_the_card_hides_from_the_right_camera():
    pair = card_before_wall()
    sample = stereo_sample(pair)
    occlusion, d, valid = sample["occlusion"].numpy(), sample["disparity"].numpy(), sample["valid"]
    assert valid.all(), "the wall fills the view"
    card = sample["depth"].numpy() < 0.25
    rows = np.nonzero(card.any(axis=1))[0]
    assert 30 < len(rows) < 120
    width = d.shape[1]
    for r in rows[2:-2]:
        columns = np.nonzero(card[r])[0]
        d_card, d_wall = d[r, columns[0]], d[r, 0]
        assert d_card - d_wall == pytest.approx(567.5 * 0.065 * (1 / 0.2 - 1 / 0.3), rel=1e-4)
        # Left of the card, the right camera sees the card where the left one sees the wall:
        # a band as wide as the disparity step (pixel centres within it: its width +- 1).
        hidden = np.nonzero(occlusion[r, : columns[0]])[0]
        assert abs(len(hidden) - (d_card - d_wall)) <= 1.0
        assert hidden[-1] == columns[0] - 1 and np.all(np.diff(hidden) == 1)
        assert not occlusion[r, columns].any(), "the card is seen by both cameras"
        # Right of the card, only wall points that leave the right image.
        leaving = np.arange(width) + 0.5 - d[r] >= width
        right_part = np.arange(width) > columns[-1]
        assert np.array_equal(occlusion[r, right_part], leaving[right_part])
    # Rows without the card: only pixels that leave the right image.
    r = rows[0] - 5
    assert np.array_equal(occlusion[r], np.arange(width) + 0.5 - d[r] >= width)


def test_occlusion_needs_matching_depth_images():
    with pytest.raises(ValueError, match="same"):
        occlusion_mask(np.ones((4, 5)), np.ones((4, 6)), 100.0, 0.1, 0.0)


def test_a_crop_keeps_disparity_and_hides_matches_outside_it():
    sample = stereo_sample(card_before_wall())
    crop = crop_sample(sample, top=60, left=100, height=120, width=100)
    torch.testing.assert_close(crop["disparity"], sample["disparity"][60:180, 100:200])
    x_right = torch.arange(100) + 0.5 - crop["disparity"]
    leaves = (x_right < 0) | (x_right >= 100)
    # The card (disparity 38 px) leaves on the left, the wall (-25 px) on the right.
    wall = crop["disparity"] < 0
    assert leaves[:, :30].any() and leaves[:, -20:][wall[:, -20:]].all()
    assert crop["occlusion"][leaves].all()
    kept = ~leaves & ~sample["occlusion"][60:180, 100:200]
    assert not crop["occlusion"][kept].any()
    assert crop["intrinsics"][0, 2] == sample["intrinsics"][0, 2] - 100
    assert crop["intrinsics"][1, 2] == sample["intrinsics"][1, 2] - 60
    with pytest.raises(ValueError, match="does not fit"):
        crop_sample(sample, top=200, left=0, height=120, width=100)


@pytest.mark.slow
def test_two_workers_give_different_samples_and_each_is_reproducible():
    data = SimulatorStereoDataset(samples=4, scenario="mixed", episode_frames=2, seed=11, **SMALL)
    loader = make_loader(data, batch_size=1, num_workers=2)
    assert loader.multiprocessing_context.get_start_method() == "spawn"
    batches = list(loader)
    assert len(batches) == 4
    # Batches alternate between workers: 0 and 1 are the two workers' first samples, taken at
    # the same step from independently drawn scenarios.
    first, second = batches[0], batches[1]
    assert first["step"] == second["step"]
    assert not torch.equal(first["left_pose"], second["left_pose"])
    assert not torch.equal(first["left"], second["left"])
    # Worker 0 draws what the main process draws (same seed, epoch and id): identical samples.
    here = next(iter(data))
    for key in ("left", "right", "disparity", "occlusion", "left_pose"):
        assert torch.equal(here[key], first[key][0]), key
    data.set_epoch(1)
    assert not torch.equal(next(iter(data))["left"], here["left"]), "a new epoch, new samples"


@pytest.mark.slow
def test_a_forked_worker_of_a_parent_that_rendered_is_refused():
    """The rule make_loader enforces, shown: fork after rendering fails with a message that
    says what to do; spawn works."""
    out = run_python(
        """
        import torch
        from ambfplus.learning import SimulatorStereoDataset, make_loader
        from ambfplus.scenes import drilling_phantom
        drilling_phantom(width=64, height=48, resolution=32).rig.capture(("rgb",))  # renders
        data = SimulatorStereoDataset(samples=1, width=64, height=48, resolution=32)
        try:
            list(torch.utils.data.DataLoader(data, num_workers=1, multiprocessing_context="fork"))
        except Exception as error:
            print("FORK FAILED:", error)
        if __name__ == "__main__":
            print("SPAWNED:", len(list(make_loader(data, num_workers=1))))
        """,
        timeout=180,
    )
    assert out.returncode == 0, out.stderr
    assert "FORK FAILED" in out.stdout and "multiprocessing_context='spawn'" in out.stdout
    assert "SPAWNED: 1" in out.stdout


def test_make_loader_refuses_fork_and_unpicklable_datasets():
    data = SimulatorStereoDataset(samples=1, **SMALL)
    with pytest.raises(ValueError, match="fork"):
        make_loader(data, num_workers=1, multiprocessing_context="fork")
    local = SimulatorStereoDataset(samples=1, scene=lambda **options: None)
    with pytest.raises(TypeError, match="module-level"):
        make_loader(local, num_workers=1)


def test_bad_dataset_options_are_named():
    with pytest.raises(ValueError, match="scenario"):
        SimulatorStereoDataset(scenario="flying")
    with pytest.raises(ValueError, match="depth"):
        SimulatorStereoDataset(passes=("rgb",))
    with pytest.raises(TypeError, match="expected an ambfplus.scenes.Scene"):
        next(iter(SimulatorStereoDataset(samples=1, scene=dict, **SMALL)))


@pytest.fixture(scope="module")
def recorded(tmp_path_factory):
    """Samples rendered in the loop while recording them."""
    folder = tmp_path_factory.mktemp("recorded")
    data = SimulatorStereoDataset(
        samples=5, scenario="drilling", episode_frames=5, seed=5, record_to=folder, **SMALL
    )
    return folder / "worker0_epoch0.h5", list(data)


def test_a_recording_gives_back_the_samples_rendered_in_the_loop(recorded):
    path, live = recorded
    data = RecordingStereoDataset(path)
    assert len(data) == 5 and data._open == {}, "lengths read, files closed again"
    for i, sample in enumerate(live):
        again = data[i]
        assert set(again) == set(sample)
        for key in sample:
            assert torch.equal(again[key], sample[key]), (i, key)
    data.close()


@pytest.mark.slow
def test_recordings_are_read_by_two_workers_that_open_their_own_files(recorded):
    path, live = recorded
    data = RecordingStereoDataset([path, path])
    batches = list(make_loader(data, batch_size=2, num_workers=2))
    assert data._open == {}, "the parent opened nothing"
    lefts = torch.cat([b["left"] for b in batches])
    assert len(lefts) == 10
    expected = torch.stack([s["left"] for s in live] * 2)
    assert torch.equal(lefts, expected)
    assert data.locate(7) == (1, 2)


def test_recording_dataset_errors_name_the_file_and_what_is_missing(recorded, tmp_path):
    path, _ = recorded
    with pytest.raises(KeyError, match="no stereo rig 'stereo'.*it has: rig"):
        RecordingStereoDataset(path, rig="stereo")
    with pytest.raises(ValueError, match="nothing.h5"):
        RecordingStereoDataset(tmp_path / "nothing.h5")
    from ambfplus.recording import Recorder
    from ambfplus.scenes import drilling_phantom

    scene = drilling_phantom(width=32, height=24, resolution=32)
    with Recorder(tmp_path / "rgb_only.h5") as rec:
        rec.add_stereo("rig", scene.rig.capture(("rgb",)))
    with pytest.raises(ValueError, match=r"rig_left of rig 'rig' has no \['depth'\]"):
        RecordingStereoDataset(tmp_path / "rgb_only.h5")
    with pytest.raises(IndexError, match="out of range"):
        RecordingStereoDataset(path)[5]


def test_optimal_transport_rows_are_distributions():
    scores = torch.randn(3, 6, 6)
    log_p = log_optimal_transport(scores, torch.tensor(0.5), iterations=50)
    rows = log_p[:, :-1, :].exp().sum(-1)
    torch.testing.assert_close(rows, torch.ones_like(rows), atol=1e-4, rtol=0)
    columns = log_p[:, :, :-1].exp().sum(-2)
    torch.testing.assert_close(columns, torch.ones_like(columns), atol=1e-4, rtol=0)


def test_disparity_is_regressed_around_the_best_match():
    # Feature 5 matches right feature 3 and, less, 4: disparity 4 * (5 - 3.25) = 7 pixels.
    log_p = torch.full((1, 9, 9), -30.0)
    log_p[0, 5, 3], log_p[0, 5, 4] = np.log(0.6), np.log(0.2)
    log_p[0, 5, 8] = np.log(0.2)  # the dustbin
    disparity, occlusion = regress_disparity(log_p)
    assert float(disparity[0, 5]) == pytest.approx(4 * (5 - 3.25), abs=1e-4)
    assert float(occlusion[0, 5]) == pytest.approx(0.2, abs=1e-4)


def random_dot_pair(shift: int, height: int = 32, width: int = 64, seed: int = 0):
    """A random-dot stereo pair whose every pixel has disparity `shift`."""
    g = torch.Generator().manual_seed(seed)
    texture = torch.rand(1, 3, height, width + shift, generator=g)
    left, right = texture[..., shift:], texture[..., :width]
    disparity = torch.full((1, height, width), float(shift))
    valid = torch.ones(1, height, width, dtype=torch.bool)
    occlusion = (torch.arange(width) + 0.5 - disparity >= width) | (
        torch.arange(width) + 0.5 - disparity < 0
    )
    return left, right, {"disparity": disparity, "valid": valid, "occlusion": occlusion}


def test_the_network_learns_a_random_dot_pair():
    torch.manual_seed(0)
    model = StereoTransformer(channels=16, layers=1, heads=2)
    left, right, batch = random_dot_pair(shift=8)
    out = model(left, right)
    assert out["disparity"].shape == (1, 32, 64) and out["occlusion"].shape == (1, 32, 64)
    optimiser = torch.optim.AdamW(model.parameters(), lr=3e-3)
    losses = []
    for _ in range(40):
        loss, _ = stereo_loss(model(left, right), batch)
        optimiser.zero_grad()
        loss.backward()
        optimiser.step()
        losses.append(loss.item())
    assert losses[-1] < 0.3 * losses[0]
    with pytest.raises(ValueError, match="multiple of 4"):
        model(left[..., :30], right[..., :30])


def test_metrics_and_row_filling():
    truth = np.array([[10.0, 10.0, 20.0, 20.0]])
    predicted = np.array([[10.0, 12.0, 20.0, 20.5]])
    m = disparity_metrics(predicted, truth, np.ones_like(truth, bool), 100.0, 0.1, 0.0)
    assert m["epe"] == pytest.approx(2.5 / 4) and m["bad1"] == pytest.approx(0.25)
    z_error = abs(10 / 12 - 1.0) + abs(10 / 20.5 - 0.5)
    assert m["depth_l1_mm"] == pytest.approx(z_error * 1000 / 4)
    row = np.array([[5.0, -1, -1, 9.0, -1, 7.0, -1]], np.float32)
    filled = fill_invalid_along_rows(row, row < 0)
    assert filled.tolist() == [[5.0, 5.0, 5.0, 9.0, 7.0, 7.0, 7.0]]


def load_example(name: str):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_the_depth_experiment_runs_at_small_size(tmp_path):
    example = load_example("stereo_depth_experiment")
    assert example.main([str(tmp_path), "--small"]) == 0
    report = json.loads((tmp_path / "results.json").read_text())
    assert report["training"]["iterations"] == 30
    visible = report["test"]["visible"]
    assert report["test"]["frames"] == 20 and visible["model"]["pixels"] > 10000
    # SGBM on clean renders of textured bone, at 160x120: well under two pixels.
    assert visible["sgbm_filled"]["epe_px"] < 2.0
    assert 0.5 < report["test"]["sgbm_density"]["visible"] <= 1.0
    for name in ("model", "sgbm_filled", "sgbm_raw"):
        assert np.isfinite(visible[name]["depth_l1_mm"]) and visible[name]["depth_l1_mm"] > 0
    history = (tmp_path / "learning_curve.csv").read_text().splitlines()
    assert len(history) == 31
    first, last = (float(line.split(",")[4]) for line in (history[1], history[-1]))
    assert last < first, "the loss falls"
    assert (tmp_path / "depth_error.png").stat().st_size > 1000
    # A second run reuses the recordings.
    assert example.ensure_sequence(
        tmp_path / "moving_drill.h5", example.MOVING_DRILL, frames=20, width=160, height=120,
        resolution=64,
    ) is False  # fmt: skip


@pytest.mark.slow
def test_the_tracking_experiment_runs_at_small_size(tmp_path):
    example = load_example("tracking_experiment")
    assert example.main([str(tmp_path), "--small"]) == 0
    report = json.loads((tmp_path / "tracking.json").read_text())["sequences"]
    camera, drill = report["moving camera, frame to frame"], report["moving drill, frame to frame"]
    assert camera["camera_travel_mm"] > 10 and drill["camera_travel_mm"] == 0
    assert camera["tracking_failures"] == 0 and camera["median_inliers"] > 30
    # With the drill masked out, a still camera stays put; a moving one drifts.
    assert drill["trajectory_translation_mm"][0] < 1.0
    assert camera["trajectory_translation_mm"][0] > drill["trajectory_translation_mm"][0]
    assert "| moving camera, keyframes |" in (tmp_path / "tracking.md").read_text()
