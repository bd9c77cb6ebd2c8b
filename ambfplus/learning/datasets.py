"""PyTorch datasets of stereo samples: rendered in the loop, or read from recordings.

Fork safety: the engine owns one EGL context per process, created on first use, and a process
forked after its parent rendered cannot render (``RenderError``). So nothing here renders or
opens a file until it is iterated or indexed in the process that uses it: each DataLoader worker
builds its own scene (and EGL context) or opens its own HDF5 files, and ``make_loader`` starts
workers with the "spawn" method, so they never inherit the parent's context or file handles,
whatever the parent did before.
"""

from __future__ import annotations

import os
import pickle
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

import numpy as np
import torch
from torch.utils.data import DataLoader, Dataset, IterableDataset, get_worker_info

from .. import RenderError, ScriptedDevice
from ..recording import Recorder, Recording, open_recording
from ..scenes import CameraPath, DrillScript, Scene, drilling_phantom
from .samples import OPTIONAL_PASSES, REQUIRED_PASSES, stereo_sample

SCENARIOS = ("camera", "drilling", "mixed")
DEFAULT_PASSES = REQUIRED_PASSES + OPTIONAL_PASSES


def _worker() -> tuple[int, int]:
    """(this worker's id, number of workers); (0, 1) in the main process."""
    info = get_worker_info()
    return (0, 1) if info is None else (info.id, info.num_workers)


def _share(total: int | None, worker: int, workers: int) -> int | None:
    """The samples one worker yields so that all of them together yield `total`."""
    if total is None:
        return None
    return total // workers + (1 if worker < total % workers else 0)


