"""Fuzz targets: each turns one input (bytes) into files and hands them to a reader through the
public Python API. A target returns normally when the reader accepts the input or raises an
``ambfplus.Error`` (a typed, named error); anything else (another exception, a crash, a hang)
is a finding. The fuzzers (``fuzz.py``) and the regression test replay the same functions."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

import ambfplus
from ambfplus.recording import open_recording, validate

# One scratch folder per process, emptied for every input.
_SCRATCH = Path(tempfile.mkdtemp(prefix="ambfplus-fuzz-"))


def scratch() -> Path:
    """An empty folder for this input's files."""
    for entry in _SCRATCH.iterdir():
        if entry.is_dir():
            shutil.rmtree(entry)
        else:
            entry.unlink()
    return _SCRATCH


def split(data: bytes, parts: int) -> list[bytes]:
    """The input cut into `parts` pieces at the separator b"\\n--8<--\\n" (missing pieces
    empty), so one input can hold several files and mutations move bytes between them."""
    pieces = data.split(b"\n--8<--\n", parts - 1)
    return pieces + [b""] * (parts - len(pieces))


def nrrd(data: bytes) -> None:
    """load_nrrd on the input (auto kind; a detached data file when the input has a second
    piece), then the same file as labels and as intensities."""
    header, detached = split(data, 2)
    folder = scratch()
    path = folder / "input.nrrd"
    path.write_bytes(header)
    (folder / "data.raw").write_bytes(detached)
    for options in ({}, {"kind": "labels"}, {"threshold": 100.0}):
        try:
            volume = ambfplus.load_nrrd(path, **options)
        except ambfplus.Error:
            continue
        labels = np.asarray(volume.labels)
        assert labels.shape == tuple(volume.shape)
        assert np.isfinite(volume.dimensions).all() and (np.asarray(volume.dimensions) > 0).all()
        assert np.isfinite(volume.patient_from_volume).all()
        for label in volume.label_table:
            label.name.encode("utf-8")


def slice_stack(data: bytes) -> None:
    """load_slice_stack on up to four slice images cut from the input; the first byte picks the
    count and alpha threshold."""
    if not data:
        return
    control, images = data[0], split(data[1:], 4)
    folder = scratch() / "slices"
    folder.mkdir()
    for k, image in enumerate(images):
        if image:
            (folder / f"plane00{k}.png").write_bytes(image)
    count = (-1, 1, 2, 3, 0, 5, -2, 2)[control & 7]
    alpha = (128, 0, 255, 300, -1, 1, 128, 200)[(control >> 3) & 7]
    try:
        volume = ambfplus.load_slice_stack(
            folder, count=count, alpha_threshold=alpha, dimensions=(0.01, 0.01, 0.01)
        )
    except ambfplus.Error:
        return
    assert np.asarray(volume.labels).shape == tuple(volume.shape)


def recording(data: bytes) -> None:
    """open_recording and validate on a head and parts cut from the input, reading every frame
    and column."""
    pieces = split(data, 3)
    folder = scratch()
    head = folder / "session.h5"
    head.write_bytes(pieces[0])
    for number, piece in enumerate(pieces[1:], start=1):
        if piece:
            (folder / f"session.h5.part{number:04d}").write_bytes(piece)
    try:
        with open_recording(head) as rec:
            for stream in rec.cameras.values():
                for i in range(len(stream)):
                    frame = stream[i]
                    for name in stream.passes:
                        getattr(frame, name)
            for rig in rec.rigs.values():
                for i in range(len(rig)):
                    rig[i]
            for column in rec.steps.values():
                np.asarray(column)
            rec.removed, rec.events, rec.metadata, rec.legend  # noqa: B018
    except ambfplus.Error:
        return
    report = validate(head, match_images=False)
    str(report)


def adf(data: bytes) -> None:
    """World.load_adf on the input as a model file, then a few steps of the world it made."""
    folder = scratch()
    path = folder / "model.yaml"
    path.write_bytes(data)
    world = ambfplus.World()
    try:
        world.load_adf(path)
    except ambfplus.Error:
        return
    for obj in world.objects:
        obj.name.encode("utf-8")
    world.step(5)


# The mesh formats the mesh target writes, picked by the input's first byte.
MESH_FORMATS = (".ply", ".obj", ".stl", ".off")


def mesh(data: bytes) -> None:
    """add_body on a mesh file made of the input after its first byte, which picks the format
    (the file's extension: PLY, OBJ, STL or OFF), then a step of the world it is in."""
    if not data:
        return
    path = scratch() / ("input" + MESH_FORMATS[data[0] % len(MESH_FORMATS)])
    path.write_bytes(data[1:])
    world = ambfplus.World()
    try:
        body = world.add_body("b", mesh=path)
    except ambfplus.Error:
        return
    world.step(1)
    assert np.isfinite(body.pose).all()


TARGETS = {
    "nrrd": nrrd,
    "slice_stack": slice_stack,
    "recording": recording,
    "adf": adf,
    "mesh": mesh,
}
CORPUS = Path(__file__).resolve().parent / "corpus"


def corpus_files(target: str) -> list[Path]:
    """The regression corpus of a target: seeds and every input a fuzzer found."""
    folder = CORPUS / target
    return sorted(p for p in folder.iterdir() if p.is_file()) if folder.is_dir() else []


def replay(target: str) -> int:
    """Runs every corpus input of a target; returns how many ran."""
    function = TARGETS[target]
    files = corpus_files(target)
    for path in files:
        try:
            function(path.read_bytes())
        except Exception as error:
            raise AssertionError(f"{target}: corpus input {path.name} raised {error!r}") from error
    return len(files)


if __name__ == "__main__":  # python targets.py TARGET: replay its corpus (in its own process)
    import sys

    print(f"{sys.argv[1]}: {replay(sys.argv[1])} inputs replayed", flush=True)
    os._exit(0)
