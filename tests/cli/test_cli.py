"""The main job: ambfplus demo renders the built-in scene headless to checked images."""

from __future__ import annotations

import json
import subprocess
import sys
import zlib

import numpy as np
import pytest

from ambfplus.cli import main
from ambfplus.cli.demo import DEPTH_PNG_SCALE


def read_png(path) -> np.ndarray:
    """A minimal PNG reader (8/16-bit grey or RGB, no interlace), so the check does not trust
    the writer's own library."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, chunks = 8, {}
    idat = b""
    while pos < len(data):
        length = int.from_bytes(data[pos : pos + 4], "big")
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IDAT":
            idat += body
        else:
            chunks[kind] = body
        pos += 12 + length
    ihdr = chunks[b"IHDR"]
    width, height = int.from_bytes(ihdr[0:4], "big"), int.from_bytes(ihdr[4:8], "big")
    bits, color_type = ihdr[8], ihdr[9]
    channels = {0: 1, 2: 3, 6: 4}[color_type]
    bpp = channels * bits // 8
    raw = zlib.decompress(idat)
    stride = width * bpp
    out = np.zeros((height, stride), np.uint8)
    prev = np.zeros(stride, np.int32)
    for r in range(height):
        f = raw[r * (stride + 1)]
        line = np.frombuffer(raw, np.uint8, stride, r * (stride + 1) + 1).astype(np.int32)
        cur = np.zeros(stride, np.int32)
        for i in range(stride):
            a = cur[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 0:
                pred = 0
            elif f == 1:
                pred = a
            elif f == 2:
                pred = b
            elif f == 3:
                pred = (a + b) // 2
            else:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
            cur[i] = (line[i] + pred) & 0xFF
        out[r] = cur
        prev = cur
    if bits == 16:
        return out.view(">u2").reshape(height, width, channels).astype(np.uint16).squeeze()
    return out.reshape(height, width, channels).squeeze()


@pytest.mark.slow
def test_demo_records_a_checked_drilling_session(tmp_path):
    out = tmp_path / "demo"
    args = ["demo", "--out", str(out), "--width", "160", "--height", "120"]
    assert main(args + ["--resolution", "64", "--every", "200"]) == 0
    rgb = read_png(out / "rgb.png")
    depth = read_png(out / "depth.png")
    meta = json.loads((out / "frame.json").read_text())
    assert rgb.shape == (120, 160, 3) and rgb.dtype == np.uint8
    assert depth.shape == (120, 160) and depth.dtype == np.uint16
    assert rgb.std() > 5
    # The rig circles 250 mm from the phantom's centre, as the paper's rig.
    metres = depth[depth > 0] / DEPTH_PNG_SCALE
    assert 0.2 < np.median(metres) < 0.3
    assert meta["width"] == 160 and len(meta["intrinsics"]) == 3
    assert (out / "depth_preview.png").stat().st_size > 100
    assert read_png(out / "montage.png").shape == (120, 480, 3)
    recording = meta["recording"]
    assert recording["voxels_removed"] > 0 and recording["frames"] == -(-recording["steps"] // 200)
    assert (out / "validation.txt").read_text().startswith(str(out / "session.h5"))
    from ambfplus.recording import open_recording, validate

    assert validate(out / "session.h5").ok
    with open_recording(out / "session.h5") as rec:
        assert len(rec.removed["step"]) == recording["voxels_removed"]
        assert len(rec.rigs["rig"]) == recording["frames"]
        # What a new user sees is drawn as the launcher draws it, and the recording says so.
        params = rec.metadata["scene"]["params"]
        assert (params["shadows"], params["antialiasing"], params["looks"]) == (True, 2, True)


def test_demo_runs_as_a_module(tmp_path):
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "ambfplus",
            "demo",
            "--out",
            str(tmp_path),
            "--width",
            "32",
            "--height",
            "24",
            "--resolution",
            "48",
            "--every",
            "500",
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,  # away from the source folder, which shadows the installed package
    )
    assert out.returncode == 0, out.stderr
    assert "covers" in out.stdout and "voxels removed" in out.stdout


def test_demo_fails_on_an_empty_render(tmp_path, monkeypatch, capsys):
    import ambfplus.scenes

    # The rig looks away from the anatomy.
    monkeypatch.setattr(ambfplus.scenes, "orbit_view", lambda t: ((0, 0, 0.3), (0, 1.0, 0.3)))
    args = ["demo", "--out", str(tmp_path), "--width", "32", "--height", "24"]
    assert main(args + ["--resolution", "48", "--every", "500"]) == 1
    assert "the render is empty" in capsys.readouterr().err


def test_info_prints_version_and_renderer(capsys):
    assert main(["info"]) == 0
    info = json.loads(capsys.readouterr().out)
    assert info["gl"]["renderer"] and info["version"]


@pytest.mark.parametrize(
    "option, value, message",
    [
        ("--every", "0", "argument --every: expected 1..1000, got 0"),
        ("--resolution", "1024", "argument --resolution: expected 8..512, got 1024"),
        ("--width", "-5", "argument --width: expected 8..4096, got -5"),
        ("--height", "tall", "argument --height: expected an integer, got 'tall'"),
    ],
)
def test_demo_refuses_values_it_cannot_honour(option, value, message, capsys, tmp_path):
    """--every 0 never reached a frame (the demo stepped forever at step 0); each bad value is
    now a one-line usage error (exit 2) before anything runs."""
    with pytest.raises(SystemExit) as exit_:
        main(["demo", "--out", str(tmp_path / "demo"), option, value])
    assert exit_.value.code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "demo").exists()
