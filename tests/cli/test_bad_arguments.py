"""Every command fails in one line (#33): each subcommand run on bad arguments (missing files,
folders for files, files that are not what the command reads, damaged specs and dataset
folders, wrong values, outputs it cannot write) exits with status 2 and one line on stderr that
names the file or argument, with no traceback; ``ambfplus --debug`` shows the traceback.

The cases run ``ambfplus.cli.main`` in this process (fast); a few run the real entry points
(``python -m ambfplus`` and the ``ambfplus`` script) to show they behave the same.
"""

from __future__ import annotations

import contextlib
import errno
import os
import pathlib
import shutil
import stat
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

import ambfplus
from ambfplus.cli import main
from ambfplus.recording import Recorder

# A spec that checks (and so reaches what comes after it).
SPEC = "version: 1\nepisodes: 1\nanatomies: [{phantom: {resolution: 16}}]\n"


def spec(**replace: str) -> str:
    """SPEC with lines replaced (key -> the whole new line) or added."""
    lines = dict(line.split(":", 1) for line in SPEC.splitlines())
    for key, value in replace.items():
        lines[key] = value
    return "".join(f"{key}:{value}\n" for key, value in lines.items())


# Files the cases name (placeholder: the name with "_" for "."): text (str) or bytes.
FILES: dict[str, str | bytes] = {
    "text": "hello\n",
    "empty": "",
    "garbage.h5": b"\x89HDF\r\n\x1a\n" + bytes(range(256)) * 2,
    "latin1.yaml": "version: 1\nname: caf\xe9\n".encode("latin-1"),
    "broken.yaml": "version: 1\nepisodes: [1,\n",
    "list.yaml": "- 1\n- 2\n",
    "spec.yaml": SPEC,
    "deep.yaml": "a: " + "[" * 3000 + "]" * 3000 + "\n",
    "bomb.yaml": "a0: &a0 [x, x]\na1: &a1 [*a0, *a0]\nversion: 1\n",
    "dup.yaml": SPEC + "episodes: 5\n",
    "big.yaml": SPEC + "# " + "x" * (1 << 20) + "\n",
    "v2.yaml": spec(version=" 2"),
    "episodes0.yaml": spec(episodes=" 0"),
    "episodes1e12.yaml": spec(episodes=" 1e12"),
    "episodes_huge.yaml": spec(episodes=" " + "9" * 40),
    "resolution.yaml": SPEC + "rigs: [{resolution: [16384, 16384]}]\n",
    "every0.yaml": SPEC + "capture: {every: 0}\n",
    "every1e12.yaml": SPEC + "capture: {every: 1000000000000}\n",
    "phantom1024.yaml": spec(anatomies=" [{phantom: {resolution: 1024}}]"),
    "phantom8.yaml": spec(anatomies=" [{phantom: {resolution: 8}}]"),
    "phantom_seed.yaml": spec(anatomies=" [{phantom: {seed: 99999999999}}]"),
    "seed_huge.yaml": SPEC + "seed: " + "9" * 30 + "\n",
    "baseline_huge.yaml": SPEC + "rigs: [{baseline: " + "9" * 400 + "}]\n",
    "baseline_nan.yaml": SPEC + "rigs: [{baseline: .nan}]\n",
    "weight_huge.yaml": spec(anatomies=" [{phantom: {}, weight: 1.0e+300}]"),
    "unknown_key.yaml": SPEC + "episode: 3\n",
    "nested_key.yaml": spec(anatomies=" [{phantom: {resolutoin: 64}}]"),
    "anatomy_missing.yaml": spec(anatomies=" [{file: no_such_ear.nrrd}]"),
    "anatomy_nul.yaml": spec(anatomies=' [{file: "ear\\0.nrrd"}]'),
    "anatomy_long.yaml": spec(anatomies=" [{file: " + "a" * 5000 + "}]"),
    "passes.yaml": SPEC + "capture: {passes: [rgb, rgb]}\n",
    "python_tag.yaml": SPEC + "name: !!python/object/apply:os.system [echo]\n",
    "control.yaml": SPEC + 'name: "\\x07"\n' + "seed: \x01\n",
    "launch_list.yaml": "- a\n- b\n",
    "labels.csv": "id,name\n1,caf\xe9\n".encode("latin-1"),
    "cohort.csv": "who,when\nx,y\n",
    "task_broken.yaml": "version: 1\nname: [x\n",
}