class SimulatorStereoDataset(IterableDataset):
    """Stereo samples rendered in the loop from a live simulation.

    Each worker (or the main process, without workers) builds its own scene when iteration
    starts, binds a scripted hand to its drill and plays episodes of `episode_frames` samples,
    one every `capture_every` physics steps:

    - "camera": the rig swings over the phantom along a random ``CameraPath`` while the drill
      rests above the bone;
    - "drilling": the rig holds a random view while the hand plunges the spinning burr into the
      bone at random sites (``DrillScript``), changing the anatomy (restored between episodes);
    - "mixed": either, at random per episode.

    Random draws come from ``SeedSequence([seed, epoch, worker id])``: workers never repeat each
    other, the same seed gives the same samples, and ``set_epoch`` moves to new ones.
    `samples` is the number per epoch over all workers (None: endless). `scene` is a function
    returning an ``ambfplus.scenes.Scene`` (default ``drilling_phantom``) called with
    `scene_options`; give a module-level function (or a ``functools.partial`` of one) so that
    spawned workers can receive it. `record_to` (a folder) also records every sample a worker
    yields to ``worker<id>_epoch<n>.h5`` there. Samples: see ``ambfplus.learning``."""

    def __init__(
        self,
        samples: int | None = 1000,
        scenario: str = "mixed",
        width: int = 640,
        height: int = 480,
        resolution: int = 128,
        capture_every: int = 40,
        episode_frames: int = 25,
        seed: int = 0,
        passes: Sequence[str] = DEFAULT_PASSES,
        scene: Callable[..., Scene] = drilling_phantom,
        scene_options: dict | None = None,
        record_to: str | os.PathLike | None = None,
    ) -> None:
        if scenario not in SCENARIOS:
            raise ValueError(f"scenario must be one of {SCENARIOS}, got {scenario!r}")
        missing = [p for p in REQUIRED_PASSES if p not in passes]
        if missing:
            raise ValueError(f"passes must include {missing} (a sample needs rgb and depth)")
        for name, value in (("capture_every", capture_every), ("episode_frames", episode_frames)):
            if int(value) < 1:
                raise ValueError(f"{name} must be >= 1, got {value}")
        if samples is not None and samples < 0:
            raise ValueError(f"samples must be >= 0 or None (endless), got {samples}")
        self.samples = samples
        self.scenario = scenario
        self.capture_every = int(capture_every)
        self.episode_frames = int(episode_frames)
        self.seed = int(seed)
        self.passes = tuple(passes)
        self.scene = scene
        self.scene_options = {
            "width": width, "height": height, "resolution": resolution, **(scene_options or {})
        }  # fmt: skip
        self.record_to = Path(record_to) if record_to is not None else None
        self.epoch = 0

    def __len__(self) -> int:
        if self.samples is None:
            raise TypeError("an endless SimulatorStereoDataset (samples=None) has no length")
        return self.samples

    def set_epoch(self, epoch: int) -> None:
        """Later iterations draw the scenarios of this epoch (set it before each epoch)."""
        self.epoch = int(epoch)

    def _build(self) -> Scene:
        scene = self.scene(**self.scene_options)
        if not isinstance(scene, Scene):
            raise TypeError(
                f"scene {getattr(self.scene, '__name__', self.scene)!r} returned "
                f"{type(scene).__name__}, expected an ambfplus.scenes.Scene"
            )
        return scene

    def __iter__(self) -> Iterator[dict[str, torch.Tensor]]:
        try:
            yield from self._samples()
        except RenderError as error:
            raise RenderError(
                f"{error}\nSimulatorStereoDataset renders in the process that iterates it, and a "
                "process forked after its parent rendered cannot render: start DataLoader "
                "workers with multiprocessing_context='spawn' (ambfplus.learning.make_loader "
                "does)."
            ) from error

    def _samples(self) -> Iterator[dict[str, torch.Tensor]]:
        worker, workers = _worker()
        quota = _share(self.samples, worker, workers)
        rng = np.random.default_rng(np.random.SeedSequence([self.seed, self.epoch, worker]))
        scene = self._build()
        world, rig = scene.world, scene.rig
        script = self._bind_hand(scene, rng)
        recorder = self._recorder(worker, scene)
        produced = 0
        try:
            while quota is None or produced < quota:
                kind = self.scenario
                if kind == "mixed":
                    kind = "camera" if rng.random() < 0.5 else "drilling"
                path = self._start_episode(scene, script, kind, rng)
                for _ in range(self.episode_frames):
                    if quota is not None and produced >= quota:
                        break
                    world.step(self.capture_every)
                    if rig is None:
                        raise ValueError("SimulatorStereoDataset: the scene has no stereo rig")
                    rig.aim(*path(world.time))
                    pair = rig.capture(self.passes)
                    if recorder is not None:
                        recorder.add_stereo("rig", pair)
                    yield stereo_sample(pair, where=f"worker {worker}, step {world.step_index}")
                    produced += 1
        finally:
            if recorder is not None:
                recorder.close()

    @staticmethod
    def _bind_hand(scene: Scene, rng) -> DrillScript:
        """A scripted hand driving the scene's drill, resting until an episode plans plunges."""
        drill = scene.drill
        script = DrillScript(drill.volume, drill.goal[:3, 3], drill.burr_radius, rng)
        device = ScriptedDevice()
        device.set_callback(script, every=10)
        scene.world.add_input_device(scene.device_name, device, drill, **scene.device_options)
        return script

    def _start_episode(self, scene: Scene, script: DrillScript, kind: str, rng) -> CameraPath:
        """Brings the drill back to rest, restores drilled anatomy and plans the episode."""
        world = scene.world
        if world.time > 0:
            script.rest(world.time)
            world.step(int(round((script.busy_until - world.time) / world.time_step)) + 1)
            scene.drill.volume.reset()
        if kind == "drilling":
            seconds = self.episode_frames * self.capture_every * world.time_step
            script.plunge_until(world.time + seconds, now=world.time)
        return CameraPath.random(rng, moving=kind == "camera")

    def _recorder(self, worker: int, scene: Scene) -> Recorder | None:
        if self.record_to is None:
            return None
        self.record_to.mkdir(parents=True, exist_ok=True)
        path = self.record_to / f"worker{worker}_epoch{self.epoch}.h5"
        recorder = Recorder(
            path,
            metadata={"scene": scene.spec, "rig": "rig", "dataset": self._description(worker)},
        )
        recorder.set_legend(scene.world)
        return recorder

    def _description(self, worker: int) -> dict:
        return {
            "kind": "SimulatorStereoDataset", "scenario": self.scenario, "seed": self.seed,
            "epoch": self.epoch, "worker": worker, "capture_every": self.capture_every,
            "episode_frames": self.episode_frames,
        }  # fmt: skip


def _recordings(path: Path) -> list[Path]:
    """A recording's head, or the shards of a dataset folder (``ambfplus generate``) in
    episode order, as its manifest lists them."""
    if not path.is_dir():
        return [path]
    from ..dataset import is_dataset, read_manifest

    if not is_dataset(path):
        raise ValueError(f"{path}: a folder, but not a dataset folder (no environment.json)")
    records, _ = read_manifest(path)
    shards = sorted({r["episode"]: r["file"] for r in records}.items())
    if not shards:
        raise ValueError(f"{path}: the dataset's manifest lists no shard yet")
    return [path / file for _, file in shards]


