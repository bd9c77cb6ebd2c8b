"""Datasets at scale: what ``ambfplus generate`` costs beyond rendering and recording.

The same episodes (640x480 stereo pairs, rgb + depth + label + instance, the default 128^3
phantom, camera and drilling scenarios, randomised lights, colours, materials and sensor noise)
are made four ways, each in its own process tree, and the CPU-seconds of the whole tree are
divided by the stereo pairs made:

- baseline: one process records them in a loop (``record_episode``, no workers, no checks);
- ``generate`` with 1 and with 2 local workers (spawned processes, validation, checksums,
  manifest, progress);
- ``generate`` on a Ray cluster of two nodes on this machine (1 CPU each), counting the
  driver and every process of the cluster (its daemons too) while the run lasts.

    python tests/benchmarks/run.py --only datasets [--quick]
"""

from __future__ import annotations

import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

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
    """The in-process loop the benchmark compares with (run in a child process)."""
    from ambfplus.dataset import load_spec, record_episode, shard_name

    spec = load_spec(spec_path)
    Path(out).mkdir(parents=True, exist_ok=True)
    for index in range(spec.episodes):
        record_episode(spec.data, index, Path(out) / shard_name(index))


def _children_cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _run(command: list[str]) -> tuple[float, float]:
    """Runs a command from outside the source tree; (wall s, CPU s of its process tree)."""
    cpu, wall = _children_cpu(), time.perf_counter()
    done = subprocess.run(command, cwd="/", capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{command[:4]} failed:\n{done.stdout}\n{done.stderr}")
    return time.perf_counter() - wall, _children_cpu() - cpu


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
                out[(process.pid, process.create_time())] = t.user + t.system
            except psutil.Error:
                pass
        return out

    def _run(self) -> None:
        while not self._stop.wait(0.05):
            self.last.update(self._sample())

    def stop(self) -> float:
        """Ends sampling; returns the CPU-seconds used since it began."""
        self._stop.set()
        self._thread.join()
        self.last.update(self._sample())
        return sum(cpu - self.start.get(key, 0.0) for key, cpu in self.last.items())


def _pairs(folder: Path) -> int:
    from ambfplus.dataset import read_manifest

    return sum(r["frames"] for r in read_manifest(folder)[0])


def datasets(args):
    episodes, frames, rounds = (4, 10, 1) if args.quick else (12, 25, 2)
    work = Path(tempfile.mkdtemp(prefix="bench_datasets"))
    spec = work / "spec.yaml"
    spec.write_text(SPEC.format(episodes=episodes, frames=frames))
    python = sys.executable
    generate = [python, "-m", "ambfplus", "generate", str(spec), "--quiet", "--out"]
    cluster = _start_cluster()
    results: dict[str, list[tuple[float, float]]] = {}
    pairs = episodes * frames
    try:
        for round_ in range(rounds):
            runs = {
                "baseline": [python, str(Path(__file__).resolve()), "baseline", str(spec)],
                "local1": generate + [None, "--workers", "1"],
                "local2": generate + [None, "--workers", "2"],
            }
            if cluster is not None:
                runs["ray"] = generate + [None, "--ray", cluster.address]
            for name, command in runs.items():
                out = work / f"{name}{round_}"
                command = [str(out) if c is None else c for c in command]
                if name == "baseline":
                    command.append(str(out))
                sampler = _ClusterCpu(cluster) if name == "ray" else None
                wall, cpu = _run(command)
                if sampler is not None:
                    time.sleep(1)  # the job's workers end
                    cpu += sampler.stop()
                else:
                    assert name == "baseline" or _pairs(out) == pairs
                results.setdefault(name, []).append((wall, cpu))
                shutil.rmtree(out, ignore_errors=True)
    finally:
        if cluster is not None:
            cluster.stop()
        shutil.rmtree(work, ignore_errors=True)
    yield from _figures(results, pairs, args.quick, cluster is not None)


def _figures(results: dict, pairs: int, quick: bool, with_ray: bool):
    common = {"pairs": pairs, "frame": "640x480 stereo pair, rgb+depth+label+instance",
              "quick": quick}  # fmt: skip
    base = [cpu / pairs for _, cpu in results["baseline"]]
    targets = {"local1": 1.10, "local2": 1.10, "ray": 1.20}
    for name, what in (("local1", "generate, 1 local worker"),
                       ("local2", "generate, 2 local workers"),
                       ("ray", "generate on Ray (2 nodes x 1 CPU, daemons counted)")):  # fmt: skip
        if name not in results:
            continue
        ours = [cpu / pairs for _, cpu in results[name]]
        ratios = [o / b for o, b in zip(ours, base)]
        yield {
            "bench": f"datasets_cpu_per_pair_{name}",
            "value": round(statistics.median(ours), 4),
            "unit": "CPU-s",
            "baseline": round(statistics.median(base), 4),
            "ratio": round(statistics.median(ratios), 4),
            "worst_ratio": round(max(ratios), 4),
            "target_ratio": targets[name],
            "what": f"process-tree CPU per stereo pair: {what}; baseline: one in-process loop",
            **common,
        }
    one = [pairs / wall for wall, _ in results["local1"]]
    for name, what in (("local2", "2 local workers"), ("ray", "Ray (2 nodes x 1 CPU)")):
        if name not in results:
            continue
        ours = [pairs / wall for wall, _ in results[name]]
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
    from ray_cluster import RayCluster

    return RayCluster(cpus_per_node=1).start()


BENCHMARKS = {"datasets": datasets}

if __name__ == "__main__" and len(sys.argv) == 4 and sys.argv[1] == "baseline":
    _baseline(sys.argv[2], sys.argv[3])
