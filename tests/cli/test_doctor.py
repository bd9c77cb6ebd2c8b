"""`ambfplus doctor`: what the engine finds here, and on a machine without an EGL driver, that it
says so, says what to install, and exits non-zero."""

from __future__ import annotations

import json
import os
import subprocess
import sys


def doctor(tmp_path, *args: str, env: dict[str, str] | None = None):
    # Run from elsewhere: in the repository, `-m ambfplus` would find the source folder.
    return subprocess.run(
        [sys.executable, "-m", "ambfplus", "doctor", *args],
        capture_output=True, text=True, cwd=tmp_path, env={**os.environ, **(env or {})},
    )  # fmt: skip


def test_doctor_reports_the_renderer_and_exits_zero_where_it_can_render(tmp_path):
    result = doctor(tmp_path, "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    checks = {c["name"]: c for c in json.loads(result.stdout)}
    assert checks["renderer"]["status"] == "ok"
    import ambfplus

    assert ambfplus.gl_info()["renderer"] in checks["renderer"]["found"]
    assert checks["EGL drivers"]["status"] == "ok" and ".json" in checks["EGL drivers"]["found"]
    assert not any(c["failed"] for c in checks.values())


def test_doctor_without_an_egl_driver_says_what_to_install_and_fails(tmp_path):
    empty = tmp_path / "no_vendors"
    empty.mkdir()
    result = doctor(tmp_path, env={"__EGL_VENDOR_LIBRARY_DIRS": str(empty)})
    assert result.returncode == 1, result.stdout + result.stderr
    assert f"no EGL vendor file in __EGL_VENDOR_LIBRARY_DIRS ({empty})" in result.stdout
    assert "no EGL driver is installed" in result.stdout
    assert "to fix:" in result.stdout and "libegl-mesa0" in result.stdout
    assert "cannot render here: EGL drivers, renderer" in result.stdout
