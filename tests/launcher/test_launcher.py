"""The interactive launcher under a virtual display (Xvfb): it opens the original drilling scene
in a window, keys sent with xdotool move the drill by the documented steps, a screenshot of the
X server shows what the camera renders, and a recorded session replays to the same removal."""

from __future__ import annotations

import json
import time

import numpy as np
import pytest
from helpers.x11 import finish, launch, screenshot, window_origin, xdo

import ambfplus

WIDTH, HEIGHT = 1536, 540


@pytest.mark.slow
def test_keys_move_the_drill_and_the_window_shows_the_scene(fixtures, display, tmp_path):
    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    process, status_file, window = launch(display, tmp_path, launch_file, 12)
    # Two steps into the view, one up; the burr spins; the next burr.
    xdo(display, "key", "--delay", "250", "ctrl+i", "ctrl+i", "ctrl+w", "space", "c")
    time.sleep(2.0)
    status = json.loads(status_file.read_text())
    screen = screenshot(display)
    left, top = window_origin(display, window)
    finish(process)

    # The fixture's drill starts at (-0.2, 0, 0); main_camera at the origin looks along -x with
    # z up: 2 mm into the view is -x, 1 mm up is +z.
    np.testing.assert_allclose(status["drill_position"], [-0.202, 0.0, 0.001], atol=1e-6)
    assert status["spinning"] and status["burr_mm"] == 1.0
    assert status["mode"] == "keyboard" and status["physics_hz"] > 900
    assert status["critical"] and np.isfinite(status["critical_mm"])  # named by labels.csv

    # The screenshot is what the camera renders for that drill (the 1 mm burr's mesh, moved).
    shot = screen[top : top + HEIGHT, left : left + WIDTH]
    sim = ambfplus.Simulator.from_launch(
        launch_file, models=[0, 2], arguments=["--labels", str(launch_file.parent / "labels.csv")]
    )
    drill, main = sim.get("drill"), sim.get("main_camera")
    # The window shows main_camera's view at the window's size.
    camera = sim.world.add_camera("view", WIDTH, HEIGHT, fov_y=main.fov_y, near=main.near,
                                  far=main.far)  # fmt: skip
    camera.pose = main.pose
    goal = drill.goal.copy()
    goal[:3, 3] = status["drill_position"]
    drill.goal, drill.burr = goal, 0
    sim.step(2)
    frame = camera.capture(passes=["rgb", "instance"])
    body = frame.instance == sim.get("1mm").id
    bone = frame.instance == sim.world.volumes[0].id
    assert body.sum() > 200 and bone.sum() > 10000
    below_status = np.zeros(body.shape, bool)
    below_status[60:] = True  # the status line covers the top rows
    difference = np.abs(shot.astype(int) - frame.rgb.astype(int)).max(axis=2)
    assert np.median(difference[bone & below_status]) <= 2
    assert np.median(difference[body & below_status]) <= 2
    assert shot[bone].mean() > 60, "the anatomy is lit, not black"


@pytest.mark.slow
def test_a_recorded_interactive_session_replays_to_the_same_removal(fixtures, display, tmp_path):
    from ambfplus.scenes import replay

    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    record = tmp_path / "session.h5"
    process, status_file, _ = launch(display, tmp_path, launch_file, 14, "--record", str(record))
    # The burr touches the ear about 76 mm in front of it: spin it and push 9 mm further.
    xdo(display, "key", "space")
    xdo(display, "key", "--delay", "20", "--repeat", "85", "ctrl+i")
    time.sleep(3.0)
    finish(process)
    status = json.loads(status_file.read_text())
    assert status["spinning"]

    report = replay(record, compare_images=False)
    assert report.voxels_removed > 100, "the session drilled"
    assert report.removal_identical and report.forces_identical, report.differences


