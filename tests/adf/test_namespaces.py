"""Namespaces as AMBF has them (issue #34): two model files reuse body and joint names under two
namespaces, one lists a block twice, and the world's stereo camera rides on a body of the later
model. Every object keeps its declared name and is addressable by its full name, by AMBF's
client key (``ns1/link``) and, where unique, by its bare name; nothing is renamed silently."""

from __future__ import annotations

import json
import logging
import textwrap
from pathlib import Path

import h5py
import numpy as np
import pytest

import ambfplus
from ambfplus.labels import legend as object_legend

BASELINE = 0.06  # m between the stereo camera's eyes, as the world file gives it
ARM_X = {"ns1": 0.0, "ns2": 0.5}


def arm(ns: str, *, twice: bool = False, namespace: bool = True) -> str:
    """A base and one link on a revolute joint, the same names in every file."""
    x, centre = ARM_X[ns], ARM_X[ns] + 0.1
    bodies = "[BODY base, BODY link, BODY link]" if twice else "[BODY base, BODY link]"
    header = f"namespace: /ambf/env/{ns}/\n" if namespace else ""
    return header + textwrap.dedent(
        f"""\
        bodies: {bodies}
        joints: [JOINT base-link]
        BODY base:
          name: base
          mass: 0.0
          shape: box
          geometry: {{x: 0.05, y: 0.05, z: 0.05}}
          location: {{position: {{x: {x}, y: 0.0, z: 0.5}}, orientation: {{r: 0, p: 0, y: 0}}}}
        BODY link:
          name: link
          mass: 0.5
          shape: box
          geometry: {{x: 0.2, y: 0.04, z: 0.04}}
          location: {{position: {{x: {centre}, y: 0.0, z: 0.5}}, orientation: {{r: 0, p: 0, y: 0}}}}
        JOINT base-link:
          name: base-link
          parent: BODY base
          child: BODY link
          parent pivot: {{x: 0.0, y: 0.0, z: 0.0}}
          child pivot: {{x: -0.1, y: 0.0, z: 0.0}}
          parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
          child axis: {{x: 0.0, y: 0.0, z: 1.0}}
          type: revolute
        """
    )


# The camera rides on the second arm's link (a model loaded after the world file) and looks
# back between the two arms; `location` and `look at` are in the link's frame.
WORLD = f"""\
gravity: {{x: 0.0, y: 0.0, z: 0.0}}
cameras: [CAMERA main]
CAMERA main:
  name: main
  parent: /ambf/env/ns2/BODY link
  location: {{x: -0.35, y: -1.2, z: 0.1}}
  look at: {{x: -0.35, y: 0.0, z: 0.0}}
  up: {{x: 0.0, y: 0.0, z: 1.0}}
  field view angle: 0.6
  publish image resolution: {{width: 160, height: 120}}
  stereo: {{mode: passive, eye separation: {BASELINE}}}
"""


def write_scene(folder: Path) -> Path:
    (folder / "arm_ns1.yaml").write_text(arm("ns1", twice=True))
    (folder / "arm_ns2.yaml").write_text(arm("ns2"))
    (folder / "world.yaml").write_text(WORLD)
    launch = folder / "launch.yaml"
    launch.write_text(
        "world config: world.yaml\ncolor config: colors.yaml\n"
        "input devices config: devices.yaml\nmultibody configs: [arm_ns1.yaml, arm_ns2.yaml]\n"
    )
    return launch


@pytest.fixture
def scene(tmp_path, caplog):
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        sim = ambfplus.Simulator.from_launch(write_scene(tmp_path), models=[0, 1], strict=True)
    return sim, tmp_path, caplog


def test_both_copies_keep_their_names_and_are_addressable(scene):
    sim, folder, caplog = scene
    assert sim.load_report.errors == []
    world = sim.world
    links = {ns: world.get(f"{ns}/link") for ns in ARM_X}
    assert links["ns1"].id != links["ns2"].id
    for ns, link in links.items():
        assert link.name == "link"  # the declared name, not "link1"
        assert link.key == f"{ns}/link"
        assert link.namespace == f"/ambf/env/{ns}/"
        assert link.qualified_name == f"/ambf/env/{ns}/link"
        # The full name and the key find the same object; so does the key as world[...].
        assert world.get(f"/ambf/env/{ns}/link").id == link.id
        assert world[f"{ns}/link"].id == link.id
        assert link.pose[0, 3] == pytest.approx(ARM_X[ns] + 0.1)
        joint = world.get(f"{ns}/base-link", kind="joint")
        assert joint.name == "base-link"
        assert (joint.parent.key, joint.child.key) == (f"{ns}/base", f"{ns}/link")
    # Nothing was renamed: every declared name is as the files give it.
    assert sorted(o.key for o in world.objects if o.kind in ("body", "joint")) == sorted(
        f"{ns}/{n}" for ns in ARM_X for n in ("base", "link", "base-link")
    )
    assert sorted({o.name for o in world.objects}) == sorted(
        {"base", "link", "base-link", "main", "main_left", "main_right"}
    )


