"""Datasets on a real Ray cluster: a head and a second node started with `ray start` on this
machine (tests/helpers/ray_cluster.py). The same spec gives the same shards as the local
executor, Ray workers killed on either node are replaced and their episodes redone, a lost
node's episodes are redone on the other, and a killed driver resumes. Skipped without the ray
extra (pip install "ambfplus[ray]"), except under CI (the environment variable CI set), which
installs it: there its absence fails."""

from __future__ import annotations

import importlib
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import pytest

# Starts a Ray cluster of two nodes on this machine.
pytestmark = pytest.mark.cluster


def _need(module: str) -> None:
    """Imports `module` (of the ray extra), or skips these tests; under CI, fails instead."""
    reason = f'the Ray tests need {module}, in the ray extra: pip install "ambfplus[ray]"'
    if os.environ.get("CI", "").lower() in ("", "0", "false"):
        pytest.importorskip(module, reason=reason)
        return
    try:
        importlib.import_module(module)
    except ImportError as error:
        pytest.fail(f"{reason} (CI is set, and CI installs the extra: {error})", pytrace=False)


_need("ray")
_need("psutil")

import psutil  # noqa: E402
from helpers.ray_cluster import NODE_IP, RayCluster  # noqa: E402
from test_dataset import manifest, shard_bytes  # noqa: E402

from ambfplus.dataset import generate, read_manifest, validate_dataset  # noqa: E402
from ambfplus.dataset.ray_executor import check_reachable  # noqa: E402

TASK = "ambfplus_episode"


@pytest.fixture(scope="module")
def cluster():
    cluster = RayCluster(cpus_per_node=1)
    try:
        cluster.start()
        yield cluster
    finally:
        cluster.stop()


def nodes_used(folder) -> set[str]:
    return {r["worker"].split(":")[0] for r in read_manifest(folder)[0]}


def test_ray_makes_the_same_shards_as_local_workers(
    cluster, dataset_spec, reference_dataset, tmp_path
):
    report = generate(dataset_spec, tmp_path / "ray", ray=cluster.address, progress=False)
    assert report.generated == 12 and report.executor["nodes"] == 2
    assert manifest(tmp_path / "ray") == manifest(reference_dataset)
    assert shard_bytes(tmp_path / "ray") == shard_bytes(reference_dataset)
    assert len(nodes_used(tmp_path / "ray")) == 2  # both nodes rendered
    # one Ray worker process per node made all of its node's episodes: one EGL context each
    workers = {r["worker"] for r in read_manifest(tmp_path / "ray")[0]}
    assert len(workers) == 2, workers
    environment = json.loads((tmp_path / "ray" / "environment.json").read_text())
    assert environment["runs"][0]["executor"] == "ray"
    assert environment["runs"][0]["address"] == cluster.address


def test_ray_makes_the_same_shards_of_a_multi_arm_scene_as_local_workers(
    cluster, multi_arm_spec, multi_arm_dataset, tmp_path
):
    # A dataset of any scene (an AMBF launch file driven by a Python episode script imported on
    # each node from the spec's python_path) on the cluster: the same bytes as one local worker.
    report = generate(multi_arm_spec, tmp_path / "ray", ray=cluster.address, progress=False)
    assert report.generated == 6
    assert manifest(tmp_path / "ray") == manifest(multi_arm_dataset)
    assert shard_bytes(tmp_path / "ray") == shard_bytes(multi_arm_dataset)
    assert validate_dataset(tmp_path / "ray", match_images=False).ok


