"""Assessment of recorded sessions: clear cases (a breach is flagged with the structure, time
and voxel count; a careful session has no violation), burr visibility by a depth test against
real renders, cavities against references and analytic masks, exposure of a structure under
a slab of known thickness, the command line, the debrief report in Chromium, and cohorts."""

from __future__ import annotations

import csv
import json
import re

import numpy as np
import pytest
from helpers.browser import chromium

import ambfplus
from ambfplus.cli import main
from ambfplus.scenes import drilling_phantom, record_session
from ambfplus.training import (
    TaskError,
    assess,
    burr_visible,
    compare_cavities,
    expert_like,
    exposure,
    load_task,
    novice_like,
    record_trainee,
)
from ambfplus.training.cohort import assess_cohort, write_group_report, write_table

RESOLUTION = 128
TASK = {
    "version": 1,
    "name": "Small mastoidectomy",
    "anatomy": {"phantom": {"resolution": RESOLUTION, "seed": 0}},
    "target": {"labels": ["Bone"], "box": {"min": [-10, -8, 9], "max": [1, 8, 15]}},
    "protect": [
        {"structure": "Facial_Nerve", "margin": 1.0},
        {"structure": "Sinus_+_Dura", "margin": 0.5},
    ],
    "expose": [{"structure": "Sinus_+_Dura", "thickness": 1.0}],
    "burrs": [4, 6],
    "time_limit": 60,
    # A 10 s session removes a few percent of any target: completion is not judged here.
    "thresholds": {"min_target_fraction": 0.0},
}
SECONDS = 10.0
FACIAL_NERVE = 10  # the phantom's label id (the original system's)


@pytest.fixture(scope="module")
def sessions(tmp_path_factory):
    """An expert-like and a novice-like recording of the small task, with depth frames."""
    folder = tmp_path_factory.mktemp("sessions")
    task = load_task(TASK)
    paths = {}
    for name, make in (("expert", expert_like), ("novice", novice_like)):
        paths[name] = folder / f"{name}.h5"
        record_trainee(make, 3, SECONDS, paths[name], task, capture_every=100,
                       passes=("rgb", "depth", "label"), width=160, height=120)  # fmt: skip
    return task, paths


class Plunge:
    """A hand that moves 20 mm back from a point along the drill's shaft (above the lateral
    surface), then plunges the spinning burr to it along the shaft (so that the shaft follows
    the hole)."""

    def __init__(self, drill_pose, point, speed=0.004):
        self.start, self.point, self.speed = drill_pose[:3, 3], np.asarray(point), speed
        self.axis = drill_pose[:3, 0]  # the shaft, from the burr up
        self.above = self.point + 0.020 * self.axis

    def __call__(self, t):
        if t < 0.5:
            p = self.start + (self.above - self.start) * t / 0.5
            return {"position": tuple(p - self.start), "buttons": 0}
        depth = min((t - 0.5) * self.speed, 0.020)
        p = self.above - depth * self.axis
        return {"position": tuple(p - self.start), "buttons": 1}