def test_mouse_navigation_turns_about_the_target_pans_and_zooms():
    from ambfplus.launcher.navigation import MOUSE_LEFT, MOUSE_RIGHT, Orbit

    world = ambfplus.World()
    camera = world.add_camera("cam", 64, 48, fov_y=0.8, near=0.01, far=5.0)
    target = np.array([0.1, -0.2, 0.05])
    camera.look_at(target + (0.3, -0.4, 0.2), target)
    orbit = Orbit(target=target.copy())
    distance = np.linalg.norm(camera.pose[:3, 3] - target)

    def pixel_of(point):
        p = np.linalg.inv(camera.pose) @ np.append(point, 1.0)
        uv = camera.intrinsics @ (p[:3] / p[2])
        return uv[:2]

    # A turn: the eye stays at its distance and the target at the image's centre.
    before = camera.pose.copy()
    turn = orbit.drag(camera.pose, 40.0, -25.0, MOUSE_LEFT)["look_at"]
    camera.look_at(*turn)
    assert np.linalg.norm(camera.pose[:3, 3] - target) == pytest.approx(distance, rel=1e-12)
    np.testing.assert_allclose(pixel_of(target), (32.0, 24.0), atol=1e-9)
    assert np.linalg.norm(camera.pose[:3, 3] - before[:3, 3]) > 0.05
    # A pan: the orientation stays, the eye and the target move by the same vector in the image
    # plane.
    before = camera.pose.copy()
    pan = orbit.drag(camera.pose, 10.0, 5.0, MOUSE_RIGHT)["pose"]
    np.testing.assert_array_equal(pan[:3, :3], before[:3, :3])
    shift = pan[:3, 3] - before[:3, 3]
    np.testing.assert_allclose(orbit.target - target, shift, atol=1e-15)
    assert abs(shift @ before[:3, 2]) < 1e-12 and np.linalg.norm(shift) > 0
    camera.pose = pan
    np.testing.assert_allclose(pixel_of(orbit.target), (32.0, 24.0), atol=1e-9)
    # Two wheel steps towards the target: (1 - zoom)^2 of the distance, same orientation.
    zoomed = orbit.scroll(camera.pose, 2.0)
    np.testing.assert_allclose(
        np.linalg.norm(zoomed[:3, 3] - orbit.target), distance * (1 - orbit.zoom) ** 2, rtol=1e-12
    )
    np.testing.assert_array_equal(zoomed[:3, :3], camera.pose[:3, :3])


@pytest.mark.slow
def test_a_task_session_shows_its_metrics_and_they_equal_the_offline_assessment(
    fixtures, display, tmp_path
):
    """--task on the original drilling scene: the overlay's task line, the live metrics written
    at the end equal the offline assessment of the session's recording, and the debrief."""
    from ambfplus.training import assess, load_task

    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    task_file = ear_task(fixtures, tmp_path, "{labels: [Bone]}", ["Facial_Nerve", "Sinus_+_Dura"])
    record, metrics, report = tmp_path / "s.h5", tmp_path / "live.json", tmp_path / "d.html"
    process, status_file, window = launch(display, tmp_path, launch_file, 14, "--record",
                                          str(record), "--task", str(task_file), "--metrics",
                                          str(metrics), "--report", str(report), "--fixtures",
                                          "--audio")  # fmt: skip
    xdo(display, "key", "space")
    xdo(display, "key", "--delay", "20", "--repeat", "85", "ctrl+i")
    time.sleep(2.0)
    shot = screenshot(display)
    left, top = window_origin(display, window)
    output = finish(process)
    status = json.loads(status_file.read_text())
    assert status["task"] == "Ear drilling" and status["elapsed_s"] > 1, output
    assert status["nearest"] in ("Facial_Nerve", "Sinus_+_Dura")
    assert status["fixtures"] == "on" and status["sound"] == "on", output
    # Every protected structure, each with its own level.
    assert [s["name"] for s in status["structures"]] == ["Facial_Nerve", "Sinus_+_Dura"]
    for s in status["structures"]:
        assert s["level"] == ("clear" if s["mm"] > 2 * s["margin_mm"] else
                              "inside" if s["mm"] <= s["margin_mm"] else "near"), s  # fmt: skip
    # The task line is drawn in its level's colour (green, amber or red) over the view.
    # (The screenshot comes before the status file's last write: the level may have changed.)
    band = shot[top : top + 80, left : left + WIDTH].astype(int)
    levels = [(120, 230, 120), (255, 200, 60), (255, 90, 90)]
    coloured = [(np.abs(band - c).max(axis=2) < 30).sum() for c in levels]
    assert max(coloured) > 50, f"no task line in a level's colour: {coloured}"
    with ambfplus.recording.open_recording(record) as rec:
        assert rec.steps["drill.fixture_force"].shape[1] == 3  # the fixtures' forces recorded
    live = json.loads(metrics.read_text())
    offline = assess(record, load_task(task_file)).data["metrics"]
    offline = json.loads(json.dumps({k: v for k, v in offline.items() if k != "removed_by_name"}))
    assert sum(live["removed_by_label"].values()) > 100, "the session drilled"
    assert_same(live, offline)
    assert report.is_file() and "Debrief: Ear drilling" in report.read_text()