def test_ray_workers_killed_on_both_nodes_are_retried(
    cluster, dataset_spec, reference_dataset, tmp_path
):
    out = tmp_path / "ray"
    killed: dict[str, int] = {}
    stop = threading.Event()

    def killer():
        rng = random.Random(20)
        while not stop.is_set() and sum(killed.values()) < 4:
            time.sleep(rng.uniform(0.1, 0.4))  # often enough to reach both nodes in the run
            running = cluster.workers_running(TASK)
            # the second node's workers first, until one of each node is gone
            ips = [ip for ip in sorted(running, reverse=True) if running[ip]]
            wanted = [ip for ip in ips if not killed.get(ip)] or ips
            if wanted:
                ip = wanted[0]
                os.kill(rng.choice(running[ip]), signal.SIGKILL)
                killed[ip] = killed.get(ip, 0) + 1

    thread = threading.Thread(target=killer)
    thread.start()
    try:
        report = generate(dataset_spec, out, ray=cluster.address, retries=8, progress=False)
    finally:
        stop.set()
        thread.join()
    assert len(killed) == 2, f"kills by node: {killed}"
    assert report.retries >= 2
    assert manifest(out) == manifest(reference_dataset)
    assert shard_bytes(out) == shard_bytes(reference_dataset)
    check = validate_dataset(out, match_images=False)
    assert check.ok and not check.warnings, str(check)


def test_a_killed_ray_driver_resumes_to_the_same_dataset(
    cluster, dataset_spec, reference_dataset, tmp_path
):
    out, log = tmp_path / "ray", tmp_path / "driver.log"
    with open(log, "wb") as stderr:
        driver = subprocess.Popen(
            [sys.executable, "-m", "ambfplus", "generate", str(dataset_spec), "--out", str(out),
             "--ray", cluster.address, "--quiet"],
            cwd="/", env=cluster.env, stdout=subprocess.DEVNULL, stderr=stderr,
        )  # fmt: skip
    try:
        listed = wait_for_listed(out, 3, driver, log)
        # the processes that ran (or run) the driver's tasks
        job_workers = {int(r["worker"].rsplit(":", 1)[1]) for r in listed}
        job_workers |= {pid for pids in cluster.workers_running(TASK).values() for pid in pids}
    finally:
        driver.kill()
        driver.wait(timeout=30)
    assert 3 <= len(read_manifest(out)[0]) < 12
    # Ray ends a dead driver's workers (its tasks too) when it notices; a task that outlived it
    # could not move a shard in anyway (the resumed run takes the folder over), but the
    # comparison below is of a run with no other job on the cluster
    alive = set(job_workers)
    for _ in range(600):
        alive = {pid for pid in alive if _running(pid)}
        if not alive:
            break
        time.sleep(0.1)
    else:
        pytest.fail(f"the killed driver's Ray workers {sorted(alive)} outlived it by 60 s")
    resumed = generate(dataset_spec, out, ray=cluster.address, progress=False)
    assert resumed.skipped >= 3 and resumed.skipped + resumed.generated == 12
    assert manifest(out) == manifest(reference_dataset)
    assert shard_bytes(out) == shard_bytes(reference_dataset)


# How long a driver may go without listing an episode before a test gives up on it (the first
# one includes connecting to the cluster and starting its workers).
STALL_S = 150


def wait_for_listed(out, count: int, driver: subprocess.Popen, log) -> list[dict]:
    """Waits while the driver lists episodes until `count` are listed; fails if it ends or goes
    STALL_S seconds without listing one."""
    listed, progress = [], time.monotonic()
    while len(listed) < count:
        if driver.poll() is not None:
            pytest.fail(f"the driver ended early: {log.read_text()}")
        records = read_manifest(out)[0]
        if len(records) > len(listed):
            listed, progress = records, time.monotonic()
        elif time.monotonic() - progress > STALL_S:
            pytest.fail(f"the driver listed no episode for {STALL_S} s: {log.read_text()}")
        time.sleep(0.05)
    return listed


def _running(pid: int) -> bool:
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.Error:
        return False


