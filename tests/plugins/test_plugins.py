"""Plugins at the four scopes, in C++ and in Python: declared in launch, world and model files,
given on the command line or from Python, called in the documented order; failures that name
what went wrong, and a Python hook that raises is contained.

The C++ plugins are built here as a third party builds them: CMake against the installed
package's config (``python -m ambfplus --cmake-dir``), once per session."""

from __future__ import annotations

import gc
import json
import logging
import os
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus.cli import main

# Appends every hook it sees to the file AMBFPLUS_TEST_PLUGIN_LOG names; an object plugin also
# writes its object's pose after every step (through Eigen, in the plugin's own code, so a
# plugin built with other vectorisation flags than the engine shows whether it sees the same).
LOG_PLUGIN_CPP = r"""
#include <cstdio>
#include <cstdlib>
#include <string>

#include <Eigen/Geometry>

#include "ambfplus/plugin/plugin.h"

namespace {

using ambfplus::plugin::Scope;

const char* const kKinds[] = {"body", "joint", "camera", "light", "volume", "drill",
                              "soft body", "sensor", "actuator", "input device"};
const char* const kScopes[] = {"simulator", "world", "model", "object"};

class LogPlugin : public ambfplus::plugin::Plugin {
 public:
  int init() override {
    std::string target = "sim";
    if (object()) {
      target = object().name() + " " + kKinds[object().kind()];
    } else if (scope() == Scope::kModel) {
      target = model();
    } else if (scope() == Scope::kWorld) {
      target = world().name();
    }
    write(std::string("init ") + kScopes[static_cast<int>(scope())] + " " + target);
    return 1;
  }
  void physics_update(double dt) override {
    write("physics " + std::to_string(world().step_index()) + (dt == 0.001 ? "" : " bad dt"));
    if (object() && std::getenv("AMBFPLUS_TEST_PLUGIN_POSES") != nullptr) write_pose();
  }
  void graphics_update() override { write("graphics " + std::to_string(world().step_index())); }
  void keyboard(int key, int, int, int) override { write("key " + std::to_string(key)); }
  void reset() override { write("reset"); }
  void close() override { write("close"); }
  void on_object_added(const ambfplus::plugin::Object& o) override { write("added " + o.name()); }
  void on_object_removed(const ambfplus::plugin::Object& o) override {
    write("removed " + o.name());
  }

 private:
  void write_pose() const {
    const ambfplus::plugin::Pose p = object().pose();
    Eigen::Isometry3d pose;
    pose.matrix() = Eigen::Map<const Eigen::Matrix<double, 4, 4, Eigen::RowMajor>>(p.data());
    // A point of the body in the world: arithmetic in the plugin's own code and flags.
    const Eigen::Vector3d point = pose * Eigen::Vector3d(0.01, 0.02, 0.03);
    std::string line = "pose " + std::to_string(world().step_index());
    char number[32];
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) {
        std::snprintf(number, sizeof number, " %.17g", pose.matrix()(r, c));
        line += number;
      }
    }
    for (int i = 0; i < 3; ++i) {
      std::snprintf(number, sizeof number, " %.17g", point[i]);
      line += number;
    }
    write(line);
  }
  void write(const std::string& line) const {
    const char* path = std::getenv("AMBFPLUS_TEST_PLUGIN_LOG");
    if (path == nullptr) return;
    if (std::FILE* f = std::fopen(path, "a")) {
      std::fprintf(f, "cpp:%s %s\n", name().c_str(), line.c_str());
      std::fclose(f);
    }
  }
};

}  // namespace

AMBFPLUS_PLUGIN(LogPlugin)
"""

# An entry point claiming another ABI version.
WRONG_ABI_CPP = r"""
#include "ambfplus/plugin/plugin.h"

extern "C" __attribute__((visibility("default"))) const AmbfplusPluginEntry*
ambfplus_plugin_entry() {
  static const AmbfplusPluginEntry entry = {AMBFPLUS_PLUGIN_ABI_VERSION + 998, "Old"};
  return &entry;
}
"""

# A plugin class without the entry point.
NO_ENTRY_CPP = r"""
#include "ambfplus/plugin/plugin.h"

class Forgotten : public ambfplus::plugin::Plugin {};

extern "C" __attribute__((visibility("default"))) void* make_forgotten() {
  return new Forgotten();
}
"""

