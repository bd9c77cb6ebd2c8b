"""Volumes and drills of one file that need an object of a file loaded later (AMBF's modular
parenting): a volume's `parent` body, a drill's `volume`; through a launch and through
world.load_adf called later."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def slices(folder: Path, n: int = 8) -> None:
    """An n^3 slab (bone below its middle), 1 mm voxels, as a slice stack in folder/slab."""
    grid = np.zeros((n, n, n), np.uint8)
    grid[:, :, : n // 2] = 1
    data = ambfplus.VolumeData(
        grid, voxel_size=(0.001,) * 3, label_table=[ambfplus.Label(1, "Bone")]
    )
    data.save_slice_stack(folder / "slab")
    ambfplus.write_label_table(folder / "slab" / "labels.csv", data.label_table)


VOLUME_ON_BASE = """
    volumes: [VOLUME slab]
    VOLUME slab:
      name: slab
      parent: BODY base
      location: {position: {x: 0.01, y: -0.02, z: 0.03}, orientation: {r: 0.2, p: -0.1, y: 0.4}}
      dimensions: {x: 0.008, y: 0.008, z: 0.008}
      images: {path: slab/, prefix: plane00, format: png, count: 8}
      labels: slab/labels.csv
    """

BASE = """
    bodies: [BODY base]
    BODY base:
      name: base
      mass: 0.0
      shape: box
      geometry: {x: 0.05, y: 0.05, z: 0.05}
      location: {position: {x: 0.3, y: 0.1, z: 0.2}, orientation: {r: 0.0, p: 0.5, y: -0.3}}
    """

DRILL_ON_SLAB = """
    drills: [DRILL burr]
    DRILL burr:
      name: burr
      volume: VOLUME slab
      cursors: 2
    """


def launch(folder: Path, models: list[str]) -> Path:
    write(folder, "world.yaml", "gravity: {x: 0.0, y: 0.0, z: -9.8}\n")
    return write(
        folder,
        "launch.yaml",
        f"""
        world config: world.yaml
        color config: colors.yaml
        input devices config: devices.yaml
        multibody configs: [{", ".join(models)}]
        """,
    )


def local_pose(parent, child) -> np.ndarray:
    return np.linalg.inv(parent.pose) @ child.pose


def expected_local() -> np.ndarray:
    return ambfplus.make_pose((0.01, -0.02, 0.03), rpy=(0.2, -0.1, 0.4))


def test_a_volume_rides_on_a_body_of_a_file_loaded_later(tmp_path):
    slices(tmp_path)
    write(tmp_path, "volume.yaml", VOLUME_ON_BASE)
    write(tmp_path, "base.yaml", BASE)
    sim = ambfplus.Simulator.from_launch(
        launch(tmp_path, ["volume.yaml", "base.yaml"]), models=[0, 1], strict=True
    )
    assert sim.load_report.errors == []
    assert not [w for w in sim.load_report.warnings if "parent" in w[1]], sim.load_report.warnings
    world = sim.world
    base, volume = world.get("base"), world.get("slab")
    assert volume.attached_to is not None and volume.attached_to.name == "base"
    # `location` is in the parent's frame, as when both are in one file.
    np.testing.assert_allclose(local_pose(base, volume), expected_local(), atol=1e-12)
    write(tmp_path, "together.yaml", BASE + VOLUME_ON_BASE)
    same = ambfplus.World()
    same.load_adf(tmp_path / "together.yaml")
    np.testing.assert_allclose(volume.pose, same.get("slab").pose, atol=1e-12)
    # It follows the body.
    moved = ambfplus.make_pose((-0.2, 0.4, 0.1), rpy=(0.3, 0.0, 1.0))
    base.kinematic = True
    base.pose = moved
    world.step(2)
    np.testing.assert_allclose(volume.pose, moved @ expected_local(), atol=1e-9)


def test_a_volume_waits_for_its_parent_across_load_adf_calls(tmp_path, caplog):
    slices(tmp_path)
    write(tmp_path, "volume.yaml", VOLUME_ON_BASE)
    write(tmp_path, "base.yaml", BASE)
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(tmp_path / "volume.yaml")
    assert any("BODY base" in r.getMessage() for r in caplog.records)
    assert world.get("slab").attached_to is None
    world.load_adf(tmp_path / "base.yaml")
    assert world.get("slab").attached_to.name == "base"
    np.testing.assert_allclose(
        local_pose(world.get("base"), world.get("slab")), expected_local(), atol=1e-12
    )


def test_a_drill_on_a_volume_of_a_file_loaded_later(tmp_path):
    slices(tmp_path)
    write(tmp_path, "drill.yaml", DRILL_ON_SLAB)
    write(tmp_path, "volume.yaml", VOLUME_ON_BASE)
    write(tmp_path, "base.yaml", BASE)
    sim = ambfplus.Simulator.from_launch(
        launch(tmp_path, ["drill.yaml", "volume.yaml", "base.yaml"]), models=[0, 1, 2], strict=True
    )
    assert sim.load_report.errors == []
    assert not [w for w in sim.load_report.warnings if "burr" in w[1]], sim.load_report.warnings
    (drill,) = sim.world.drills
    assert drill.name == "burr" and drill.volume.name == "slab"
    assert len(drill.cursor_radii) == 2


def test_a_drill_waits_for_its_volume_across_load_adf_calls(tmp_path, caplog):
    slices(tmp_path)
    write(tmp_path, "drill.yaml", DRILL_ON_SLAB)
    write(tmp_path, "volume.yaml", VOLUME_ON_BASE.replace("      parent: BODY base\n", ""))
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(tmp_path / "drill.yaml")
    assert any("VOLUME slab" in r.getMessage() for r in caplog.records)
    assert world.drills == []
    world.load_adf(tmp_path / "volume.yaml")
    (drill,) = world.drills
    assert drill.volume.name == "slab"
    # A drill made late drills like one declared beside its volume.
    write(
        tmp_path,
        "together.yaml",
        (tmp_path / "volume.yaml").read_text() + textwrap.dedent(DRILL_ON_SLAB),
    )
    same = ambfplus.World()
    same.load_adf(tmp_path / "together.yaml")
    forces = []
    for w in (world, same):
        (d,) = w.drills
        # From above the slab down into its bone (the lower half), in the volume's frame.
        for z in np.linspace(0.01, -0.002, 7):
            d.goal = w.get("slab").pose @ ambfplus.make_pose((0.0, 0.0, z))
            w.step(10)
        forces.append(d.force.ravel().copy())
    up = world.get("slab").pose[:3, 2]
    assert forces[0] @ up > 0.1  # pushed back out of the bone
    np.testing.assert_allclose(forces[0], forces[1], atol=1e-12)


def test_a_drill_whose_volume_never_comes_is_a_warning_at_the_end(tmp_path):
    write(tmp_path, "drill.yaml", DRILL_ON_SLAB)
    sim = ambfplus.Simulator.from_launch(launch(tmp_path, ["drill.yaml"]), models=[0])
    warned = [w for w in sim.load_report.warnings if "DRILL burr" in w[1]]
    assert warned and "VOLUME slab" in warned[0][1], sim.load_report.warnings
    assert sim.world.drills == []


def test_load_volumes_still_refuses_a_drill_without_its_volume(tmp_path):
    path = write(tmp_path, "drill.yaml", DRILL_ON_SLAB)
    with pytest.raises(ambfplus.ConfigError, match="not one of the file's volumes"):
        ambfplus.World().load_volumes(path)


VOLUME_PLUGIN_PY = """
import os

