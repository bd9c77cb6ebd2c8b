"""What an executor is: something that runs a list of episodes somewhere and reports, as
events, each shard made (``Done``), each attempt that failed and will be retried (``Retry``)
and each episode that failed for good (``Failed``). Attempts are counted by the executor:
an episode is tried at most ``retries + 1`` times."""

from __future__ import annotations

import shutil
from collections.abc import Generator
from dataclasses import dataclass


@dataclass
class Done:
    """A shard is in place; `record` is its manifest line."""

    record: dict


@dataclass
class Retry:
    """An attempt at an episode failed (`reason`); attempt number `attempt` follows."""

    episode: int
    attempt: int
    reason: str


@dataclass
class Failed:
    """An episode failed on each of its `attempts`; `reason` is the last failure."""

    episode: int
    attempts: int
    reason: str


class WorkerStartError(RuntimeError):
    """A worker that died before it could take an episode (retrying would not help)."""


class Executor:
    """Runs episodes; subclasses implement ``run`` (and ``connect`` when they need to)."""

    name = "executor"

    def __init__(self, retries: int = 3, timeout: float | None = None) -> None:
        if retries < 0:
            raise ValueError(f"retries must be >= 0, got {retries}")
        if timeout is not None and not timeout > 0:
            raise ValueError(f"the episode timeout must be > 0 s, got {timeout}")
        self.retries = int(retries)
        self.timeout = timeout

    @staticmethod
    def discard(out, run_id: str | None, index: int, attempt: int) -> None:
        """Deletes what a failed attempt left under .partial/ (its worker is gone)."""
        from .episode import partial_folder

        shutil.rmtree(partial_folder(out, index, attempt, run_id), ignore_errors=True)

    def connect(self) -> None:
        """Reaches the workers' side before anything is written (nothing to do locally)."""

    def describe(self) -> dict:
        """What environment.json records of this executor."""
        return {"executor": self.name}

    def run(self, spec_data: dict, out, todo: list[int], run_id: str | None = None) -> Generator:
        """Runs the episodes of `todo` into dataset folder `out` as run `run_id` (see
        ``episode.run_episode``), yielding events."""
        raise NotImplementedError

    def close(self) -> None:
        """Releases what ``connect`` took."""
