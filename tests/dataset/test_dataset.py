"""Datasets at scale with the local executor: specs checked before anything runs, episodes that
are pure functions of (spec, seed, index), identical shards whatever the number of workers,
workers and drivers killed mid-run, randomised looks over exact ground truth, and reading and
checking dataset folders. (The Ray executor: test_dataset_ray.py.)"""

from __future__ import annotations

import json
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import EXAMPLES

from ambfplus.dataset import (
    GenerateError,
    SpecError,
    StaleRunError,
    dataset_info,
    generate,
    load_spec,
    read_manifest,
    record_episode,
    run_episode,
    sample_episode,
    validate_dataset,
    without_run_fields,
)
from ambfplus.dataset.sampling import HANDLE_COLOR, METAL_COLOR
from ambfplus.recording import open_recording
from ambfplus.scenes import anatomy_data, drilling_scene

BASE_SPEC = {
    "version": 1,
    "episodes": 2,
    "anatomies": [{"phantom": {"resolution": 32}}],
    "rigs": [{"resolution": [64, 48]}],
    "capture": {"every": 20, "frames": 2},
}


def manifest(folder) -> list[dict]:
    records, problems = read_manifest(folder)
    assert not problems
    return [without_run_fields(r) for r in records]


def shard_bytes(folder: Path) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted((folder / "shards").iterdir())}


def start_generate(spec, out, *options) -> subprocess.Popen:
    """`ambfplus generate` with 2 local workers in a process of its own, run from outside the
    source tree (which has no engine)."""
    command = ["generate", str(spec), "--out", str(out), "--workers", "2", "--quiet", *options]
    return subprocess.Popen([sys.executable, "-m", "ambfplus", *command], cwd="/",
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)  # fmt: skip


def run_cli(*args) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "ambfplus", *args],
        cwd="/",
        capture_output=True,
        text=True,
        timeout=300,
    )


# Specs -------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "change, where",
    [
        ({"colour": 1}, "colour: unknown key"),
        ({"episodes": 0}, "episodes: expected a value >= 1"),
        ({"episodes": 10**12}, "episodes: expected a value <= 1000000, got 1000000000000 (a "),
        ({"capture": {"every": 10**12}}, "capture.every: expected a value <= 60000"),
        (
            {"rigs": [{"resolution": [16384, 16384]}]},
            "rigs[0].resolution[0]: expected a value <= 4096, got 16384 (a 4096x4096",
        ),
        (
            {"anatomies": [{"phantom": {"resolution": 1024}}]},
            "anatomies[0].phantom.resolution: expected a value <= 512",
        ),
        ({"episodes": "12"}, "episodes: expected an integer, got str"),
        ({"version": 2}, "version: spec schema version 2 is not supported"),
        (
            {"rigs": [{"baseline": {"uniform": [0.08, 0.05]}}]},
            "rigs[0].baseline.uniform: empty range: low 0.08 > high 0.05",
        ),
        ({"rigs": [{"baseline": [0.05, 0.08]}]}, "rigs[0].baseline: expected a value, {uniform"),
        ({"rigs": [{"resolution": [640]}]}, "rigs[0].resolution: expected a list of 2 numbers"),
        ({"anatomies": [{"file": "no/such/ear.nrrd"}]}, "anatomies[0].file: no such file"),
        ({"anatomies": []}, "anatomies: expected a non-empty list"),
        (
            {"anatomies": [{"phantom": {"resolution": 32}, "file": "x"}]},
            "anatomies[0]: expected exactly one of phantom, file",
        ),
        ({"scenarios": [{"kind": "juggling"}]}, "scenarios[0].kind: unknown scenario 'juggling'"),
        ({"capture": {"passes": ["rgb", "depht"]}}, "capture.passes[1]: unknown pass 'depht'"),
        (
            {"appearance": {"lights": {"count": {"choice": []}}}},
            "appearance.lights.count.choice: expected a non-empty list",
        ),
        (
            {"appearance": {"background": {"uniform": [0.0, 1.5]}}},
            "appearance.background.uniform[1]: expected a value <= 1",
        ),
        (
            {"appearance": {"noise": {"rgb_sigma": True}}},
            "appearance.noise.rgb_sigma: expected a number, got bool",
        ),
        (
            {"appearance": {"rendering": {"antialiasing": 5}}},
            "appearance.rendering.antialiasing: expected a value <= 4, got 5",
        ),
        (
            {"appearance": {"rendering": {"looks": "yes"}}},
            "appearance.rendering.looks: expected true or false, got str 'yes'",
        ),
        (
            {"appearance": {"rendering": {"shading": True}}},
            "appearance.rendering.shading: unknown key; expected one of antialiasing, looks",
        ),
    ],
)
def test_bad_specs_name_the_key(change, where, tmp_path):
    with pytest.raises(SpecError) as error:
        load_spec({**BASE_SPEC, **change})
    assert where in str(error.value)
    # generate refuses before any worker starts or any file is written
    out = tmp_path / "out"
    with pytest.raises(SpecError):
        generate({**BASE_SPEC, **change}, out, progress=False)
    assert not out.exists()