# The entry point's name on data, not a function: calling it would crash.
DATA_ENTRY_CPP = r"""
extern "C" __attribute__((visibility("default"))) const int ambfplus_plugin_entry = 42;
"""

PLUGINS_CMAKE = """
cmake_minimum_required(VERSION 3.24)
project(ambfplus_test_plugins CXX)
find_package(ambfplus CONFIG REQUIRED)
ambfplus_add_plugin(logplugin log_plugin.cpp)
ambfplus_add_plugin(wrongabi wrong_abi.cpp)
add_library(noentry MODULE no_entry.cpp)
target_link_libraries(noentry PRIVATE ambfplus::ambfplus)
add_library(dataentry MODULE data_entry.cpp)
# The same plugin built as other projects might build it: unoptimised without AVX, and
# optimised for AVX2 (where the CPU has it), against the engine built with the package's flags.
ambfplus_add_plugin(logplugin_noavx log_plugin.cpp)
target_compile_options(logplugin_noavx PRIVATE -O0 -mno-avx)
if(AMBFPLUS_TEST_AVX2)
  ambfplus_add_plugin(logplugin_avx2 log_plugin.cpp)
  target_compile_options(logplugin_avx2 PRIVATE -O3 -mavx2 -mfma)
endif()
"""

# The same log from Python.
LOG_PLUGIN_PY = """
import os

import ambfplus


class LogPlugin(ambfplus.Plugin):
    def write(self, line):
        with open(os.environ["AMBFPLUS_TEST_PLUGIN_LOG"], "a") as f:
            f.write(f"py:{self.name} {line}\\n")

    def init(self):
        if self.object is not None:
            target = f"{self.object.name} {self.object.kind}"
        elif self.model is not None:
            target = self.model.name
        elif self.scope == "world":
            target = self.world.name
        else:
            target = "sim"
        self.write(f"init {self.scope} {target}")
        return 1

    def physics_update(self, dt):
        self.write(f"physics {self.world.step_index}" + ("" if dt == 0.001 else " bad dt"))

    def graphics_update(self):
        self.write(f"graphics {self.world.step_index}")

    def keyboard(self, key, scancode, action, mods):
        self.write(f"key {key}")

    def reset(self):
        self.write("reset")

    def close(self):
        self.write("close")

    def on_object_added(self, obj):
        self.write(f"added {obj.name}")

    def on_object_removed(self, obj):
        self.write(f"removed {obj.name}")
"""


def run(command: list[str], cwd: Path | None = None) -> subprocess.CompletedProcess:
    result = subprocess.run(command, cwd=cwd, capture_output=True, text=True)
    assert result.returncode == 0, f"{command} failed:\n{result.stdout}\n{result.stderr}"
    return result


def cpu_has_avx2() -> bool:
    try:
        return " avx2 " in Path("/proc/cpuinfo").read_text().replace("\n", " ")
    except OSError:
        return False


@pytest.fixture(scope="session")
def cpp_plugins(tmp_path_factory) -> Path:
    """liblogplugin.so, libwrongabi.so and libnoentry.so, built against the package's config."""
    cmake = shutil.which("cmake")
    assert cmake, "cmake is needed to build C++ plugins (pip install cmake)"
    src = tmp_path_factory.mktemp("plugin_src")
    (src / "CMakeLists.txt").write_text(PLUGINS_CMAKE)
    (src / "log_plugin.cpp").write_text(LOG_PLUGIN_CPP)
    (src / "wrong_abi.cpp").write_text(WRONG_ABI_CPP)
    (src / "no_entry.cpp").write_text(NO_ENTRY_CPP)
    (src / "data_entry.cpp").write_text(DATA_ENTRY_CPP)
    build = src / "build"
    run(
        [
            cmake,
            "-S",
            str(src),
            "-B",
            str(build),
            f"-Dambfplus_DIR={ambfplus.cmake_dir()}",
            "-DCMAKE_BUILD_TYPE=Release",
            f"-DAMBFPLUS_TEST_AVX2={'ON' if cpu_has_avx2() else 'OFF'}",
        ]
    )
    run([cmake, "--build", str(build), "-j2"])
    return build