@pytest.fixture(scope="module")
def fx(tmp_path_factory) -> dict[str, str]:
    """The placeholders' paths: FILES, and folders, FIFOs, a recording, a phantom NRRD and
    dataset folders damaged in one way each."""
    root = tmp_path_factory.mktemp("bad_arguments")
    paths = {"root": str(root), "missing": str(root / "missing.h5")}
    for name, content in FILES.items():
        path = root / name
        if isinstance(content, bytes):
            path.write_bytes(content)
        else:
            path.write_text(content)
        paths[name.replace(".", "_")] = str(path)
    (root / "folder").mkdir()
    paths["folder"] = str(root / "folder")
    os.mkfifo(root / "fifo.h5")
    paths["fifo"] = str(root / "fifo.h5")
    os.mkfifo(root / "fifo.yaml")
    paths["fifo_yaml"] = str(root / "fifo.yaml")
    paths["under_file"] = str(root / "text" / "out")
    paths["session"] = str(root / "session.h5")
    with Recorder(root / "session.h5", metadata={"run": "bad arguments"}) as rec:
        steps = np.arange(10)
        rec.add_steps({"step": steps, "time": steps * 1e-3})
    ambfplus.phantom(16).save_nrrd(root / "ear.nrrd")
    paths["nrrd"] = str(root / "ear.nrrd")
    environments: dict[str, str | bytes] = {
        "ds_list": "[1, 2]",
        "ds_not_json": "{episodes: 2",
        "ds_latin1": b'{"episodes": "\xff"}',
        "ds_no_episodes": "{}",
        "ds_episodes_text": '{"episodes": "many"}',
        "ds_episodes_null": '{"episodes": null}',
        "ds_deep": "[" * 100000 + "]" * 100000,
        "ds_spec_list": '{"episodes": 1, "spec": [1]}',
    }
    for name, content in environments.items():
        folder = root / name
        folder.mkdir()
        env = folder / "environment.json"
        if isinstance(content, bytes):
            env.write_bytes(content)
        else:
            env.write_text(content)
        paths[name] = str(folder)
    (root / "ds_env_folder" / "environment.json").mkdir(parents=True)
    paths["ds_env_folder"] = str(root / "ds_env_folder")
    (root / "ds_env_fifo").mkdir()
    os.mkfifo(root / "ds_env_fifo" / "environment.json")
    paths["ds_env_fifo"] = str(root / "ds_env_fifo")
    return paths


