"""``ambfplus doctor``: what the installed engine finds on this machine (renderer, EGL devices and
drivers, optional libraries, extras) and, in plain words, what to install for what is missing.

The engine renders through the system's GL vendor-neutral dispatch libraries (glvnd's
``libEGL.so.1`` and ``libOpenGL.so.0``) and whichever driver they dispatch to (Mesa or NVIDIA);
those are the only graphics pieces a wheel cannot carry. Everything that touches EGL runs in a
child process, so a broken driver cannot take the report down and this process never
initialises EGL (which must not happen before a fork).
"""

from __future__ import annotations

import ctypes
import importlib.util
import json
import os
import platform
import subprocess
import sys
from dataclasses import asdict, dataclass
from pathlib import Path

# Where glvnd looks for EGL vendor files (JSON naming each driver's EGL library) unless
# __EGL_VENDOR_LIBRARY_FILENAMES or __EGL_VENDOR_LIBRARY_DIRS say otherwise.
GLVND_VENDOR_DIRS = ("/etc/glvnd/egl_vendor.d", "/usr/share/glvnd/egl_vendor.d")
PROBE_TIMEOUT_S = 120

# What to install, per distribution family, for each missing piece.
FIXES = {
    "gl_dispatch": {
        "debian": "sudo apt-get install libegl1 libopengl0",
        "fedora": "sudo dnf install libglvnd-egl libglvnd-opengl",
        "arch": "sudo pacman -S libglvnd",
        "other": "install the GL vendor-neutral dispatch libraries (libglvnd: libEGL.so.1, "
        "libOpenGL.so.0) from your distribution",
    },
    "egl_driver": {
        "debian": "sudo apt-get install libegl-mesa0 libgl1-mesa-dri (Mesa: GPUs it supports, "
        "else software rendering), or the NVIDIA driver on an NVIDIA GPU",
        "fedora": "sudo dnf install mesa-libEGL mesa-dri-drivers, or the NVIDIA driver on an "
        "NVIDIA GPU",
        "arch": "sudo pacman -S mesa, or the NVIDIA driver on an NVIDIA GPU",
        "other": "install Mesa's EGL driver (libEGL_mesa.so.0 with its DRI drivers) or the "
        "NVIDIA driver; either registers an EGL vendor file in /usr/share/glvnd/egl_vendor.d",
    },
    "openxr": {
        "debian": "sudo apt-get install libopenxr-loader1 (and an OpenXR runtime such as Monado)",
        "fedora": "sudo dnf install openxr-libs (and an OpenXR runtime such as Monado)",
        "arch": "sudo pacman -S openxr (and an OpenXR runtime such as Monado)",
        "other": "install the Khronos OpenXR loader (libopenxr_loader.so.1) and a runtime",
    },
    "openhmd": {
        "debian": "sudo apt-get install libopenhmd0",
        "fedora": "install OpenHMD (libopenhmd.so.0)",
        "arch": "install OpenHMD (libopenhmd.so.0)",
        "other": "install OpenHMD (libopenhmd.so.0)",
    },
}

# The package's extras and a module each one brings.
EXTRAS = {
    "torch": ("torch", "cv2"),
    "gui": ("glfw", "PIL"),
    "test": ("pytest", "nbclient"),
}

# Run in a child process: EGL devices through glvnd (ctypes), then the engine's own context.
_PROBE = r"""
import ctypes, json, sys
out = {"devices": None, "device_error": None, "gl": None, "gl_error": None}
try:
    egl = ctypes.CDLL("libEGL.so.1")
    egl.eglGetProcAddress.restype = ctypes.c_void_p
    egl.eglGetProcAddress.argtypes = [ctypes.c_char_p]
    query = egl.eglGetProcAddress(b"eglQueryDevicesEXT")
    string = egl.eglGetProcAddress(b"eglQueryDeviceStringEXT")
    if query and string:
        query = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p),
                                 ctypes.POINTER(ctypes.c_int))(query)
        string = ctypes.CFUNCTYPE(ctypes.c_char_p, ctypes.c_void_p, ctypes.c_int)(string)
        count = ctypes.c_int(0)
        devices = (ctypes.c_void_p * 16)()
        if query(16, devices, ctypes.byref(count)):
            found = []
            for i in range(count.value):
                extensions = (string(devices[i], 0x3055) or b"").decode().split()  # EGL_EXTENSIONS
                node = None
                if "EGL_EXT_device_drm" in extensions:
                    node = (string(devices[i], 0x3233) or b"").decode() or None  # DRM device file
                found.append({"index": i, "extensions": extensions, "drm_device": node,
                              "software": "EGL_MESA_device_software" in extensions})
            out["devices"] = found
        else:
            out["device_error"] = "eglQueryDevicesEXT failed"
    else:
        out["device_error"] = "no EGL_EXT_device_enumeration (no EGL vendor library loaded)"
except OSError as error:
    out["device_error"] = str(error)
try:
    import ambfplus
    out["gl"] = ambfplus.gl_info()
except Exception as error:
    out["gl_error"] = f"{type(error).__name__}: {error}"
print(json.dumps(out))
"""


