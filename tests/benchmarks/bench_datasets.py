"""Datasets at scale: what ``ambfplus generate`` costs beyond rendering and recording.

The same episodes (640x480 stereo pairs, rgb + depth + label + instance, the default 128^3
phantom, camera and drilling scenarios, randomised lights, colours, materials and sensor noise)
are made four ways, each in its own process tree, and the CPU-seconds of the whole tree are
divided by the stereo pairs made:

- baseline: one process records them in a loop (``record_episode``, no workers, no checks);
- ``generate`` with 1 and with 2 local workers (forked from a fork server, validation,
  checksums, manifest, progress);
- ``generate`` on a Ray cluster of two nodes on this machine (1 CPU each, started as the README
  suggests: no dashboard, no log monitor), counting the driver and every process of the
  cluster (its daemons too) while the run lasts.

Every process of a tree counts: this process becomes a child subreaper, so helpers that outlive
the command (the fork server exits after its driver) are reaped here and their CPU time, with
their children's, reaches this process's children's times. Each round runs the four in a
rotated order, so that the machine's drift does not always hit the same one. Beside each ratio,
a breakdown: the CPU-seconds spent outside the episodes themselves (the tree's time minus the
episodes' own process time as the workers report it, and the baseline's loop outside its
episodes), and for Ray the cluster's daemons apart and the number of Ray worker processes
started (one per node when each keeps its EGL context for all its episodes). Each run notes the
machine's 1-minute load average as it starts.

    python tests/benchmarks/run.py --only datasets [--quick]
"""

from __future__ import annotations

import ctypes
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PR_SET_CHILD_SUBREAPER = 36
SPEC = """\
version: 1
name: bench
episodes: {episodes}
seed: 1
capture: {{every: 40, frames: {frames}, passes: [rgb, depth, label, instance]}}
anatomies: [{{phantom: {{resolution: 128, seed: {{choice: [0, 1]}}}}}}]
scenarios: [{{kind: camera}}, {{kind: drilling}}, {{kind: mixed}}]
rigs: [{{resolution: [640, 480]}}]
appearance:
  lights: {{count: {{uniform: [1, 3]}}, intensity: {{uniform: [0.4, 1.0]}}}}
  labels: {{color_jitter: 20}}
  material: {{specular: {{uniform: [0.05, 0.4]}}}}
  background: {{uniform: [0.0, 0.2]}}
  intrinsics: {{fov_y_jitter: 0.02, principal_point_jitter: 2.0}}
  noise: {{rgb_sigma: {{uniform: [0.5, 2.0]}}}}
"""


def _baseline(spec_path: str, out: str) -> None:
    """The in-process loop the benchmark compares with (run in a child process); prints the
    CPU-seconds its episodes took."""
    from ambfplus.dataset import load_spec, record_episode, shard_name

    spec = load_spec(spec_path)
    Path(out).mkdir(parents=True, exist_ok=True)
    episodes = 0.0
    for index in range(spec.episodes):
        started = time.process_time()
        record_episode(spec.data, index, Path(out) / shard_name(index))
        episodes += time.process_time() - started
    print(json.dumps({"episodes_cpu": episodes}))


def _set_subreaper(on: bool) -> None:
    """While on, orphans of our children's trees become our children (Linux), so that we
    reap them and their CPU time reaches RUSAGE_CHILDREN."""
    try:
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, int(on), 0, 0, 0)
    except (OSError, AttributeError):
        print("datasets: cannot become a child subreaper: helpers that outlive a run are not "
              "counted", file=sys.stderr)  # fmt: skip


def _children() -> list[int]:
    pids = []
    for task in Path("/proc/self/task").iterdir():
        try:
            pids += [int(p) for p in (task / "children").read_text().split()]
        except OSError:
            pass
    return pids


def _reap_orphans(before: set[int], timeout: float = 60.0) -> None:
    """Waits for every child process left by a run (its helpers, reparented here), apart from
    those that were there `before` it."""
    deadline = time.monotonic() + timeout
    while left := [pid for pid in _children() if pid not in before]:
        if time.monotonic() > deadline:
            raise RuntimeError(f"processes left by a run did not end: {left}")
        for pid in left:
            try:
                os.waitpid(pid, os.WNOHANG)
            except ChildProcessError:
                pass
        time.sleep(0.05)


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(command: list[str]) -> tuple[float, float, str]:
    """Runs a command from outside the source tree; (wall s, CPU s of its process tree,
    stdout)."""
    before = set(_children())
    cpu, wall = _children_cpu(), time.perf_counter()
    done = subprocess.run(command, cwd="/", capture_output=True, text=True)
    wall = time.perf_counter() - wall
    _reap_orphans(before)
    if done.returncode != 0:
        raise RuntimeError(f"{command[:4]} failed:\n{done.stdout}\n{done.stderr}")
    return wall, _children_cpu() - cpu, done.stdout