def test_hostile_yaml_fails_fast_and_small(tmp_path):
    """An alias bomb (nine lines expanding to 10^9 nodes) is refused before anything expands:
    quickly and in little memory (the test would not end otherwise); a FIFO is not read."""
    import resource

    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 10)}]" for i in range(1, 9)]
    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("\n".join(lines) + "\nversion: 1\nepisodes: 1\nname: *a8\n")
    before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    with pytest.raises(SpecError, match=r"bomb\.yaml: line 2, column 10: YAML aliases \(\*a0\)"):
        load_spec(bomb)
    grown_mb = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
    assert grown_mb < 100
    fifo = tmp_path / "spec.fifo"
    os.mkfifo(fifo)
    with pytest.raises(SpecError, match=r"spec\.fifo: not a regular file"):
        load_spec(fifo)


def test_bad_yaml_and_unreadable_volume_name_the_file(tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text("version: 1\nepisodes: [1\n")
    with pytest.raises(SpecError, match=r"bad\.yaml: not valid YAML \(line 3"):
        load_spec(bad)
    broken = tmp_path / "ear.nrrd"
    broken.write_text("NRRD0004\ntype: nonsense\n\n")
    spec = tmp_path / "spec.yaml"
    spec.write_text("version: 1\nepisodes: 1\nanatomies: [{file: ear.nrrd}]\n")
    with pytest.raises(SpecError, match=r"anatomies\[0\]\.file: cannot load .*ear\.nrrd"):
        generate(spec, tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists()


def test_ray_without_the_extra_says_what_to_install(monkeypatch, tmp_path):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now fails
    with pytest.raises(ImportError, match=r'pip install "ambfplus\[ray\]"'):
        generate(BASE_SPEC, tmp_path / "out", ray="auto", progress=False)
    assert not (tmp_path / "out").exists()


@pytest.mark.slow
def test_the_ray_tests_fail_rather_than_skip_under_ci_without_ray(tmp_path):
    ray_tests = Path(__file__).with_name("test_dataset_ray.py")
    without_ray = "import sys; sys.modules['ray'] = None; import pytest; sys.exit(pytest.main())"
    command = [sys.executable, "-c", without_ray, str(ray_tests), "-q", "-p", "no:cacheprovider"]
    results = {}
    for ci in ("true", None):
        env = {k: v for k, v in os.environ.items() if k != "CI"}
        env.update({"CI": ci} if ci else {})
        results[ci] = subprocess.run(
            command, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300
        )
    failed, skipped = results["true"], results[None]
    # a collection error (pytest's 2) under CI; elsewhere the module is skipped (no test runs: 5)
    assert failed.returncode == pytest.ExitCode.INTERRUPTED, failed.stdout + failed.stderr
    assert 'pip install "ambfplus[ray]"' in failed.stdout, failed.stdout
    assert skipped.returncode == pytest.ExitCode.NO_TESTS_COLLECTED, skipped.stdout
    assert "1 skipped" in skipped.stdout, skipped.stdout


def test_ray_gpu_ids_choose_the_engines_cuda_device():
    from ambfplus.dataset.ray_executor import select_gpu

    environ = {"CUDA_VISIBLE_DEVICES": "2,3"}  # as Ray sets it: the ordinal is the position
    assert select_gpu(["3"], environ) == "1" and environ["AMBFPLUS_CUDA_DEVICE"] == "1"
    environ = {}
    assert select_gpu([2], environ) == "2" and environ["AMBFPLUS_CUDA_DEVICE"] == "2"
    environ = {"AMBFPLUS_EGL_DEVICE": "1"}  # a device the user chose stays chosen
    assert select_gpu([0], environ) is None and "AMBFPLUS_CUDA_DEVICE" not in environ
    assert select_gpu([], {}) is None


def test_the_example_spec_is_valid():
    spec = load_spec(EXAMPLES / "dataset_spec.yaml")
    assert spec.episodes == 6 and len(spec.data["anatomies"]) == 2
    kinds = {sample_episode(spec, i).scenario["kind"] for i in range(spec.episodes)}
    assert kinds <= {"camera", "drilling", "mixed"} and len(kinds) >= 2


def test_the_cli_reports_a_bad_spec_without_a_traceback(tmp_path):
    spec = tmp_path / "spec.yaml"
    spec.write_text("version: 1\nepisodes: 1\nanatomies: [{phantom: {resolutoin: 64}}]\n")
    done = run_cli("generate", str(spec), "--out", str(tmp_path / "o"))
    assert done.returncode == 2
    assert "anatomies[0].phantom.resolutoin: unknown key" in done.stderr
    assert "Traceback" not in done.stderr


# Sampling ----------------------------------------------------------------------------------


def test_an_episode_is_a_pure_function_of_spec_seed_and_index(dataset_spec):
    spec = load_spec(dataset_spec)
    first = [sample_episode(spec, i).describe() for i in range(spec.episodes)]
    assert first == [sample_episode(spec, i).describe() for i in range(spec.episodes)]
    assert len({json.dumps(d, sort_keys=True) for d in first}) == spec.episodes
    other_seed = load_spec({**spec.data, "seed": spec.seed + 1})
    assert sample_episode(other_seed, 3).describe() != first[3]
    # appearance draws come from their own streams: the geometry stays
    plain = dict(spec.data, appearance={})
    for i in range(spec.episodes):
        a, b = sample_episode(spec, i), sample_episode(plain, i)
        assert (a.anatomy, a.scenario, a.frames, a.camera_path) == (
            b.anatomy,
            b.scenario,
            b.frames,
            b.camera_path,
        )
        for key in ("width", "height", "baseline", "working_distance"):
            assert a.scene[key] == b.scene[key]


# Generating --------------------------------------------------------------------------------


@pytest.mark.slow
def test_one_and_two_workers_make_identical_shards(dataset_spec, reference_dataset, tmp_path):
    report = generate(dataset_spec, tmp_path / "two", workers=2, progress=False)
    assert report.generated == 12 and report.retries == 0
    assert manifest(tmp_path / "two") == manifest(reference_dataset)
    assert shard_bytes(tmp_path / "two") == shard_bytes(reference_dataset)
    # the comparison covers drilling: removal logs and changed anatomy
    removed = 0
    for record in read_manifest(reference_dataset)[0]:
        with open_recording(reference_dataset / record["file"]) as rec:
            removed += len(rec.removed["step"])
            assert rec.metadata["dataset"]["episode"] == record["episode"]
    assert removed > 0
    workers = {r["worker"] for r in read_manifest(tmp_path / "two")[0]}
    assert len(workers) == 2
    # a finished dataset validates, and running again makes nothing
    report = validate_dataset(tmp_path / "two", match_images=False)
    assert report.ok, str(report)
    again = generate(dataset_spec, tmp_path / "two", workers=2, progress=False)
    assert (again.generated, again.skipped) == (0, 12)
    environment = json.loads((tmp_path / "two" / "environment.json").read_text())
    assert [r["status"] for r in environment["runs"]] == ["complete", "complete"]
    assert environment["runs"][0]["renderers"] and environment["ambfplus_version"]
    assert (tmp_path / "two" / "spec.yaml").read_text() == dataset_spec.read_text()


def _children(pid: int) -> list[int]:
    try:
        return [int(p) for p in Path(f"/proc/{pid}/task/{pid}/children").read_text().split()]
    except OSError:
        return []


def _descendants(pid: int) -> list[int]:
    found, todo = [], _children(pid)
    while todo:
        found.append(todo.pop())
        todo += _children(found[-1])
    return found


def _worker_pids(driver: int) -> list[int]:
    """The generate driver's worker processes (forked by its fork server, named
    ambfplus-worker)."""
    found = []
    for pid in _descendants(driver):
        try:
            if Path(f"/proc/{pid}/comm").read_text().strip() == "ambfplus-worker":
                found.append(pid)
        except OSError:
            pass
    return found


@pytest.mark.slow
def test_killed_workers_are_replaced_and_their_episodes_redone(
    dataset_spec, reference_dataset, tmp_path
):
    out = tmp_path / "data"
    driver = start_generate(dataset_spec, out, "--retries", "6")
    killed, rng = [], random.Random(18)
    while driver.poll() is None and len(killed) < 4:
        time.sleep(rng.uniform(0.3, 1.2))
        pids = _worker_pids(driver.pid)
        if pids:
            victim = rng.choice(pids)
            os.kill(victim, signal.SIGKILL)
            killed.append(victim)
    _, stderr = driver.communicate(timeout=300)
    assert driver.returncode == 0, stderr.decode()
    assert killed  # a quiet machine may finish the run after the first kill
    assert manifest(out) == manifest(reference_dataset)
    assert shard_bytes(out) == shard_bytes(reference_dataset)
    report = validate_dataset(out, match_images=False)
    assert report.ok and not report.warnings, str(report)
    runs = json.loads((out / "environment.json").read_text())["runs"]
    assert runs[-1]["retries"] >= 1  # at least one kill hit a worker at work


@pytest.mark.slow
def test_a_killed_driver_resumes_to_the_same_dataset(dataset_spec, reference_dataset, tmp_path):
    out = tmp_path / "data"
    driver = start_generate(dataset_spec, out)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(read_manifest(out)[0]) < 4:
        time.sleep(0.05)
    workers = _worker_pids(driver.pid)
    assert len(workers) == 2
    tree = _descendants(driver.pid)  # the workers, their fork server, multiprocessing's helper
    driver.kill()
    driver.wait(timeout=30)
    assert 4 <= len(read_manifest(out)[0]) < 12
    for pid in tree:  # the workers and their fork server die with their driver
        for _ in range(100):
            if not Path(f"/proc/{pid}").exists() or "Z" in _state(pid):
                break
            time.sleep(0.05)
        else:
            pytest.fail(
                f"process {pid} ({'worker' if pid in workers else 'helper'}) outlived its driver"
            )
    # what a killed driver may leave: a torn manifest line, unlisted shard files, partials
    with open(out / "manifest.jsonl", "a") as f:
        f.write('{"episode": 11, "seed"')
    (out / "shards" / "episode_000011.h5.part0001").write_bytes(b"half a shard")
    (out / ".partial" / "episode_000010.lost.1.0").mkdir(parents=True, exist_ok=True)
    report = validate_dataset(out, match_images=False)
    assert not report.ok and any("missing" in p for p in report.problems)
    resumed = generate(dataset_spec, out, workers=2, progress=False)
    assert resumed.skipped >= 4 and resumed.skipped + resumed.generated == 12
    assert manifest(out) == manifest(reference_dataset)
    assert shard_bytes(out) == shard_bytes(reference_dataset)
    assert not (out / ".partial").exists()
    runs = json.loads((out / "environment.json").read_text())["runs"]
    assert [r["status"] for r in runs] == ["running", "complete"]  # the first never finished


def _state(pid: int) -> str:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(") ", 1)[1][0]
    except (OSError, IndexError):
        return "Z"


def test_a_folder_holds_one_spec_and_one_generation_at_a_time(dataset_spec, tmp_path):
    out = tmp_path / "data"
    generate(BASE_SPEC, out, progress=False)
    with pytest.raises(GenerateError, match="holds a dataset of another spec"):
        generate({**BASE_SPEC, "seed": 5}, out, progress=False)
    stranger = tmp_path / "notes"
    stranger.mkdir()
    (stranger / "todo.txt").write_text("x")
    with pytest.raises(GenerateError, match="not empty and not a dataset folder"):
        generate(BASE_SPEC, stranger, progress=False)
    import fcntl

    with open(out / ".lock", "a+") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        with pytest.raises(GenerateError, match="another generation is writing"):
            generate(BASE_SPEC, out, progress=False)


# A task of a run whose driver died, as Ray may leave one running: it checks the folder's run,
# then waits (while the new run takes the folder over and cleans it) and records episode 1 as
# the new run makes it too, then waits again until the new run has listed it.
LATE_TASK = """
import json, sys, time
from pathlib import Path
import ambfplus.dataset.episode as episode

out, run, signals = Path(sys.argv[1]), sys.argv[2], Path(sys.argv[3])
spec_data = json.loads(Path(sys.argv[4]).read_text())
record = episode.record_episode

def wait_for(name):
    deadline = time.monotonic() + 300
    while not (signals / name).exists():
        assert time.monotonic() < deadline, name
        time.sleep(0.02)

def late_record(spec_data, index, path, plan=None):
    print(path.parent.name, flush=True)
    wait_for("resumed")
    summary = record(spec_data, index, path, plan)
    wait_for("listed")
    return summary

episode.record_episode = late_record
try:
    episode.run_episode(spec_data, out, 1, 0, worker="late", run=run)
except episode.StaleRunError as error:
    print("stale:", error, flush=True)
    sys.exit(3)
"""


def test_a_dead_runs_late_task_cannot_touch_the_resumed_runs_shard(tmp_path, monkeypatch):
    import ambfplus.dataset.driver as driver_module

    spec = load_spec({**BASE_SPEC, "capture": {"every": 50, "frames": 3}})
    out, signals = tmp_path / "data", tmp_path / "signals"
    signals.mkdir()
    generate(spec, out, progress=False)
    dead_run = (out / ".run").read_text().strip()
    # as if its driver had died before listing episode 1, whose task still runs somewhere
    first = read_manifest(out)[0][0]
    (out / "manifest.jsonl").write_text(json.dumps(first) + "\n")
    spec_file = tmp_path / "spec.json"
    spec_file.write_text(json.dumps(spec.data))
    late = subprocess.Popen(
        [sys.executable, "-c", LATE_TASK, str(out), dead_run, str(signals), str(spec_file)],
        cwd="/",
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        late_partial = late.stdout.readline().strip()  # past its check of the folder's run
        assert late_partial == f"episode_000001.{dead_run}.attempt0", late.stderr.read()
        resume = driver_module._resume

        def resume_then_signal(*args):
            records = resume(*args)
            (signals / "resumed").touch()
            return records

        class Writer(driver_module.ManifestWriter):
            def append(self, record):  # the late task tries to move its shard in now
                super().append(record)
                before.append((head.stat().st_ino, head.read_bytes()))
                (signals / "listed").touch()
                late.wait(timeout=300)
                left.append((out / ".partial" / late_partial).exists())

        head, before, left = out / "shards" / "episode_000001.h5", [], []
        monkeypatch.setattr(driver_module, "_resume", resume_then_signal)
        monkeypatch.setattr(driver_module, "ManifestWriter", Writer)
        report = generate(spec, out, progress=False)
        stdout, stderr = late.communicate(timeout=300)
    finally:
        (signals / "listed").touch()
        if late.poll() is None:
            late.kill()
    assert late.returncode == 3 and "is no longer this folder's current run" in stdout, stderr
    assert (report.generated, report.skipped) == (1, 1)
    runs = json.loads((out / "environment.json").read_text())["runs"]
    assert runs[0]["run_id"] == dead_run and runs[1]["run_id"] not in (dead_run, "")
    assert [(head.stat().st_ino, head.read_bytes())] == before  # not replaced
    assert [r["episode"] for r in read_manifest(out)[0]] == [0, 1]
    assert left == [False]  # the late task deleted its own partial shard
    check = validate_dataset(out, match_images=False)
    assert check.ok and not check.warnings, str(check)


def test_an_attempt_keeps_a_complete_shard_and_a_stale_one_makes_nothing(tmp_path):
    from ambfplus.dataset.episode import take_over

    spec = load_spec(BASE_SPEC)
    out = tmp_path / "data"
    out.mkdir()
    take_over(out, "run-a")
    record = run_episode(spec.data, out, 0, 0, run="run-a")
    head = out / record["file"]
    inode = head.stat().st_ino
    # a second attempt of the same run (its first was thought lost) keeps the shard in place
    again = run_episode(spec.data, out, 0, 1, run="run-a")
    assert without_run_fields(again) == without_run_fields(record)
    assert head.stat().st_ino == inode
    take_over(out, "run-b")
    with pytest.raises(StaleRunError, match="run-a is no longer this folder's current run"):
        run_episode(spec.data, out, 1, 0, run="run-a")
    assert sorted(p.name for p in (out / "shards").iterdir()) == [
        Path(record["file"]).name,
        *(Path(p).name for p in record["parts"]),
    ]
    assert not any((out / ".partial").iterdir())


def test_an_episode_that_keeps_failing_stops_the_run_with_its_error(tmp_path, monkeypatch):
    import ambfplus
    import ambfplus.dataset.driver as module

    ear = tmp_path / "ear.nrrd"
    ambfplus.phantom(24).save_nrrd(ear)
    spec = tmp_path / "spec.yaml"
    spec.write_text(
        "version: 1\nepisodes: 2\ncapture: {every: 10, frames: 1}\n"
        "rigs: [{resolution: [32, 24]}]\nanatomies: [{file: ear.nrrd}]\n"
    )
    checked = module.check_sources

    def check_then_spoil(data):  # the file goes bad after the spec was checked
        checked(data)
        ear.write_text("NRRD0004\ntype: nonsense\n\n")

    monkeypatch.setattr(module, "check_sources", check_then_spoil)
    with pytest.raises(
        GenerateError,
        match=r"episode \d failed 2 times; the last time: (.|\n)*"
        r"ear\.nrrd",
    ):
        generate(spec, tmp_path / "out", retries=1, progress=False)
    assert read_manifest(tmp_path / "out")[0] == []


def test_the_progress_bar_reports_episodes_and_retries(tmp_path, monkeypatch):
    import io

    import ambfplus
    import ambfplus.dataset.driver as module

    stream = io.StringIO()
    report = generate(BASE_SPEC, tmp_path / "fine", progress=stream)
    final = _last_line(stream.getvalue())
    assert report.generated == 2
    assert final.startswith("generate: 100%") and "2/2" in final and "0 retries" in final, final
    assert re.search(r"\d+\.\d pairs/s", final), final
    # every attempt fails (the volume goes bad after the spec was checked): 2 retries, then
    # the run stops
    ear = tmp_path / "ear.nrrd"
    ambfplus.phantom(24).save_nrrd(ear)
    spec = {**BASE_SPEC, "anatomies": [{"file": str(ear)}]}
    checked = module.check_sources

    def check_then_spoil(data):
        checked(data)
        ear.write_text("NRRD0004\ntype: nonsense\n\n")

    monkeypatch.setattr(module, "check_sources", check_then_spoil)
    stream = io.StringIO()
    with pytest.raises(GenerateError):
        generate(spec, tmp_path / "failing", retries=1, progress=stream)
    text = stream.getvalue()
    assert "0/2" in _last_line(text) and "2 retries" in _last_line(text), text
    for episode in (0, 1):
        assert f"episode {episode}: retrying (attempt 2): " in text  # counted from 1


def _last_line(text: str) -> str:
    """What a terminal would show last of a tqdm bar's output."""
    return [line for line in re.split(r"[\r\n]", text) if line.strip()][-1]


# Randomisation -----------------------------------------------------------------------------


def test_randomisation_is_real_recorded_and_within_the_ranges(reference_dataset):
    spec = load_spec(reference_dataset / "spec.yaml")
    base_fov = spec.data["rigs"][0]["fov_y"]
    table = {
        label.id: label.color
        for label in anatomy_data({"phantom": {"resolution": 40, "seed": 0}}).label_table
    }
    appearance = spec.data["appearance"]
    light_low, light_high = appearance["lights"]["color"]["uniform"]
    drill = appearance["drill"]
    seen = {"lights": set(), "intensity": [], "background": [], "fov": [], "cx": [], "sigma": []}
    seen.update(light_color=[], metal=[], handle=[], label_colors={})
    for key in appearance["material"]:
        seen[f"material.{key}"] = []
    for key in ("specular", "shininess"):
        if key in drill:
            seen[f"drill.{key}"] = []
    for record in read_manifest(reference_dataset)[0]:
        with open_recording(reference_dataset / record["file"]) as rec:
            sampled = rec.metadata["sampled"]
            scene = sampled["scene"]
            lights = scene["lights"]
            assert 1 <= len(lights) <= 3
            seen["lights"].add(len(lights))
            for light in lights:
                assert 0.3 <= light["intensity"] <= 1.0
                assert np.all(
                    (light_low <= np.array(light["color"]))
                    & (light["color"] <= np.array(light_high))
                )
                assert light["type"] in ("directional", "point", "spot")
                seen["intensity"].append(light["intensity"])
                seen["light_color"].append(light["color"])
            jitter = appearance["labels"]["color_jitter"]
            assert sampled["label_colors"]
            for label_id, color in sampled["label_colors"].items():
                assert np.all(np.abs(np.subtract(color, table[int(label_id)])) <= jitter)
                seen["label_colors"].setdefault(label_id, set()).add(tuple(color))
            # the anatomy's and the drill's materials
            for key, value in appearance["material"].items():
                low, high = value["uniform"]
                assert low <= scene["volume_material"][key] <= high, key
                seen[f"material.{key}"].append(scene["volume_material"][key])
            for key in ("specular", "shininess"):
                if key in drill:
                    low, high = drill[key]["uniform"]
                    assert low <= scene["drill_metal"][key] <= high, key
                    seen[f"drill.{key}"].append(scene["drill_metal"][key])
            for name, color, base in (
                ("metal", scene["drill_metal"]["color"], METAL_COLOR),
                ("handle", scene["drill_handle"]["color"], HANDLE_COLOR),
            ):
                assert np.all(np.abs(np.subtract(color, base)) <= drill["color_jitter"] + 1e-12)
                seen[name].append(color)
            # the legend the shard carries has the jittered colours
            volume = next(e for e in rec.legend.values() if e["kind"] == "volume")
            assert {str(i): list(v["color"]) for i, v in volume["labels"].items()} == sampled[
                "label_colors"
            ]
            background = np.array(scene["background"])
            assert np.all((0 <= background) & (background <= 0.25))
            seen["background"].append(background)
            pair = rec.rigs["rig"][0]
            sky = pair.left.depth == 0
            assert sky.any()
            # where nothing is hit the image shows the background (plus the sensor noise)
            sigma = sampled["rgb_noise"]["sigma"]
            assert 0.5 <= sigma <= 2.0
            seen["sigma"].append(sigma)
            mean = pair.left.rgb[sky].mean(axis=0)
            assert np.all(np.abs(mean - 255 * background) < 1.0)
            assert np.std(pair.left.rgb[sky].astype(float) - 255 * background) > 0.3
            # intrinsics: the focal follows the jittered field of view
            fov = scene["fov_y"]
            assert abs(fov / base_fov - 1) <= 0.03 + 1e-12
            k = pair.left.intrinsics
            assert k[1, 1] == pytest.approx(pair.left.height / (2 * np.tan(fov / 2)))
            offset = scene["principal_point_offset"]
            assert all(abs(o) <= 2.0 for o in offset)
            dcx = pair.dcx
            assert k[0, 2] == pytest.approx(pair.left.width / 2 - dcx / 2 + offset[0])
            assert k[1, 2] == pytest.approx(pair.left.height / 2 + offset[1])
            seen["fov"].append(fov)
            seen["cx"].append(offset[0])
    assert len(seen["lights"]) >= 2
    scalars = ["intensity", "fov", "cx", "sigma"] + [k for k in seen if "." in k]
    assert (
        len(scalars) == 7
    )  # the spec samples the anatomy's specular and shininess, the drill's specular
    for key in scalars:
        assert np.std(seen[key]) > 0, key
    for key in ("background", "light_color", "metal", "handle"):
        assert np.std(np.array(seen[key]), axis=0).min() > 0, key  # every channel varies
    # every label's colour differs between episodes
    assert set(seen["label_colors"]) == {str(i) for i in table}
    assert all(len(colors) > 1 for colors in seen["label_colors"].values()), seen["label_colors"]


def test_appearance_rendering_sets_the_rig_cameras():
    spec = load_spec(
        {
            **BASE_SPEC,
            "appearance": {"rendering": {"shadows": True, "antialiasing": 3, "looks": True}},
        }
    )
    scene = drilling_scene(**sample_episode(spec, 0).scene)
    for camera in (scene.rig.left, scene.rig.right):
        assert (camera.shadows, camera.antialiasing, camera.looks) == (True, 3, True)
    plain = drilling_scene(**sample_episode(load_spec(BASE_SPEC), 0).scene)
    assert (plain.rig.left.shadows, plain.rig.left.antialiasing, plain.rig.left.looks) == (
        False, 1, False,
    )  # fmt: skip


def test_other_looks_leave_the_ground_truth_exact(dataset_spec, tmp_path):
    spec = load_spec(dataset_spec)
    other = dict(spec.data)
    other["appearance"] = {
        **spec.data["appearance"],
        "lights": {**spec.data["appearance"]["lights"], "intensity": {"uniform": [1.2, 2.0]}},
        "labels": {"color_jitter": 90.0},
        "material": {"specular": 0.9, "shininess": 4.0},
        "background": [0.9, 0.1, 0.5],
        "noise": {"rgb_sigma": 6.0},
        "rendering": {"shadows": True, "antialiasing": 2, "looks": True},
    }
    index = next(
        i for i in range(spec.episodes) if sample_episode(spec, i).scenario["kind"] != "camera"
    )
    paths = []
    for name, data in (("a", spec.data), ("b", other)):
        paths.append(tmp_path / f"{name}.h5")
        record_episode(data, index, paths[-1])
    with open_recording(paths[0]) as a, open_recording(paths[1]) as b:
        assert a.metadata["sampled"]["scene"]["lights"] != b.metadata["sampled"]["scene"]["lights"]
        drawn = {k: b.metadata["scene"]["params"][k] for k in ("shadows", "antialiasing", "looks")}
        assert drawn == {"shadows": True, "antialiasing": 2, "looks": True}  # the rig's cameras
        assert len(a.removed["step"]) > 0
        for key in ("step", "voxel", "label"):
            assert np.array_equal(a.removed[key], b.removed[key])
        for stream in ("rig_left", "rig_right"):
            sa, sb = a.cameras[stream], b.cameras[stream]
            for column in ("depth", "label", "instance", "voxel", "pose", "intrinsics"):
                assert np.array_equal(getattr(sa, column)[:], getattr(sb, column)[:]), column
            assert not np.array_equal(sa.rgb[:], sb.rgb[:])


# Reading and checking ----------------------------------------------------------------------


@pytest.mark.slow
def test_validate_finds_damage_gaps_and_duplicates(reference_dataset, tmp_path):
    out = tmp_path / "copy"
    shutil.copytree(reference_dataset, out)
    report = validate_dataset(out)  # with block matching of the stereo pairs
    assert report.ok, str(report)
    assert report.shards_checked == 12 and report.frames == sum(
        r["frames"] for r in read_manifest(out)[0]
    )
    lines = (out / "manifest.jsonl").read_text().splitlines()
    part = out / json.loads(lines[3])["parts"][0]
    data = bytearray(part.read_bytes())
    data[len(data) // 2] ^= 0xFF
    part.write_bytes(bytes(data))
    (out / "manifest.jsonl").write_text("\n".join(lines[:5] + lines[6:] + [lines[1]]) + "\n")
    report = validate_dataset(out, match_images=False)
    text = str(report)
    assert not report.ok
    assert "episodes listed more than once: 1" in text
    assert "1 episodes missing: 5" in text
    assert "episode 3 (shards/episode_000003.h5): checksum differs" in text
    assert "files in shards/ that no record lists: episode_000005.h5" in text
    done = run_cli("validate", str(out), "--json", "--no-image-matching")
    assert done.returncode == 1 and json.loads(done.stdout)["ok"] is False


def test_info_counts_by_anatomy_scenario_and_label(reference_dataset):
    info = dataset_info(reference_dataset)
    records = read_manifest(reference_dataset)[0]
    assert info["episodes"] == {"listed": 12, "expected": 12}
    assert sum(v["episodes"] for v in info["by_anatomy"].values()) == 12
    assert set(info["by_anatomy"]) == {"phantom", "phantom48"}
    for kind, counts in info["by_scenario"].items():
        assert counts["frames"] == sum(r["frames"] for r in records if r["scenario"] == kind)
    # label pixels agree with the shards' label images
    with open_recording(reference_dataset / records[0]["file"]) as rec:
        bone = sum(int((rec.cameras[s].label[:] == 1).sum()) for s in ("rig_left", "rig_right"))
    assert records[0]["label_pixels"]["Bone"] == bone
    assert info["label_pixels"]["Bone"]["pixels"] == sum(r["label_pixels"]["Bone"] for r in records)
    done = run_cli("dataset", "info", str(reference_dataset))
    assert done.returncode == 0 and "12 of 12 episodes" in done.stdout and "Bone" in done.stdout


def test_the_learning_dataset_reads_a_dataset_folder(reference_dataset):
    pytest.importorskip("torch", reason="ambfplus.learning needs the torch extra")
    from ambfplus.learning import RecordingStereoDataset

    data = RecordingStereoDataset(reference_dataset)
    records = sorted(read_manifest(reference_dataset)[0], key=lambda r: r["episode"])
    assert len(data) == sum(r["frames"] for r in records)
    assert data.paths == [reference_dataset / r["file"] for r in records]
    sample = data[len(data) - 1]
    assert tuple(sample["left"].shape) == (3, 120, 160)
    assert sample["valid"].any()
