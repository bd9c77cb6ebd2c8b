"""The committed type stubs are the ones the installed extension module generates."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
from helpers import REPO

ROOT = REPO


def test_generated_stubs_match_the_module(tmp_path):
    pytest.importorskip("pybind11_stubgen", reason="pip install 'ambfplus[test]' brings it")
    result = subprocess.run(
        [sys.executable, str(ROOT / ".ci" / "stubs"), "--check"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stdout[-20000:] + result.stderr


def test_package_ships_the_stubs():
    import ambfplus

    package = Path(ambfplus.__file__).parent
    assert (package / "py.typed").exists()
    installed = (package / "_core.pyi").read_text()
    assert installed == (ROOT / "ambfplus" / "_core.pyi").read_text(), (
        "the installed stubs differ from the source tree's: reinstall (pip install .)"
    )
