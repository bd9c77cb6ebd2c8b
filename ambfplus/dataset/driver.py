"""``generate(spec, out)``: makes (or completes) a dataset folder from a spec.

    DIR/spec.yaml          the spec as given
    DIR/environment.json   package version, spec hash, platform, and one entry per run
                           (executor, workers, renderers, start and end, retries)
    DIR/manifest.jsonl     one line per complete shard (ambfplus.dataset.manifest)
    DIR/shards/episode_000012.h5 (+ .part0001)   one recording per episode
    DIR/.partial/, DIR/.run, DIR/.lock   shards being made, the current run's id, the lock

Running it again resumes: shards listed in the manifest (whose files are there, of the listed
size) are kept; anything else in ``shards/`` and everything under ``.partial/`` is deleted and
its episodes are made again. One generation at a time writes a folder (a lock file says so),
and each run takes the folder over (``.run``) before it cleans it, so tasks a killed driver left
running on a cluster cannot put anything into ``shards/`` afterwards (see ``episode``).
"""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import platform
import shutil
import socket
import sys
import time
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import TextIO

from .. import __version__
from ..fileio import write_text
from .episode import PARTIAL, RUN_FILE, SHARDS, new_run_id, take_over
from .executor import Done, Executor, Failed, Retry
from .manifest import MANIFEST, ManifestWriter, read_manifest, rewrite_manifest
from .spec import DatasetSpec, SpecError, load_spec

ENVIRONMENT = "environment.json"
SPEC_FILE = "spec.yaml"
LOCK = ".lock"
FORMAT = "ambfplus.dataset"
FORMAT_VERSION = 1


class GenerateError(RuntimeError):
    """A generation that could not finish: the message names the folder and the cause."""


@dataclass
class GenerateReport:
    """What a run did."""

    folder: Path
    episodes: int  #: in the spec
    generated: int  #: shards made by this run
    skipped: int  #: complete shards found from an earlier run
    retries: int
    frames: int  #: stereo pairs made by this run
    seconds: float
    executor: dict = field(default_factory=dict)
    renderers: list = field(default_factory=list)


def generate(
    spec,
    out,
    *,
    workers: int = 1,
    ray: str | None = None,
    retries: int = 3,
    timeout: float | None = None,
    progress: bool | TextIO = True,
    ray_options: dict | None = None,
) -> GenerateReport:
    """Generates the dataset of `spec` (a path, a dict or a DatasetSpec) into folder `out`, with
    `workers` local processes or on the Ray cluster at `ray` ("auto", "local" or an address;
    needs ``ambfplus[ray]``). Each episode is tried at most `retries` + 1 times, and at most
    `timeout` seconds each. `progress`: a live bar on stderr (True), on a text stream, or
    none (False). Call it under ``if __name__ == "__main__":`` (local workers import
    the main module again)."""
    spec = spec if isinstance(spec, DatasetSpec) else load_spec(spec)
    check_sources(spec)
    executor = _executor(workers, ray, retries, timeout, ray_options or {})
    executor.connect()
    try:
        return _generate(spec, Path(out), executor, progress)
    finally:
        executor.close()


def _executor(workers, ray, retries, timeout, ray_options) -> Executor:
    if ray is not None:
        from .ray_executor import RayExecutor

        return RayExecutor(ray, retries=retries, timeout=timeout, **ray_options)
    from .local import LocalExecutor

    return LocalExecutor(workers, retries=retries, timeout=timeout)


def check_sources(spec: DatasetSpec) -> None:
    """Loads every anatomy file of the spec once, or builds its scene once (``scene``), so that
    a bad one fails before any worker starts (naming the file and the spec's entry)."""
    from ..volumes import load_volume

    if "scene" in spec.data:
        from .sources import check_scene

        check_scene(spec)
        return
    for i, entry in enumerate(spec.data["anatomies"]):
        if "file" not in entry:
            continue
        options = {k: v for k, v in entry.items() if k not in ("file", "name", "weight")}
        try:
            load_volume(entry["file"], **options)
        except (ValueError, OSError, RuntimeError) as error:
            raise SpecError(
                f"{spec.source}: anatomies[{i}].file: cannot load {entry['file']}: {error}"
            ) from None


