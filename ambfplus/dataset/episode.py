"""Running one episode: its scene built from its plan, filmed and recorded into a shard, the
shard checked and moved into the dataset. Runs in a worker (a local worker process or a Ray
worker), which creates its EGL context on its first render and keeps it for its next
episodes.

Each run of ``generate`` has an id, and the folder's ``.run`` file names the current one. A
worker records under a folder of its own (``.partial/episode_000012.<run>.attempt0``) and moves
the shard into ``shards/`` only while holding a lock on ``.run`` that names its run, and only
when no complete shard of its episode is there. A new run takes ``.run`` over (under the same
lock) before it cleans the folder, so that a task its killed predecessor left running on a
cluster can neither touch the new run's partial shards nor replace or delete a shard in
``shards/``; only the driver writes the manifest.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import hashlib
import os
import secrets
import shutil
import socket
import time
from pathlib import Path

import numpy as np

from .. import NullDevice, ScriptedDevice, __version__, gl_info
from ..labels import legend as object_legend
from ..recording.schema import find_parts
from ..scenes import DrillScript, anatomy_data, drilling_scene, record_session
from ..stereo import StereoFrame
from .manifest import shard_checksum
from .sampling import EpisodePlan, jitter_label_colors, sample_episode
from .spec import SCHEMA_VERSION, spec_hash

SHARDS = "shards"
PARTIAL = ".partial"
# The current run's id; its lock serialises moves into shards/ against a run taking over.
RUN_FILE = ".run"
# Shards are reproducible files: their recording id comes from the spec and the episode, and
# their creation time is the epoch (as SOURCE_DATE_EPOCH=0 builds); the manifest says when each
# was made.
REPRODUCIBLE_CREATED = "1970-01-01T00:00:00+00:00"
# One part per shard: a part closes only when the recorder does.
SHARD_FLUSH_INTERVAL_S = 1e6
_FRAME_FIELDS = ("camera", "time", "step", "intrinsics", "pose")


class EpisodeError(RuntimeError):
    """An episode whose shard could not be made (the message says which and why)."""


class StaleRunError(EpisodeError):
    """An attempt of a run that is no longer its folder's current run (its driver died and a
    later run took the folder over): it made nothing and left shards/ alone."""


def new_run_id() -> str:
    """A run's id, unique per run: the driver's pid and random bits."""
    return f"{os.getpid()}-{secrets.token_hex(4)}"


@contextlib.contextmanager
def _locked_run_file(out: Path, operation: int):
    """The folder's run file, open and locked (flock: released however its holder ends)."""
    fd = os.open(out / RUN_FILE, os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, operation)
        yield fd
    finally:
        os.close(fd)


def _run_of(fd: int) -> str:
    return os.pread(fd, 256, 0).decode(errors="replace").strip()


def take_over(out, run: str) -> None:
    """Makes `run` the current run of dataset folder `out`: from then on, attempts of earlier
    runs cannot move a shard into shards/ (waits for one that is doing so)."""
    with _locked_run_file(Path(out), fcntl.LOCK_EX) as fd:
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"{run}\n".encode(), 0)
        os.fsync(fd)


def _check_run(fd: int, out: Path, run: str | None, index: int) -> None:
    current = _run_of(fd)
    if run is not None and current != run:
        raise StaleRunError(
            f"{out}: episode {index}: run {run} is no longer this folder's current run "
            f"({current or 'none'}); its attempt made nothing"
        )


def shard_name(index: int) -> str:
    """``episode_000012.h5``: the head file of episode 12's shard."""
    return f"episode_{index:06d}.h5"


def record_episode(spec_data: dict, index: int, path, plan: EpisodePlan | None = None) -> dict:
    """Builds episode `index` of a normalised spec and records it to `path` (a reproducible
    recording). Returns its summary: frames, label pixel counts, what was drawn."""
    plan = plan or sample_episode(spec_data, index)
    if "scene" in spec_data:
        return _record_scene_episode(spec_data, index, path, plan)
    assert plan.camera_path is not None, "the built-in scene's episodes have a camera path"
    source = plan.scene["anatomy"]
    table = anatomy_data(source).label_table
    label_colors = jitter_label_colors(table, plan.label_color_jitter, plan.rngs["colors"])
    scene = drilling_scene(**plan.scene, label_colors=label_colors)
    target = np.asarray(scene.target)
    x, y, z = target + plan.camera_path.target
    path_plan = dataclasses.replace(plan.camera_path, target=(float(x), float(y), float(z)))
    seconds = plan.frames * plan.capture_every * scene.world.time_step
    device: NullDevice | ScriptedDevice
    device, motion = (
        NullDevice(),
        (path_plan if path_plan.azimuth_swing or path_plan.elevation_swing else None),
    )
    rig = scene.rig
    assert rig is not None, "a drilling scene has a stereo rig"
    rig.aim(*path_plan(0.0))
    if plan.scenario["kind"] in ("drilling", "mixed"):
        drill = scene.drill
        script = DrillScript(
            drill.volume, drill.goal[:3, 3], drill.burr_radius, plan.rngs["motion"]
        )
        script.plunge_until(seconds)
        scripted = ScriptedDevice()
        scripted.set_callback(script, every=10)
        device = scripted
    counter = _LabelCounter({label.id: label.name for label in table}, "label")
    sampled = plan.describe()
    sampled["camera_path"] = dataclasses.asdict(path_plan)
    sampled["label_colors"] = label_colors
    return _record(spec_data, index, path, plan, scene, device, seconds, counter, sampled,
                   camera_motion=motion)  # fmt: skip


