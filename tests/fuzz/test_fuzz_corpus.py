"""The fuzzers' regression corpus (tests/fuzz/corpus: seeds and every input a fuzzer found),
replayed through the same targets the fuzzers run, each target in its own process so that a
crash fails only its test; and, marked ``fuzz``, a minute of fuzzing per reader."""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

FUZZ = Path(__file__).resolve().parent
TARGETS = ["nrrd", "slice_stack", "recording", "adf", "mesh"]


@pytest.mark.parametrize("target", TARGETS)
def test_every_corpus_input_is_accepted_or_a_typed_error(target):
    inputs = list((FUZZ / "corpus" / target).iterdir())
    assert inputs, f"the {target} corpus is empty"
    done = subprocess.run(
        [sys.executable, str(FUZZ / "targets.py"), target],
        capture_output=True, text=True, timeout=600, cwd=FUZZ,
    )  # fmt: skip
    assert done.returncode == 0, f"exit code {done.returncode}:\n{done.stdout}\n{done.stderr}"
    assert f"{target}: {len(inputs)} inputs replayed" in done.stdout


# Every reader, the recording reader included: libhdf5 loops forever on a damaged global heap,
# which the reader no longer meets unchecked (ambfplus/recording/hdf5.py).
FUZZED_IN_CI = TARGETS


def keep_findings(target: str, work: Path) -> str:
    """Copies every finding of a fuzzing run into the kept folder (AMBFPLUS_FUZZ_FOUND, default
    tests/fuzz/found/, when writable: CI keeps it as an artifact) and describes each with its
    bytes in base64, so that the test's log alone reproduces it after pytest's tmp_path is gone."""
    kept = Path(os.environ.get("AMBFPLUS_FUZZ_FOUND", FUZZ / "found")) / target
    lines = []
    for finding in sorted(work.glob("finding-*")):
        data = finding.read_bytes()
        try:
            kept.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(finding, kept / finding.name)
            where = f"kept as {kept / finding.name}"
        except OSError as error:
            where = f"not kept ({error})"
        lines.append(
            f"{finding.name} ({len(data)} bytes, {where}); to replay it, decode into "
            f"tests/fuzz/corpus/{target}/:\n{base64.b64encode(data).decode()}"
        )
    return "\n".join(lines)


@pytest.mark.fuzz
@pytest.mark.slow  # a minute each
@pytest.mark.parametrize("target", FUZZED_IN_CI)
def test_a_minute_of_fuzzing_finds_nothing(target, tmp_path):
    pytest.importorskip("atheris", reason='fuzzing needs atheris: pip install "ambfplus[fuzz]"')
    done = subprocess.run(
        [sys.executable, str(FUZZ / "fuzz.py"), target, "--seconds", "60", "--work", str(tmp_path)],
        capture_output=True, text=True, timeout=600, cwd=FUZZ,
    )  # fmt: skip
    findings = keep_findings(target, tmp_path / target)
    log = tmp_path / target / "fuzz.log"
    tail = log.read_text()[-4000:] if log.exists() else done.stderr[-4000:]
    assert not findings, f"{findings}\n\nfuzzer log (tail):\n{tail}"
    lines = done.stdout.strip().splitlines()
    assert lines, f"fuzz.py printed nothing (exit code {done.returncode}):\n{done.stderr[-4000:]}"
    result = json.loads(lines[-1])
    assert result["executed"] > 0, done.stdout + done.stderr
    assert done.returncode == 0 and result["exit_code"] == 0, (result, tail)


def test_a_finding_is_kept_and_printed_in_base64(tmp_path, monkeypatch):
    work = tmp_path / "work" / "nrrd"
    work.mkdir(parents=True)
    (work / "finding-crash-abc").write_bytes(b"NRRD0004\n\xff\x00")
    (work / "corpus").mkdir()
    monkeypatch.setenv("AMBFPLUS_FUZZ_FOUND", str(tmp_path / "kept"))
    report = keep_findings("nrrd", work)
    assert (tmp_path / "kept" / "nrrd" / "finding-crash-abc").read_bytes() == b"NRRD0004\n\xff\x00"
    assert base64.b64decode(report.splitlines()[-1]) == b"NRRD0004\n\xff\x00"
    assert "finding-crash-abc (11 bytes, kept as" in report
    assert keep_findings("nrrd", tmp_path / "nothing") == ""
