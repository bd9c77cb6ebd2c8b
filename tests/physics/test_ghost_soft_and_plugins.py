"""Ghost objects report the soft bodies overlapping them (a node inside the ghost's shape) as
well as rigid bodies, to Python (body.overlapping) and to plugins (ambfplus_ghost_overlaps);
plugins of joints and sensors made when a later file brings their bodies are loaded then.

The C++ plugin is built here as a third party builds it (CMake against the package's config)."""

from __future__ import annotations

import shutil
import subprocess
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus

HALF = 0.04  # the ghost box's half size
EDGE = 0.03  # the soft cube's edge

# Logs its init (with its object's name) and, for a ghost, what overlaps it after every step.
PROBE_CPP = r"""
#include <cstdio>
#include <cstdlib>
#include <string>

#include "ambfplus/plugin/plugin.h"

namespace {

class Probe : public ambfplus::plugin::Plugin {
 public:
  int init() override {
    write("init " + (object() ? object().name() : model()));
    return 1;
  }
  void physics_update(double) override {
    if (!object() || object().kind() != AMBFPLUS_BODY) return;
    AmbfplusId ids[64];
    const int n = ambfplus_ghost_overlaps(object().world(), object().id(), ids, 64);
    if (n < 0) return;  // not a ghost
    std::string line = "overlaps " + std::to_string(world().step_index());
    for (int i = 0; i < n && i < 64; ++i) {
      line += " " + ambfplus::plugin::Object(object().world(), ids[i]).name();
    }
    write(line);
  }

 private:
  void write(const std::string& line) const {
    const char* path = std::getenv("AMBFPLUS_TEST_PROBE_LOG");
    if (path == nullptr) return;
    if (std::FILE* f = std::fopen(path, "a")) {
      std::fprintf(f, "%s\n", line.c_str());
      std::fclose(f);
    }
  }
};

}  // namespace

AMBFPLUS_PLUGIN(Probe)
"""

PROBE_CMAKE = """
cmake_minimum_required(VERSION 3.24)
project(ambfplus_probe_plugin CXX)
find_package(ambfplus CONFIG REQUIRED)
ambfplus_add_plugin(probe probe.cpp)
"""


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> Path:
    """The folder holding libprobe.so."""
    cmake = shutil.which("cmake")
    assert cmake, "cmake is needed to build C++ plugins (pip install cmake)"
    src = tmp_path_factory.mktemp("probe_src")
    (src / "CMakeLists.txt").write_text(PROBE_CMAKE)
    (src / "probe.cpp").write_text(PROBE_CPP)
    build = src / "build"
    for command in (
        [cmake, "-S", str(src), "-B", str(build), f"-Dambfplus_DIR={ambfplus.cmake_dir()}"],
        [cmake, "--build", str(build), "-j2"],
    ):
        result = subprocess.run(command, capture_output=True, text=True)
        assert result.returncode == 0, f"{command}:\n{result.stdout}\n{result.stderr}"
    assert (build / "libprobe.so").exists()
    return build


@pytest.fixture
def probe_log(tmp_path, monkeypatch) -> Path:
    log = tmp_path / "probe.log"
    monkeypatch.setenv("AMBFPLUS_TEST_PROBE_LOG", str(log))
    return log


def lines(log: Path) -> list[str]:
    return log.read_text().splitlines() if log.exists() else []


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def cube_stl(path: Path, edge: float = EDGE, n: int = 3) -> Path:
    """A cube's surface centred on the origin, each face an n x n grid (ASCII STL)."""
    h = edge / 2
    u = np.linspace(-h, h, n + 1)
    out = ["solid cube"]
    for axis in range(3):
        for sign in (-1.0, 1.0):
            a, b = [k for k in range(3) if k != axis]
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0.0, 0.0, 0.0]
                        p[axis], p[a], p[b] = sign * h, u[i + di], u[j + dj]
                        quad.append(p)
                    for tri in ((quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])):
                        out.append("facet normal 0 0 0\nouter loop")
                        out += [f"vertex {p[0]} {p[1]} {p[2]}" for p in tri]
                        out.append("endloop\nendfacet")
    out.append("endsolid cube")
    path.write_text("\n".join(out))
    return path


def inside_box(points: np.ndarray, pose: np.ndarray, half: float) -> np.ndarray:
    """Per point, its largest |coordinate| in the box's frame minus the half size (< 0 inside)."""
    local = (np.linalg.inv(pose) @ np.c_[points, np.ones(len(points))].T).T[:, :3]
    return np.abs(local).max(axis=1) - half


def ghost_scene(tmp_path, with_ghost=True):
    world = ambfplus.World()
    world.gravity = (0.0, 0.0, -9.8)
    pose = ambfplus.make_pose((0.01, 0.0, 0.0), rpy=(0.0, 0.0, 0.5))
    ghost = world.add_ghost("zone", "box", size=(2 * HALF,) * 3, pose=pose) if with_ghost else None
    soft = world.add_soft_body(
        "jelly",
        str(cube_stl(tmp_path / "cube.stl")),
        pose=ambfplus.make_pose((0.0, 0.0, 0.12)),
        mass=0.05,
        config={"piterations": 10, "kDP": 0.01, "bending constraint": 2},
    )
    rigid = world.add_body(
        "stone", "sphere", radius=0.01, mass=0.0, pose=ambfplus.make_pose((0.5, 0, 0))
    )
    return world, ghost, soft, rigid, pose