def _generate(spec: DatasetSpec, out: Path, executor: Executor, progress) -> GenerateReport:
    out.mkdir(parents=True, exist_ok=True)
    with _FolderLock(out):
        environment = _prepare(out, spec)
        run_id = new_run_id()
        records = _resume(out, spec, run_id)
        todo = [i for i in range(spec.episodes) if i not in records]
        run = {
            **executor.describe(),
            "run_id": run_id,
            "host": socket.gethostname(),
            "pid": os.getpid(),
            "started": _now(),
            "finished": None,
            "status": "running",
            "skipped": len(records),
            "todo": len(todo),
        }
        environment["runs"].append(run)
        _write_json(out / ENVIRONMENT, environment)
        started = time.perf_counter()
        bar = _Progress(spec.episodes, len(records), progress)
        writer = ManifestWriter(out)
        made = frames = retries = 0
        renderers: set[str] = set()
        events = executor.run(spec.data, out, todo, run_id)
        try:
            for event in events:
                if isinstance(event, Done):
                    record = event.record
                    if record["episode"] in records:
                        continue  # a second attempt's report: the first is listed
                    writer.append(record)
                    records[record["episode"]] = record
                    made, frames = made + 1, frames + record["frames"]
                    renderers.add(record.get("renderer", ""))
                    bar.done(record)
                elif isinstance(event, Retry):
                    retries += 1
                    bar.retry(event)
                elif isinstance(event, Failed):
                    raise GenerateError(
                        f"{out}: episode {event.episode} failed {event.attempts} times; the "
                        f"last time: {event.reason.strip()}"
                    )
            run["status"] = "complete"
            # this run's workers are done, and earlier runs' tasks cannot move their shards
            shutil.rmtree(out / PARTIAL, ignore_errors=True)
        except BaseException as error:
            run["status"] = "interrupted" if isinstance(error, KeyboardInterrupt) else "failed"
            raise
        finally:
            events.close()  # stops the workers
            writer.close()
            bar.close()
            rewrite_manifest(out, list(records.values()))
            with contextlib.suppress(OSError):  # only when empty: no worker is writing there
                (out / PARTIAL).rmdir()
            run.update(
                finished=_now(),
                made=made,
                frames=frames,
                retries=retries,
                renderers=sorted(renderers),
            )
            _write_json(out / ENVIRONMENT, environment)
        return GenerateReport(
            folder=out,
            episodes=spec.episodes,
            generated=made,
            skipped=run["skipped"],
            retries=retries,
            frames=frames,
            seconds=time.perf_counter() - started,
            executor=executor.describe(),
            renderers=sorted(renderers),
        )


def _prepare(out: Path, spec: DatasetSpec) -> dict:
    """Checks that `out` is empty or a dataset of this very spec; writes spec.yaml and the
    environment's description on a first run. Returns the environment."""
    env_path = out / ENVIRONMENT
    if env_path.is_file():
        environment = json.loads(env_path.read_text())
        if environment.get("spec_sha256") != spec.sha256:
            raise GenerateError(
                f"{out} holds a dataset of another spec (its {ENVIRONMENT} has spec_sha256 "
                f"{environment.get('spec_sha256')}, this spec has {spec.sha256}); generate into "
                "another folder, or delete it first"
            )
        return environment
    ours = {SPEC_FILE, ENVIRONMENT, MANIFEST, SHARDS, PARTIAL, LOCK, RUN_FILE, MANIFEST + ".tmp"}
    strangers = sorted(p.name for p in out.iterdir() if p.name not in ours)
    if strangers:
        raise GenerateError(
            f"{out} is not empty and not a dataset folder (it holds {', '.join(strangers[:5])}); "
            "generate into an empty or new folder"
        )
    (out / SPEC_FILE).write_text(spec.text)
    environment = {
        "format": FORMAT,
        "format_version": FORMAT_VERSION,
        "ambfplus_version": __version__,
        "spec_sha256": spec.sha256,
        "spec": spec.data,
        "episodes": spec.episodes,
        "python": sys.version.split()[0],
        "platform": platform.platform(),
        "packages": _package_versions(),
        "runs": [],
    }
    _write_json(out / ENVIRONMENT, environment)
    return environment


