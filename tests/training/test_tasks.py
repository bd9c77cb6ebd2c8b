"""Training tasks: the shipped tasks load and name structures of the phantom; bad tasks are
refused with the file and the key; a task on the original system's ear (fixture)."""

from __future__ import annotations

import re

import numpy as np
import pytest

import ambfplus
from ambfplus.training import BUILTIN_TASKS, TaskError, builtin_task, load_task

GOOD = {
    "version": 1,
    "name": "test",
    "anatomy": {"phantom": {"resolution": 32, "seed": 0}},
    "target": {"labels": ["Bone"], "box": {"min": [-5, -5, 0], "max": [5, 5, 20]}},
    "protect": [{"structure": "Facial_Nerve", "margin": 1.0}],
    "expose": [{"structure": "Sinus_+_Dura", "thickness": 0.5}],
    "burrs": [2, 4],
    "time_limit": 300,
}


@pytest.mark.parametrize("name", BUILTIN_TASKS)
def test_builtin_tasks_name_structures_of_the_phantom(name):
    task = builtin_task(name)
    data = task.anatomy_data()
    labels = np.asarray(data.labels)
    for structure in task.protect + task.expose:
        ids = task.label_ids(data, structure)
        assert ids and all((labels == i).any() for i in ids), structure.name
    target = task.target_mask(data)
    assert target.sum() > 100
    assert set(np.unique(labels[target])) == {1}  # bone only, inside its box
    # The target keeps clear of every protected structure by more than its margin.
    for p in task.protect:
        inside = np.isin(labels, task.label_ids(data, p))
        field = ambfplus.DistanceField(data, task.label_ids(data, p), 0.01).values()
        assert field[target].min() > p.length, p.name
        assert not (inside & target).any()


def test_a_task_file_round_trips_its_values_in_metres(tmp_path):
    import yaml

    path = tmp_path / "task.yaml"
    path.write_text(yaml.safe_dump(GOOD))
    task = load_task(path)
    assert task.protect[0].length == pytest.approx(0.001)
    assert task.expose[0].length == pytest.approx(0.0005)
    assert task.expose[0].reach == pytest.approx(0.002)  # the default
    assert task.burrs == pytest.approx([0.002, 0.004])
    assert task.target["box"][0][0] == pytest.approx([-0.005, -0.005, 0.0])
    assert task.text == path.read_text()
    mask = task.target_mask(task.anatomy_data())
    centres = np.argwhere(mask)
    assert len(centres)
    size = 0.048 / 32
    x = (centres[:, 0] + 0.5) * size - 0.024
    assert x.min() >= -0.005 and x.max() <= 0.005


@pytest.mark.parametrize(
    ("change", "key"),
    [
        ({"version": 2}, "version"),
        ({"protect": [{"structure": "Facial_Nerve", "margn": 1}]}, "protect[0].margn"),
        ({"protect": [{"structure": "Facial_Nerve"}]}, "protect[0].margin"),
        ({"protect": [{"structure": "Facial_Nerve", "margin": -1}]}, "protect[0].margin"),
        ({"protect": [{"structure": 1.5, "margin": 1}]}, "protect[0].structure"),
        ({"target": {"labels": ["Bone"], "mask": "x.nrrd"}}, "target"),
        (
            {"target": {"labels": ["Bone"], "box": {"min": [0, 0, 5], "max": [1, 1, 5]}}},
            "target.box.max",
        ),
        ({"target": {"references": []}}, "target.references"),
        ({"burrs": [-1]}, "burrs[0]"),
        ({"thresholds": {"min_visibility": 2}}, "thresholds.min_visibility"),
        ({"thresholds": {"min_visibilty": 0.5}}, "thresholds.min_visibilty"),
        ({"anatomy": {"phantom": {"resolution": 4}}}, "anatomy.phantom.resolution"),
        ({"anatomy": {"file": "nowhere.nrrd"}}, "anatomy.file"),
        ({"time_limit": 0}, "time_limit"),
    ],
)
def test_bad_tasks_name_the_key(change, key):
    with pytest.raises(TaskError, match="<task>: " + re.escape(key)):
        load_task({**GOOD, **change})


def test_unknown_structures_name_the_key_and_the_labels():
    task = load_task({**GOOD, "protect": [{"structure": "Facial_Nerve", "margin": 1},
                                          {"structure": "Facial nerve", "margin": 1}]})  # fmt: skip
    with pytest.raises(TaskError, match=r"protect\[1\]\.structure.*'Facial nerve'.*Facial_Nerve"):
        task.protect_config(task.anatomy_data())


def test_bad_yaml_names_the_line(tmp_path):
    path = tmp_path / "broken.yaml"
    path.write_text("version: 1\nname: x\nanatomy: {phantom: {resolution: 32}\n")
    with pytest.raises(TaskError, match=r"broken.yaml: not valid YAML \(line 4"):
        load_task(path)
    with pytest.raises(TaskError, match="no such task file"):
        load_task(tmp_path / "missing.yaml")


def test_a_task_on_the_original_systems_ear(fixtures, tmp_path):
    """A task over the fixture ear (volume ADF + label names): its structures resolve by the
    names the original system gives them."""
    ear = fixtures / "volumetric_drilling"
    path = tmp_path / "ear_task.yaml"
    path.write_text(
        "version: 1\nname: Ear mastoidectomy\n"
        f"anatomy: {{file: {ear / 'ADF' / 'volume_171.yaml'}, labels: {ear / 'labels.csv'}}}\n"
        "target: {labels: [Bone], box: {min: [-20, -20, 0], max: [20, 20, 40]}}\n"
        "protect:\n  - {structure: Facial_Nerve, margin: 1.0}\n"
        "  - {structure: [Sinus_+_Dura], margin: 0.5, name: Sinus and dura}\n"
        "expose:\n  - {structure: Sinus_+_Dura, thickness: 1.0}\n"
    )
    task = load_task(path)
    data = task.anatomy_data()
    config = task.protect_config(data)
    names = {label.id: label.name for label in data.label_table}
    assert [names[i] for i in config[0]["labels"]] == ["Facial_Nerve"]
    assert config[1]["name"] == "Sinus and dura"
    assert task.target_mask(data).any()
