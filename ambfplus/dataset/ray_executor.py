"""The Ray executor (``pip install "ambfplus[ray]"``): the same episodes as Ray tasks on a
cluster (``ray.init(address=...)``), one EGL context per Ray worker process, created on its
first render. Where Ray gives a task a GPU, the worker renders on it (the engine's
``AMBFPLUS_CUDA_DEVICE`` selection; unless the environment already chooses a device).

Ray's own task retries are off: a task whose worker died (SIGKILL, a lost node) or that raised
comes back as an error, and this executor submits the episode again (its ``retries``), exactly
as the local one does. Every node must see the dataset folder at the same path (a shared
filesystem) and have ambfplus installed.
"""

from __future__ import annotations

import logging
import os
import socket
import time
from collections import deque
from collections.abc import Generator
from pathlib import Path
from typing import Any

from .executor import Done, Executor, Failed, Retry


def require_ray():
    """Imports ray, or says how to install it."""
    try:
        import ray
    except ImportError as error:
        raise ImportError(
            'running on Ray needs the optional extra: pip install "ambfplus[ray]"'
        ) from error
    return ray


def ambfplus_episode(
    spec_data: dict, out: str, index: int, attempt: int, run_id: str | None = None
) -> dict:
    """A Ray task: makes one episode's shard (see ``ambfplus.dataset.episode.run_episode``)."""
    import ray

    select_gpu(ray.get_gpu_ids(), os.environ)
    from .episode import run_episode

    node = ray.get_runtime_context().get_node_id()[:8]
    worker = f"ray-{node}:{os.getpid()}"
    return run_episode(spec_data, out, index, attempt, worker=worker, run=run_id)


def select_gpu(gpu_ids, environ) -> str | None:
    """Points the engine's EGL device selection at the GPU Ray assigned (its CUDA ordinal among
    the devices this process sees), unless a device is already chosen. Returns the ordinal set,
    if any. Has no effect once this process has rendered (its context stays where it is)."""
    if not gpu_ids or "AMBFPLUS_CUDA_DEVICE" in environ or "AMBFPLUS_EGL_DEVICE" in environ:
        return None
    gpu = str(gpu_ids[0])
    visible = [v.strip() for v in environ.get("CUDA_VISIBLE_DEVICES", "").split(",") if v.strip()]
    ordinal = str(visible.index(gpu)) if gpu in visible else gpu
    environ["AMBFPLUS_CUDA_DEVICE"] = ordinal
    return ordinal


def check_reachable(address: str, timeout: float = 5.0) -> None:
    """Raises ConnectionError naming `address` ("host:port" or "ray://host:port") when nothing
    answers there."""
    target = address.split("://", 1)[-1]
    host, _, port = target.rpartition(":")
    if not host or not port.isdigit():
        raise ConnectionError(
            f"Ray address {address!r}: expected host:port, ray://host:port, 'auto' or 'local'"
        )
    try:
        socket.create_connection((host, int(port)), timeout=timeout).close()
    except OSError as error:
        raise ConnectionError(
            f"cannot reach a Ray cluster at {address}: {error.strerror or error} (is its head "
            "running? `ray start --head` prints the address to use)"
        ) from None


class RayExecutor(Executor):
    """Runs episodes as Ray tasks on the cluster at `address`: "auto" (the cluster this machine
    belongs to, or RAY_ADDRESS), "local" (a new single-machine cluster for this run), or
    "host:port" / "ray://host:port". Each task asks for `cpus` CPUs and `gpus` GPUs."""

    name = "ray"

    def __init__(
        self,
        address: str,
        retries: int = 3,
        timeout: float | None = None,
        cpus: float = 1.0,
        gpus: float = 0.0,
        init_options: dict | None = None,
    ) -> None:
        super().__init__(retries, timeout)
        self.address = address
        self.cpus, self.gpus = float(cpus), float(gpus)
        self.init_options = dict(init_options or {})
        self._ray: Any = None
        self._resources: dict = {}

    def connect(self) -> None:
        ray = require_ray()
        if self.address not in ("auto", "local"):
            check_reachable(self.address)
        options = {"log_to_driver": False, "logging_level": logging.WARNING, **self.init_options}
        # "local" is said to Ray too: without an address, ray.init joins the cluster named by
        # RAY_ADDRESS or the last one `ray start` began on this machine.
        options["address"] = self.address
        if self.address == "local":
            options.setdefault("include_dashboard", False)
        # Ray puts the driver's current folder first on its workers' sys.path: from a source
        # checkout, that would shadow the installed package (which has the engine) with the
        # bare sources. Connect from a folder that holds no Python packages.
        here = os.getcwd()
        os.chdir("/")
        try:
            ray.init(**options)
        except ConnectionError as error:
            raise ConnectionError(
                f"cannot connect to a Ray cluster at {self.address!r}: {error}"
            ) from None
        finally:
            os.chdir(here)
        self._ray = ray
        self._resources = ray.cluster_resources()

    def describe(self) -> dict:
        nodes: list = [n for n in self._ray.nodes() if n.get("Alive")] if self._ray else []
        return {
            "executor": self.name,
            "address": self.address,
            "nodes": len(nodes),
            "cpus": self._resources.get("CPU", 0),
            "gpus": self._resources.get("GPU", 0),
            "task_cpus": self.cpus,
            "task_gpus": self.gpus,
        }

    def run(self, spec_data: dict, out, todo: list[int], run_id: str | None = None) -> Generator:
        ray = self._ray
        # A worker runs any number of these tasks in one process (one EGL context for all its
        # episodes) however the GPUs are asked for: Ray's default for a function declared with
        # GPUs is a new process per task.
        task = ray.remote(max_calls=0)(ambfplus_episode).options(
            num_cpus=self.cpus, num_gpus=self.gpus, max_retries=0
        )
        spec_ref = ray.put(spec_data)
        out = Path(out).resolve()  # workers run elsewhere
        queue = deque((index, 0) for index in todo)
        slots = max(1.0, self._resources.get("CPU", 1.0) / max(self.cpus, 1e-9))
        window = max(2, int(2 * slots))  # keep every worker busy without flooding the queue
        running: dict = {}
        cancelled: set = set()
        while queue or running:
            while queue and len(running) < window:
                index, attempt = queue.popleft()
                ref = task.remote(spec_ref, str(out), index, attempt, run_id)
                running[ref] = (index, attempt, time.monotonic())
            ready, _ = ray.wait(list(running), num_returns=1, timeout=1.0)
            for ref in ready:
                index, attempt, _ = running.pop(ref)
                try:
                    yield Done(ray.get(ref))
                    continue
                except ray.exceptions.RayTaskError as error:
                    reason = str(error)
                except ray.exceptions.RayError as error:
                    reason = f"{type(error).__name__}: {error}"
                if ref in cancelled:
                    reason = f"took more than {self.timeout} s and was cancelled"
                    cancelled.discard(ref)
                self.discard(out, run_id, index, attempt)
                if attempt >= self.retries:
                    yield Failed(index, attempt + 1, reason)
                    return
                queue.append((index, attempt + 1))
                yield Retry(index, attempt + 1, reason)
            if self.timeout is not None:
                now = time.monotonic()
                for ref, (_, _, since) in running.items():
                    if ref not in cancelled and now - since > self.timeout:
                        ray.cancel(ref, force=True)
                        cancelled.add(ref)

    def close(self) -> None:
        if self._ray is not None and self._ray.is_initialized():
            self._ray.shutdown()
        self._ray = None