def test_the_block_listed_twice_is_made_once_with_a_warning(scene):
    sim, folder, caplog = scene
    assert len([o for o in sim.world.objects if o.key == "ns1/link"]) == 1
    loaded = caplog.get_records("setup")
    assert not [r for r in loaded if "unknown key" in r.getMessage()]
    warned = [r.getMessage() for r in loaded if "again" in r.getMessage()]
    assert len(warned) == 1 and "arm_ns1.yaml" in warned[0] and "'BODY link'" in warned[0]


def test_an_ambiguous_bare_name_names_the_candidates(scene):
    sim, _, _ = scene
    with pytest.raises(ambfplus.NotFound, match=r"'link' is ambiguous.*ns1/link, ns2/link"):
        sim.world.get("link")
    with pytest.raises(KeyError):
        sim.world["link"]  # world[...] takes keys only
    # A bare name that one namespace alone has is found (the stereo camera's eyes, AMBF's
    # root namespace).
    assert sim.world.get("main_left").key == "main_left"
    with pytest.raises(ambfplus.ArgumentError, match=r"poses: 'link' is ambiguous"):
        sim.world.get("main_left").capture(passes=("rgb",), poses=["link"])


def test_the_stereo_camera_rides_on_the_later_models_body_with_its_baseline(scene):
    sim, _, _ = scene
    world = sim.world
    main, left, right = (world.get(n) for n in ("main", "main_left", "main_right"))
    assert main.attached_to is not None and main.attached_to.key == "ns2/link"
    baseline = np.linalg.norm(left.pose[:3, 3] - right.pose[:3, 3])
    assert baseline == pytest.approx(BASELINE, abs=1e-9)
    # The eyes sit either side of the camera along its x axis.
    x_axis = main.pose[:3, 0]
    assert (right.pose[:3, 3] - left.pose[:3, 3]) @ x_axis == pytest.approx(BASELINE, abs=1e-9)
    world.step(1)
    legend = object_legend(world)
    # The legend keeps declared names, and the key of each object under a namespace.
    keys = {entry.get("key", entry["name"]) for entry in legend.values()}
    assert {"ns1/link", "ns2/link", "ns1/base", "ns2/base"} <= keys
    assert {e["name"] for e in legend.values() if e.get("key") == "ns2/link"} == {"link"}
    for eye in (left, right):
        frame = eye.capture(passes=("rgb", "instance"), poses=["ns1/link", "/ambf/env/ns2/link"])
        assert frame.camera == eye.name
        # Poses asked for by key or full name come back under the key.
        assert set(frame.poses) == {"ns1/link", "ns2/link"}
        for key in ("ns1/link", "ns2/link"):
            np.testing.assert_allclose(frame.poses[key], world.get(key).pose, atol=1e-6)
        seen = {
            legend[int(i)].get("key", legend[int(i)]["name"])
            for i in np.unique(frame.instance)
            if int(i) in legend
        }
        # Both arms are in view of each eye: the camera sees the scene from the ridden link.
        assert {"ns1/link", "ns2/link"} <= seen, seen


def test_moving_an_object_to_a_taken_key_is_refused(scene):
    sim, _, _ = scene
    link = sim.world.get("ns1/link")
    with pytest.raises(ambfplus.ArgumentError, match="ns2/link"):
        link.namespace = "/ambf/env/ns2/"
    assert link.key == "ns1/link"
    link.namespace = "/ambf/env/ns3/"
    assert link.key == "ns3/link" and sim.world.get("ns3/link").id == link.id
    assert "ns1/link" not in sim.world


def test_the_same_name_twice_in_one_namespace_is_renamed_with_a_warning(tmp_path, caplog):
    (tmp_path / "arm.yaml").write_text(arm("ns1", namespace=False))
    world = ambfplus.World()
    world.load_adf(tmp_path / "arm.yaml")
    with caplog.at_level(logging.WARNING, logger="ambfplus"):
        world.load_adf(tmp_path / "arm.yaml")
    assert sorted(o.key for o in world.bodies) == ["base", "base1", "link", "link1"]
    warned = [
        r.getMessage()
        for r in caplog.records
        if "the same name in the same namespace" in r.getMessage()
    ]
    assert len(warned) >= 2 and all("arm.yaml" in w for w in warned), warned


