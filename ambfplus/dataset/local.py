"""The default executor: worker processes on this machine, each with its own EGL context
(created on its first render), fed one episode at a time through a pipe.

Workers are forked from a fork server (``multiprocessing``'s "forkserver" start method): a
fresh process, started once per driver, that has imported the engine and the episode code but
never rendered, so each worker starts without importing them again and without inheriting a
GL context. Like spawned processes, workers import the main module of a script again (it
needs the ``if __name__ == "__main__":`` guard), and they take the driver's environment as it
is when they start.

A worker that dies (SIGKILL, a crash) is noticed through its process sentinel: its episode goes
back to the queue and a new worker takes its place. Workers die with the driver: a thread
watches the driver's end of a pipe that closes when the driver exits however it exits, and
Linux's parent-death signal covers the fork server.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import threading
import time
import traceback
from collections import deque
from collections.abc import Generator, Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from pathlib import Path

from .executor import Done, Executor, Failed, Retry, WorkerStartError

PR_SET_PDEATHSIG, PR_SET_NAME = 1, 15
# What `ps` and `top` show for a worker (at most 15 bytes).
WORKER_NAME = b"ambfplus-worker"
# Imported once by the fork server, so that its workers start with them.
PRELOAD = ["ambfplus.dataset.local", "ambfplus.dataset.episode"]


def _worker_context():
    """The fork server's context, preloading the engine (spawn where there is no fork)."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context("spawn")
    context = multiprocessing.get_context("forkserver")
    context.set_forkserver_preload(PRELOAD)  # no effect once its server runs
    return context


def _die_with_driver() -> None:
    """Ends this worker as soon as the driver exits (a thread waiting on the driver's pipe),
    and asks Linux to SIGKILL it when its parent (the fork server) exits."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_NAME, WORKER_NAME, 0, 0, 0)
        parent = os.getppid()
        libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        if os.getppid() != parent:  # the parent died before the request took effect
            os._exit(1)
    except (OSError, AttributeError):
        pass
    driver = multiprocessing.parent_process()
    if driver is None or driver.sentinel is None:
        return

    def watch() -> None:
        wait([driver.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="driver-watch", daemon=True).start()


def _worker_main(
    connection, spec_data: dict, out: str, run_id: str | None, name: str, environ: dict
) -> None:
    """A worker's loop: receive (episode, attempt), make the shard, send back its record."""
    _die_with_driver()
    os.environ.clear()  # the driver's environment now, not the fork server's
    os.environ.update(environ)
    from .episode import run_episode

    connection.send(("ready", None, None, os.getpid()))
    while True:
        try:
            task = connection.recv()
        except (EOFError, OSError):
            return
        if task is None:
            return
        index, attempt = task
        try:
            record = run_episode(spec_data, out, index, attempt, worker=name, run=run_id)
            connection.send(("done", index, attempt, record))
        except Exception:
            connection.send(("failed", index, attempt, traceback.format_exc()))


@dataclass
class _Slot:
    number: int
    process: multiprocessing.Process
    connection: Connection
    task: tuple[int, int] | None = None
    since: float = field(default_factory=time.monotonic)
    ready: bool = False

    @property
    def name(self) -> str:
        return f"local-{self.number}:{self.process.pid}"


