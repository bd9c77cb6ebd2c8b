"""Python plugins (the ``Plugin`` base class and how the engine makes one from a file or an
entry point), and the folders C++ plugins build against (``cmake_dir``, ``plugin_dir``)."""

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

from .. import _core
from .._core import PluginError

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


def plugin_from_file(path: str):
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


def plugin_from_entry_point(name: str):
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
_core._register_plugin_support(Plugin, plugin_from_file, plugin_from_entry_point)


def cmake_dir() -> str:
    """The folder holding ``ambfplusConfig.cmake``, for building C++ plugins out of tree:
    ``cmake -Dambfplus_DIR=$(python -m ambfplus --cmake-dir)``. In an installed package it is
    ``<package>/cmake`` (headers in ``<package>/include``); in a build tree's package mirror it
    is the same folder there, pointing at the source tree's headers."""
    folder = Path(__file__).resolve().parents[1] / "cmake"
    if not (folder / "ambfplusConfig.cmake").is_file():
        # The package folder may hold links into a build tree: look beside the engine itself.
        folder = Path(_core.__file__).resolve().parent / "cmake"
    if not (folder / "ambfplusConfig.cmake").is_file():
        raise FileNotFoundError(f"no ambfplusConfig.cmake in {folder}: the package is incomplete")
    return str(folder)


def plugin_dir() -> str:
    """The package's own plugin folder (``plugins`` beside libambfplus), searched after
    ``AMBFPLUS_PLUGIN_PATH``."""
    return str(Path(_core.__file__).resolve().parent / "plugins")