class RecordingStereoDataset(Dataset):
    """Stereo samples read from the pairs of one or more recordings (``ambfplus.recording``),
    in order: index i runs through the first recording's pairs of rig `rig`, then the next's.
    A dataset folder (``ambfplus generate``) stands for its shards, in episode order.

    Files are opened lazily, in the process that reads them (each DataLoader worker opens its
    own), and never held open by the parent: lengths are read once at construction and the
    files closed again. `transform(sample) -> sample` runs on every sample."""

    def __init__(
        self,
        paths: str | os.PathLike | Sequence[str | os.PathLike],
        rig: str = "rig",
        transform: Callable[[dict], dict] | None = None,
    ) -> None:
        if isinstance(paths, (str, os.PathLike)):
            paths = [paths]
        self.paths = [shard for p in paths for shard in _recordings(Path(p))]
        if not self.paths:
            raise ValueError("RecordingStereoDataset needs at least one recording")
        self.rig = rig
        self.transform = transform
        self.lengths = [self._count(path) for path in self.paths]
        self._starts = np.cumsum([0] + self.lengths)
        self._open: dict[int, Recording] = {}
        self._pid: int | None = None

    def _count(self, path: Path) -> int:
        with open_recording(path) as rec:
            if self.rig not in rec.rigs:
                raise KeyError(
                    f"{path}: no stereo rig '{self.rig}' in this recording (it has: "
                    f"{', '.join(rec.rigs) or 'none'})"
                )
            rig = rec.rigs[self.rig]
            for side in (rig.left, rig.right):
                missing = [p for p in REQUIRED_PASSES if p not in side.passes]
                if missing:
                    raise ValueError(
                        f"{path}: stream {side.name} of rig '{self.rig}' has no {missing} "
                        f"images; a stereo sample needs {' and '.join(REQUIRED_PASSES)} in both "
                        "views"
                    )
            return len(rig)

    def __len__(self) -> int:
        return int(self._starts[-1])

    def locate(self, index: int) -> tuple[int, int]:
        """(which recording, pair index in it) of a dataset index."""
        if not -len(self) <= index < len(self):
            raise IndexError(f"index {index} out of range for {len(self)} stereo pairs")
        index %= len(self)
        file = int(np.searchsorted(self._starts, index, side="right")) - 1
        return file, index - int(self._starts[file])

    def _recording(self, file: int):
        if self._pid != os.getpid():
            # A copy in another process (a worker) never uses handles it did not open.
            self._open, self._pid = {}, os.getpid()
        rec = self._open.get(file)
        if rec is None:
            rec = self._open[file] = open_recording(self.paths[file])
        return rec

    def __getitem__(self, index: int) -> dict[str, torch.Tensor]:
        file, pair_index = self.locate(int(index))
        pair = self._recording(file).rigs[self.rig][pair_index]
        sample = stereo_sample(pair, where=f"{self.paths[file]} pair {pair_index}")
        return self.transform(sample) if self.transform is not None else sample

    def close(self) -> None:
        """Closes the files this process opened."""
        if self._pid == os.getpid():
            for rec in self._open.values():
                rec.close()
        self._open = {}

    def __getstate__(self) -> dict:
        state = dict(self.__dict__)
        state["_open"], state["_pid"] = {}, None
        return state


def make_loader(
    dataset: Dataset,
    batch_size: int = 4,
    num_workers: int = 0,
    **options,
) -> DataLoader:
    """A DataLoader whose workers are spawned, never forked (see the module): safe whatever the
    parent process rendered or opened. The dataset must be picklable to reach them. `options`
    go to ``DataLoader`` (e.g. ``shuffle`` for a map-style dataset)."""
    if num_workers > 0:
        try:
            pickle.dumps(dataset)
        except Exception as error:
            raise TypeError(
                f"the dataset cannot be sent to spawned workers ({error}); give it module-level "
                "functions (not lambdas or local functions) and no open files"
            ) from error
        options.setdefault("multiprocessing_context", "spawn")
        options.setdefault("persistent_workers", False)
    if options.get("multiprocessing_context") == "fork":
        raise ValueError(
            "multiprocessing_context='fork' is not safe with the engine: a process forked after "
            "its parent rendered cannot render; use 'spawn' (the default here) or 'forkserver'"
        )
    return DataLoader(dataset, batch_size=batch_size, num_workers=num_workers, **options)
