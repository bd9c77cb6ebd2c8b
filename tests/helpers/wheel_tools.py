"""Helpers shared by the wheel's tests and its benchmark: build the wheel (.ci/build-wheel),
download its Python dependencies for an interpreter, install it into a fresh venv offline."""

from __future__ import annotations

import email.parser
import os
import re
import subprocess
import sys
import time
import venv
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
BUILD_WHEEL = REPO / ".ci" / "build-wheel"


def wheel_or_build(folder: Path) -> Path:
    """The wheel named by AMBFPLUS_WHEEL, else one built from this repository into `folder`."""
    given = os.environ.get("AMBFPLUS_WHEEL")
    if given:
        return Path(given).resolve()
    result = subprocess.run(
        [sys.executable, str(BUILD_WHEEL), "--out", str(folder)],
        capture_output=True,
        text=True,
        cwd=REPO,
    )
    if result.returncode != 0:
        raise RuntimeError(
            f".ci/build-wheel failed:\n{result.stdout[-4000:]}\n{result.stderr[-4000:]}"
        )
    return Path(result.stdout.strip().splitlines()[-1])


def requirements(wheel: Path) -> list[str]:
    """The wheel's unconditional dependencies (Requires-Dist without an extra)."""
    with zipfile.ZipFile(wheel) as archive:
        name = next(n for n in archive.namelist() if n.endswith(".dist-info/METADATA"))
        metadata = email.parser.Parser().parsestr(archive.read(name).decode())
    return [
        r.split(";")[0].strip() for r in metadata.get_all("Requires-Dist") or [] if "extra" not in r
    ]


def manylinux_platforms(glibc: tuple[int, int], machine: str = "x86_64") -> list[str]:
    """Every manylinux platform tag a glibc of this version runs (pip does not expand them)."""
    major, minor = glibc
    tags = [f"manylinux_{major}_{m}_{machine}" for m in range(minor, 4, -1)]
    return tags + [
        f"{alias}_{machine}" for alias in ("manylinux2014", "manylinux2010", "manylinux1")
    ]


def download_wheelhouse(
    wheel: Path, folder: Path, python: tuple[int, int], glibc: tuple[int, int]
) -> Path:
    """Downloads the wheel's dependencies (binary wheels only) for a Python and glibc into
    `folder`, so the wheel installs offline; raises RuntimeError when pip cannot."""
    platforms = [arg for tag in manylinux_platforms(glibc) for arg in ("--platform", tag)]
    command = [sys.executable, "-m", "pip", "download", "-q", "--only-binary=:all:",
               "--python-version", f"{python[0]}.{python[1]}", *platforms, "-d", str(folder),
               *requirements(wheel)]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True)
    if result.returncode != 0:
        raise RuntimeError(f"pip download failed: {result.stderr.strip()[-2000:]}")
    return folder


def install_into_new_venv(folder: Path, wheel: Path, wheelhouse: Path) -> tuple[Path, float]:
    """A fresh venv (no system packages) with the wheel installed offline from the wheelhouse;
    returns its python and the seconds `pip install` took."""
    venv.EnvBuilder(with_pip=True, clear=True).create(folder)
    python = folder / "bin" / "python"
    start = time.perf_counter()
    subprocess.run(
        [str(python), "-m", "pip", "install", "-q", "--no-index", "--find-links", str(wheelhouse),
         str(wheel)],
        check=True, capture_output=True, text=True,
        # No configured index or find-links: the wheelhouse alone.
        env={**os.environ, "PIP_CONFIG_FILE": os.devnull},
    )  # fmt: skip
    return python, time.perf_counter() - start


def glibc_version() -> tuple[int, int]:
    """This machine's glibc as (major, minor)."""
    import platform

    major, minor = re.match(r"(\d+)\.(\d+)", platform.libc_ver()[1]).groups()
    return int(major), int(minor)
