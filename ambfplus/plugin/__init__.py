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

Modules: ``loader`` (the ``Plugin`` base class, making one from a file or an entry point, the
CMake and plugin folders) and ``probe`` (loading a plugin file in a throwaway process first).
The package is ``plugin``, the engine area's name, not ``plugins``: ``ambfplus/plugins/`` is the
folder of installed native plugins that the engine searches for plugin files by name, and a
Python module there would shadow a user's plugin file of the same name.
"""

from .. import _core
from .loader import ENTRY_POINT_GROUP, Plugin, cmake_dir, plugin_dir
from .probe import ProbeResult, check_plugin, probe_plugin, resolve, with_probe

# Deliberately replaces the bound methods with their probing wrappers.
_core.World.load_plugin = with_probe(_core.World.load_plugin)  # type: ignore[method-assign]
_core.Simulator.load_plugin = with_probe(_core.Simulator.load_plugin)  # type: ignore[method-assign]

__all__ = [
    "ENTRY_POINT_GROUP",
    "Plugin",
    "ProbeResult",
    "check_plugin",
    "cmake_dir",
    "plugin_dir",
    "probe_plugin",
    "resolve",
]