@pytest.mark.slow
def test_a_breach_of_the_facial_nerve_is_flagged(tmp_path, sessions):
    task, _ = sessions
    scene = drilling_phantom(resolution=RESOLUTION, width=160, height=120)
    scene.drill.burr = 2  # the 4 mm burr: through 17 mm of mastoid to the nerve in time
    data = scene.drill.volume.data
    labels = np.asarray(data.labels)
    nerve = np.argwhere(labels == FACIAL_NERVE)
    top = nerve[np.argmax(nerve[:, 2])]  # the nerve's highest voxel, under the lateral face
    point = np.array(data.voxel_center(*top)) - np.array([0, 0, 0.001])
    device = ambfplus.ScriptedDevice()
    device.set_callback(Plunge(np.array(scene.drill.pose), point), every=10)
    path = tmp_path / "breach.h5"
    record_session(scene, path, device, 8.0, capture_every=200, passes=("depth",))
    result = assess(path, task)
    breaches = [v for v in result.data["violations"] if v["kind"] == "breach"]
    assert [b["structure"] for b in breaches] == ["Facial_Nerve"]
    nerve_cut = result.data["metrics"]["removed_by_label"][FACIAL_NERVE]
    assert breaches[0]["voxels"] == nerve_cut > 0
    # The time is when the first nerve voxel went, as the recording's removed voxels say.
    with ambfplus.recording.open_recording(path) as rec:
        removed, steps = rec.removed, rec.steps
    first = int(removed["step"][np.flatnonzero(removed["label"] == FACIAL_NERVE)[0]])
    assert breaches[0]["step"] == first
    assert breaches[0]["time"] == pytest.approx(
        steps["time"][np.searchsorted(steps["step"], first)]
    )
    item = next(i for i in result.data["rubric"] if i["key"] == "no_breach:Facial_Nerve")
    assert item["passed"] is False and item["value"] == nerve_cut


def test_a_careful_session_has_no_violation_and_outscores_a_novice(sessions):
    task, paths = sessions
    expert, novice = assess(paths["expert"], task), assess(paths["novice"], task)
    assert expert.data["violations"] == []
    assert all(i["passed"] for i in expert.data["rubric"] if i["key"].startswith("no_breach"))
    assert expert.score > novice.score
    e, n = expert.data["metrics"], novice.data["metrics"]
    assert e["cutting_force_p95"] < n["cutting_force_p95"]
    assert expert.data["target"]["outside_fraction"] < novice.data["target"]["outside_fraction"]
    # The expert cuts with the task's largest burr; visibility is measured.
    assert expert.data["burrs_cutting"] == [0.006]
    assert expert.data["visibility"]["fraction"] > 0.8  # its own shaft does not hide it


def test_the_task_must_be_of_the_recordings_anatomy(sessions):
    _, paths = sessions
    other = load_task({**TASK, "anatomy": {"phantom": {"resolution": 32, "seed": 0}}})
    with pytest.raises(TaskError, match="is not the anatomy"):
        assess(paths["expert"], other)


def test_a_session_is_its_own_perfect_reference(sessions):
    task, paths = sessions
    result = assess(paths["novice"], task, references=[paths["novice"], paths["expert"]])
    same, other = result.data["references"]
    assert same["dice"] == pytest.approx(1.0)
    assert same["over"] == same["under"] == same["surface_max"] == 0.0
    assert other["dice"] < 0.9 and other["over"] > 0 and other["surface_mean"] > 0


def test_cavity_comparison_against_analytic_masks():
    """Two 10-voxel cubes offset by 2 voxels along x: Dice 2*80/200, over = under = 20 voxels
    of volume, and surface distances of 0..2 voxels."""
    shape, voxel = (30, 30, 30), 0.001
    a = np.zeros(shape, bool)
    b = np.zeros(shape, bool)
    a[5:15, 5:15, 5:15] = True
    b[7:17, 5:15, 5:15] = True
    labels = np.ones(shape, np.uint16)
    protected = np.full(shape, 1.0)
    result = compare_cavities(a, b, labels, voxel**3, np.array(shape) * voxel, protected=protected)
    assert result["dice"] == pytest.approx(2 * 800 / 2000)
    assert result["over"] == pytest.approx(200 * voxel**3)
    assert result["under"] == pytest.approx(200 * voxel**3)
    assert result["over_weighted"] == pytest.approx(result["over"])  # far from any structure
    assert result["surface_max"] == pytest.approx(2 * voxel, abs=1e-6)
    # Over-drilling next to a protected structure weighs up to 5 times as much.
    near = np.where(a & ~b, 0.0, 1.0)
    close = compare_cavities(a, b, labels, voxel**3, np.array(shape) * voxel, protected=near)
    assert close["over_weighted"] == pytest.approx(5 * result["over"])