@pytest.fixture
def plugin_log(tmp_path, monkeypatch) -> Path:
    log = tmp_path / "hooks.log"
    monkeypatch.setenv("AMBFPLUS_TEST_PLUGIN_LOG", str(log))
    return log


def lines(log: Path) -> list[str]:
    return log.read_text().splitlines() if log.exists() else []


def write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return path


def plugins_yaml(cpp_name: str, cpp_file: str, cpp_dir: Path, py_name: str, indent: str) -> str:
    return (
        f"{indent}- {{name: {cpp_name}, filename: {cpp_file}, path: '{cpp_dir}'}}\n"
        f"{indent}- {{name: {py_name}, filename: logplugin.py, path: .}}"
    )


def scene(folder: Path, cpp_dir: Path, library: str = "logplugin") -> Path:
    """A launch file whose four levels each declare the C++ (lib<library>.so) and the Python
    log plugin."""
    (folder / "logplugin.py").write_text(LOG_PLUGIN_PY)
    write(
        folder,
        "world.yaml",
        """\
        cameras: [camera1]
        camera1:
          name: camera1
          location: {x: 1.0, y: 0.0, z: 0.0}
          look at: {x: 0.0, y: 0.0, z: 0.0}
          up: {x: 0.0, y: 0.0, z: 1.0}
          publish image resolution: {width: 16, height: 12}
        plugins:
        WORLD
        """,
    ).write_text(
        (folder / "world.yaml")
        .read_text()
        .replace("WORLD", plugins_yaml("world_cpp", f"lib{library}.so", cpp_dir, "world_py", ""))
    )
    # The model's C++ plugin is named without its extension, as AMBF's files may name it.
    write(
        folder,
        "model.yaml",
        """\
        bodies: [BODY box]
        plugins:
        MODEL
        BODY box:
          name: box
          mass: 0.0
          shape: BOX
          geometry: {x: 0.1, y: 0.1, z: 0.1}
          location: {position: {x: 0, y: 0, z: 0}, orientation: {r: 0, p: 0, y: 0}}
          plugins:
        OBJECT
        """,
    ).write_text(
        (folder / "model.yaml")
        .read_text()
        .replace("MODEL", plugins_yaml("model_cpp", library, cpp_dir, "model_py", ""))
        .replace("OBJECT", plugins_yaml("obj_cpp", f"lib{library}.so", cpp_dir, "obj_py", "  "))
    )
    launch = write(
        folder,
        "launch.yaml",
        """\
        world config: world.yaml
        color config: colors.yaml
        input devices config: devices.yaml
        multibody configs: [model.yaml]
        plugins:
        SIMULATOR
        """,
    )
    launch.write_text(
        launch.read_text().replace(
            "SIMULATOR", plugins_yaml("sim_cpp", f"lib{library}.so", cpp_dir, "sim_py", "")
        )
    )
    return launch


CALL_ORDER = ["sim", "world", "model", "obj"]


def each(event: str) -> list[str]:
    """event from every plugin in call order: simulator, world, model, object; C++ first
    within each, as declared."""
    return [f"{lang}:{scope}_{lang} {event}" for scope in CALL_ORDER for lang in ("cpp", "py")]


# The log plugin as the package builds plugins, and built with other flags than the engine.
VARIANTS = ["logplugin", "logplugin_noavx", "logplugin_avx2"]


def variant(cpp_plugins: Path, library: str) -> Path:
    path = cpp_plugins / f"lib{library}.so"
    if library.endswith("avx2") and not path.exists():
        pytest.skip("this CPU has no AVX2, so the AVX2 build of the plugin cannot run")
    return path