def test_exports_name_frames_and_categories_by_key(scene, tmp_path):
    # A recording of the scene: COCO categories and TF frames carry the namespaced names.
    pytest.importorskip("mcap_ros2")
    pytest.importorskip("pycocotools")
    from mcap.reader import make_reader
    from mcap_ros2.decoder import DecoderFactory

    from ambfplus.export import export
    from ambfplus.recording import Recorder, open_recording

    sim, _, _ = scene
    world, left = sim.world, sim.world.get("main_left")
    path = tmp_path / "ns.h5"
    world.start_step_log([world.get("ns1/link"), world.get("ns2/link")])
    with Recorder(path) as rec:
        rec.set_legend(world)
        for _ in range(3):
            world.step(5)
            rec.add_frame("main_left", left.capture(passes=("rgb", "depth", "instance")))
            rec.add_steps(world.take_step_log())
    world.stop_step_log()
    # Step-log columns are named by keys, and come back so from the recording (HDF5 stores
    # the '/' escaped).
    with open_recording(path) as rec:
        steps = rec.steps
        for key in ("ns1/link", "ns2/link"):
            np.testing.assert_allclose(steps[f"{key}.pose"][-1], world.get(key).pose, atol=1e-12)
    export(path, tmp_path / "coco", "coco", progress=False)
    document = json.loads((tmp_path / "coco" / "main_left.json").read_text())
    categories = {c["name"] for c in document["categories"]}
    assert {"ns1/link", "ns2/link", "ns1/base", "ns2/base"} <= categories
    export(path, tmp_path / "ns.mcap", "mcap", progress=False)
    frames = set()
    with open(tmp_path / "ns.mcap", "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, _, _, message in reader.iter_decoded_messages(topics=["/tf"]):
            frames.update(t.child_frame_id for t in message.transforms)
    assert {"ns1/link", "ns2/link"} <= frames and "link" not in frames
    # The original system's layout has no namespaces: the two links by their keys, '_' for '/'.
    export(path, tmp_path / "orig.h5", "original-h5", progress=False)
    (written,) = (tmp_path / "orig.h5").glob("*.hdf5")
    with h5py.File(written) as f:
        poses = f["physics_data/continuous_data/high_frequency_poses"]
        assert {"ns1_link_pose", "ns2_link_pose"} <= set(poses)
        assert {"pose_ns1_link", "pose_ns2_link"} <= set(f["vision_data/continuous_data"])


def test_a_reference_resolves_within_its_files_namespace_first(tmp_path):
    # A later file under ns2 hangs a light on "BODY link": ns2's, though ns1 has a link too.
    launch = write_scene(tmp_path)
    (tmp_path / "lamp.yaml").write_text(
        "namespace: /ambf/env/ns2/\nlights: [LIGHT lamp]\n"
        "LIGHT lamp: {name: lamp, parent: BODY link, location: {x: 0, y: 0, z: 0.2}}\n"
    )
    sim = ambfplus.Simulator.from_launch(launch, models=[0, 1], extra=[tmp_path / "lamp.yaml"],
                                         strict=True)  # fmt: skip
    lamp = sim.world.get("ns2/lamp")
    assert lamp.attached_to is not None and lamp.attached_to.key == "ns2/link"


def test_the_ambf_client_keys_and_finds_objects_as_ambf_does(scene, capsys):
    from ambfplus.ambf_client import Client

    sim, _, _ = scene
    client = Client(simulator=sim)
    names = client.get_obj_names()
    assert {"ns1/link", "ns2/link", "ns1/base", "main_left"} <= set(names)
    assert not [n for n in names if n.endswith("base-link")]  # joints have no topic in AMBF
    assert client.get_obj_handle("ns2/link").get_name() == "/ambf/env/ns2/link"
    # A unique part of a key finds it; a part two keys hold lists them and finds nothing.
    assert client.get_obj_handle("s1/li").get_name() == "/ambf/env/ns1/link"
    assert client.get_obj_handle("link") is None
    assert "ns1/link, ns2/link" in capsys.readouterr().out
    # Full names and ADF blocks still work.
    assert client.get_obj_handle("/ambf/env/ns2/base").get_name() == "/ambf/env/ns2/base"