def test_residual_thickness_over_a_structure_under_a_slab():
    """A structure (z < 10) under bone up to z = 20, drilled down to leave 3 voxels of bone over
    part of it: thickness 3 voxels there, exposed once it is under the target thickness."""
    n, voxel = 24, 0.0005
    labels = np.zeros((n, n, n), np.uint16)
    labels[:, :, :20] = 1
    labels[:, :, :10] = 2
    structure = labels == 2
    target = np.zeros_like(structure)
    target[6:18, 6:18, 13:20] = True  # drilled away: leaves z = 10, 11, 12 over the structure
    final = labels.copy()
    final[target] = 0
    dims = np.full(3, n * voxel)
    thin = exposure(final, structure, target, dims, thickness=3.5 * voxel, reach=5 * voxel)
    thick = exposure(final, structure, target, dims, thickness=2.5 * voxel, reach=5 * voxel)
    under = structure[6:18, 6:18, 9]  # the surface voxels straight under the cavity
    assert thin["thickness_min"] == pytest.approx(3 * voxel)
    assert thin["exposed_fraction"] >= under.sum() / thin["surface_voxels"]
    assert thick["exposed_fraction"] == 0.0


def test_burr_visibility_behind_a_bone_plate(tmp_path):
    """The burr under the phantom's lateral face is hidden by the bone above it, and visible once
    a channel above it is drilled away: real renders of the surgeon camera's depth."""
    scene = drilling_phantom(resolution=RESOLUTION, width=160, height=120)
    camera, drill = scene.rig.left, scene.drill
    data = drill.volume.data
    below = np.array([0.0, 0.0, 0.008])  # the burr's centre 4.6 mm under the surface
    pose = np.array(drill.pose)
    pose[:3, 3] = below
    drill.pose = pose
    radius = drill.burr_radius

    def seen(labels: bool):
        frame = camera.capture(passes=["depth", "label"])
        return burr_visible(frame.depth, camera.intrinsics, camera.pose, below, radius,
                            label=frame.label if labels else None)  # fmt: skip

    assert not seen(False) and not seen(True)
    # Drill a wide channel from the surface down to the burr, toward the camera.
    eye = np.array(camera.pose)[:3, 3]
    direction = (eye - below) / np.linalg.norm(eye - below)
    for s in np.arange(0.0, 0.012, 0.0005):
        data.remove_sphere(below + direction * (s + radius), 0.0045)
    assert seen(False) and seen(True)


@pytest.mark.slow
def test_the_command_line_writes_json_and_a_report_chromium_shows(sessions, tmp_path):
    task, paths = sessions
    task_file = tmp_path / "task.yaml"
    import yaml

    task_file.write_text(yaml.safe_dump(TASK))
    out_json, out_html = tmp_path / "a.json", tmp_path / "a.html"
    code = main(["assess", str(paths["novice"]), "--task", str(task_file),
                              "--reference", str(paths["expert"]), "--json", str(out_json),
                              "--report", str(out_html)])  # fmt: skip
    assert code == 0
    data = json.loads(out_json.read_text())
    assert data["task"]["name"] == "Small mastoidectomy"
    assert data["references"][0]["recording"] == str(paths["expert"])
    page = out_html.read_text()
    assert "http://" not in page.replace("http://www.w3.org/2000/svg", "")  # nothing fetched
    with chromium(tmp_path / "profile") as browser:
        opened = browser.open(out_html.as_uri())
        assert opened["errors"] == [] and opened["title"] == "Debrief: Small mastoidectomy"
        assert opened["images"] == 4  # the surgeon's view and three standard views
        shot = browser.screenshot(tmp_path / "report.png")
    from PIL import Image

    image = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    assert image.std() > 20  # a rendered page, not a blank one
    # The views show the over-drilled (red) voxels the novice left.
    assert ((image[..., 0] > 180) & (image[..., 1] < 80) & (image[..., 2] < 80)).sum() > 50