@pytest.mark.parametrize("library", VARIANTS)
def test_plugins_at_four_scopes_run_their_hooks_in_order(
    cpp_plugins, plugin_log, tmp_path, library
):
    variant(cpp_plugins, library)
    launch = scene(tmp_path, cpp_plugins, library)

    def session():
        sim = ambfplus.Simulator.from_launch(launch, models=[0], strict=True)
        plugins = sim.world.plugins
        assert [(p.name, p.language, p.scope, p.enabled) for p in plugins] == [
            (f"{scope}_{lang}", "c++" if lang == "cpp" else "python", s, True)
            for scope, s in zip(CALL_ORDER, ["simulator", "world", "model", "object"])
            for lang in ("cpp", "py")
        ]
        assert plugins[5].attached_to.name == "model" and plugins[7].attached_to.name == "box"
        assert plugins[1].instance.name == "sim_py"
        # The model's, declared without its extension, is found as lib<name>.so.
        assert plugins[0].file == plugins[4].file == str(cpp_plugins / f"lib{library}.so")
        del plugins
        sim.step(2)
        camera = sim.get("camera1")
        camera.capture()
        camera.capture()  # the same step: no second graphics update
        sim.step(1)
        sim.world.reset_plugins()
        sim.world.send_key(65)

    session()
    gc.collect()
    expected = (
        [
            "cpp:world_cpp init world World",
            "py:world_py init world World",
            # World plugins see the model's objects arrive; object and model plugins come once
            # their model is complete, then the launch file's simulator plugins.
            "cpp:world_cpp added box",
            "py:world_py added box",
            "cpp:obj_cpp init object box body",
            "py:obj_py init object box body",
            "cpp:model_cpp init model model",
            "py:model_py init model model",
            "cpp:sim_cpp init simulator sim",
            "py:sim_py init simulator sim",
        ]
        + each("physics 1")
        + each("physics 2")
        + each("graphics 2")
        + each("physics 3")
        + each("reset")
        + each("key 65")
        # At the world's destruction: the reverse of call order.
        + each("close")[::-1]
    )
    assert lines(plugin_log) == expected


def test_command_line_plugins_are_simulator_plugins(cpp_plugins, plugin_log, tmp_path, capsys):
    launch = scene(tmp_path, cpp_plugins)
    extra = write(tmp_path, "extra.py", LOG_PLUGIN_PY)
    code = main(
        [
            "launch",
            str(launch),
            "-l",
            "0",
            "--steps",
            "1",
            "--plugins",
            f"{extra},{cpp_plugins / 'liblogplugin.so'}",
        ]
    )
    summary = json.loads(capsys.readouterr().out)
    assert code == 0, summary["errors"]
    assert summary["plugins"][:4] == [
        "sim_cpp (c++, simulator)",
        "sim_py (python, simulator)",
        "extra (python, simulator)",
        "liblogplugin (c++, simulator)",
    ]
    log = lines(plugin_log)
    assert log[log.index("py:sim_py init simulator sim") + 1 :][:2] == [
        "py:extra init simulator sim",
        "cpp:liblogplugin init simulator sim",
    ]
    assert "py:extra physics 1" in log and "cpp:liblogplugin close" in log


def test_python_plugins_from_objects_files_and_entry_points(tmp_path, monkeypatch):
    world = ambfplus.World()
    body = world.add_body("ball", "sphere", radius=0.05, kinematic=True)

    class Mover(ambfplus.Plugin):
        """Moves its body 1 mm along x per step."""

        def physics_update(self, dt):
            pose = self.object.pose.copy()
            pose[0, 3] += 0.001
            self.object.pose = pose

    info = world.load_plugin(Mover(), body)
    assert (info.scope, info.language, info.name) == ("object", "python", "Mover")
    assert info.attached_to.name == "ball"
    world.step(3)
    assert body.pose[0, 3] == pytest.approx(0.003)

    # A file whose create_plugin() makes the plugin; an init returning 0 drops it.
    factory = write(
        tmp_path,
        "factory.py",
        """\
        import ambfplus

        class Declines(ambfplus.Plugin):
            def init(self):
                return 0

        def create_plugin():
            return Declines()
        """,
    )
    assert world.load_plugin(factory) is None
    assert [p.name for p in world.plugins] == ["Mover"]

    # An installed distribution naming a plugin class in the group ambfplus.plugins.
    site = tmp_path / "site"
    (site / "fake_plugins-1.0.dist-info").mkdir(parents=True)
    (site / "fake_plugins-1.0.dist-info" / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: fake-plugins\nVersion: 1.0\n"
    )
    (site / "fake_plugins-1.0.dist-info" / "entry_points.txt").write_text(
        "[ambfplus.plugins]\ncounter = fake_plugin_module:Counter\n"
    )
    write(
        site,
        "fake_plugin_module.py",
        """\
        import ambfplus

        class Counter(ambfplus.Plugin):
            steps = 0

            def physics_update(self, dt):
                self.steps += 1
        """,
    )
    monkeypatch.syspath_prepend(str(site))
    counter = world.load_plugin("counter", world.simulator)
    assert (counter.scope, counter.language) == ("simulator", "python")
    assert "entry point 'counter'" in counter.file
    world.step(2)
    assert counter.instance.steps == 2


