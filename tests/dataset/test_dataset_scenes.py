"""Datasets of any scene (issue #34): a spec names an AMBF launch file or a Python factory and an
episode script (Python or waypoints); episodes stay pure functions of (spec, seed, index), come
out byte-identical with one or two workers (and on Ray: test_dataset_ray.py), resume after a
killed driver, and name every object's instance masks by its namespaced key."""

from __future__ import annotations

import json
import shutil
import signal
import time
from pathlib import Path

import numpy as np
import pytest
import yaml
from helpers import EXAMPLES
from helpers.multi_arm import BASELINE, BASES, LINK, RESOLUTION
from test_dataset import manifest, shard_bytes, start_generate

from ambfplus.dataset import (
    SpecError,
    generate,
    load_spec,
    read_manifest,
    sample_episode,
    validate_dataset,
)
from ambfplus.dataset.sources import build_episode_scene
from ambfplus.recording import open_recording


def scene_spec(folder: Path, **changes) -> dict:
    """A spec of the multi-arm scene in `folder` (its launch file there), as a dict."""
    spec = {
        "version": 1,
        "episodes": 2,
        "scene": {"launch": str(folder / "scene" / "launch.yaml"), "models": [0, 1, 2, 3]},
        "capture": {"every": 20, "frames": 2, "passes": ["rgb", "instance"]},
    }
    for key, value in changes.items():
        if value is None:
            spec.pop(key, None)
        else:
            spec[key] = value
    return spec


# Specs -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "change, where",
    [
        ({"scene": {"launch": "x.yaml", "factory": "m:f"}}, "scene: expected exactly one of"),
        ({"scene": {"launch": "no/such/launch.yaml"}}, "scene.launch: no such file"),
        ({"scene": {"factory": "not a module"}}, "scene.factory: expected module:function"),
        ({"scene": {"factory": "m:f", "models": [0]}}, "scene.models: does not apply to a scene"),
        ({"anatomies": [{"phantom": {}}]}, "anatomies: applies to the built-in drilling scene"),
        ({"scenarios": [{"kind": "camera"}]}, "scenarios: applies to the built-in drilling"),
        ({"appearance": {"labels": {"color_jitter": 5}}}, "appearance.labels: label colours"),
        ({"episode": {"script": "m:f", "waypoints": []}}, "episode: expected one of script"),
        (
            {"episode": {"waypoints": [{"time": 0.5}, {"time": 0.5}]}},
            "episode.waypoints[1].time: waypoint times must increase",
        ),
        (
            {"episode": {"waypoints": [{"time": 0, "joint": {}}]}},
            "episode.waypoints[0].joint: unknown key",
        ),
        (
            {"episode": {"waypoints": [{"time": 0, "bodies": {"b": {"rpy": [0, 0, 0]}}}]}},
            "episode.waypoints[0].bodies.b.position: missing (required)",
        ),
        (
            {"episode": {"waypoints": [{"time": 0, "joints": {"j": {"uniform": [1, 0]}}}]}},
            "episode.waypoints[0].joints.j.uniform: empty range",
        ),
    ],
)
def test_bad_scene_specs_name_the_key(change, where, multi_arm_spec):
    folder = multi_arm_spec.parent
    spec = scene_spec(folder)
    spec.update(change)
    with pytest.raises(SpecError) as error:
        load_spec(spec)
    assert where in str(error.value), str(error.value)


def test_an_episode_script_without_a_scene_is_refused():
    spec = {"version": 1, "episodes": 1, "anatomies": [{"phantom": {}}],
            "episode": {"script": "m:f"}}  # fmt: skip
    with pytest.raises(SpecError, match="episode: an episode script drives a scene"):
        load_spec(spec)