# (id, argv with {placeholders}, what the line must name). Status 2 and one line for every case.
# fmt: off
CASES = [
    # the command line itself
    ("no-command", [], "command"),
    ("unknown-command", ["drill"], "'drill'"),
    ("debug-alone", ["--debug"], "command"),
    ("unknown-global-option", ["--verbose", "info"], "--verbose"),
    ("dataset-no-subcommand", ["dataset"], "dataset_command"),
    ("dataset-unknown-subcommand", ["dataset", "list"], "'list'"),
    # info, doctor
    ("info-extra-argument", ["info", "now"], "now"),
    ("info-unknown-option", ["info", "--json"], "--json"),
    ("doctor-unknown-option", ["doctor", "--fix"], "--fix"),
    ("doctor-extra-argument", ["doctor", "gpu"], "gpu"),
    # demo (argument errors only: it never gets to build its scene)
    ("demo-every-0", ["demo", "--out", "{root}/d", "--every", "0"], "--every"),
    ("demo-every-word", ["demo", "--out", "{root}/d", "--every", "often"], "--every"),
    ("demo-resolution-1024", ["demo", "--out", "{root}/d", "--resolution", "1024"], "--resolution"),
    ("demo-resolution-8", ["demo", "--out", "{root}/d", "--resolution", "8"], "resolution"),
    ("demo-width-negative", ["demo", "--out", "{root}/d", "--width", "-5"], "--width"),
    ("demo-height-word", ["demo", "--out", "{root}/d", "--height", "tall"], "--height"),
    ("demo-out-is-a-file", ["demo", "--out", "{text}"], "{text}"),
    ("demo-out-under-a-file", ["demo", "--out", "{under_file}"], "{under_file}"),
    ("demo-out-not-permitted", ["demo", "--out", "/sys/ambfplus-demo"], "/sys/ambfplus-demo"),
    ("demo-out-is-a-fifo", ["demo", "--out", "{fifo}"], "{fifo}"),
    # validate: a folder must be a dataset; a file is checked as a recording and a dataset's
    # damaged values are reported (its report, status 1, is not an error)
    ("validate-folder", ["validate", "{folder}"], "{folder}"),
    ("validate-env-not-json", ["validate", "{ds_not_json}"], "{ds_not_json}"),
    ("validate-env-not-utf8", ["validate", "{ds_latin1}"], "{ds_latin1}"),
    ("validate-env-deep", ["validate", "{ds_deep}", "--json"], "{ds_deep}"),
    ("validate-env-is-a-folder", ["validate", "{ds_env_folder}"], "{ds_env_folder}"),
    ("validate-env-is-a-fifo", ["validate", "{ds_env_fifo}"], "{ds_env_fifo}"),
    ("validate-no-path", ["validate"], "recording"),
    # dataset info
    ("info-missing", ["dataset", "info", "{missing}"], "{missing}"),
    ("info-file", ["dataset", "info", "{text}"], "{text}"),
    ("info-folder", ["dataset", "info", "{folder}"], "{folder}"),
    ("info-fifo", ["dataset", "info", "{fifo}"], "{fifo}"),
    ("info-env-list", ["dataset", "info", "{ds_list}"], "{ds_list}"),
    ("info-env-not-json", ["dataset", "info", "{ds_not_json}"], "{ds_not_json}"),
    ("info-env-not-utf8", ["dataset", "info", "{ds_latin1}", "--json"], "{ds_latin1}"),
    ("info-env-no-episodes", ["dataset", "info", "{ds_no_episodes}"], "{ds_no_episodes}"),
    ("info-env-deep", ["dataset", "info", "{ds_deep}"], "{ds_deep}"),
    ("info-env-spec-list", ["dataset", "info", "{ds_spec_list}"], "{ds_spec_list}"),
    ("info-env-is-a-folder", ["dataset", "info", "{ds_env_folder}"], "{ds_env_folder}"),
    # replay
    ("replay-missing", ["replay", "{missing}"], "{missing}"),
    ("replay-folder", ["replay", "{folder}"], "{folder}"),
    ("replay-garbage", ["replay", "{garbage_h5}"], "{garbage_h5}"),
    ("replay-empty", ["replay", "{empty}"], "{empty}"),
    ("replay-text", ["replay", "{text}"], "{text}"),
    ("replay-fifo", ["replay", "{fifo}"], "{fifo}"),
    ("replay-no-scene", ["replay", "{session}"], "{session}"),
    ("replay-onto-itself", ["replay", "{session}", "--out", "{session}"], "{session}"),
    ("replay-width-word", ["replay", "{session}", "--width", "wide"], "--width"),
    ("replay-baseline-word", ["replay", "{session}", "--baseline", "far"], "--baseline"),
    # assess
    ("assess-nothing", ["assess"], "--group"),
    ("assess-missing", ["assess", "{missing}"], "{missing}"),
    ("assess-folder", ["assess", "{folder}"], "{folder}"),
    ("assess-garbage", ["assess", "{garbage_h5}"], "{garbage_h5}"),
    ("assess-fifo", ["assess", "{fifo}"], "{fifo}"),
    ("assess-no-scene", ["assess", "{session}"], "{session}"),
    ("assess-session-and-group", ["assess", "{session}", "--group", "{folder}"], "--group"),
    ("assess-group-missing", ["assess", "--group", "{missing}"], "{missing}"),
    ("assess-group-not-a-cohort", ["assess", "--group", "{cohort_csv}"], "{cohort_csv}"),
    ("assess-task-unknown", ["assess", "{session}", "--task", "cortical"], "cortical"),
    ("assess-task-missing", ["assess", "{session}", "--task", "{root}/no_task.yaml"],
     "no_task.yaml"),
    ("assess-task-broken", ["assess", "{session}", "--task", "{task_broken_yaml}"],
     "{task_broken_yaml}"),
    ("assess-task-not-utf8", ["assess", "{session}", "--task", "{latin1_yaml}"], "{latin1_yaml}"),
    ("assess-task-deep", ["assess", "{session}", "--task", "{deep_yaml}"], "{deep_yaml}"),
    ("assess-task-alias", ["assess", "{session}", "--task", "{bomb_yaml}"], "{bomb_yaml}"),
    ("assess-task-fifo", ["assess", "{session}", "--task", "{fifo_yaml}"], "{fifo_yaml}"),
    ("assess-task-folder", ["assess", "{session}", "--task", "{folder}"], "{folder}"),
    # convert
    ("convert-missing", ["convert", "{missing}", "{root}/c1"], "{missing}"),
    ("convert-text", ["convert", "{text}", "{root}/c2"], "{text}"),
    ("convert-folder-no-size", ["convert", "{folder}", "{root}/c3.nrrd"], "{folder}"),
    ("convert-not-utf8-adf", ["convert", "{latin1_yaml}", "{root}/c4"], "{latin1_yaml}"),
    ("convert-broken-adf", ["convert", "{broken_yaml}", "{root}/c5"], "{broken_yaml}"),
    ("convert-fifo", ["convert", "{fifo}", "{root}/c6"], "{fifo}"),
    ("convert-garbage", ["convert", "{garbage_h5}", "{root}/c7"], "{garbage_h5}"),
    ("convert-unknown-output", ["convert", "{nrrd}", "{root}/c8.weird"], "c8.weird"),
    ("convert-output-not-permitted", ["convert", "{nrrd}", "/sys/ambfplus.nrrd"],
     "/sys/ambfplus.nrrd"),
    ("convert-output-under-a-file", ["convert", "{nrrd}", "{under_file}.nrrd"], "{text}"),
    ("convert-output-exists", ["convert", "{nrrd}", "/dev/full"], "/dev/full"),
    ("convert-onto-itself", ["convert", "{nrrd}", "{nrrd}"], "{nrrd}"),
    ("convert-labels-missing", ["convert", "{folder}", "{root}/c9", "--labels", "{missing}",
                                "--dimensions", "1", "1", "1"],
     "{missing}"),
    ("convert-dimensions-zero", ["convert", "{folder}", "{root}/c10", "--dimensions", "0", "1",
                                 "1"],
     "--dimensions"),
    ("convert-dimensions-nan", ["convert", "{folder}", "{root}/c11", "--dimensions", "nan", "1",
                                "1"],
     "--dimensions"),
    ("convert-voxel-size-word", ["convert", "{folder}", "{root}/c12", "--voxel-size", "a", "b",
                                 "c"],
     "--voxel-size"),
    ("convert-size-twice", ["convert", "{folder}", "{root}/c13", "--voxel-size", "1", "1", "1",
                            "--dimensions", "1", "1", "1"],
     "--dimensions"),
    ("convert-label-negative", ["convert", "{nrrd}", "{root}/c14.stl", "--label", "-1"], "--label"),
    ("convert-threshold-inf", ["convert", "{nrrd}", "{root}/c15.stl", "--threshold", "inf"],
     "--threshold"),
    ("convert-no-output", ["convert", "{nrrd}"], "output"),
    # launch (argument errors and files that are not launch files: nothing is simulated)
    ("launch-missing", ["launch", "{missing}"], "{missing}"),
    ("launch-folder", ["launch", "{folder}"], "{folder}"),
    ("launch-fifo", ["launch", "{fifo_yaml}"], "{fifo_yaml}"),
    ("launch-not-utf8", ["launch", "{latin1_yaml}"], "{latin1_yaml}"),
    ("launch-broken", ["launch", "{broken_yaml}"], "{broken_yaml}"),
    ("launch-binary", ["launch", "{garbage_h5}"], "{garbage_h5}"),
    ("launch-empty", ["launch", "{empty}"], "{empty}"),
    ("launch-a-list", ["launch", "{launch_list_yaml}"], "{launch_list_yaml}"),
    ("launch-a-spec", ["launch", "{spec_yaml}"], "{spec_yaml}"),
    ("launch-indices-word", ["launch", "{spec_yaml}", "-l", "one,two"], "-l"),
    ("launch-steps-negative", ["launch", "{spec_yaml}", "--steps", "-1"], "--steps"),
    ("launch-steps-huge", ["launch", "{spec_yaml}", "--steps", "1000000000000"], "--steps"),
    # check-plugins (a plugin that fails its probe is its verdict, status 1; these are not)
    ("check-plugins-none", ["check-plugins"], "plugins"),
    ("check-plugins-timeout-0", ["check-plugins", "{text}", "--timeout", "0"], "--timeout"),
    ("check-plugins-timeout-nan", ["check-plugins", "{text}", "--timeout", "nan"], "--timeout"),
    ("check-plugins-timeout-word", ["check-plugins", "{text}", "--timeout", "long"], "--timeout"),
    # export
    ("export-missing", ["export", "{missing}", "--to", "mcap", "{root}/e1.mcap"], "{missing}"),
    ("export-garbage", ["export", "{garbage_h5}", "--to", "mcap", "{root}/e2.mcap"],
     "{garbage_h5}"),
    ("export-text", ["export", "{text}", "--to", "original-h5", "{root}/e3"], "{text}"),
    ("export-folder", ["export", "{folder}", "--to", "coco", "{root}/e4"], "{folder}"),
    ("export-fifo", ["export", "{fifo}", "--to", "mcap", "{root}/e5.mcap"], "{fifo}"),
    ("export-unknown-format", ["export", "{session}", "--to", "avi", "{root}/e6"], "avi"),
    ("export-no-format", ["export", "{session}", "{root}/e7"], "--to"),
    ("export-output-exists", ["export", "{session}", "--to", "mcap", "{text}"], "{text}"),
    ("export-onto-itself", ["export", "{session}", "--to", "mcap", "{session}", "--force"],
     "{session}"),
    ("export-compression", ["export", "{session}", "--to", "mcap", "{root}/e8", "--compression",
                            "gzip"],
     "--compression"),
    ("export-jpeg-quality-word", ["export", "{session}", "--to", "mcap", "{root}/e9",
                                  "--jpeg-quality", "best"],
     "--jpeg-quality"),
    # generate: specs (each fails before anything is made) and options
    ("generate-missing", ["generate", "{missing}", "--out", "{root}/g"], "{missing}"),
    ("generate-folder", ["generate", "{folder}", "--out", "{root}/g"], "{folder}"),
    ("generate-fifo", ["generate", "{fifo_yaml}", "--out", "{root}/g"], "{fifo_yaml}"),
    ("generate-not-utf8", ["generate", "{latin1_yaml}", "--out", "{root}/g"], "{latin1_yaml}"),
    ("generate-binary", ["generate", "{garbage_h5}", "--out", "{root}/g"], "{garbage_h5}"),
    ("generate-broken", ["generate", "{broken_yaml}", "--out", "{root}/g"], "{broken_yaml}"),
    ("generate-empty", ["generate", "{empty}", "--out", "{root}/g"], "{empty}"),
    ("generate-a-list", ["generate", "{list_yaml}", "--out", "{root}/g"], "{list_yaml}"),
    ("generate-deep", ["generate", "{deep_yaml}", "--out", "{root}/g"], "{deep_yaml}"),
    ("generate-alias-bomb", ["generate", "{bomb_yaml}", "--out", "{root}/g"], "{bomb_yaml}"),
    ("generate-duplicate-key", ["generate", "{dup_yaml}", "--out", "{root}/g"], "{dup_yaml}"),
    ("generate-too-big", ["generate", "{big_yaml}", "--out", "{root}/g"], "{big_yaml}"),
    ("generate-control-character", ["generate", "{control_yaml}", "--out", "{root}/g"],
     "{control_yaml}"),
    ("generate-python-tag", ["generate", "{python_tag_yaml}", "--out", "{root}/g"],
     "{python_tag_yaml}"),
    ("generate-version-2", ["generate", "{v2_yaml}", "--out", "{root}/g"], "{v2_yaml}"),
    ("generate-episodes-0", ["generate", "{episodes0_yaml}", "--out", "{root}/g"],
     "{episodes0_yaml}"),
    ("generate-episodes-1e12", ["generate", "{episodes1e12_yaml}", "--out", "{root}/g"],
     "{episodes1e12_yaml}"),
    ("generate-episodes-huge", ["generate", "{episodes_huge_yaml}", "--out", "{root}/g"],
     "{episodes_huge_yaml}"),
    ("generate-resolution-16384", ["generate", "{resolution_yaml}", "--out", "{root}/g"],
     "{resolution_yaml}"),
    ("generate-every-0", ["generate", "{every0_yaml}", "--out", "{root}/g"], "{every0_yaml}"),
    ("generate-every-1e12", ["generate", "{every1e12_yaml}", "--out", "{root}/g"],
     "{every1e12_yaml}"),
    ("generate-phantom-1024", ["generate", "{phantom1024_yaml}", "--out", "{root}/g"],
     "{phantom1024_yaml}"),
    ("generate-phantom-8", ["generate", "{phantom8_yaml}", "--out", "{root}/g"], "{phantom8_yaml}"),
    ("generate-phantom-seed", ["generate", "{phantom_seed_yaml}", "--out", "{root}/g"],
     "{phantom_seed_yaml}"),
    ("generate-seed-huge", ["generate", "{seed_huge_yaml}", "--out", "{root}/g"],
     "{seed_huge_yaml}"),
    ("generate-baseline-huge", ["generate", "{baseline_huge_yaml}", "--out", "{root}/g"],
     "{baseline_huge_yaml}"),
    ("generate-baseline-nan", ["generate", "{baseline_nan_yaml}", "--out", "{root}/g"],
     "{baseline_nan_yaml}"),
    ("generate-weight-huge", ["generate", "{weight_huge_yaml}", "--out", "{root}/g"],
     "{weight_huge_yaml}"),
    ("generate-unknown-key", ["generate", "{unknown_key_yaml}", "--out", "{root}/g"],
     "{unknown_key_yaml}"),
    ("generate-nested-unknown-key", ["generate", "{nested_key_yaml}", "--out", "{root}/g"],
     "resolutoin"),
    ("generate-anatomy-missing", ["generate", "{anatomy_missing_yaml}", "--out", "{root}/g"],
     "no_such_ear.nrrd"),
    ("generate-anatomy-nul", ["generate", "{anatomy_nul_yaml}", "--out", "{root}/g"],
     "{anatomy_nul_yaml}"),
    ("generate-anatomy-name-too-long", ["generate", "{anatomy_long_yaml}", "--out", "{root}/g"],
     "{anatomy_long_yaml}"),
    ("generate-pass-twice", ["generate", "{passes_yaml}", "--out", "{root}/g"], "{passes_yaml}"),
    ("generate-out-is-a-file", ["generate", "{spec_yaml}", "--out", "{text}"], "{text}"),
    ("generate-out-under-a-file", ["generate", "{spec_yaml}", "--out", "{under_file}"],
     "{under_file}"),
    ("generate-out-not-permitted", ["generate", "{spec_yaml}", "--out", "/sys/ambfplus-data"],
     "/sys/ambfplus-data"),
    ("generate-no-out", ["generate", "{spec_yaml}"], "--out"),
    ("generate-workers-0", ["generate", "{spec_yaml}", "--out", "{root}/g", "--workers", "0"],
     "--workers"),
    ("generate-retries-negative", ["generate", "{spec_yaml}", "--out", "{root}/g", "--retries",
                                   "-1"],
     "--retries"),
    ("generate-timeout-nan", ["generate", "{spec_yaml}", "--out", "{root}/g", "--timeout", "nan"],
     "--timeout"),
    ("generate-timeout-negative", ["generate", "{spec_yaml}", "--out", "{root}/g", "--timeout",
                                   "-5"],
     "--timeout"),
    ("generate-ray-cpus-0", ["generate", "{spec_yaml}", "--out", "{root}/g", "--ray-cpus", "0"],
     "--ray-cpus"),
    ("generate-ray-gpus-inf", ["generate", "{spec_yaml}", "--out", "{root}/g", "--ray-gpus", "inf"],
     "--ray-gpus"),
]
# fmt: on


