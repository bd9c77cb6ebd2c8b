"""Scripted trainees: seeded drilling policies that behave like a careful expert or like a
novice, for tests, benchmarks and demos of the training tools.

A trainee is a ``ScriptedDevice`` callback (``device.set_callback(trainee)``), like the
scenes' ``DrillScript``: it returns the hand's position in the device frame (world axes, metres
from the drill's start) and its buttons (bit 0 spins the burr). It plans the whole session up
front from the anatomy as it is when planning starts:

- **expert-like**: broad strokes along the target region's longer side, layer by layer, each
  layer a little narrower than the one above (saucerisation), the burr centre kept clear of
  every protected structure by its margin and a little more (checked on the structures'
  distance fields), and a light touch (the hand leads the bone surface by a fraction of a
  millimetre);
- **novice-like**: plunges at random sites, deep and narrow, pressing hard, with short wiggles
  instead of strokes, and now and then drifting toward a protected structure, ignoring margins.

Every parameter is drawn from the style's ranges with the trainee's random generator, so each
seed gives its own session.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._core import DistanceField, ScriptedDevice
from ..scenes import drilling_phantom


@dataclass(frozen=True)
class TraineeStyle:
    """How a trainee drills: each value is a (low, high) range drawn once per trainee."""

    name: str
    #: Depth removed per pass (metres), and the burr's sink per plunge for a plunging style.
    layer_depth: tuple[float, float]
    #: Hand speed while cutting (metres per second).
    speed: tuple[float, float]
    #: How far the hand leads the bone surface into the bone (metres): the force it presses with.
    press: tuple[float, float]
    #: Extra clearance (metres) beyond each protected structure's margin; negative ignores it.
    clearance: tuple[float, float]
    #: Chance per stroke or plunge of aiming at the nearest protected structure.
    drift: tuple[float, float]
    #: Broad strokes across the region (True) or plunges at sites (False).
    strokes: bool
    #: Spacing of strokes as a fraction of the burr's radius.
    spacing: tuple[float, float] = (0.8, 1.0)


EXPERT = TraineeStyle(
    name="expert",
    layer_depth=(0.0003, 0.0005),
    speed=(0.004, 0.007),
    press=(0.0001, 0.0003),
    clearance=(0.0003, 0.0006),
    drift=(0.0, 0.0),
    strokes=True,
)

NOVICE = TraineeStyle(
    name="novice",
    layer_depth=(0.0025, 0.0045),
    speed=(0.010, 0.018),
    press=(0.0008, 0.0015),
    clearance=(-1.0, -1.0),
    drift=(0.25, 0.45),
    strokes=False,
)


@dataclass
class ProtectedField:
    """A structure the trainee keeps (or fails to keep) clear of."""

    name: str
    field: DistanceField
    margin: float


@dataclass
class TrainingRegion:
    """Where the trainee works, in the volume frame (metres): a box across the lateral surface
    (x, y half-extents about a centre) down to `depth` below the surface, narrowing by `taper`
    per metre of depth (saucerisation)."""

    center: tuple[float, float] = (0.0, 0.0)
    half_extent: tuple[float, float] = (0.006, 0.006)
    depth: float = 0.004
    taper: float = 0.8


@dataclass
class _Plan:
    waypoints: list[tuple[float, np.ndarray, int]] = field(default_factory=list)

    @property
    def end(self) -> float:
        return self.waypoints[-1][0] if self.waypoints else 0.0

    def go(self, dt: float, where: np.ndarray, buttons: int) -> None:
        self.waypoints.append((self.end + max(dt, 1e-3), np.asarray(where, float), buttons))


class ScriptedTrainee:
    """A seeded drilling policy over a volume (see the module's docstring).

    `volume` is the world's volume (its ``raycast`` finds the surface), `drill_start` the burr
    centre's starting point (world frame), `protect` the structures to keep clear of, `region`
    where to drill. Call ``plan(seconds)`` once, then hand the trainee to a ScriptedDevice."""

    def __init__(
        self,
        volume,
        drill_start,
        burr_radius: float,
        style: TraineeStyle,
        rng: np.random.Generator,
        protect: list[ProtectedField] | None = None,
        region: TrainingRegion | None = None,
    ) -> None:
        self.volume = volume
        self.start = np.asarray(drill_start, dtype=float)
        self.burr_radius = float(burr_radius)
        self.style = style
        self.rng = rng
        self.protect = list(protect or [])
        self.region = region or TrainingRegion()
        pose = np.asarray(volume.pose, dtype=float)
        self._world_from_volume = pose
        self._volume_from_world = np.linalg.inv(pose)
        draw = lambda r: float(rng.uniform(*r))  # noqa: E731 (one draw per parameter)
        self.params = {
            "layer_depth": draw(style.layer_depth),
            "speed": draw(style.speed),
            "press": draw(style.press),
            "clearance": draw(style.clearance),
            "drift": draw(style.drift),
            "spacing": draw(style.spacing) * self.burr_radius,
        }
        self._plan = _Plan([(0.0, np.zeros(3), 0)])

    # -- the callback -------------------------------------------------------------------------

    def __call__(self, t: float) -> dict:
        points = self._plan.waypoints
        times = [w[0] for w in points]
        i = int(np.searchsorted(times, t, side="right")) - 1
        if i < 0:
            return {"position": tuple(points[0][1]), "buttons": points[0][2]}
        if i >= len(points) - 1:
            return {"position": tuple(points[-1][1]), "buttons": points[-1][2]}
        (t0, p0, buttons), (t1, p1, _) = points[i], points[i + 1]
        s = (t - t0) / (t1 - t0)
        return {"position": tuple(p0 + s * (p1 - p0)), "buttons": buttons}

    @property
    def busy_until(self) -> float:
        return self._plan.end

    # -- geometry -----------------------------------------------------------------------------

    def _to_world(self, p_volume: np.ndarray) -> np.ndarray:
        return (self._world_from_volume @ np.append(p_volume, 1.0))[:3]

    def _device(self, p_volume: np.ndarray) -> np.ndarray:
        """A volume-frame burr centre as the hand's device-frame position."""
        return self._to_world(p_volume) - self.start

    def _surface(self, x: float, y: float) -> float | None:
        """The bone surface's height (volume z) above (x, y), or None where there is none."""
        origin = self._to_world(np.array([x, y, 0.05]))
        down = self._world_from_volume[:3, :3] @ np.array([0.0, 0.0, -1.0])
        hit = self.volume.raycast(tuple(origin), tuple(down))
        if hit is None:
            return None
        return float((self._volume_from_world @ np.append(hit["position"], 1.0))[2])

    def _clear(self, p: np.ndarray) -> bool:
        """Whether a burr centred at p (volume frame) keeps every margin, with the style's
        extra clearance (a negative clearance ignores margins)."""
        extra = self.params["clearance"]
        if extra < 0:
            return True
        return all(
            float(s.field.sample(p)[0]) - self.burr_radius >= s.margin + extra for s in self.protect
        )

    def _toward_structure(self) -> tuple[float, float] | None:
        """A site on the surface above the protected structure nearest the region's centre."""
        if not self.protect:
            return None
        cx, cy = self.region.center
        best, site = math.inf, None
        for dx, dy in self.rng.uniform(-1, 1, size=(24, 2)) * self.region.half_extent:
            surface = self._surface(cx + dx, cy + dy)
            if surface is None:
                continue
            below = np.array([cx + dx, cy + dy, surface - self.region.depth])
            d = min(float(s.field.sample(below)[0]) for s in self.protect)
            if d < best:
                best, site = d, (cx + dx, cy + dy)
        return site

    # -- planning -----------------------------------------------------------------------------

    def plan(self, seconds: float) -> None:
        """Plans the session until `seconds` (from the end of what is planned)."""
        end = self._plan.end + seconds
        if self.style.strokes:
            self._plan_strokes(end)
        else:
            self._plan_plunges(end)
        self._plan.go(0.3, np.zeros(3), 0)  # back to the start, burr off

    def _move_to(self, target: np.ndarray, buttons: int, speed: float) -> None:
        last = self._plan.waypoints[-1][1]
        distance = float(np.linalg.norm(target - last))
        self._plan.go(distance / speed, target, buttons)

    def _plan_strokes(self, end: float) -> None:
        region, p = self.region, self.params
        layer = 0
        while self._plan.end < end:
            layer += 1
            depth = layer * p["layer_depth"]
            if depth > region.depth:
                break
            # Saucerised: the walls slope, each side in by `taper` per metre of depth.
            hx, hy = (h - region.taper * depth for h in region.half_extent)
            if min(hx, hy) < 0.0005:  # the region has narrowed to nothing
                break
            # Strokes run along the region's longer side, rows across the shorter one.
            along, across = (0, 1) if hx >= hy else (1, 0)
            half = (hx, hy)
            rows = max(1, int(2 * half[across] / p["spacing"]))
            for row in range(rows + 1):
                if self._plan.end >= end:
                    break
                line = np.empty((24, 2))
                line[:, across] = (
                    region.center[across] - half[across] + (2 * half[across] * row / rows)
                )
                line[:, along] = np.linspace(
                    region.center[along] - half[along], region.center[along] + half[along], 24
                )
                if row % 2:
                    line = line[::-1]
                self._stroke(line, depth)

    def _stroke(self, line: np.ndarray, depth: float) -> None:
        """One pass through the (x, y) points of `line`, `depth` below the surface as it was
        first found."""
        r, p = self.burr_radius, self.params
        path = []
        for x, y in line:
            x, y = float(x), float(y)
            surface = self._surface(x, y)
            if surface is None:
                continue
            centre = np.array([x, y, self._floor(x, y) + r - depth - p["press"]])
            # Lift the burr where it would come within a margin.
            lifted = centre.copy()
            while not self._clear(lifted) and lifted[2] < surface + r:
                lifted[2] += 0.0002
            if lifted[2] >= surface + r:
                continue
            path.append(lifted)
        if len(path) < 2:
            return
        first = path[0]
        above = first + np.array([0.0, 0.0, 0.003])
        self._move_to(self._device(above), 0, 0.03)
        self._plan.go(0.15, self._device(above), 1)  # spin up
        self._move_to(self._device(first), 1, p["speed"])
        for point in path[1:]:
            self._move_to(self._device(point), 1, p["speed"])
        self._move_to(self._device(path[-1] + np.array([0.0, 0.0, 0.003])), 1, 0.03)

    def _floor(self, x: float, y: float) -> float:
        """The surface height where planning first found it (later layers go down from there)."""
        key = (round(x, 5), round(y, 5))
        cache = self.__dict__.setdefault("_floors", {})
        if key not in cache:
            cache[key] = self._surface(x, y)
        return cache[key]

    def _plan_plunges(self, end: float) -> None:
        r, region, p, rng = self.burr_radius, self.region, self.params, self.rng
        while self._plan.end < end:
            site, drifting = None, rng.random() < p["drift"]
            if drifting:
                site = self._toward_structure()
            if site is None:
                dx, dy = rng.uniform(-1, 1, size=2) * region.half_extent
                site = (region.center[0] + dx, region.center[1] + dy)
            surface = self._surface(*site)
            if surface is None:
                self._plan.go(0.05, self._plan.waypoints[-1][1], 0)
                continue
            sink = float(rng.uniform(*self.style.layer_depth)) + p["press"]
            if drifting and self.protect:
                # Down to the structure below, and a little into it.
                top = np.array([site[0], site[1], surface])
                reach = min(float(s.field.sample(top)[0]) for s in self.protect)
                sink = max(sink, reach + float(rng.uniform(0.0, 0.0006)))
            above = np.array([site[0], site[1], surface + r + 0.003])
            bottom = np.array([site[0], site[1], surface + r - sink])
            heading = rng.uniform(0, 2 * math.pi)
            wiggle = rng.uniform(0.0008, 0.0018) * np.array(
                [math.cos(heading), math.sin(heading), 0]
            )
            self._move_to(self._device(above), 0, 0.04)
            self._plan.go(0.1, self._device(above), 1)
            self._move_to(self._device(bottom), 1, p["speed"])
            self._move_to(self._device(bottom + wiggle), 1, p["speed"])
            self._move_to(self._device(bottom - wiggle), 1, p["speed"])
            self._move_to(self._device(above), 1, 0.04)


# The phantom's lateral surface (volume z, metres) and the drill's burrs (scenes.drilling_phantom).
PHANTOM_SURFACE = 0.0140
# Where trainees drill the phantom unless told otherwise: the mastoid behind and below the ear
# canal (whose skin the drill may not cut), 12 mm square about 4 mm behind and 6 mm below the
# origin.
PHANTOM_REGION = TrainingRegion(center=(-0.004, -0.006))
DRILL_BURRS = (0.001, 0.002, 0.004, 0.006)


def expert_like(volume, drill_start, burr_radius, rng, **options) -> ScriptedTrainee:
    """A careful expert-like trainee (see the module's docstring)."""
    return ScriptedTrainee(volume, drill_start, burr_radius, EXPERT, rng, **options)


def novice_like(volume, drill_start, burr_radius, rng, **options) -> ScriptedTrainee:
    """A novice-like trainee (see the module's docstring)."""
    return ScriptedTrainee(volume, drill_start, burr_radius, NOVICE, rng, **options)


@dataclass
class TraineeSession:
    """What ``drill_phantom`` gives: the drill, and the session's step log and removed voxels
    (as ``World.take_step_log`` and ``Drill.take_removed`` give them)."""

    drill: object
    steps: dict
    removed: dict


def _trainee_on_phantom(
    make, seed, seconds, protect, resolution, region, field_band, burr, width=640, height=480
):
    """The phantom scene with a planned trainee on a ScriptedDevice: (scene, device)."""
    scene = drilling_phantom(resolution=resolution, width=width, height=height)
    drill = scene.drill
    if burr is not None:
        drill.burr = burr
    fields = [
        ProtectedField(name, DistanceField(drill.volume.data, labels, field_band), margin)
        for name, labels, margin in protect
    ]
    trainee = make(
        drill.volume,
        drill.pose[:3, 3],
        drill.burr_radius,
        np.random.default_rng(seed),
        protect=fields,
        region=region or PHANTOM_REGION,
    )
    trainee.plan(seconds)
    device = ScriptedDevice()
    device.set_callback(trainee, every=10)
    return scene, device


def drill_phantom(
    make,
    seed: int,
    seconds: float,
    protect: list[tuple[str, object, float]],
    resolution: int = 128,
    region: TrainingRegion | None = None,
    field_band: float = 0.03,
    burr: int | None = None,
) -> TraineeSession:
    """A scripted trainee (``make``: expert_like or novice_like) drilling the built-in phantom
    (``scenes.drilling_phantom``) for `seconds`; `protect` lists (name, labels, margin in
    metres), whose distance fields, `field_band` deep, the trainee plans with; `burr` selects
    the drill's burr. The step log is taken every 10,000 steps, so long sessions keep little in
    the engine."""
    scene, device = _trainee_on_phantom(
        make, seed, seconds, protect, resolution, region, field_band, burr
    )
    world, drill = scene.world, scene.drill
    world.add_input_device(scene.device_name, device, drill, **scene.device_options)
    world.start_step_log([drill])
    total = int(round(seconds / world.time_step))
    chunks = []
    while world.step_index < total:
        world.step(min(10000, total - world.step_index))
        chunks.append((world.take_step_log(), drill.take_removed()))
    world.stop_step_log()
    steps = {k: np.concatenate([c[0][k] for c in chunks]) for k in chunks[0][0]}
    removed = {k: np.concatenate([c[1][k] for c in chunks]) for k in chunks[0][1]}
    return TraineeSession(drill, steps, removed)


def task_setup(task, style: TraineeStyle) -> dict:
    """How a scripted trainee of `style` works on a training task of the built-in phantom:
    ``resolution``, ``protect`` (the task's structures), ``region`` (the target's box) and
    ``burr`` (an expert takes the largest burr the task allows, a novice the drill's largest).
    Raises ValueError for a task that is not on the phantom or has no target box."""
    if "phantom" not in task.anatomy:
        raise ValueError(f"{task.source}: scripted trainees drill the built-in phantom only")
    if "box" not in task.target:
        raise ValueError(f"{task.source}: scripted trainees need a target box")
    # The first box's width; the union's depth.
    (x0, y0, _), (x1, y1, z1) = task.target["box"][0]
    z0 = min(low[2] for low, _ in task.target["box"])
    surface = min(z1, PHANTOM_SURFACE)
    burr = len(DRILL_BURRS) - 1
    if style.strokes and task.burrs:
        largest = max(task.burrs)
        burr = min(range(len(DRILL_BURRS)), key=lambda i: abs(DRILL_BURRS[i] - largest))
    # An expert keeps the whole burr inside the box; a novice aims its centre anywhere in it.
    inset = DRILL_BURRS[burr] / 2 if style.strokes else 0.0
    region = TrainingRegion(
        center=((x0 + x1) / 2, (y0 + y1) / 2),
        half_extent=(max((x1 - x0) / 2 - inset, 0.0005), max((y1 - y0) / 2 - inset, 0.0005)),
        depth=max(surface - z0, 0.0),
        taper=0.8 if style.strokes else 0.0,
    )
    return {
        "resolution": int(task.anatomy["phantom"]["resolution"]),
        "protect": [(p.name, p.labels, p.length) for p in task.protect],
        "region": region,
        "burr": burr,
    }


def record_trainee(
    make,
    seed: int,
    seconds: float,
    path,
    task=None,
    *,
    capture_every: int = 50,
    passes=("rgb", "depth", "label"),
    width: int = 320,
    height: int = 240,
    **setup,
) -> dict:
    """Records a scripted trainee on the built-in phantom to `path` (a recording like any
    other, with stereo frames every `capture_every` steps), set up for `task` (``task_setup``)
    or by `setup` (resolution, protect, region, burr, as ``drill_phantom``). Returns
    record_session's summary."""
    from ..scenes import record_session

    options = {"resolution": 128, "protect": [], "region": None, "burr": None}
    if task is not None:
        options.update(task_setup(task, _STYLES[make]))
    options.update(setup)
    scene, device = _trainee_on_phantom(
        make,
        seed,
        seconds,
        options["protect"],
        options["resolution"],
        options["region"],
        0.03,
        options["burr"],
        width=width,
        height=height,
    )
    return record_session(
        scene,
        path,
        device,
        seconds,
        capture_every=capture_every,
        passes=passes,
        metadata={
            "trainee": {
                "style": _STYLES[make].name,
                "seed": seed,
                "task": None if task is None else task.name,
            }
        },
    )


_STYLES = {expert_like: EXPERT, novice_like: NOVICE}