def test_python_hook_exception_is_logged_once_and_disables_only_that_plugin(caplog):
    world = ambfplus.World()

    class Faulty(ambfplus.Plugin):
        calls = 0

        def physics_update(self, dt):
            self.calls += 1
            if self.calls == 2:
                raise ZeroDivisionError("bad step")

    class Steady(ambfplus.Plugin):
        calls = 0

        def physics_update(self, dt):
            self.calls += 1

    faulty, steady = Faulty(), Steady()
    world.load_plugin(faulty)
    world.load_plugin(steady)
    with caplog.at_level(logging.ERROR, logger="ambfplus"):
        world.step(5)
    assert world.step_index == 5
    assert (faulty.calls, steady.calls) == (2, 5)
    assert [p.enabled for p in world.plugins] == [False, True]
    errors = [r.getMessage() for r in caplog.records if r.levelno >= logging.ERROR]
    assert len(errors) == 1, errors
    assert "plugin 'Faulty'" in errors[0] and "physics_update failed" in errors[0]
    assert "disabled" in errors[0]
    assert "Traceback" in errors[0] and "ZeroDivisionError: bad step" in errors[0]


def test_python_init_exception_is_a_plugin_error():
    world = ambfplus.World()

    class Broken(ambfplus.Plugin):
        def init(self):
            raise ValueError("no configuration")

    with pytest.raises(ambfplus.PluginError, match="init") as error:
        world.load_plugin(Broken())
    assert "Traceback" in str(error.value) and "ValueError: no configuration" in str(error.value)
    assert world.plugins == []


def test_wrong_abi_version_names_both_versions(cpp_plugins):
    world = ambfplus.World()
    library = cpp_plugins / "libwrongabi.so"
    with pytest.raises(ambfplus.PluginError) as error:
        world.load_plugin(library)
    message = str(error.value)
    version = ambfplus._core.PLUGIN_ABI_VERSION
    assert str(library) in message
    assert f"built for plugin ABI version {version + 998}" in message
    assert f"has plugin ABI version {version}" in message


def test_missing_entry_point_is_named(cpp_plugins):
    world = ambfplus.World()
    library = cpp_plugins / "libnoentry.so"
    with pytest.raises(ambfplus.PluginError) as error:
        world.load_plugin(library)
    assert str(library) in str(error.value)
    assert "no entry point ambfplus_plugin_entry" in str(error.value)
    assert "AMBFPLUS_PLUGIN" in str(error.value)


def test_an_entry_point_that_is_data_is_refused_not_called(cpp_plugins):
    world = ambfplus.World()
    library = cpp_plugins / "libdataentry.so"
    with pytest.raises(ambfplus.PluginError, match="ambfplus_plugin_entry is not a function"):
        world.load_plugin(library)


