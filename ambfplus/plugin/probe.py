"""Loading a plugin in a throwaway process first: ``probe_plugin(path)``.

A C++ plugin's static initialisers run inside the process that loads it, during ``dlopen``,
before the engine can check anything: one that throws aborts the process, one that dereferences
a bad pointer kills it. A Python plugin's module-level code runs when it is imported. The probe
does what loading does up to the plugin's ``init`` (open the library and call its entry point,
or import the module and make the plugin object) in a child process, and reports how that
process ended; ``world.load_plugin(path, probe=True)`` and ``ambfplus check-plugins`` refuse a
plugin whose probe did not end cleanly, with the probe's own output.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from .._core import PluginError, plugin_search_path
from .loader import plugin_from_file

PROBE_TIMEOUT_S = 60.0
# Stages the child prints as it passes them, so a crash says where it happened.
STAGES = ("opened", "entry", "made")


@dataclass
class ProbeResult:
    """How a probe went: ``ok``, the stage it reached, the child's exit code (negative: the
    signal that killed it) and its output."""

    path: Path
    ok: bool
    stage: str
    returncode: int | None
    output: str

    @property
    def message(self) -> str:
        if self.ok:
            return f"{self.path}: probe passed"
        how = (
            f"did not finish in {PROBE_TIMEOUT_S:g} s"
            if self.returncode is None
            else f"was killed by {signal.Signals(-self.returncode).name}"
            if self.returncode < 0
            else f"exited with status {self.returncode}"
        )
        where = {
            "start": "while loading the library (its static initialisers) or importing the module",
            "opened": "while looking up or calling its entry point",
            "entry": "while making the plugin object",
            "made": "after making the plugin object",
        }[self.stage]
        tail = self.output.strip()[-2000:]
        return f"{self.path}: refused: loading it in a probe process {how} {where}" + (
            f"; the probe's output:\n{tail}" if tail else " (no output)"
        )


def resolve(plugin) -> Path | None:
    """The file a plugin argument names: an existing path, or a name found in the plugin
    search path (AMBFPLUS_PLUGIN_PATH, the package's plugins) as NAME, libNAME.so or NAME.so.
    None when it names no file (an entry point, say)."""
    path = Path(os.fspath(plugin))
    if path.is_file():
        return path
    if os.sep in str(plugin):
        return None
    for folder in plugin_search_path():
        for name in (str(plugin), f"lib{plugin}.so", f"{plugin}.so"):
            candidate = Path(folder) / name
            if candidate.is_file():
                return candidate
    return None


def probe_plugin(plugin, timeout: float = PROBE_TIMEOUT_S) -> ProbeResult:
    """Loads the plugin file in a child process as far as its ``init`` and reports how that
    went (never raises for a bad plugin; ``check_plugin`` does)."""
    path = resolve(plugin)
    if path is None:
        raise PluginError(f"{plugin}: no plugin file of that name to probe")
    command = [sys.executable, "-m", "ambfplus.plugin.probe", str(path.resolve())]
    try:
        # From a neutral folder: a source tree's ambfplus/ in the caller's folder would shadow
        # the installed package.
        done = subprocess.run(
            command, capture_output=True, text=True, errors="replace", timeout=timeout,
            cwd=tempfile.gettempdir(),
        )  # fmt: skip
        output, returncode = done.stdout + done.stderr, done.returncode
    except subprocess.TimeoutExpired as expired:
        output = _text(expired.stdout) + _text(expired.stderr)
        returncode = None
    stages = [line[len("ambfplus-probe: ") :] for line in output.splitlines()
              if line.startswith("ambfplus-probe: ")]  # fmt: skip
    stage = stages[-1] if stages else "start"
    output = "\n".join(line for line in output.splitlines()
                       if not line.startswith("ambfplus-probe: "))  # fmt: skip
    return ProbeResult(path, returncode == 0 and stage == "made", stage, returncode, output)


def check_plugin(plugin, timeout: float = PROBE_TIMEOUT_S) -> Path:
    """Probes a plugin file and raises PluginError with the probe's message unless it loads
    cleanly; returns the file."""
    result = probe_plugin(plugin, timeout)
    if not result.ok:
        raise PluginError(result.message)
    return result.path


def with_probe(native):
    """World/Simulator.load_plugin with ``probe=``: a plugin file is first loaded in a probe
    process (see the module) and refused with the probe's message unless that ends
    cleanly, since a C++ plugin's static initialisers run inside the process that loads it."""

    def load_plugin(self, plugin, *args, probe: bool = False, **kwargs):
        if probe and isinstance(plugin, (str, os.PathLike)):
            check_plugin(plugin)
        return native(self, plugin, *args, **kwargs)

    load_plugin.__doc__ = (native.__doc__ or "") + (
        "\n\nprobe=True loads a plugin file in a probe process first and raises PluginError "
        "with the probe's output when that process crashes, hangs or fails."
    )
    return load_plugin


def _text(data) -> str:
    if data is None:
        return ""
    return data.decode(errors="replace") if isinstance(data, bytes) else data


def _probe_here(path: str) -> int:
    """The child's side: load as the engine would, printing each stage reached. Run as
    ``python -m ambfplus.plugin.probe``, the child has imported the package first, and with it
    libambfplus, which native plugins link against."""
    import ctypes

    def stage(name: str) -> None:
        print(f"ambfplus-probe: {name}", flush=True)

    if path.endswith(".py"):
        stage("opened")
        stage("entry")
        plugin_from_file(path)
        stage("made")
        return 0
    library = ctypes.CDLL(path, mode=os.RTLD_NOW | os.RTLD_LOCAL)
    stage("opened")
    try:
        entry = library.ambfplus_plugin_entry
    except AttributeError:
        print(f"{path}: no entry point ambfplus_plugin_entry", file=sys.stderr)
        return 3
    entry.restype = ctypes.POINTER(ctypes.c_int)  # the entry's first field: its ABI version
    stage("entry")
    version = entry()
    if not version:
        print(f"{path}: the entry point returned nothing", file=sys.stderr)
        return 3
    print(f"ABI version {version[0]}", flush=True)
    stage("made")
    return 0


if __name__ == "__main__":
    sys.exit(_probe_here(sys.argv[1]))