@dataclass
class Check:
    """One finding: what was looked at, what was found, and what to do about it."""

    name: str
    status: str  # "ok", "missing" (required), "optional" (not installed, not needed), "info"
    found: str
    fix: str | None = None
    required: bool = False

    @property
    def failed(self) -> bool:
        """True for a required piece that is missing or broken."""
        return self.required and self.status != "ok"


def distribution_family() -> str:
    """'debian', 'fedora', 'arch' or 'other', from /etc/os-release (ID and ID_LIKE)."""
    try:
        text = Path("/etc/os-release").read_text()
    except OSError:
        return "other"
    fields = dict(
        line.split("=", 1) for line in text.splitlines() if "=" in line and not line.startswith("#")
    )
    ids = " ".join(fields.get(key, "").strip('"') for key in ("ID", "ID_LIKE")).split()
    for family, members in (
        ("debian", ("debian", "ubuntu")),
        ("fedora", ("fedora", "rhel", "centos", "rocky", "almalinux")),
        ("arch", ("arch",)),
    ):
        if any(i in members for i in ids):
            return family
    return "other"


def fix_for(piece: str, family: str) -> str:
    """The install instruction for a missing piece on this distribution family."""
    return FIXES[piece].get(family, FIXES[piece]["other"])


def can_load(name: str) -> str | None:
    """None when the shared library loads by this name, else the loader's message."""
    try:
        ctypes.CDLL(name)
    except OSError as error:
        return str(error)
    return None


def egl_vendor_files() -> tuple[list[str], str]:
    """The EGL vendor files glvnd will read, and where it looks (as the environment sets it)."""
    explicit = os.environ.get("__EGL_VENDOR_LIBRARY_FILENAMES")
    if explicit:
        files = [f for f in explicit.split(":") if f]
        return [f for f in files if Path(f).is_file()], "__EGL_VENDOR_LIBRARY_FILENAMES"
    dirs = os.environ.get("__EGL_VENDOR_LIBRARY_DIRS")
    where = "__EGL_VENDOR_LIBRARY_DIRS" if dirs else "glvnd's default folders"
    folders = [d for d in dirs.split(":") if d] if dirs else list(GLVND_VENDOR_DIRS)
    found = []
    for folder in folders:
        found += (
            sorted(str(p) for p in Path(folder).glob("*.json")) if Path(folder).is_dir() else []
        )
    return found, f"{where} ({':'.join(folders)})"


def vendor_library(path: str) -> str:
    """The driver library an EGL vendor file names."""
    try:
        return json.loads(Path(path).read_text())["ICD"]["library_path"]
    except (OSError, ValueError, KeyError, TypeError):
        return "unreadable vendor file"


def package_kind() -> str:
    """How this ambfplus was installed: a repaired wheel (libraries bundled) or a source build."""
    package = Path(__file__).resolve().parent
    bundled = package.parent / "ambfplus.libs"
    if bundled.is_dir():
        count = sum(1 for p in bundled.iterdir() if ".so" in p.name)
        return f"self-contained wheel ({count} bundled libraries in {bundled})"
    return "built from source (libraries from the system)"


def probe() -> dict:
    """EGL devices and the engine's OpenGL context, from a child process."""
    try:
        result = subprocess.run(
            [sys.executable, "-c", _PROBE], capture_output=True, text=True, timeout=PROBE_TIMEOUT_S
        )
    except subprocess.TimeoutExpired:
        return {"crash": f"the EGL probe did not finish in {PROBE_TIMEOUT_S} s (a hung driver?)"}
    lines = result.stdout.strip().splitlines()
    if result.returncode != 0 or not lines:
        tail = (result.stderr.strip().splitlines() or ["no output"])[-1]
        return {"crash": f"the EGL probe exited with {result.returncode}: {tail}"}
    return json.loads(lines[-1])


