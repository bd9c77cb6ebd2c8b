"""A real two-node Ray cluster on this machine for the tests: a head and a second node, each
started with `ray start` on its own loopback address (127.0.0.2, 127.0.0.3), with its own temp
dir and ports, one CPU and a small object store each, and as the README suggests for
generating datasets: no dashboard and no log monitor; and without token authentication (see
below). `ray start` runs in this Python (its workers import the ambfplus under test, not
another one on PATH). Stopping it kills exactly the processes it started (found by their temp
dirs) and their children, never anyone else's Ray."""

from __future__ import annotations

import os
import shutil
import socket
import subprocess
import sys
import tempfile
import time

import psutil

HEAD_IP, NODE_IP = "127.0.0.2", "127.0.0.3"
OBJECT_STORE_BYTES = 100 * 1000 * 1000  # Ray's minimum is 75 MB
WORKER_PORTS = 40
# Per node: node manager, object manager, dashboard agent (listen, grpc), runtime env agent,
# metrics; then the head's own port and its dashboard; then each node's worker ports.
PORTS_PER_NODE = 6


def _free(ip: str, port: int) -> bool:
    with socket.socket() as s:
        try:
            s.bind((ip, port))
        except OSError:
            return False
    with socket.socket() as s:  # Ray binds some ports on every address
        try:
            s.bind(("", port))
        except OSError:
            return False
    return True


def _port_block(count: int) -> int:
    """The first of `count` consecutive ports free on both loopback addresses."""
    rng = __import__("random").Random(os.getpid() ^ int(time.time()))
    for _ in range(200):
        base = rng.randrange(20000, 60000 - count)
        if all(_free(ip, p) for p in range(base, base + count) for ip in (HEAD_IP, NODE_IP)):
            return base
    raise RuntimeError(f"no block of {count} free ports found")


class RayCluster:
    """`ray start` a head and a second node; ``address`` is the head's; ``stop()`` ends them."""

    def __init__(self, cpus_per_node: int = 1, env: dict | None = None) -> None:
        self.cpus = cpus_per_node
        self.dirs = [
            tempfile.mkdtemp(prefix="rayh", dir="/tmp"),
            tempfile.mkdtemp(prefix="rayw", dir="/tmp"),
        ]
        count = 2 + 2 * (PORTS_PER_NODE + WORKER_PORTS)
        base = _port_block(count)
        self.port, self.dashboard_port = base, base + 1
        self.address = f"{HEAD_IP}:{self.port}"
        self._next = base + 2
        # Without token authentication whatever ~/.ray/auth_token holds: a token there (any
        # `ray.init()` on this machine writes one) puts a head started by `ray start` in token
        # mode but not a second node, which then cannot join. Drivers connect either way.
        self.env = {**os.environ, "RAY_USAGE_STATS_ENABLED": "0", "RAY_AUTH_MODE": "disabled"}
        self.env.update(env or {})  # Ray's settings (RAY_<name>) for every process it starts
        self.log = ""

    def _node_ports(self) -> list[str]:
        p = self._next
        self._next += PORTS_PER_NODE + WORKER_PORTS
        first_worker = p + PORTS_PER_NODE
        return [
            f"--node-manager-port={p}",
            f"--object-manager-port={p + 1}",
            f"--dashboard-agent-listen-port={p + 2}",
            f"--dashboard-agent-grpc-port={p + 3}",
            f"--runtime-env-agent-port={p + 4}",
            f"--metrics-export-port={p + 5}",
            f"--min-worker-port={first_worker}",
            f"--max-worker-port={first_worker + WORKER_PORTS - 1}",
        ]

    def _start(self, args: list[str]) -> None:
        common = [
            f"--num-cpus={self.cpus}",
            f"--object-store-memory={OBJECT_STORE_BYTES}",
            "--disable-usage-stats",
            "--include-log-monitor=false",
        ]
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "ray.scripts.scripts",
                "start",
                *args,
                *common,
                *self._node_ports(),
            ],
            cwd="/",
            env=self.env,
            capture_output=True,
            text=True,
            timeout=120,
        )
        self.log += done.stdout + done.stderr
        if done.returncode != 0:
            raise RuntimeError(f"ray start failed:\n{done.stdout}\n{done.stderr}")

    def start(self) -> RayCluster:
        try:
            self._start(
                [
                    "--head",
                    f"--port={self.port}",
                    f"--node-ip-address={HEAD_IP}",
                    f"--temp-dir={self.dirs[0]}",
                    "--include-dashboard=false",
                    f"--dashboard-port={self.dashboard_port}",
                ]
            )
            self._start(
                [
                    f"--address={self.address}",
                    f"--node-ip-address={NODE_IP}",
                    f"--temp-dir={self.dirs[1]}",
                ]
            )
        except BaseException:
            self.stop()
            raise
        return self

    def raylets(self) -> dict[str, psutil.Process]:
        """Each node's raylet, by node IP."""
        out = {}
        for process in self.processes():
            try:
                if process.name() == "raylet":
                    ip = HEAD_IP if self.dirs[0] in " ".join(process.cmdline()) else NODE_IP
                    out[ip] = process
            except psutil.Error:
                pass
        return out

    def workers_running(self, task: str) -> dict[str, list[int]]:
        """PIDs of worker processes running `task` (Ray titles them ray::<task>), by node IP."""
        out: dict[str, list[int]] = {}
        for ip, raylet in self.raylets().items():
            for child in raylet.children(recursive=True):
                try:
                    if " ".join(child.cmdline()).startswith(f"ray::{task}"):
                        out.setdefault(ip, []).append(child.pid)
                except psutil.Error:
                    pass
        return out

    def processes(self, ip: str | None = None) -> list[psutil.Process]:
        """Every process this cluster started (or those of the node at `ip`): those naming its
        temp dirs, and their children."""
        dirs = self.dirs if ip is None else [self.dirs[0 if ip == HEAD_IP else 1]]
        roots = []
        for process in psutil.process_iter(["cmdline"]):
            cmdline = " ".join(process.info["cmdline"] or [])
            if any(d in cmdline for d in dirs):
                roots.append(process)
        found = {p.pid: p for p in roots}
        for root in roots:
            try:
                found.update({c.pid: c for c in root.children(recursive=True)})
            except psutil.Error:
                pass
        return list(found.values())

    def kill_node(self, ip: str) -> list[int]:
        """Loses the node at `ip` as a machine would: SIGKILLs its raylet, its workers and its
        agents at once. Returns their PIDs."""
        processes = self.processes(ip)
        for process in processes:
            try:
                process.kill()
            except psutil.Error:
                pass
        return [process.pid for process in processes]

    def stop(self) -> None:
        """Ends this cluster's processes (SIGTERM, then SIGKILL) and removes its temp dirs."""
        processes = self.processes()
        for process in processes:
            try:
                process.terminate()
            except psutil.Error:
                pass
        _, alive = psutil.wait_procs(processes, timeout=10)
        for process in alive:
            try:
                process.kill()
            except psutil.Error:
                pass
        psutil.wait_procs(alive, timeout=10)
        for d in self.dirs:
            shutil.rmtree(d, ignore_errors=True)