def test_a_ghost_reports_a_soft_body_while_a_node_is_inside_it(tmp_path):
    world, ghost, soft, rigid, pose = ghost_scene(tmp_path)
    reference_world, _, reference, _, _ = ghost_scene(tmp_path, with_ghost=False)
    states = []
    for step in range(300):
        world.step(1)
        reference_world.step(1)
        names = [o.name for o in ghost.overlapping]
        # No force on the soft body: the same nodes, bit for bit, as without the ghost.
        np.testing.assert_array_equal(soft.nodes, reference.nodes)
        depth = inside_box(soft.nodes, pose, HALF).min()
        if depth < -1e-4:
            assert names == ["jelly"], (step, depth, names)
            assert isinstance(ghost.overlapping[0], ambfplus.SoftBody)
        elif depth > 1e-4:
            assert names == [], (step, depth, names)
        states.append("jelly" in names)
        # The rigid body moved in and out is reported beside it, in creation order.
        if step == 150:
            rigid.pose = ambfplus.make_pose((0.0, 0.0, 0.0))
            world.step(1)
            reference_world.step(1)
            if inside_box(soft.nodes, pose, HALF).min() < -1e-4:
                assert [o.name for o in ghost.overlapping] == ["jelly", "stone"]
            rigid.pose = ambfplus.make_pose((0.5, 0.0, 0.0))
    # It fell into the ghost and out of its bottom: reported, then not.
    assert True in states and states[-1] is False and states[0] is False


def test_plugins_of_a_joint_and_sensor_made_later_are_loaded_then(tmp_path, probe, probe_log):
    plugin = f"plugins: [{{name: probe, filename: libprobe.so, path: '{probe}'}}]"
    write(
        tmp_path,
        "tool.yaml",
        f"""
        bodies: [BODY tip]
        joints: [JOINT tip-base]
        sensors: [SENSOR feeler]
        actuators: [ACTUATOR grip]
        BODY tip:
          name: tip
          mass: 0.1
          shape: sphere
          geometry: {{radius: 0.01}}
          location: {{position: {{x: 0.0, y: 0.0, z: 0.5}}, orientation: {{r: 0, p: 0, y: 0}}}}
        JOINT tip-base:
          name: tip-base
          parent: BODY base
          child: BODY tip
          parent pivot: {{x: 0.0, y: 0.0, z: 0.5}}
          child pivot: {{x: 0.0, y: 0.0, z: 0.0}}
          parent axis: {{x: 0.0, y: 0.0, z: 1.0}}
          child axis: {{x: 0.0, y: 0.0, z: 1.0}}
          type: fixed
          {plugin}
        SENSOR feeler:
          name: feeler
          type: Proximity
          parent: BODY base
          direction: {{x: 0, y: 0, z: -1}}
          range: 1.0
          {plugin}
        ACTUATOR grip:
          name: grip
          type: Constraint
          parent: BODY base
          {plugin}
        """,
    )
    write(
        tmp_path,
        "base.yaml",
        """
        bodies: [BODY base]
        BODY base:
          name: base
          mass: 0.0
          shape: box
          geometry: {x: 0.1, y: 0.1, z: 0.1}
        """,
    )
    write(tmp_path, "world.yaml", "gravity: {x: 0.0, y: 0.0, z: -9.8}\n")
    launch = write(
        tmp_path,
        "launch.yaml",
        """
        world config: world.yaml
        color config: colors.yaml
        input devices config: devices.yaml
        multibody configs: [tool.yaml, base.yaml]
        """,
    )
    sim = ambfplus.Simulator.from_launch(launch, models=[0, 1], strict=True)
    assert sim.load_report.errors == []
    warned = [w[1] for w in sim.load_report.warnings]
    assert not [w for w in warned if "plugins are not loaded" in w or "plugin '" in w], warned
    assert sorted(lines(probe_log)) == ["init feeler", "init grip", "init tip-base"]
    assert sim.world.get("tip-base").parent.name == "base"

    # The same through world.load_adf called later.
    probe_log.unlink()
    world = ambfplus.World()
    world.load_adf(tmp_path / "tool.yaml")
    assert lines(probe_log) == []
    world.load_adf(tmp_path / "base.yaml")
    assert sorted(lines(probe_log)) == ["init feeler", "init grip", "init tip-base"]


def test_a_plugin_sees_the_ghost_overlaps_python_sees(tmp_path, probe, probe_log):
    cube_stl(tmp_path / "cube.stl")
    model = write(
        tmp_path,
        "ghost.yaml",
        f"""
        ghost objects: [GHOST zone]
        GHOST zone:
          name: zone
          shape: box
          geometry: {{x: {2 * HALF}, y: {2 * HALF}, z: {2 * HALF}}}
          location: {{position: {{x: 0.01, y: 0.0, z: 0.0}}, orientation: {{r: 0, p: 0, y: 0.5}}}}
          plugins: [{{name: probe, filename: libprobe.so, path: '{probe}'}}]
        """,
    )
    world = ambfplus.World()
    world.gravity = (0.0, 0.0, -9.8)
    world.load_adf(model)
    ghost = world.get("zone")
    world.add_soft_body(
        "jelly",
        str(tmp_path / "cube.stl"),
        pose=ambfplus.make_pose((0.0, 0.0, 0.12)),
        mass=0.05,
        config={"piterations": 10, "kDP": 0.01, "bending constraint": 2},
    )
    world.add_body(
        "ball", "sphere", radius=0.01, mass=0.1, pose=ambfplus.make_pose((0.02, 0.03, 0.2))
    )
    seen = []
    for _ in range(250):
        world.step(1)
        seen.append(
            " ".join(["overlaps", str(world.step_index)] + [o.name for o in ghost.overlapping])
        )
    assert [line for line in lines(probe_log) if line.startswith("overlaps")] == seen
    reported = " ".join(seen)
    assert "jelly" in reported and "ball" in reported