def test_plugins_built_with_other_flags_read_the_same_poses(cpp_plugins, plugin_log, monkeypatch):
    """The ABI carries poses as double[16]: plugins built unoptimised without AVX and optimised
    with AVX2 read exactly the poses Python reads of a tumbling body, every step."""
    monkeypatch.setenv("AMBFPLUS_TEST_PLUGIN_POSES", "1")
    seen = {}
    for library in VARIANTS:
        if library.endswith("avx2") and not (cpp_plugins / f"lib{library}.so").exists():
            continue
        plugin_log.unlink(missing_ok=True)
        world = ambfplus.World()
        body = world.add_body("tumbler", "box", size=(0.1, 0.05, 0.02), mass=1.0)
        body.angular_velocity = (1.0, 2.0, 3.0)
        body.linear_velocity = (0.1, 0.0, 0.5)
        world.load_plugin(cpp_plugins / f"lib{library}.so", body, name="obj_cpp")
        python = []
        for _ in range(30):
            world.step(1)
            python.append((world.step_index, body.pose))
        logged = [line.split() for line in lines(plugin_log) if " pose " in line]
        assert len(logged) == 30, library
        for (step, pose), line in zip(python, logged):
            assert int(line[2]) == step
            values = np.array([float(v) for v in line[3:]])
            assert np.array_equal(values[:12], pose[:3].ravel()), (library, step)
            # The plugin's own arithmetic: its flags may round (FMA) differently.
            point = pose[:3, :3] @ (0.01, 0.02, 0.03) + pose[:3, 3]
            assert np.allclose(values[12:], point, rtol=0, atol=1e-15), (library, step)
        seen[library] = np.array([[float(v) for v in line[3:15]] for line in logged])
        world.close_plugins()
    assert len(seen) >= 2
    first = next(iter(seen.values()))
    for positions in seen.values():
        assert np.array_equal(positions, first)


def test_missing_plugin_lists_every_path_tried_and_leaves_no_model(
    tmp_path, plugin_log, monkeypatch
):
    monkeypatch.setenv("AMBFPLUS_PLUGIN_PATH", f"{tmp_path / 'a'}:{tmp_path / 'b'}")
    (tmp_path / "logplugin.py").write_text(LOG_PLUGIN_PY)
    model = write(
        tmp_path,
        "model.yaml",
        """\
        bodies: [BODY box]
        BODY box:
          name: box
          mass: 0.0
          shape: BOX
          geometry: {x: 0.1, y: 0.1, z: 0.1}
          plugins:
          - {name: first, filename: logplugin.py, path: .}
          - {name: gone, filename: nothere, path: plugins}
        """,
    )
    world = ambfplus.World()
    with pytest.raises(ambfplus.PluginError) as error:
        world.load_adf(model)
    message = str(error.value)
    assert message.startswith(f"{model}: BODY box: plugin 'gone'")
    for tried in [
        tmp_path / "plugins" / "nothere",
        tmp_path / "plugins" / "nothere.so",
        tmp_path / "plugins" / "libnothere.so",
        tmp_path / "a" / "nothere",
        tmp_path / "b" / "libnothere.so",
        Path(ambfplus.plugin_dir()) / "nothere.so",
    ]:
        assert str(tried) in message
    assert "python entry point 'nothere'" in message
    assert 'dlopen("libnothere.so"): ' in message
    # All or nothing: the body is gone, and the plugin that had loaded was closed with it.
    assert "box" not in world and len(world.models) == 1 and world.plugins == []
    assert lines(plugin_log) == ["py:first init object box body", "py:first close"]


def test_plugin_failures_in_a_launch_are_reported_unless_strict(tmp_path, cpp_plugins, plugin_log):
    launch = scene(tmp_path, cpp_plugins)
    text = (tmp_path / "world.yaml").read_text().replace("filename: logplugin.py", "filename: x.py")
    (tmp_path / "world.yaml").write_text(text)
    sim = ambfplus.Simulator.from_launch(launch, models=[0])
    errors = sim.load_report.errors
    assert len(errors) == 1 and errors[0][0] == str(tmp_path / "world.yaml")
    assert "world: plugin 'world_py': 'x.py' not found; tried " in errors[0][1]
    assert str(tmp_path / "x.py") in errors[0][1]
    assert "box" in sim.world and len(sim.world.plugins) == 7
    del sim
    with pytest.raises(ambfplus.PluginError, match="world.yaml: world: plugin 'world_py'"):
        ambfplus.Simulator.from_launch(launch, models=[0], strict=True)


def test_cmake_dir_helper_finds_the_package_config(tmp_path):
    printed = run([sys.executable, "-m", "ambfplus", "--cmake-dir"], cwd=tmp_path).stdout.strip()
    assert printed == ambfplus.cmake_dir()
    assert (Path(printed) / "ambfplusConfig.cmake").is_file()
    assert (Path(printed) / "ambfplusConfigVersion.cmake").is_file()
    assert os.path.isdir(Path(printed).parent) and ambfplus._core.plugin_search_path()[-1] == (
        ambfplus.plugin_dir()
    )