def diagnose() -> list[Check]:
    """Every check, in the order a person would fix them."""
    family = distribution_family()
    checks: list[Check] = []
    from . import __version__

    checks.append(Check("ambfplus", "ok", f"{__version__}, {package_kind()}", required=True))
    checks.append(
        Check(
            "python",
            "info",
            f"{platform.python_version()} ({sys.executable}), "
            f"{' '.join(platform.libc_ver())} on {platform.machine()}",
        )
    )
    dispatch = {name: can_load(name) for name in ("libEGL.so.1", "libOpenGL.so.0")}
    missing = [name for name, error in dispatch.items() if error]
    checks.append(
        Check(
            "GL dispatch",
            "missing" if missing else "ok",
            f"cannot load {', '.join(missing)}" if missing else "libEGL.so.1, libOpenGL.so.0",
            fix_for("gl_dispatch", family) if missing else None,
            required=True,
        )
    )
    vendors, where = egl_vendor_files()
    checks.append(
        Check(
            "EGL drivers",
            "ok" if vendors else "missing",
            "; ".join(f"{Path(v).name} -> {vendor_library(v)}" for v in vendors)
            if vendors
            else f"no EGL vendor file in {where}: no EGL driver is installed",
            None if vendors else fix_for("egl_driver", family),
            required=True,
        )
    )
    found = (
        probe() if not missing else {"crash": "not tried: the GL dispatch libraries are missing"}
    )
    devices = found.get("devices")
    if devices is not None:
        described = [
            f"{d['index']}: "
            + ("software (Mesa llvmpipe)" if d["software"] else d["drm_device"] or "GPU")
            for d in devices
        ]
        checks.append(
            Check(
                "EGL devices", "info", f"{len(devices)}: {', '.join(described)}" if devices else "0"
            )
        )
    elif found.get("device_error"):
        checks.append(Check("EGL devices", "info", found["device_error"]))
    gl = found.get("gl")
    if gl:
        detail = (
            f"{gl['renderer']}, OpenGL {gl['version']}, EGL {gl['egl_version']} "
            f"({gl['egl_vendor']}), {gl['device']}"
        )
        software = "llvmpipe" in gl["renderer"] or "softpipe" in gl["renderer"]
        checks.append(Check("renderer", "ok", detail, required=True))
        if software:
            checks.append(
                Check(
                    "GPU",
                    "info",
                    "none in use: rendering in software on the CPU (correct, slower)",
                    "for a GPU: its driver (NVIDIA's, or Mesa's for AMD and Intel); "
                    "AMBFPLUS_EGL_DEVICE or AMBFPLUS_CUDA_DEVICE picks one of several",
                )
            )
    else:
        error = found.get("gl_error") or found.get("crash", "unknown")
        checks.append(
            Check(
                "renderer",
                "missing",
                f"the engine cannot create an OpenGL 4.5 context: {error}",
                fix_for("egl_driver", family) if not missing else fix_for("gl_dispatch", family),
                required=True,
            )
        )
    openxr = can_load("libopenxr_loader.so.1")
    checks.append(
        Check(
            "OpenXR",
            "optional" if openxr else "ok",
            "the loader is not installed (head-mounted displays through OpenXR only)"
            if openxr
            else "libopenxr_loader.so.1",
            fix_for("openxr", family) if openxr else None,
        )
    )
    openhmd = can_load("libopenhmd.so.0")
    checks.append(
        Check(
            "OpenHMD",
            "optional" if openhmd else "ok",
            "not installed (head tracking through OpenHMD only)" if openhmd else "libopenhmd.so.0",
            fix_for("openhmd", family) if openhmd else None,
        )
    )
    for extra, modules in EXTRAS.items():
        absent = [m for m in modules if importlib.util.find_spec(m) is None]
        checks.append(
            Check(
                f"extra [{extra}]",
                "optional" if absent else "ok",
                f"missing {', '.join(absent)}" if absent else ", ".join(modules),
                f'pip install "ambfplus[{extra}]"' if absent else None,
            )
        )
    display = os.environ.get("DISPLAY")
    checks.append(
        Check(
            "display",
            "ok" if display else "info",
            f"DISPLAY={display} (the launcher's window)"
            if display
            else "no DISPLAY: headless use only (the launcher's window needs X11)",
        )
    )
    return checks


def report(checks: list[Check]) -> str:
    """The checks as aligned plain text, each missing piece followed by how to fix it."""
    width = max(len(c.name) for c in checks)
    lines = []
    for check in checks:
        lines.append(f"{check.status:<8} {check.name:<{width}}  {check.found}")
        if check.fix and check.status != "ok":
            label = "to fix" if check.status == "missing" else "to add"
            lines.append(f"{'':<8} {'':<{width}}  {label}: {check.fix}")
    failed = [c.name for c in checks if c.failed]
    if failed:
        lines.append(f"\nambfplus cannot render here: {', '.join(failed)} (see 'to fix' above).")
    else:
        lines.append("\nambfplus can render here.")
    return "\n".join(lines)


def main(as_json: bool = False) -> int:
    """Prints the report; 0 when the engine can render, 1 when something required is missing."""
    checks = diagnose()
    if as_json:
        print(json.dumps([{**asdict(c), "failed": c.failed} for c in checks], indent=2))
    else:
        print(report(checks))
    return 1 if any(c.failed for c in checks) else 0
