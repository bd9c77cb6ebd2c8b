"""Plugins in Python, and where to find what C++ plugins build against.

A Python plugin is a subclass of :class:`Plugin` overriding the hooks it needs, the same hooks
C++ plugins have (``ambfplus/plugin/plugin.h``). It is declared in an ADF file by its ``.py``
file (``plugins: [{name: logger, filename: logger.py, path: .}]``), given to
``world.load_plugin(...)`` / ``sim.load_plugin(...)`` as a file or an object, or installed as an
entry point of the group ``ambfplus.plugins`` and named by its entry-point name.

From a file, the plugin is what the module's ``create_plugin()`` returns, else an instance of the
first :class:`Plugin` subclass the file defines. The engine calls its hooks with the GIL held for
each call only (``World.step`` releases it). A hook that raises is logged once with its traceback
and the plugin is disabled; the simulation goes on. ``init`` raising is a :class:`PluginError`.

Trust: a plugin runs inside the process that loads it. A C++ plugin's static initialisers (global
objects' constructors) run during ``dlopen``, before the engine can check its entry point, and a
Python plugin's module-level code runs on import: one that throws or crashes there takes the
process down, whatever the engine does. For a plugin you do not trust, ``load_plugin(path,
probe=True)`` (or ``ambfplus check-plugins FILE...``, ``ambfplus launch --check-plugins``) loads
it in a probe process first and refuses it with the probe's output when that process fails.

Handles (``self.world``, ``self.object``, ...) are made on each access and each keeps the
simulator alive, as every handle does. The simulator keeps its plugins, so a handle stored on a
plugin is a cycle the garbage collector cannot see (the simulator then lives until the process
ends): keep names and look objects up in the hooks, or drop stored handles in ``close()`` and
call ``world.close_plugins()`` when done.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import importlib.util
import os
import re
import sys
from pathlib import Path
from types import ModuleType
from typing import Any

from . import _core
from ._core import PluginError

# Entry points of this group name Python plugins (a class or a factory returning a plugin).
ENTRY_POINT_GROUP = "ambfplus.plugins"


class Plugin:
    """Base of Python plugins: override the hooks you need (all default to doing nothing).

    The engine sets ``_site`` before ``init``; the properties below read it.
    """

    _site: Any = None

    @property
    def name(self) -> str:
        """The name it was declared with (ADF ``name``), else its file's stem or class."""
        return self._site.name if self._site is not None else type(self).__name__

    @property
    def scope(self) -> str:
        """``'simulator'``, ``'world'``, ``'model'`` or ``'object'``."""
        return self._site.scope

    @property
    def plugin_file(self) -> str:
        """The file it was loaded from."""
        return self._site.file

    @property
    def simulator(self):
        return self._site.simulator

    @property
    def world(self):
        return self._site.world

    @property
    def model(self):
        """The model (model scope) or the object's model (object scope), else None."""
        return self._site.model

    @property
    def object(self):
        """The object (object scope), else None."""
        return self._site.object

    def init(self) -> int | bool | None:
        """Called once when loaded. Return >= 1 (or True, or nothing) to keep the plugin."""
        return 1

    def physics_update(self, dt: float) -> None:
        """Called at the end of every world step, after physics and sensors; ``dt`` seconds."""

    def graphics_update(self) -> None:
        """Called before a camera renders, once per world step that renders."""

    def keyboard(self, key: int, scancode: int, action: int, mods: int) -> None:
        """A key event (GLFW's codes; action 0 release, 1 press, 2 repeat)."""

    def mouse_button(self, button: int, action: int, mods: int) -> None:
        """A mouse button event."""

    def mouse_move(self, x: float, y: float) -> None:
        """The cursor moved to (x, y) window pixels."""

    def mouse_scroll(self, dx: float, dy: float) -> None:
        """The scroll wheel moved."""

    def reset(self) -> None:
        """``world.reset_plugins()`` was called."""

    def close(self) -> None:
        """Called once before the plugin goes (its world destroyed, its model removed, or
        ``world.close_plugins()``)."""

    def on_object_added(self, obj) -> None:
        """An object was added to the world (simulator and world plugins) or to this plugin's
        model (model plugins)."""

    def on_object_removed(self, obj) -> None:
        """An object is about to be removed; same plugins as ``on_object_added``."""