class _ClusterCpu:
    """CPU-seconds of every process of a Ray cluster while a run lasts. Raylets reap their
    workers without adding their times to their own (SIGCHLD ignored), so a thread samples
    each process 20 times a second and keeps its last reading: a worker that ends loses at
    most its last 50 ms."""

    def __init__(self, cluster) -> None:
        import threading

        self.cluster = cluster
        self.start = self._sample()
        self.last = dict(self.start)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _sample(self) -> dict:
        import psutil

        out = {}
        for process in self.cluster.processes():
            try:
                t = process.cpu_times()
                worker = process.ppid() in self.raylets
                out[(process.pid, process.create_time())] = (t.user + t.system, worker)
            except psutil.Error:
                pass
        return out

    @property
    def raylets(self) -> set[int]:
        if not hasattr(self, "_raylets"):
            self._raylets = {p.pid for p in self.cluster.raylets().values()}
        return self._raylets

    def _run(self) -> None:
        while not self._stop.wait(0.05):
            self.last.update(self._sample())

    def stop(self) -> tuple[float, float, int]:
        """Ends sampling; returns the CPU-seconds used since it began, the workers' and the
        rest's (raylets, GCS, agents), and how many worker processes were started."""
        self._stop.set()
        self._thread.join()
        self.last.update(self._sample())
        workers = daemons = 0.0
        started = 0
        for key, (cpu, worker) in self.last.items():
            used = cpu - self.start.get(key, (0.0, worker))[0]
            if worker and key not in self.start:
                workers += used
                started += 1
            else:
                daemons += used
        return workers, daemons, started


def _episodes_cpu(folder: Path) -> tuple[int, float]:
    """(stereo pairs, CPU-seconds of the episodes as their workers measured them)."""
    from ambfplus.dataset import read_manifest

    records = read_manifest(folder)[0]
    return sum(r["frames"] for r in records), sum(r["cpu_seconds"] for r in records)


def datasets(args):
    episodes, frames, rounds = (4, 10, 1) if args.quick else (12, 25, 3)
    work = Path(tempfile.mkdtemp(prefix="bench_datasets"))
    spec = work / "spec.yaml"
    spec.write_text(SPEC.format(episodes=episodes, frames=frames))
    python = sys.executable
    generate = [python, "-m", "ambfplus", "generate", str(spec), "--quiet", "--out"]
    cluster = _start_cluster()
    _set_subreaper(True)  # after the cluster started: its daemons are not our children
    results: dict[str, list[dict]] = {}
    pairs = episodes * frames
    names = ["baseline", "local1", "local2"] + (["ray"] if cluster is not None else [])
    try:
        for round_ in range(rounds):
            order = names[round_ % len(names) :] + names[: round_ % len(names)]
            for name in order:
                out = work / f"{name}{round_}"
                if name == "baseline":
                    command = [python, str(Path(__file__).resolve()), "baseline", str(spec),
                               str(out)]  # fmt: skip
                elif name == "ray":
                    command = generate + [str(out), "--ray", cluster.address]
                else:
                    command = generate + [str(out), "--workers", name[-1]]
                sampler = _ClusterCpu(cluster) if name == "ray" else None
                load = os.getloadavg()[0]  # the machine is shared: its load goes with each run
                wall, cpu, stdout = _run(command)
                run = {"wall": wall, "driver": cpu, "load": load}
                if sampler is not None:
                    time.sleep(1)  # the job's workers end
                    run["workers"], run["daemons"], run["processes"] = sampler.stop()
                if name == "baseline":
                    run["episodes"] = json.loads(stdout.strip().splitlines()[-1])["episodes_cpu"]
                else:
                    made, run["episodes"] = _episodes_cpu(out)
                    assert made == pairs, (name, made, pairs)
                run["cpu"] = cpu + run.get("workers", 0.0) + run.get("daemons", 0.0)
                results.setdefault(name, []).append(run)
                shutil.rmtree(out, ignore_errors=True)
    finally:
        _set_subreaper(False)
        if cluster is not None:
            cluster.stop()
        shutil.rmtree(work, ignore_errors=True)
    yield from _figures(results, pairs, args.quick)


