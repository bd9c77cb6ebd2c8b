"""Plugins that cannot be trusted: a C++ plugin's static initialisers run inside the process that
loads it, so ``load_plugin(path, probe=True)`` and ``ambfplus check-plugins`` load it in a probe
process first and refuse it with the probe's message. The plugins are built here as a third
party builds them (CMake against the package's config)."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

import ambfplus
from ambfplus.cli import main
from ambfplus.plugin import probe_plugin

GOOD_CPP = r"""
#include "ambfplus/plugin/plugin.h"
class Good : public ambfplus::plugin::Plugin {};
AMBFPLUS_PLUGIN(Good)
"""

# A global object whose constructor throws: std::terminate during dlopen.
THROWS_CPP = r"""
#include <stdexcept>
#include "ambfplus/plugin/plugin.h"
struct Boom { Boom() { throw std::runtime_error("static initialiser of throws.cpp failed"); } };
static Boom boom;
class Throws : public ambfplus::plugin::Plugin {};
AMBFPLUS_PLUGIN(Throws)
"""

# A global object whose constructor writes through a null pointer: SIGSEGV during dlopen.
CRASHES_CPP = r"""
#include <cstdio>
#include "ambfplus/plugin/plugin.h"
struct Crash { Crash() { std::puts("crashes.cpp: about to crash"); std::fflush(stdout);
                         *static_cast<volatile int*>(nullptr) = 1; } };
static Crash crash;
class Crashes : public ambfplus::plugin::Plugin {};
AMBFPLUS_PLUGIN(Crashes)
"""

CMAKE = """
cmake_minimum_required(VERSION 3.24)
project(ambfplus_probe_plugins CXX)
find_package(ambfplus CONFIG REQUIRED)
ambfplus_add_plugin(good good.cpp)
ambfplus_add_plugin(throws throws.cpp)
ambfplus_add_plugin(crashes crashes.cpp)
"""


@pytest.fixture(scope="module")
def plugins(tmp_path_factory) -> Path:
    cmake = shutil.which("cmake")
    assert cmake, "cmake is needed to build C++ plugins (pip install cmake)"
    src = tmp_path_factory.mktemp("probe_src")
    for name, text in [("CMakeLists.txt", CMAKE), ("good.cpp", GOOD_CPP),
                       ("throws.cpp", THROWS_CPP), ("crashes.cpp", CRASHES_CPP)]:  # fmt: skip
        (src / name).write_text(text)
    build = src / "build"
    for command in (
        [cmake, "-S", str(src), "-B", str(build), f"-Dambfplus_DIR={ambfplus.cmake_dir()}",
         "-DCMAKE_BUILD_TYPE=Release"],
        [cmake, "--build", str(build), "-j2"],
    ):  # fmt: skip
        done = subprocess.run(command, capture_output=True, text=True)
        assert done.returncode == 0, done.stdout + done.stderr
    return build


def library(build: Path, name: str) -> Path:
    return next(build.rglob(f"lib{name}.so"))


def test_a_plugin_whose_static_initialiser_throws_is_refused_with_the_probe_output(plugins):
    path = library(plugins, "throws")
    world = ambfplus.World()
    with pytest.raises(ambfplus.PluginError) as info:
        world.load_plugin(str(path), probe=True)
    message = str(info.value)
    assert str(path) in message and "SIGABRT" in message
    assert "static initialiser of throws.cpp failed" in message  # std::terminate's report
    assert "while loading the library" in message
    assert world.plugins == []


def test_a_plugin_whose_static_initialiser_crashes_is_refused(plugins):
    path = library(plugins, "crashes")
    with pytest.raises(ambfplus.PluginError, match="SIGSEGV") as info:
        ambfplus.Simulator().load_plugin(str(path), probe=True)
    assert "crashes.cpp: about to crash" in str(info.value)


def test_a_good_plugin_passes_its_probe_and_loads(plugins):
    path = library(plugins, "good")
    result = probe_plugin(path)
    assert result.ok and result.returncode == 0, result.message
    world = ambfplus.World()
    world.load_plugin(str(path), probe=True)
    assert [p.name for p in world.plugins] == ["libgood"]  # named after its file


def test_check_plugins_command_reports_each_plugin(plugins, capsys):
    paths = [str(library(plugins, name)) for name in ("good", "throws")]
    assert main(["check-plugins", *paths]) == 1
    out = capsys.readouterr().out
    assert f"{paths[0]}: probe passed" in out
    assert f"{paths[1]}: refused" in out and "SIGABRT" in out