import ambfplus


class Note(ambfplus.Plugin):
    def init(self):
        with open(os.environ["AMBFPLUS_TEST_VOLUME_PLUGIN"], "a") as f:
            f.write(f"init {self.object.name} {self.object.kind}\\n")
        return 1
"""


def test_volume_blocks_load_their_plugins_and_warn_of_keys_not_applied(
    tmp_path, monkeypatch, caplog
):
    slices(tmp_path)
    log = tmp_path / "volume_plugin.log"
    monkeypatch.setenv("AMBFPLUS_TEST_VOLUME_PLUGIN", str(log))
    (tmp_path / "note.py").write_text(VOLUME_PLUGIN_PY)
    block = VOLUME_ON_BASE.replace("      parent: BODY base\n", "").rstrip(" ") + (
        "      plugins: [{name: note, filename: note.py, path: .}]\n"
        "      color rgba: {r: 1.0, g: 0.0, b: 0.0, a: 1.0}\n"
        "      colour: red\n"
    )
    write(tmp_path, "volume.yaml", block)
    world = ambfplus.World()
    with caplog.at_level("WARNING"):
        world.load_adf(tmp_path / "volume.yaml")
    assert log.read_text().splitlines() == ["init slab volume"]
    messages = " ".join(r.getMessage() for r in caplog.records)
    assert "'color rgba' is not applied" in messages
    assert "unknown key 'colour'" in messages
