"""The original layout's descriptive attributes written whole, and COCO anatomy categories taken
from the volume's label table: one per structure the frames show, each annotation's category the
label of its pixels."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import h5py
import numpy as np
import pytest

import ambfplus
from ambfplus.recording import Recorder, open_recording
from ambfplus.scenes import drilling_phantom, orbit_view, record_session

pytest.importorskip("pycocotools", reason='needs pip install "ambfplus[export]"')

from ambfplus.export import export  # noqa: E402

# pycocotools 2.0.11 warns under NumPy 2 when decoding; the masks are right.
pytestmark = pytest.mark.filterwarnings("ignore:__array__ implementation:DeprecationWarning")


@pytest.fixture(scope="module")
def session(tmp_path_factory) -> Path:
    """0.6 s of the phantom at 160x120: the burr plunges into the bone while the rig circles;
    a stereo frame every 100 steps."""
    path = tmp_path_factory.mktemp("session") / "s.h5"
    scene = drilling_phantom(resolution=64, width=160, height=120)
    surface = scene.drill.volume.raycast((0.0, 0.0, 0.05), (0.0, 0.0, -1.0))["position"]
    down = surface[2] + scene.drill.burr_radius - 0.002 - scene.drill.goal[2, 3]
    device = ambfplus.ScriptedDevice()
    device.set_waypoints([
        {"time": 0.0, "position": (0, 0, 0)},
        {"time": 0.2, "position": (0, 0, down + 0.004), "buttons": 1},
        {"time": 0.6, "position": (0, 0, down), "buttons": 1},
    ])  # fmt: skip
    summary = record_session(scene, path, device, seconds=0.6, capture_every=100,
                             camera_motion=orbit_view)  # fmt: skip
    assert summary["voxels_removed"] > 0 and summary["frames"] == 6
    return path


# Original layout -------------------------------------------------------------------------------


def test_original_layout_describes_itself_in_full_sentences(session, tmp_path):
    out = tmp_path / "original"
    result = export(session, out, "original-h5", chunk_size=4, progress=False)
    assert len(result.details["files"]) == 2
    for name in result.details["files"]:
        with h5py.File(out / Path(name).name, "r") as f:
            attrs = f["ambfplus"].attrs
            layout, poses = str(attrs["layout"]), str(attrs["camera_poses"])
        assert layout == (
            "volumetric_drilling data_record v3 (metadata_v3, vision_data, physics_data)"
        )
        assert poses == (
            "pose_main_camera and camera high-frequency poses are "
            "T_world_ambf_camera = T_world_cv @ T_cv_ambf (camera_extrinsic)"
        )
        assert layout.endswith("physics_data)") and poses.endswith("(camera_extrinsic)")


# COCO ------------------------------------------------------------------------------------------


def label_table(rec) -> tuple[int, dict[int, str]]:
    """The recording's one volume: its id and its label names by id."""
    [(volume_id, entry)] = [(i, e) for i, e in rec.legend.items() if e["kind"] == "volume"]
    return volume_id, {int(k): v["name"] for k, v in entry["labels"].items()}


def test_coco_anatomy_categories_are_the_labels_the_frames_show(session, tmp_path):
    from pycocotools.coco import COCO

    out = tmp_path / "coco"
    export(session, out, "coco", progress=False)
    with open_recording(session) as rec:
        volume_id, names = label_table(rec)
        shown = set()
        for stream in rec.cameras.values():
            for index in range(len(stream)):
                frame = stream[index]
                on_volume = frame.instance == volume_id
                assert np.all(frame.label[on_volume] > 0)  # every volume pixel has a label
                shown |= {int(v) for v in np.unique(frame.label[on_volume])}
        assert len(shown) >= 2
        expected = {names[label] for label in shown}
        lists = []
        for name, stream in rec.cameras.items():
            document = json.loads((out / f"{name}.json").read_text())
            lists.append(document["categories"])
            anatomy = [c for c in document["categories"] if c["supercategory"] == "anatomy"]
            # One category per structure shown, named after its label; no catch-all.
            assert sorted(c["name"] for c in anatomy) == sorted(expected)
            assert {c["label_id"] for c in anatomy} == shown
            assert not [c for c in document["categories"] if c["supercategory"] == "volume"]
            assert "anatomy" not in expected and "anatomy" not in {
                c["name"] for c in document["categories"]
            }
            coco = COCO(str(out / f"{name}.json"))
            categories = {c["id"]: c for c in coco.loadCats(coco.getCatIds())}
            for index in range(len(stream)):
                frame = stream[index]
                covered = np.zeros(frame.label.shape, bool)
                for annotation in coco.loadAnns(coco.getAnnIds(imgIds=index + 1)):
                    if annotation["instance_id"] != volume_id:
                        continue
                    mask = coco.annToMask(annotation).astype(bool)
                    labels = np.unique(frame.label[mask])
                    # The category is the label of every pixel of its mask.
                    assert labels.tolist() == [annotation["label_id"]]
                    category = categories[annotation["category_id"]]
                    assert category["name"] == names[annotation["label_id"]]
                    assert category["label_id"] == annotation["label_id"]
                    covered |= mask
                assert np.array_equal(covered, frame.instance == volume_id)
        assert all(categories == lists[0] for categories in lists)


def test_coco_unlabelled_volume_pixels_are_named_and_warned(tmp_path):
    """A recording whose volume pixels include label 0 (as renders before #35 had): those
    pixels take a category named after the volume, with a warning; labelled ones their label's."""
    legend = {
        1: {"name": "ear", "kind": "volume", "labels": {
            1: {"name": "Bone", "color": [230, 220, 200]},
            3: {"name": "Facial_Nerve", "color": [250, 5, 9]},
            4: {"name": "Cochlea", "color": [5, 250, 9]}}},
        2: {"name": "ball", "kind": "body", "color": [10, 20, 30]},
    }  # fmt: skip
    instance = np.array([[1, 1, 1, 2], [1, 1, 0, 2]], np.int32)
    label = np.array([[1, 3, 0, 0], [3, 1, 0, 0]], np.uint16)
    path = tmp_path / "t.h5"
    with Recorder(path) as recorder:
        recorder.set_legend(legend)
        recorder.add_frame("cam", SimpleNamespace(
            camera="cam", time=0.001, step=1, pose=np.eye(4),
            intrinsics=np.array([[2.0, 0, 2], [0, 2.0, 1], [0, 0, 1]]),
            instance=instance, label=label,
        ))  # fmt: skip
    result = export(path, tmp_path / "coco", "coco", progress=False)
    document = json.loads((tmp_path / "coco" / "cam.json").read_text())
    by_id = {c["id"]: c for c in document["categories"]}
    assert sorted((c["name"], c["supercategory"]) for c in by_id.values()) == [
        ("Bone", "anatomy"), ("Facial_Nerve", "anatomy"), ("ball", "body"), ("ear", "volume"),
    ]  # fmt: skip
    named = {(a["instance_id"], a["label_id"]): by_id[a["category_id"]]["name"]
             for a in document["annotations"]}  # fmt: skip
    assert named == {(1, 0): "ear", (1, 1): "Bone", (1, 3): "Facial_Nerve", (2, 0): "ball"}
    assert any("ear has pixels without a label" in w for w in result.details["warnings"])