def _record_scene_episode(spec_data: dict, index: int, path, plan: EpisodePlan) -> dict:
    """An episode of a spec with a scene: the scene built, the dataset's rig placed, driven by
    the episode's script or waypoints. Its pixel counts are by object key (the instance pass:
    namespaced objects under their ``ns/name`` keys)."""
    from .sources import build_episode_scene

    scene, controller = build_episode_scene(spec_data, plan)
    seconds = plan.frames * plan.capture_every * scene.world.time_step
    names = {int(i): e.get("key", e["name"]) for i, e in object_legend(scene.world).items()}
    counter = _LabelCounter(names, "instance")
    return _record(spec_data, index, path, plan, scene, None, seconds, counter, plan.describe(),
                   controller=controller)  # fmt: skip


def _record(spec_data, index, path, plan, scene, device, seconds, counter, sampled, **options):
    """Records an episode's scene into a reproducible shard with its dataset metadata; returns
    its summary for the manifest."""
    noise = _RgbNoise(plan.rgb_noise)
    metadata = {
        "dataset": {
            "episode": index,
            "seed": plan.seed,
            "base_seed": int(spec_data["seed"]),
            "spec_sha256": spec_hash(spec_data),
            "schema_version": SCHEMA_VERSION,
            "name": spec_data.get("name", ""),
        },
        "sampled": sampled,
    }
    recording_id = hashlib.sha256(f"{spec_hash(spec_data)}/{index}".encode()).hexdigest()[:32]
    summary = record_session(
        scene,
        path,
        device,
        seconds,
        capture_every=plan.capture_every,
        passes=plan.passes,
        metadata=metadata,
        transform=lambda pair: noise(counter(pair)),
        recorder_options={
            "recording_id": recording_id,
            "created": REPRODUCIBLE_CREATED,
            "flush_interval_s": SHARD_FLUSH_INTERVAL_S,
        },
        **options,
    )
    return {
        "frames": summary["frames"],
        "label_pixels": counter.by_name(),
        "anatomy": plan.anatomy["name"],
        "scenario": plan.scenario["kind"],
        "seed": plan.seed,
    }


class _LabelCounter:
    """Pixels per id of one pass over every recorded image of it (both views): anatomy labels
    (the label pass) or objects (the instance pass), named by `names` ({id: name})."""

    def __init__(self, names: dict[int, str], pass_name: str) -> None:
        self.names = names
        self.pass_name = pass_name
        self.counts: np.ndarray = np.zeros(1, dtype=np.int64)

    def __call__(self, pair: StereoFrame) -> StereoFrame:
        for frame in (pair.left, pair.right):
            label = getattr(frame, self.pass_name, None)
            if label is not None:
                counts = np.bincount(np.asarray(label).ravel())
                if len(counts) > len(self.counts):
                    self.counts = np.pad(self.counts, (0, len(counts) - len(self.counts)))
                self.counts[: len(counts)] += counts
        return pair

    def by_name(self) -> dict[str, int]:
        return {
            self.names.get(i, f"label_{i}"): int(n)
            for i, n in enumerate(self.counts)
            if n and i != 0
        }