def test_ray_local_is_a_cluster_of_its_own_whose_gpu_workers_keep_their_context(
    cluster, dataset_spec, reference_dataset, tmp_path, monkeypatch
):
    # RAY_ADDRESS names the two-node cluster, which "local" must not join
    monkeypatch.setenv("RAY_ADDRESS", cluster.address)
    monkeypatch.setenv("RAY_USAGE_STATS_ENABLED", "0")
    # Ray would give a new local cluster token authentication and write ~/.ray/auth_token,
    # which changes every later `ray start` on this machine
    monkeypatch.setenv("RAY_AUTH_MODE", "disabled")
    # The run's cluster declares one GPU; the environment chooses the device tasks render on
    # (llvmpipe's), as it may on a GPU machine, so the GPU's id changes nothing.
    monkeypatch.setenv("AMBFPLUS_EGL_DEVICE", "0")
    temp_dir = tempfile.mkdtemp(prefix="rayl", dir="/tmp")  # short: Ray's socket paths
    try:
        report = generate(
            dataset_spec,
            tmp_path / "local",
            ray="local",
            progress=False,
            ray_options={
                "gpus": 1,
                "init_options": {"num_cpus": 1, "num_gpus": 1, "_temp_dir": temp_dir},
            },
        )
    finally:
        shutil.rmtree(temp_dir, ignore_errors=True)
    assert (report.executor["nodes"], report.executor["gpus"]) == (1, 1)
    assert manifest(tmp_path / "local") == manifest(reference_dataset)
    assert shard_bytes(tmp_path / "local") == shard_bytes(reference_dataset)
    # Ray gives a function declared with GPUs a new process per task; ours keeps one worker
    # (and its EGL context) for every episode
    workers = {r["worker"] for r in read_manifest(tmp_path / "local")[0]}
    assert len(workers) == 1, workers


def test_an_unreachable_ray_address_says_so(tmp_path):
    with pytest.raises(ConnectionError, match=r"cannot reach a Ray cluster at 127\.0\.0\.1:9"):
        generate(
            {"version": 1, "episodes": 1, "anatomies": [{"phantom": {}}]},
            tmp_path / "out",
            ray="127.0.0.1:9",
            progress=False,
        )
    assert not (tmp_path / "out").exists()
    with pytest.raises(ConnectionError, match="expected host:port"):
        check_reachable("nowhere")


# A few short episodes that a lost node's share of is redone on the other node.
LOST_NODE_SPEC = """\
version: 1
episodes: 6
seed: 11
capture: {every: 250, frames: 4, passes: [rgb, depth, label]}
anatomies: [{phantom: {resolution: 40}}]
scenarios: [{kind: camera}]
rigs: [{resolution: [160, 120]}]
"""


def test_a_lost_ray_node_has_its_episodes_redone(tmp_path):
    spec, out = tmp_path / "spec.yaml", tmp_path / "ray"
    spec.write_text(LOST_NODE_SPEC)
    # a cluster of its own (this one loses a node), whose head notices a lost node in seconds
    lost = RayCluster(
        cpus_per_node=1,
        env={"RAY_health_check_period_ms": "1000", "RAY_health_check_failure_threshold": "3"},
    )
    killed: list[int] = []
    stop = threading.Event()

    def lose_the_second_node():  # as soon as it runs an episode
        while not stop.is_set():
            if lost.workers_running(TASK).get(NODE_IP):
                killed.extend(lost.kill_node(NODE_IP))
                return
            time.sleep(0.05)

    thread = threading.Thread(target=lose_the_second_node)
    try:
        lost.start()
        thread.start()
        report = generate(spec, out, ray=lost.address, retries=3, timeout=120, progress=False)
    finally:
        stop.set()
        if thread.is_alive():
            thread.join()
        lost.stop()
    assert killed, "the second node never ran an episode"
    assert report.retries >= 1 and report.generated == 6
    records = read_manifest(out)[0]
    assert sorted(r["episode"] for r in records) == list(range(6))  # none missing, none twice
    check = validate_dataset(out, match_images=False)
    assert check.ok and not check.warnings, str(check)
    environment = json.loads((out / "environment.json").read_text())
    assert environment["runs"][0]["retries"] == report.retries