# Modules loaded from plugin files, by (real path, modification time): a file declared for
# several objects is imported once, and again when it changes.
_modules: dict[tuple[str, int], ModuleType] = {}


def _module_from_file(path: str) -> ModuleType:
    real = os.path.realpath(path)
    key = (real, os.stat(real).st_mtime_ns)
    if key in _modules:
        return _modules[key]
    digest = hashlib.sha1(real.encode()).hexdigest()[:10]
    name = f"ambfplus_plugin_{re.sub(r'[^0-9a-zA-Z_]', '_', Path(real).stem)}_{digest}"
    spec = importlib.util.spec_from_file_location(name, real)
    if spec is None or spec.loader is None:
        raise PluginError(f"{path}: not a Python file Python can import")
    module = importlib.util.module_from_spec(spec)
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)
    except BaseException:
        del sys.modules[name]
        raise
    _modules[key] = module
    return module


def _from_file(path: str):
    """The plugin a Python file defines (the engine's loader calls this for ``.py`` files)."""
    module = _module_from_file(path)
    factory = getattr(module, "create_plugin", None)
    if callable(factory):
        return factory()
    for value in vars(module).values():
        if (
            isinstance(value, type)
            and issubclass(value, Plugin)
            and value is not Plugin
            and value.__module__ == module.__name__
        ):
            return value()
    raise PluginError(
        f"{path}: no plugin in it: define a subclass of ambfplus.Plugin or a function "
        "create_plugin() returning one"
    )


def _from_entry_point(name: str):
    """The plugin an ``ambfplus.plugins`` entry point of this name gives, or None."""
    if sys.version_info >= (3, 10):
        found = importlib.metadata.entry_points(group=ENTRY_POINT_GROUP, name=name)
    else:  # pragma: no cover - Python 3.9
        found = [
            e
            for e in importlib.metadata.entry_points().get(ENTRY_POINT_GROUP, ())
            if e.name == name
        ]
    for entry in found:
        target = entry.load()
        return target()  # a class or a factory
    return None


# The engine makes Python plugins through these (it never imports this package itself).
_core._register_plugin_support(Plugin, _from_file, _from_entry_point)


def _with_probe(native):
    """World/Simulator.load_plugin with ``probe=``: a plugin file is first loaded in a probe
    process (``ambfplus.plugin_probe``) and refused with the probe's message unless that ends
    cleanly, since a C++ plugin's static initialisers run inside the process that loads it."""

    def load_plugin(self, plugin, *args, probe: bool = False, **kwargs):
        if probe and isinstance(plugin, (str, os.PathLike)):
            from .plugin_probe import check_plugin

            check_plugin(plugin)
        return native(self, plugin, *args, **kwargs)

    load_plugin.__doc__ = (native.__doc__ or "") + (
        "\n\nprobe=True loads a plugin file in a probe process first and raises PluginError "
        "with the probe's output when that process crashes, hangs or fails."
    )
    return load_plugin


_core.World.load_plugin = _with_probe(_core.World.load_plugin)
_core.Simulator.load_plugin = _with_probe(_core.Simulator.load_plugin)


def cmake_dir() -> str:
    """The folder holding ``ambfplusConfig.cmake``, for building C++ plugins out of tree:
    ``cmake -Dambfplus_DIR=$(python -m ambfplus --cmake-dir)``. In an installed package it is
    ``<package>/cmake`` (headers in ``<package>/include``); in a build tree's package mirror it
    is the same folder there, pointing at the source tree's headers."""
    folder = Path(__file__).resolve().parent / "cmake"
    if not (folder / "ambfplusConfig.cmake").is_file():
        # The package folder may hold links into a build tree: look beside the engine itself.
        folder = Path(_core.__file__).resolve().parent / "cmake"
    if not (folder / "ambfplusConfig.cmake").is_file():
        raise FileNotFoundError(f"no ambfplusConfig.cmake in {folder}: the package is incomplete")
    return str(folder)


def plugin_dir() -> str:
    """The package's own plugin folder (``plugins`` beside libambfplus), searched after
    ``AMBFPLUS_PLUGIN_PATH``."""
    from . import _core

    return str(Path(_core.__file__).resolve().parent / "plugins")