@pytest.mark.slow
def test_a_cohort_table_and_group_report(sessions, tmp_path):
    task, paths = sessions
    table = tmp_path / "cohort.csv"
    with table.open("w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["session", "participant", "group", "date"])
        w.writerow([paths["novice"], "ana", "resident", "2026-01-01"])
        w.writerow([paths["expert"], "ana", "resident", "2026-02-01"])
        w.writerow([paths["expert"], "bo", "attending", "2026-01-15"])
    rows = assess_cohort(table, task)
    assert [r["participant"] for r in rows] == ["ana", "ana", "bo"]
    assert rows[1]["score"] == rows[2]["score"] > rows[0]["score"]
    written = write_table(rows, tmp_path / "out" / "metrics.csv")
    with written[0].open() as f:
        back = list(csv.DictReader(f))
    assert float(back[0]["score"]) == pytest.approx(rows[0]["score"])
    page = write_group_report(rows, tmp_path / "out" / "report.html").read_text()
    assert page.count("<polyline") >= 2 and "attending" in page
    bad = tmp_path / "bad.csv"
    bad.write_text("session,participant,date\nx.h5,a,2026\n")
    with pytest.raises(ValueError, match="bad.csv: the CSV has no column 'group'"):
        assess_cohort(bad, task)


@pytest.mark.slow
def test_every_kind_of_recording_is_assessed(sessions, reference_dataset, tmp_path):
    """A replay (the same removal, so the same metrics), a dataset episode and the demo."""
    from ambfplus.cli.demo import run_demo
    from ambfplus.scenes import replay

    task, paths = sessions
    replayed = tmp_path / "replay.h5"
    replay(paths["novice"], out=replayed, compare_images=False)
    original, again = assess(paths["novice"], task), assess(replayed, task)
    assert again.data["session"]["kind"] == "replay"
    assert again.data["metrics"] == original.data["metrics"]
    episode = sorted(reference_dataset.glob("shards/episode_*.h5"))[0]
    result = assess(episode)  # no task: every critical structure protected by 1 mm
    assert result.data["session"]["kind"] == "dataset episode"
    assert result.data["metrics"]["ticks"] > 0 and result.data["metrics"]["structures"]
    assert run_demo(tmp_path / "demo", 160, 120, 128, 200) == 0
    demo = json.loads((tmp_path / "demo" / "assessment.json").read_text())
    assert demo["session"]["kind"] == "demo" and demo["task"]["name"] == "Cortical mastoidectomy"
    assert (tmp_path / "demo" / "debrief.html").stat().st_size > 10000


def test_the_command_line_says_what_is_wrong(sessions, tmp_path, capsys):
    """Each mistake: status 2 and one line on stderr naming it (the CLI's one error path)."""
    _, paths = sessions

    def refused(args, message):
        assert main(args) == 2
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
        assert re.search(message, err), err

    refused(["assess", str(tmp_path / "none.h5")],
            r"ambfplus assess: .*none.h5: no such recording file")  # fmt: skip
    refused(["assess", str(paths["expert"]), "--task", "cortical"],
            "no built-in task of that name.*cortical_mastoidectomy")  # fmt: skip
    other = tmp_path / "other.yaml"
    other.write_text("version: 1\nname: x\nanatomy: {phantom: {resolution: 64}}\n"
                     "target: {labels: [Bone]}\n")  # fmt: skip
    refused(["assess", str(paths["expert"]), "--task", str(other)],
            "other.yaml: the task's anatomy .* is not the anatomy")  # fmt: skip


def test_columns_are_read_part_by_part_as_whole_columns_are(sessions):
    _, paths = sessions
    with ambfplus.recording.open_recording(paths["novice"]) as rec:
        assert len(rec.parts) > 1
        names = ["step", "drill.pose", "drill.on"]
        some = rec.read_columns("steps", names)
        for name in names:
            np.testing.assert_array_equal(some[name], rec.steps[name])
        with pytest.raises(KeyError, match="steps has no column 'drill.nothing'"):
            rec.read_columns("steps", ["drill.nothing"])
