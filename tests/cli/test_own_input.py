"""No command writes over its own input: export, replay and convert refuse an output that is
their input, lies inside it or holds it, with --force or without, before anything is touched."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus.cli import main
from ambfplus.recording import Recorder


def digest(*roots: Path) -> dict[str, str]:
    """SHA-256 of every file under (or at) the roots, by path."""
    out = {}
    for root in roots:
        files = [root] if root.is_file() else sorted(p for p in root.rglob("*") if p.is_file())
        for path in files:
            out[str(path)] = hashlib.sha256(path.read_bytes()).hexdigest()
    return out


@pytest.fixture()
def recording(tmp_path) -> Path:
    """A recording of two parts (a step log only: the refusal comes before it is read)."""
    path = tmp_path / "session.h5"
    with Recorder(path, metadata={"run": "own input"}) as rec:
        for part in range(2):
            steps = np.arange(10 * part, 10 * part + 10)
            rec.add_steps({"step": steps, "time": steps * 1e-3})
            rec.flush()
    assert len(list(tmp_path.glob("session.h5.part*"))) == 2
    return path


def refused(capsys, *argv: str) -> str:
    """Runs the command; asserts it fails (status 2) with one line naming the refusal."""
    assert main(list(argv)) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "never writes over its own input" in err, err
    return err


def test_export_and_replay_refuse_the_recording_and_its_parts(recording, capsys):
    before = digest(recording.parent)
    part = Path(f"{recording}.part0001")
    for out in (recording, part):
        for to in ("mcap", "original-h5"):
            err = refused(capsys, "export", str(recording), "--to", to, str(out), "--force")
            assert f"the output is the input {out}" in err
    # A link to the head is the head.
    link = recording.parent / "link.h5"
    os.symlink(recording, link)
    refused(capsys, "export", str(recording), "--to", "mcap", str(link), "--force")
    # A folder holding the recording would be replaced by the export's folder.
    err = refused(capsys, "export", str(recording), "--to", "coco", str(recording.parent),
                  "--force")  # fmt: skip
    assert "holds the input" in err
    for out in (recording, part):
        refused(capsys, "replay", str(recording), "--out", str(out))
    link.unlink()
    assert digest(recording.parent) == before
    # Beside it is fine: the rule refuses the input only.
    assert main(["export", str(recording), "--to", "original-h5", str(recording.parent / "o")]) == 0


def test_a_dataset_folder_is_not_exported_into_itself(tmp_path, capsys):
    dataset = tmp_path / "dataset"
    (dataset / "shards").mkdir(parents=True)
    (dataset / "manifest.jsonl").write_text('{"episode": 0}\n')
    (dataset / "shards" / "episode_000000.h5").write_bytes(b"not read")
    before = digest(dataset)
    for out in (dataset, dataset / "shards", dataset / "coco"):
        err = refused(capsys, "export", str(dataset), "--to", "coco", str(out), "--force")
        assert "the output is the input" in err or "lies inside the input" in err
    refused(capsys, "export", str(dataset), "--to", "coco", str(tmp_path), "--force")
    assert digest(dataset) == before


def test_convert_refuses_its_source_and_the_slices_an_adf_names(tmp_path, capsys):
    nrrd = tmp_path / "ear.nrrd"
    ambfplus.phantom(16).save_nrrd(nrrd)
    slices = tmp_path / "slices"
    assert main(["convert", str(nrrd), str(slices)]) == 0
    capsys.readouterr()
    adf = slices / "volume.yaml"
    before = digest(nrrd, slices)
    refused(capsys, "convert", str(nrrd), str(nrrd))
    refused(capsys, "convert", str(slices), str(slices))
    refused(capsys, "convert", str(slices), str(slices / "more"))
    refused(capsys, "convert", str(adf), str(slices))  # the folder its images are in
    refused(capsys, "convert", str(adf), str(slices / "ear.nrrd"))
    refused(capsys, "convert", str(nrrd), str(tmp_path))
    assert digest(nrrd, slices) == before
    # The API refuses the same, with the same error.
    with pytest.raises(ambfplus.fileio.OwnInputError, match="never writes over its own input"):
        ambfplus.volumes.convert_volume(adf, slices)
    assert main(["convert", str(adf), str(tmp_path / "again.nrrd")]) == 0
    again = ambfplus.volumes.load_volume(tmp_path / "again.nrrd")
    assert np.array_equal(np.asarray(again.labels), np.asarray(ambfplus.phantom(16).labels))