def _resume(out: Path, spec: DatasetSpec, run_id: str) -> dict[int, dict]:
    """The complete shards of an earlier run, by episode; makes `run_id` the folder's run, then
    deletes everything else (partial shards, shards a killed driver did not list) and rewrites
    the manifest clean."""
    records: dict[int, dict] = {}
    for record in read_manifest(out)[0]:
        index = record["episode"]
        if index in records or not 0 <= index < spec.episodes:
            continue
        files = [out / record["file"]] + [out / p for p in record["parts"]]
        if (
            all(f.is_file() for f in files)
            and sum(f.stat().st_size for f in files) == record["bytes"]
        ):
            records[index] = record
    take_over(out, run_id)  # before cleaning: an earlier run's late task could move a shard in
    shutil.rmtree(out / PARTIAL, ignore_errors=True)
    kept = {Path(r["file"]).name for r in records.values()}
    kept |= {Path(p).name for r in records.values() for p in r["parts"]}
    shards = out / SHARDS
    if shards.is_dir():
        for stale in shards.iterdir():
            if stale.name not in kept:
                stale.unlink()
    rewrite_manifest(out, list(records.values()))
    return records


def _package_versions() -> dict:
    import h5py
    import numpy

    return {
        "numpy": numpy.__version__,
        "h5py": h5py.version.version,
        "hdf5": h5py.version.hdf5_version,
    }


def _now() -> str:
    return datetime.now(timezone.utc).isoformat(timespec="seconds")


def _write_json(path: Path, value) -> None:
    write_text(path, json.dumps(value, indent=2, sort_keys=True) + "\n")


class _FolderLock:
    """An exclusive lock on a dataset folder for one generation (released when its process
    ends, however it ends)."""

    def __init__(self, folder: Path) -> None:
        self.path = folder / LOCK

    def __enter__(self) -> _FolderLock:
        self._file = open(self.path, "a+")
        try:
            fcntl.flock(self._file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._file.seek(0)
            holder = self._file.read().strip() or "another process"
            self._file.close()
            raise GenerateError(
                f"{self.path.parent}: another generation is writing this folder ({holder})"
            ) from None
        self._file.seek(0)
        self._file.truncate()
        self._file.write(f"pid {os.getpid()} on {socket.gethostname()}\n")
        self._file.flush()
        return self

    def __exit__(self, *exc_info) -> None:
        self._file.close()


class _Progress:
    """A live bar (tqdm): episodes, stereo pairs per second, ETA, retries; on stderr (`output`
    True), on a text stream, or nowhere (False)."""

    def __init__(self, total: int, initial: int, output) -> None:
        self.bar = None
        self.frames = self.retries = 0
        self.started = time.perf_counter()
        if output is not False and output is not None:
            from tqdm import tqdm

            self.file = sys.stderr if output is True else output
            self.bar = tqdm(
                total=total,
                file=self.file,
                initial=initial,
                unit="episode",
                dynamic_ncols=True,
                desc="generate",
                smoothing=0.1,
            )
            self._postfix()

    def done(self, record: dict) -> None:
        self.frames += record["frames"]
        if self.bar is not None:
            self.bar.update(1)
            self._postfix()

    def retry(self, event: Retry) -> None:
        self.retries += 1
        if self.bar is not None:
            self.bar.write(  # beside the bar (tqdm's default is stdout)
                f"episode {event.episode}: retrying (attempt {event.attempt + 1}): "
                f"{event.reason.strip().splitlines()[-1]}",
                file=self.file,
            )
            self._postfix()

    def _postfix(self) -> None:
        assert self.bar is not None, "called only with a bar"
        rate = self.frames / max(time.perf_counter() - self.started, 1e-9)
        self.bar.set_postfix_str(f"{rate:.1f} pairs/s, {self.retries} retries")

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