@pytest.mark.parametrize(
    "episode, message",
    [
        (
            {"waypoints": [{"time": 0.0, "joints": {"arm3/base-link1": 0.1}}]},
            r"waypoints\[0\]\.joints\.arm3/base-link1: .*arm3/base-link1",
        ),
        ({"script": "no_such_module:drive"}, "cannot import 'no_such_module'"),
        ({"script": "arms_episode:no_such_function"}, "arms_episode has no 'no_such_function'"),
        ({"script": "arms_episode:REACH"}, "is not a function"),
    ],
)
def test_a_scene_that_cannot_run_fails_before_any_worker_starts(
    episode, message, multi_arm_spec, tmp_path
):
    folder = multi_arm_spec.parent
    spec = scene_spec(folder, episode=episode)
    spec["scene"]["python_path"] = [str(folder / "scene")]
    with pytest.raises(SpecError, match=message):
        generate(spec, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()  # nothing ran


def test_scene_episodes_are_pure_functions_of_spec_seed_and_index(multi_arm_spec):
    spec = load_spec(EXAMPLES / "multi_arm" / "dataset_spec.yaml")
    first = [sample_episode(spec, i).describe() for i in range(spec.episodes)]
    assert first == [sample_episode(spec, i).describe() for i in range(spec.episodes)]
    assert len({json.dumps(d, sort_keys=True) for d in first}) == spec.episodes
    # Each episode drew its own joint targets, inside the spec's ranges.
    targets = [d["episode"]["waypoints"][1]["joints"]["arm1/base-link1"] for d in first]
    assert len(set(targets)) == spec.episodes and all(0.3 <= t <= 0.7 for t in targets)
    # Looks come from their own streams: other lights leave the motion and the rig alone.
    plain = dict(spec.data, appearance={})
    for i in range(spec.episodes):
        a, b = sample_episode(spec, i), sample_episode(plain, i)
        assert a.episode == b.episode
        assert {k: a.scene[k] for k in ("width", "height", "baseline")} == {
            k: b.scene[k] for k in ("width", "height", "baseline")
        }


def test_the_rig_takes_the_scene_pairs_place_or_stands_at_the_view(multi_arm_spec):
    folder = multi_arm_spec.parent
    # The scene's pair (main_left, main_right): the rig keeps its baseline, resolution and
    # field of view, and rides on the camera frame with it.
    spec = load_spec(scene_spec(folder))
    scene, controller = build_episode_scene(spec.data, sample_episode(spec, 0))
    world, rig = scene.world, scene.rig
    pair = world.get("main_left"), world.get("main_right")
    assert controller is None and scene.drill is None
    assert rig.baseline == pytest.approx(BASELINE, abs=1e-9)
    assert (rig.left.width, rig.left.height) == RESOLUTION
    assert rig.left.fov_y == pytest.approx(pair[0].fov_y)
    np.testing.assert_allclose(rig.left.pose, pair[0].pose, atol=1e-9)
    assert rig.left.attached_to.key == pair[0].attached_to.key == "main"  # on CameraFrame
    frame = world.get("CameraFrame")
    frame.pose = frame.pose @ np.array(
        [[1, 0, 0, 0.1], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float
    )
    world.step(1)
    np.testing.assert_allclose(rig.left.pose, world.get("main_left").pose, atol=1e-9)
    # A rigs entry overrides what it gives; a view places a free rig.
    view = {"eye": [0.4, -0.3, 1.2], "target": [0.4, 0.0, 0.5]}
    spec = load_spec(
        scene_spec(
            folder,
            rigs=[{"baseline": 0.08, "resolution": [64, 48]}],
            scene={**scene_spec(folder)["scene"], "view": view},
        )  # fmt: skip
    )
    scene, _ = build_episode_scene(spec.data, sample_episode(spec, 0))
    rig = scene.rig
    assert rig.baseline == pytest.approx(0.08) and (rig.left.width, rig.left.height) == (64, 48)
    assert rig.left.attached_to is None
    middle = (rig.left.pose[:3, 3] + rig.right.pose[:3, 3]) / 2
    np.testing.assert_allclose(middle, view["eye"], atol=1e-9)
    axis = np.subtract(view["target"], view["eye"])
    np.testing.assert_allclose(rig.left.pose[:3, 2], axis / np.linalg.norm(axis), atol=1e-9)


def test_the_rig_draws_as_the_scene_pair_draws(multi_arm_spec, tmp_path):
    """Shadows, antialiasing and looks that the scene's files give its stereo pair are the
    dataset rig's too, but for what the spec's appearance.rendering gives; a free rig draws
    without them."""
    folder = tmp_path / "multi_arm"
    shutil.copytree(multi_arm_spec.parent / "scene", folder / "scene")
    world_file = folder / "scene" / "world.yaml"
    world_file.write_text(
        world_file.read_text().replace(
            "  name: main\n", "  name: main\n  shadows: true\n  antialiasing: 3\n  looks: true\n"
        )
    )
    spec = load_spec(scene_spec(folder))
    scene, _ = build_episode_scene(spec.data, sample_episode(spec, 0))
    pair = scene.world.get("main_left")
    assert (pair.shadows, pair.antialiasing, pair.looks) == (True, 3, True)
    for camera in (scene.rig.left, scene.rig.right):
        assert (camera.shadows, camera.antialiasing, camera.looks) == (True, 3, True)
    # The spec's appearance.rendering overrides what it gives.
    spec = load_spec(scene_spec(folder, appearance={"rendering": {"antialiasing": 2}}))
    scene, _ = build_episode_scene(spec.data, sample_episode(spec, 0))
    for camera in (scene.rig.left, scene.rig.right):
        assert (camera.shadows, camera.antialiasing, camera.looks) == (True, 2, True)
    view = {"eye": [0.4, -0.3, 1.2], "target": [0.4, 0.0, 0.5]}
    spec = load_spec(scene_spec(folder, scene={**scene_spec(folder)["scene"], "view": view}))
    scene, _ = build_episode_scene(spec.data, sample_episode(spec, 0))
    left = scene.rig.left
    assert (left.shadows, left.antialiasing, left.looks) == (False, 1, False)


# Generating --------------------------------------------------------------------------------


def _yaw(pose: np.ndarray) -> float:
    return float(np.arctan2(pose[1, 0], pose[0, 0]))


def test_datasets_of_a_multi_arm_scene_are_identical_with_one_and_two_workers(
    multi_arm_spec, multi_arm_dataset, tmp_path
):
    report = generate(multi_arm_spec, tmp_path / "two", workers=2, progress=False)
    assert report.generated == 6 and report.retries == 0
    assert manifest(tmp_path / "two") == manifest(multi_arm_dataset)
    assert shard_bytes(tmp_path / "two") == shard_bytes(multi_arm_dataset)
    assert len({r["worker"] for r in read_manifest(tmp_path / "two")[0]}) == 2
    checked = validate_dataset(tmp_path / "two", match_images=False)
    assert checked.ok and not checked.warnings, str(checked)
    records, _ = read_manifest(multi_arm_dataset)
    swings = set()
    for record in records:
        assert record["anatomy"] == "scene" and record["scenario"] == "script"
        # Pixels are counted per object under its key: both arms' links, apart.
        pixels = record["label_pixels"]
        assert pixels["arm1/link1"] > 0 and pixels["arm2/link1"] > 0, pixels
        with open_recording(multi_arm_dataset / record["file"]) as rec:
            steps = rec.steps
            # The script's grasp happened: the ghost sensed the needle, the grip holds it, and
            # it travels with the jaw once the arm swings away.
            needle = steps["needle.pose"][:, :3, 3]
            jaw = steps["arm1/jaw.pose"][:, :3, 3]
            gap = np.linalg.norm(needle - jaw, axis=1)
            assert gap[0] > 0.08  # out of the jaw's reach as the arm starts
            assert gap[-1] < 0.06 and np.linalg.norm(needle[-1] - needle[0]) > 0.08
            swings.add(round(_yaw(steps["arm1/link1.pose"][-1]), 3))
            # The second arm's link lies where its joint angle puts it (the base is static).
            q0 = _yaw(steps["arm2/link1.pose"][-1])
            expected = np.add(BASES["arm2"], LINK / 2 * np.array([np.cos(q0), np.sin(q0), 0]))
            np.testing.assert_allclose(steps["arm2/link1.pose"][-1][:3, 3], expected, atol=2e-3)
            # Instance masks are named by namespaced keys in the legend.
            legend = rec.legend
            ids = {e.get("key", e["name"]): i for i, e in legend.items()}
            instance = rec.cameras["rig_left"].instance[:]
            for key in ("arm1/link1", "arm2/link1", "needle"):
                assert (instance == ids[key]).any(), key
            assert rec.metadata["dataset"]["episode"] == record["episode"]
    assert len(swings) == 6  # each episode swung by its own drawn angle


def test_coco_categories_of_a_scene_dataset_are_the_namespaced_keys(multi_arm_dataset, tmp_path):
    pytest.importorskip("pycocotools")
    from ambfplus.export import export

    record = read_manifest(multi_arm_dataset)[0][0]
    shard = multi_arm_dataset / record["file"]
    export(shard, tmp_path / "coco", "coco", progress=False)
    document = json.loads((tmp_path / "coco" / "rig_left.json").read_text())
    names = {c["id"]: c["name"] for c in document["categories"]}
    assert {"arm1/link1", "arm2/link1", "arm1/base", "arm2/base", "needle"} <= set(names.values())
    with open_recording(shard) as rec:
        legend = rec.legend
        instance = rec.cameras["rig_left"].instance[:]
    ids = {e.get("key", e["name"]): i for i, e in legend.items()}
    first = document["images"][0]["id"]
    areas = {
        names[a["category_id"]]: a["area"]
        for a in document["annotations"]
        if a["image_id"] == first
    }
    for key in ("arm1/link1", "arm2/link1"):
        assert areas[key] == int((instance[0] == ids[key]).sum()), key


@pytest.mark.slow
def test_a_killed_driver_resumes_a_scene_dataset_to_the_same_shards(
    multi_arm_spec, multi_arm_dataset, tmp_path
):
    out = tmp_path / "data"
    driver = start_generate(multi_arm_spec, out)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_manifest(out)[0]) < 2:
        time.sleep(0.02)
    driver.send_signal(signal.SIGKILL)
    driver.wait(timeout=30)
    assert 2 <= len(read_manifest(out)[0]) < 6 or driver.returncode == -signal.SIGKILL
    resumed = generate(multi_arm_spec, out, workers=2, progress=False)
    assert resumed.skipped >= 2 and resumed.skipped + resumed.generated == 6
    assert manifest(out) == manifest(multi_arm_dataset)
    assert shard_bytes(out) == shard_bytes(multi_arm_dataset)
    assert validate_dataset(out, match_images=False).ok


def test_the_multi_arm_example_generates_with_its_factory_and_waypoints(tmp_path):
    folder = tmp_path / "multi_arm"
    shutil.copytree(EXAMPLES / "multi_arm", folder)
    spec_file = folder / "dataset_spec.yaml"
    data = yaml.safe_load(spec_file.read_text())
    data["episodes"] = 2
    spec_file.write_text(yaml.safe_dump(data))
    report = generate(spec_file, tmp_path / "out", workers=1, progress=False)
    assert report.generated == 2
    assert validate_dataset(tmp_path / "out", match_images=False).ok
    spec = load_spec(spec_file)
    for record in read_manifest(tmp_path / "out")[0]:
        plan = sample_episode(spec, record["episode"])
        reach = plan.episode["waypoints"][1]["joints"]
        with open_recording(tmp_path / "out" / record["file"]) as rec:
            steps = rec.steps
            # The joints reached their drawn waypoint targets (the links' yaw is the sum of the
            # joint angles up to them; the bases are static and unturned).
            q0 = _yaw(steps["arm1/link1.pose"][-1])
            q01 = _yaw(steps["arm1/link2.pose"][-1])
            assert q0 == pytest.approx(reach["arm1/base-link1"], abs=0.03)
            assert q01 - q0 == pytest.approx(reach["arm1/link1-link2"], abs=0.03)
            # The factory drew the needle's place from the episode's stream.
            assert rec.metadata["sampled"]["scenario"]["kind"] == "waypoints"
            assert rec.cameras["rig_left"].rgb.shape[1:3] == (120, 160)