def _figures(results: dict, pairs: int, quick: bool):
    common = {"pairs": pairs, "frame": "640x480 stereo pair, rgb+depth+label+instance",
              "quick": quick, "rounds": len(results["baseline"])}  # fmt: skip
    base = [r["cpu"] / pairs for r in results["baseline"]]
    outside = [r["cpu"] - r["episodes"] for r in results["baseline"]]
    yield {
        "bench": "datasets_cpu_per_pair_baseline",
        "value": round(statistics.median(base), 4),
        "unit": "CPU-s",
        "worst": round(max(base), 4),
        "outside_episodes_cpu_s": [round(v, 2) for v in outside],
        "wall_s": [round(r["wall"], 1) for r in results["baseline"]],
        "load_1min": [round(r["load"], 1) for r in results["baseline"]],
        "what": "process CPU per stereo pair of one in-process loop of record_episode",
        **common,
    }
    targets = {"local1": 1.10, "local2": 1.10, "ray": 1.20}
    for name, what in (("local1", "generate, 1 local worker"),
                       ("local2", "generate, 2 local workers"),
                       ("ray", "generate on Ray (2 nodes x 1 CPU, daemons counted)")):  # fmt: skip
        if name not in results:
            continue
        runs = results[name]
        ours = [r["cpu"] / pairs for r in runs]
        ratios = [o / b for o, b in zip(ours, base)]
        line = {
            "bench": f"datasets_cpu_per_pair_{name}",
            "value": round(statistics.median(ours), 4),
            "unit": "CPU-s",
            "baseline": round(statistics.median(base), 4),
            "ratio": round(statistics.median(ratios), 4),
            "worst_ratio": round(max(ratios), 4),
            "ratios": [round(r, 3) for r in ratios],
            "target_ratio": targets[name],
            # CPU-s of the tree outside the episodes' own process time, per run
            "outside_episodes_cpu_s": [round(r["cpu"] - r["episodes"], 2) for r in runs],
            "episodes_cpu_s": [round(r["episodes"], 2) for r in runs],
            "wall_s": [round(r["wall"], 1) for r in runs],
            "load_1min": [round(r["load"], 1) for r in runs],
            "what": f"process-tree CPU per stereo pair: {what}; baseline: one in-process loop",
            **common,
        }
        if name == "ray":
            line["driver_cpu_s"] = [round(r["driver"], 2) for r in runs]
            line["workers_outside_episodes_cpu_s"] = [
                round(r["workers"] - r["episodes"], 2) for r in runs
            ]
            line["daemons_cpu_s"] = [round(r["daemons"], 2) for r in runs]
            line["daemons_cpu_s_per_wall_s"] = [round(r["daemons"] / r["wall"], 4) for r in runs]
            # one per node when each worker keeps its process (and EGL context) for all its tasks
            line["worker_processes"] = [r["processes"] for r in runs]
        yield line
    one = [pairs / r["wall"] for r in results["local1"]]
    for name, what in (("local2", "2 local workers"), ("ray", "Ray (2 nodes x 1 CPU)")):
        if name not in results:
            continue
        ours = [pairs / r["wall"] for r in results[name]]
        ratios = [o / b for o, b in zip(ours, one)]
        yield {
            "bench": f"datasets_throughput_{name}",
            "value": round(statistics.median(ours), 3),
            "unit": "pairs/s",
            "baseline": round(statistics.median(one), 3),
            "ratio": round(statistics.median(ratios), 3),
            "worst_ratio": round(min(ratios), 3),
            "what": f"wall-clock stereo pairs per second, {what}; baseline: 1 local worker",
            **common,
        }


def _start_cluster():
    """A two-node Ray cluster on this machine (tests/ray_cluster.py), or None without ray."""
    try:
        import psutil  # noqa: F401
        import ray  # noqa: F401
    except ImportError:
        print('datasets: ray is not installed (pip install "ambfplus[ray]"): no Ray figures',
              file=sys.stderr)  # fmt: skip
        return None
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
    from helpers.ray_cluster import RayCluster

    return RayCluster(cpus_per_node=1).start()


BENCHMARKS = {"datasets": datasets}

if __name__ == "__main__" and len(sys.argv) == 4 and sys.argv[1] == "baseline":
    _baseline(sys.argv[2], sys.argv[3])