class _RgbNoise:
    """Gaussian sensor noise on the RGB images (rounded, clipped to 0..255), drawn from the
    episode's noise seed, the pair's number and the view; every other pass stays exact."""

    def __init__(self, spec: dict) -> None:
        self.sigma = float(spec["sigma"])
        self.seed = int(spec["seed"])
        self.pairs = 0

    def __call__(self, pair: StereoFrame) -> StereoFrame:
        if self.sigma <= 0 or getattr(pair.left, "rgb", None) is None:
            return pair
        views = []
        for side, frame in enumerate((pair.left, pair.right)):
            rng = np.random.default_rng(
                np.random.SeedSequence(self.seed, spawn_key=(self.pairs, side))
            )
            rgb = np.asarray(frame.rgb, dtype=np.float32)
            noisy = rgb + rng.normal(0.0, self.sigma, rgb.shape).astype(np.float32)
            views.append(_replace_rgb(frame, np.clip(np.rint(noisy), 0, 255).astype(np.uint8)))
        self.pairs += 1
        # The noisy views are mappings of a frame's fields, which only the recorder reads
        # (Recorder.add_stereo takes them), not the frames StereoFrame's fields are typed as.
        return StereoFrame(views[0], views[1], pair.baseline, pair.dcx)  # type: ignore[arg-type]


def _replace_rgb(frame, rgb: np.ndarray) -> dict:
    """A frame as a mapping (as the recorder takes it) with another RGB image."""
    out = {name: getattr(frame, name) for name in _FRAME_FIELDS}
    for name in ("depth", "label", "instance", "voxel", "segmentation", "points"):
        value = getattr(frame, name, None)
        if value is not None:
            out[name] = value
    out["rgb"] = rgb
    return out


def partial_folder(out, index: int, attempt: int, run: str | None = None) -> Path:
    """Where attempt `attempt` of run `run` at episode `index` records its shard before it is
    complete (the executor deletes it when the attempt fails). No two runs share one."""
    stem = shard_name(index)[:-3] + (f".{run}" if run else "")
    return Path(out) / PARTIAL / f"{stem}.attempt{attempt}"


def run_episode(
    spec_data: dict,
    out,
    index: int,
    attempt: int = 0,
    worker: str = "",
    run: str | None = None,
) -> dict:
    """Makes episode `index`'s shard in dataset folder `out`: recorded under ``.partial/``,
    validated, then moved into ``shards/`` (its parts first, its head last), as attempt
    `attempt` of run `run` (None: whatever run the folder has). Returns the episode's manifest
    record. Raises StaleRunError, leaving nothing behind and shards/ untouched, once another run
    has taken the folder over."""
    from ..recording import validate

    started, cpu_started = time.perf_counter(), time.process_time()
    out = Path(out)
    name = shard_name(index)
    out.mkdir(parents=True, exist_ok=True)
    with _locked_run_file(out, fcntl.LOCK_SH) as fd:
        _check_run(fd, out, run, index)  # a dead run's queued task renders nothing
    partial = partial_folder(out, index, attempt, run)
    shutil.rmtree(partial, ignore_errors=True)
    partial.mkdir(parents=True)
    try:
        head = partial / name
        summary = record_episode(spec_data, index, head)
        report = validate(head, match_images=False)
        if not report.ok:
            failed = "; ".join(f"{c.name}: {c.detail}" for c in report.failed)
            raise EpisodeError(f"episode {index}: its shard does not validate: {failed}")
        files = [head] + [p for _, p in find_parts(head)]
        digest, size = shard_checksum(files)
        kept = _move_into_shards(out, files, run, index)
        if kept is not None:  # an earlier attempt of this run finished it: that shard stays
            files = kept
            digest, size = shard_checksum(files)
    finally:
        shutil.rmtree(partial, ignore_errors=True)
    return {
        "episode": index,
        "seed": summary["seed"],
        "anatomy": summary["anatomy"],
        "scenario": summary["scenario"],
        "frames": summary["frames"],
        "bytes": size,
        "sha256": digest,
        "file": f"{SHARDS}/{name}",
        "parts": [f"{SHARDS}/{file.name}" for file in files[1:]],
        "version": __version__,
        "renderer": gl_info()["renderer"],
        "label_pixels": summary["label_pixels"],
        "seconds": round(time.perf_counter() - started, 3),
        "cpu_seconds": round(time.process_time() - cpu_started, 3),
        "worker": worker or f"{socket.gethostname()}:{os.getpid()}",
        "attempt": attempt,
    }


def _move_into_shards(out: Path, files: list[Path], run: str | None, index: int):
    """Moves a checked shard (head, then parts) into shards/, parts first and the head last (the
    head names a complete shard), each by an atomic rename, while holding the run file's lock
    and only if `run` is still the folder's run. Never replaces a complete shard: when the head
    is there already, moves nothing and returns that shard's files (None when it moved)."""
    shards = out / SHARDS
    with _locked_run_file(out, fcntl.LOCK_EX) as fd:
        _check_run(fd, out, run, index)
        head = shards / files[0].name
        if head.is_file():
            return [head] + [p for _, p in find_parts(head)]
        shards.mkdir(exist_ok=True)
        for file in files[1:] + files[:1]:
            os.replace(file, shards / file.name)
    return None