def run(argv: list[str], capsys) -> tuple[int, str]:
    """main(argv) in this process: (status, stderr); a usage error's SystemExit is a status."""
    capsys.readouterr()
    try:
        status = main(argv)
    except SystemExit as stop:
        status = stop.code if isinstance(stop.code, int) else 1
    return status, capsys.readouterr().err


def assert_one_line(status: int, err: str, named: str, argv: list[str]) -> str:
    lines = [line for line in err.splitlines() if line.strip()]
    assert "Traceback" not in err, err
    assert len(lines) == 1, err
    assert status == 2, (status, err)
    assert named in lines[0], (named, lines[0])
    return lines[0]


@pytest.mark.parametrize("argv, named", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_a_bad_argument_is_one_line_with_status_2(argv, named, fx, capsys, monkeypatch):
    monkeypatch.chdir(fx["root"])  # nothing a command writes by default lands elsewhere
    argv = [a.format(**fx) for a in argv]
    status, err = run(argv, capsys)
    assert_one_line(status, err, named.format(**fx), argv)


def test_there_are_at_least_100_cases_and_every_command_has_some():
    from ambfplus.cli import COMMANDS

    assert len(CASES) + len(OS_ERRORS) + len(UNREADABLE) >= 100
    names = {m.__name__.rsplit(".", 1)[1].replace("_", "-") for m in COMMANDS}
    covered = {c[1][0] for c in CASES if c[1]}
    assert names <= covered, names - covered


# OS errors a command meets writing its output (a full or read-only disk, a quota), raised
# where it makes its output folder; with and without the file name, which the line supplies.
OS_ERRORS = [
    ("demo", errno.ENOSPC, True, "no space left"),
    ("demo", errno.ENOSPC, False, "no space left"),
    ("demo", errno.EROFS, True, "read-only file system"),
    ("demo", errno.EROFS, False, "read-only file system"),
    ("demo", errno.EDQUOT, False, "quota"),
    ("demo", errno.EACCES, True, "permission denied"),
    ("demo", errno.EIO, True, "input/output error"),
    ("generate", errno.ENOSPC, True, "no space left"),
    ("generate", errno.EROFS, False, "read-only file system"),
    ("generate", errno.EACCES, True, "permission denied"),
]


@pytest.mark.parametrize("command, code, with_name, says", OS_ERRORS)
def test_a_full_or_read_only_disk_is_one_line(command, code, with_name, says, fx, capsys,
                                              monkeypatch):  # fmt: skip
    def refuse(self, *args, **kwargs):
        if with_name:
            raise OSError(code, os.strerror(code), str(self))
        raise OSError(code, os.strerror(code))

    monkeypatch.setattr(pathlib.Path, "mkdir", refuse)
    out = f"{fx['root']}/{command}_{code}_{with_name}"
    argv = (
        ["demo", "--out", out] if command == "demo" else ["generate", fx["spec_yaml"], "--out", out]
    )
    status, err = run(argv, capsys)
    line = assert_one_line(status, err, out, argv)
    assert says in line and ": " in line.split(out, 1)[1], line  # and what to do


@contextlib.contextmanager
def unprivileged():
    """Runs the block as user nobody when this process is root (whom permissions do not
    stop), so that a file's mode is obeyed; as it is otherwise."""
    if os.geteuid() != 0:
        yield
        return
    # What the commands import on demand, imported while the interpreter's own files are
    # readable (an interpreter installed under /root is not readable by nobody).
    import encodings.utf_8_sig  # noqa: F401

    import yaml  # noqa: F401

    import ambfplus.dataset.check  # noqa: F401
    import ambfplus.dataset.driver  # noqa: F401
    import ambfplus.dataset.local  # noqa: F401
    import ambfplus.training.cohort  # noqa: F401

    try:
        os.seteuid(65534)
    except OSError:
        pytest.skip("cannot drop root privileges here")
    try:
        yield
    finally:
        os.seteuid(0)


@pytest.fixture(scope="module")
def locked():
    """A world-readable folder (pytest's own are root's only) holding a spec and a dataset
    folder that nobody may read, a phantom NRRD, and a folder nobody may write into."""
    root = Path(tempfile.mkdtemp(prefix="ambfplus-locked-"))
    try:
        root.chmod(0o755)
        (root / "spec.yaml").write_text(SPEC)
        (root / "spec.yaml").chmod(0)
        (root / "dataset").mkdir()
        (root / "dataset" / "environment.json").write_text('{"episodes": 1}')
        (root / "dataset").chmod(0)
        (root / "readonly").mkdir()
        (root / "readonly").chmod(stat.S_IRUSR | stat.S_IXUSR | 0o055)
        ambfplus.phantom(16).save_nrrd(root / "ear.nrrd")
        (root / "ear.nrrd").chmod(0o644)
        yield root
    finally:
        for path in (root / "dataset", root / "readonly"):
            path.chmod(0o755)
        shutil.rmtree(root, ignore_errors=True)


# fmt: off
UNREADABLE = [
    ("generate-spec-unreadable", ["generate", "{root}/spec.yaml", "--out", "{root}/g"],
     "{root}/spec.yaml"),
    ("assess-task-unreadable", ["assess", "{root}/x.h5", "--task", "{root}/spec.yaml"],
     "{root}/spec.yaml"),
    ("dataset-info-unreadable", ["dataset", "info", "{root}/dataset"], "{root}/dataset"),
    ("validate-unreadable", ["validate", "{root}/dataset"], "{root}/dataset"),
    ("demo-out-unwritable", ["demo", "--out", "{root}/readonly/demo"], "{root}/readonly/demo"),
    ("convert-out-unwritable", ["convert", "{root}/ear.nrrd", "{root}/readonly/slices"],
     "{root}/readonly/slices"),
    ("convert-nrrd-unwritable", ["convert", "{root}/ear.nrrd", "{root}/readonly/ear.nrrd"],
     "{root}/readonly/ear.nrrd"),
]
# fmt: on


@pytest.mark.parametrize("argv, named", [c[1:] for c in UNREADABLE],
                         ids=[c[0] for c in UNREADABLE])  # fmt: skip
def test_permission_denied_is_one_line(argv, named, locked, capsys):
    argv = [a.format(root=locked) for a in argv]
    with unprivileged():
        status, err = run(argv, capsys)
    line = assert_one_line(status, err, named.format(root=locked), argv)
    assert "permission denied" in line.lower(), line


def test_an_unexpected_error_is_one_line_saying_how_to_see_it(fx, capsys, monkeypatch):
    """A bug (an error the package does not raise on purpose) is still one line, with its type
    and how to see the traceback."""
    from ambfplus.cli import info

    def broken(args):
        return 1 // 0

    monkeypatch.setattr(info, "run", broken)
    status, err = run(["info"], capsys)
    line = assert_one_line(status, err, "ZeroDivisionError", ["info"])
    assert line.startswith("ambfplus info: ") and "ambfplus --debug" in line
    with pytest.raises(ZeroDivisionError):
        main(["--debug", "info"])


def test_an_interrupt_is_one_line_with_status_130(capsys, monkeypatch):
    from ambfplus.cli import info

    def interrupted(args):
        raise KeyboardInterrupt

    monkeypatch.setattr(info, "run", interrupted)
    status, err = run(["info"], capsys)
    assert status == 130 and err.strip() == "ambfplus info: interrupted"


def test_debug_reraises_the_error_itself(fx, capsys):
    from ambfplus.dataset import SpecError

    with pytest.raises(SpecError, match="no such spec file"):
        main(["--debug", "generate", fx["missing"], "--out", f"{fx['root']}/g"])
    with pytest.raises(FileNotFoundError):
        main(["--debug", "dataset", "info", fx["folder"]])


def test_a_status_a_command_chooses_is_kept(fx, capsys):
    """1 still means the command ran and its result is a failure: validate of a file that is
    not a recording reports its checks."""
    assert main(["validate", fx["text"]]) == 1
    captured = capsys.readouterr()
    assert "Traceback" not in captured.err and fx["text"] in captured.out


def cli(*argv: str, cwd: str) -> subprocess.CompletedProcess:
    """The real entry point, in a process of its own, from outside the source folder."""
    return subprocess.run(argv, capture_output=True, text=True, timeout=120, cwd=cwd)


@pytest.mark.parametrize(
    "entry, argv, named",
    [
        ("module", ["validate", "{folder}"], "{folder}"),
        ("module", ["generate", "{deep_yaml}", "--out", "{root}/g"], "{deep_yaml}"),
        ("module", ["demo", "--every", "0"], "--every"),
        ("script", ["dataset", "info", "{ds_list}"], "{ds_list}"),
        ("script", ["convert", "{latin1_yaml}", "{root}/s1"], "{latin1_yaml}"),
    ],
)
def test_the_real_entry_points_fail_in_one_line(entry, argv, named, fx):
    if entry == "script":
        script = shutil.which("ambfplus") or str(Path(sys.executable).parent / "ambfplus")
        if not Path(script).exists():
            pytest.skip("no ambfplus script on PATH")
        command = [script]
    else:
        command = [sys.executable, "-m", "ambfplus"]
    argv = [a.format(**fx) for a in argv]
    done = cli(*command, *argv, cwd=fx["root"])
    assert_one_line(done.returncode, done.stderr, named.format(**fx), argv)
    assert done.returncode == 2


def test_debug_shows_the_traceback_from_the_real_entry_point(fx):
    done = cli(sys.executable, "-m", "ambfplus", "--debug", "dataset", "info", fx["ds_list"],
               cwd=fx["root"])  # fmt: skip
    assert done.returncode != 0
    assert "Traceback (most recent call last)" in done.stderr
    assert "ConfigError" in done.stderr.strip().splitlines()[-1], done.stderr


def test_a_json_command_prints_no_half_document(fx, capsys):
    """--json asks for JSON on stdout; an error goes to stderr as one line and stdout stays
    empty, so that a JSON reader at the other end of a pipe sees nothing, not half a document."""
    capsys.readouterr()
    assert main(["dataset", "info", fx["ds_not_json"], "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and len(captured.err.strip().splitlines()) == 1