def ear_task(fixtures, tmp_path, target: str, protect: list[str]):
    """A task on the original system's ear (the launch file's volume_256): its target (YAML
    text), each protected structure with a 1 mm margin."""
    ear = fixtures / "volumetric_drilling"
    task_file = tmp_path / "task.yaml"
    task_file.write_text(
        "version: 1\nname: Ear drilling\n"
        f"anatomy: {{file: {ear / 'ADF' / 'volume_256.yaml'}, labels: {ear / 'labels.csv'}}}\n"
        f"target: {target}\nprotect:\n"
        + "".join(f"  - {{structure: {name}, margin: 1.0}}\n" for name in protect)
    )
    return task_file


def assert_same(live, offline, path="metrics"):
    """Equal, floats to 1e-9 relative (sums of the same terms may round differently)."""
    if isinstance(live, dict):
        assert live.keys() == offline.keys(), path
        for key in live:
            assert_same(live[key], offline[key], f"{path}.{key}")
    elif isinstance(live, list):
        assert len(live) == len(offline), path
        for i, (a, b) in enumerate(zip(live, offline)):
            assert_same(a, b, f"{path}[{i}]")
    elif isinstance(live, float) and isinstance(offline, float):
        assert live == pytest.approx(offline, rel=1e-9, abs=1e-12), path
    else:
        assert live == offline, path


def test_the_overlay_shows_each_protected_structure_in_its_own_level():
    """The task's overlay draws every protected structure in its level's colour (green, amber,
    red): three structures clear, near and inside their margins give all three colours."""
    from ambfplus.launcher.status import Status, draw_overlay, level_of

    assert [level_of(5.0, 1.0), level_of(1.5, 1.0), level_of(0.5, 1.0)] == [
        "clear", "near", "inside"
    ]  # fmt: skip
    levels = {"clear": (120, 230, 120), "near": (255, 200, 60), "inside": (255, 90, 90)}

    def counts(structures):
        status = Status(task="T", nearest="a", nearest_mm=9.0, nearest_margin_mm=1.0,
                        structures=structures)  # fmt: skip
        image = draw_overlay(status, 640, 200)[..., :3].astype(int)
        return {k: int((np.abs(image - c).max(axis=2) < 30).sum()) for k, c in levels.items()}

    one = [{"name": "a", "mm": 9.0, "margin_mm": 1.0, "level": "clear"}]
    three = one + [
        {"name": "b", "mm": 1.5, "margin_mm": 1.0, "level": "near"},
        {"name": "c", "mm": 0.5, "margin_mm": 1.0, "level": "inside"},
    ]
    before, after = counts(one), counts(three)
    assert before["near"] == 0 and before["inside"] == 0, before
    assert after["near"] > 30 and after["inside"] > 30, after


@pytest.mark.slow
def test_plan_guidance_from_the_task_and_its_toggle(fixtures, tmp_path):
    """--plan stay / follow: the task's target region becomes the drill's plan (a fixture on
    its boundary, and with follow an attraction toward it); Ctrl+G turns both off and on,
    the plan's field kept. --plan needs --task."""
    from ambfplus.launcher.options import parse_args
    from ambfplus.launcher.session import LaunchSession

    launch_file = fixtures / "volumetric_drilling" / "launch.yaml"
    target = "{labels: [Bone], box: {min: [-10, -10, -10], max: [10, 10, 10]}}"
    task_file = ear_task(fixtures, tmp_path, target, ["Facial_Nerve"])

    def session_of(*options):  # the launch file's volume_256 ear and drill, as in launch()
        return LaunchSession(*parse_args([str(launch_file), "-l", "0,2", *options]))

    session = session_of("--task", str(task_file), "--plan", "follow")
    drill = session.drill
    target = session.task.target_mask(drill.volume.data)
    assert 0 < target.sum() < (np.asarray(drill.volume.data.labels) > 0).sum()
    assert drill.plan["voxels"] == int(target.sum()) and drill.plan["enabled"]
    assert drill.plan["stop"] == LaunchSession.PLAN_FIXTURE["stop"]
    assert drill.follows_plan == LaunchSession.PLAN_FOLLOW
    assert session.toggle_fixtures() is False
    assert not drill.plan["enabled"] and drill.follows_plan is None
    assert drill.plan["voxels"] == int(target.sum())
    assert session.toggle_fixtures() is True
    assert drill.plan["enabled"] and drill.follows_plan == LaunchSession.PLAN_FOLLOW
    session.finish()
    stay = session_of("--task", str(task_file), "--plan", "stay")
    assert stay.drill.plan["enabled"] and stay.drill.follows_plan is None
    stay.finish()
    with pytest.raises(SystemExit, match="--plan needs --task"):
        session_of("--plan", "stay")