class LocalExecutor(Executor):
    """Runs episodes in `workers` processes on this machine."""

    name = "local"

    def __init__(self, workers: int = 1, retries: int = 3, timeout: float | None = None) -> None:
        super().__init__(retries, timeout)
        if workers < 1:
            raise ValueError(f"workers must be >= 1, got {workers}")
        self.workers = int(workers)
        self._context = _worker_context()
        self._started = 0
        self._start_failures = 0  # workers in a row that died before they were ready
        self._out: str | Path | None = None
        self._run_id: str | None = None

    def describe(self) -> dict:
        return {"executor": self.name, "workers": self.workers}

    def _start(self, spec_data: dict, out: str) -> _Slot:
        ours, theirs = self._context.Pipe()
        self._started += 1
        number = self._started
        process = self._context.Process(
            target=_worker_main,
            args=(theirs, spec_data, out, self._run_id, f"local-{number}", dict(os.environ)),
            name=f"ambfplus-generate-{number}",
            daemon=True,
        )
        process.start()
        theirs.close()
        return _Slot(number, process, ours)

    def run(self, spec_data: dict, out, todo: list[int], run_id: str | None = None) -> Generator:
        queue = deque((index, 0) for index in todo)
        self._out, self._run_id = out, run_id
        slots: list[_Slot] = []
        try:
            slots = [self._start(spec_data, str(out)) for _ in range(min(self.workers, len(queue)))]
            while queue or any(slot.task for slot in slots):
                for slot in slots:
                    if slot.task is None and queue:
                        slot.task, slot.since = queue.popleft(), time.monotonic()
                        slot.connection.send(slot.task)
                waitables = [s.connection for s in slots] + [s.process.sentinel for s in slots]
                ready = set(wait(waitables, timeout=1.0))
                for k, slot in enumerate(slots):
                    if slot.connection in ready:
                        yield from self._receive(slot, queue)
                    if slot.process.sentinel in ready or not slot.process.is_alive():
                        yield from self._replace(k, slots, queue, spec_data, str(out))
                    elif self._overdue(slot):
                        slot.process.kill()  # noticed as a death on the next round
        finally:
            _stop(slots)

    def _receive(self, slot: _Slot, queue: deque) -> Iterator:
        try:
            message = slot.connection.recv()
        except (EOFError, OSError):
            return  # the worker died; its sentinel says so
        kind, index, attempt, payload = message
        if kind == "ready":
            slot.ready = True
            self._start_failures = 0
            return
        slot.task = None
        if kind == "done":
            yield Done(payload)
        else:
            yield from self._failed(index, attempt, payload, queue)

    def _failed(self, index: int, attempt: int, reason: str, queue: deque) -> Iterator:
        self.discard(self._out, self._run_id, index, attempt)
        if attempt >= self.retries:
            yield Failed(index, attempt + 1, reason)
            return
        queue.append((index, attempt + 1))
        yield Retry(index, attempt + 1, reason)

    def _replace(self, k: int, slots: list, queue: deque, spec_data: dict, out: str) -> Iterator:
        slot = slots[k]
        slot.process.join(timeout=5)
        code = slot.process.exitcode
        slot.connection.close()
        if not slot.ready:
            self._start_failures += 1
        # A worker that exits by itself before it is ready cannot start (an import error, a
        # script without the main guard); killed ones are faults like any other, unless they
        # keep dying before they are ready.
        killed = code is not None and code < 0
        if not slot.ready and (
            not killed or self._start_failures > self.workers * (self.retries + 1)
        ):
            raise WorkerStartError(
                f"a worker process could not start (exit code {code}; its error is above). "
                "Workers import the main module again, so a script that "
                "calls generate() must be a file and call it under "
                '`if __name__ == "__main__":`'
            )
        if slot.task is not None:
            index, attempt = slot.task
            how = f"signal {-code}" if code is not None and code < 0 else f"exit code {code}"
            overdue = self._overdue(slot)
            reason = f"worker {slot.name} " + (
                f"took more than {self.timeout} s and was killed" if overdue else f"died ({how})"
            )
            yield from self._failed(index, attempt, reason, queue)
        slots[k] = self._start(spec_data, out)

    def _overdue(self, slot: _Slot) -> bool:
        return (
            slot.task is not None
            and self.timeout is not None
            and time.monotonic() - slot.since > self.timeout
        )


def _stop(slots: list[_Slot]) -> None:
    """Asks idle workers to finish, then kills whatever is still running."""
    for slot in slots:
        try:
            slot.connection.send(None)
        except (OSError, ValueError):
            pass
    deadline = time.monotonic() + 10
    for slot in slots:
        slot.process.join(timeout=max(0.0, deadline - time.monotonic()))
        if slot.process.is_alive():
            slot.process.kill()
            slot.process.join(timeout=5)
        slot.connection.close()
