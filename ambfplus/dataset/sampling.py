"""What one episode of a dataset is: every value drawn from the spec's ranges by a pure function
of (spec, base seed, episode index).

Each kind of draw has its own random stream (``STREAMS``), all children of the episode's seed,
so that changing one part of a spec leaves the others' draws alone: the same geometry (anatomy,
scenario, rig, camera path, drilling) under other lights, colours or noise, for instance.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field

import numpy as np

from ..scenes import CameraPath
from .spec import DatasetSpec

STREAMS = (
    "anatomy",
    "scenario",
    "rig",
    "motion",
    "lights",
    "colors",
    "materials",
    "background",
    "intrinsics",
    "noise",
    # Streams added later come last, so that earlier streams keep their draws.
    "scene",
    "script",
)
# The drill's default look (ambfplus.scenes.METAL and HANDLE), jittered by appearance.drill.
METAL_COLOR = (0.72, 0.74, 0.8)
HANDLE_COLOR = (0.2, 0.45, 0.75)


def episode_seed(base_seed: int, index: int) -> int:
    """The seed of episode `index` of a dataset whose base seed is `base_seed` (53 bits, exact
    in any JSON reader)."""
    words = np.random.SeedSequence([int(base_seed), int(index)]).generate_state(2, np.uint32)
    return ((int(words[0]) << 32) | int(words[1])) & ((1 << 53) - 1)


def streams(seed: int) -> dict[str, np.random.Generator]:
    """The episode's random streams, one per kind of draw."""
    return {
        name: np.random.default_rng(np.random.SeedSequence(int(seed), spawn_key=(k,)))
        for k, name in enumerate(STREAMS)
    }


def draw(value, rng: np.random.Generator):
    """A value of a normalised spec: fixed values as they are, ranges and choices drawn."""
    if not isinstance(value, dict):
        return value
    if "uniform" in value:
        low, high = value["uniform"]
        integer = value.get("integer", False)
        if isinstance(low, list):
            return [_uniform(lo, hi, integer, rng) for lo, hi in zip(low, high)]
        return _uniform(low, high, integer, rng)
    if "choice" in value:
        weights = np.asarray(value["weights"], dtype=float)
        return value["choice"][int(rng.choice(len(weights), p=weights / weights.sum()))]
    raise ValueError(f"not a spec value: {value!r}")


def _uniform(low, high, integer: bool, rng: np.random.Generator):
    if integer:
        return int(rng.integers(int(low), int(high) + 1))
    return float(rng.uniform(low, high))


def _pick(entries: list[dict], rng: np.random.Generator) -> int:
    weights = np.asarray([e["weight"] for e in entries], dtype=float)
    return int(rng.choice(len(entries), p=weights / weights.sum()))


@dataclass
class EpisodePlan:
    """Everything drawn for one episode before its scene exists. ``scene`` holds
    ``ambfplus.scenes.drilling_scene``'s arguments; the camera path's target and the lights are
    relative to the anatomy's centre (the scene places them); ``motion`` and ``colors`` are the
    streams the worker draws the drilling script and the label colours from, which need the
    built anatomy."""

    index: int
    seed: int
    anatomy: dict
    scenario: dict
    frames: int
    capture_every: int
    passes: list
    scene: dict
    camera_path: CameraPath | None
    label_color_jitter: float
    rgb_noise: dict
    rngs: dict = field(repr=False, default_factory=dict)
    #: a spec with a scene: its episode (script, or waypoints with their values drawn)
    episode: dict | None = None

    def describe(self) -> dict:
        """The drawn values (JSON) for the shard's metadata."""
        out = {
            "anatomy": self.anatomy,
            "scenario": {**self.scenario, "frames": self.frames},
            "camera_path": None if self.camera_path is None else asdict(self.camera_path),
            "label_color_jitter": self.label_color_jitter,
            "rgb_noise": self.rgb_noise,
            "scene": self.scene,
        }
        if self.episode is not None:
            out["episode"] = self.episode
        return out


def sample_episode(spec: DatasetSpec | dict, index: int) -> EpisodePlan:
    """Draws episode `index` of a spec (a DatasetSpec or its normalised data)."""
    data = spec.data if isinstance(spec, DatasetSpec) else spec
    if not 0 <= index < int(data["episodes"]):
        raise IndexError(f"episode {index} is outside the spec's 0..{data['episodes'] - 1}")
    seed = episode_seed(data["seed"], index)
    rng = streams(seed)
    if "scene" in data:
        return _sample_scene_episode(data, index, seed, rng)
    anatomy_index = _pick(data["anatomies"], rng["anatomy"])
    anatomy_entry = data["anatomies"][anatomy_index]
    source = _anatomy_source(anatomy_entry, rng["anatomy"])
    scenario_index = _pick(data["scenarios"], rng["scenario"])
    scenario = data["scenarios"][scenario_index]
    frames = draw(scenario.get("frames", data["capture"]["frames"]), rng["scenario"])
    distance = draw(scenario["distance"], rng["scenario"])
    rig_index = _pick(data["rigs"], rng["rig"])
    rig = data["rigs"][rig_index]
    width, height = draw(rig["resolution"], rng["rig"])
    fov_y = draw(rig["fov_y"], rng["rig"])
    appearance = data["appearance"]
    fov_scale, principal_point_offset = _intrinsics(appearance, rng["intrinsics"])
    moving = scenario["kind"] in ("camera", "mixed")
    scene = {
        "anatomy": source,
        "width": int(width),
        "height": int(height),
        "baseline": draw(rig["baseline"], rng["rig"]),
        "working_distance": None
        if rig["working_distance"] is None
        else draw(rig["working_distance"], rng["rig"]),
        "fov_y": fov_y * fov_scale,
        "principal_point_offset": principal_point_offset,
        "background": draw(appearance.get("background", [0.0, 0.0, 0.0]), rng["background"]),
        "lights": _lights(appearance.get("lights"), rng["lights"]),
        **_materials(appearance, rng["materials"]),
        **appearance.get("rendering", {}),
    }
    return EpisodePlan(
        index=index,
        seed=seed,
        anatomy={"index": anatomy_index, "name": anatomy_entry["name"], "source": source},
        scenario={
            "index": scenario_index,
            "kind": scenario["kind"],
            "distance": distance,
            "rig": rig_index,
        },
        frames=int(frames),
        capture_every=int(data["capture"]["every"]),
        passes=list(data["capture"]["passes"]),
        scene=scene,
        camera_path=CameraPath.random(
            rng["motion"], moving=moving, target=(0.0, 0.0, 0.0), distance=(distance, distance)
        ),
        label_color_jitter=float(
            draw(appearance.get("labels", {}).get("color_jitter", 0.0), rng["colors"])
        ),
        rgb_noise=_noise(appearance, rng["noise"]),
        rngs=rng,
    )


def _noise(appearance: dict, rng: np.random.Generator) -> dict:
    sigma = draw(appearance.get("noise", {}).get("rgb_sigma", 0.0), rng)
    return {
        "model": "gaussian",
        "sigma": float(sigma),
        "unit": "8-bit levels",
        "applies_to": "rgb only",
        "seed": int(rng.integers(1 << 53)),
    }


def _intrinsics(appearance: dict, rng: np.random.Generator) -> tuple[float, list[float]]:
    """(field of view scale, principal point offset in pixels) of the intrinsics jitter."""
    intrinsics = appearance.get("intrinsics", {})
    fov_scale = 1.0 + _symmetric(draw(intrinsics.get("fov_y_jitter", 0.0), rng), rng)
    pp_jitter = draw(intrinsics.get("principal_point_jitter", 0.0), rng)
    return fov_scale, [_symmetric(pp_jitter, rng) for _ in range(2)]


def _sample_scene_episode(data: dict, index: int, seed: int, rng: dict) -> EpisodePlan:
    """An episode of a spec with a scene: the rig (None where the scene's stereo pair says),
    the lights around the scene's ``lights_at``, and the episode's waypoint values drawn."""
    scene = data["scene"]
    rig_index = _pick(data["rigs"], rng["rig"])
    rig = data["rigs"][rig_index]
    frames = draw(data["capture"]["frames"], rng["scenario"])

    def maybe(value):
        return None if value is None else draw(value, rng["rig"])

    resolution = maybe(rig["resolution"])
    appearance = data["appearance"]
    fov_scale, principal_point_offset = _intrinsics(appearance, rng["intrinsics"])
    lights = _lights(appearance.get("lights"), rng["lights"])
    for light in lights or []:
        if "position" in light:
            light["position"] = [p + c for p, c in zip(light["position"], scene["lights_at"])]
    plan_scene = {
        "width": None if resolution is None else int(resolution[0]),
        "height": None if resolution is None else int(resolution[1]),
        "baseline": maybe(rig["baseline"]),
        "working_distance": maybe(rig["working_distance"]),
        "fov_y": maybe(rig["fov_y"]),
        "fov_y_scale": fov_scale,
        "principal_point_offset": principal_point_offset,
        "background": draw(appearance.get("background", [0.0, 0.0, 0.0]), rng["background"]),
        "lights": lights,
    }
    if "rendering" in appearance:
        plan_scene["rendering"] = dict(appearance["rendering"])
    episode = data["episode"]
    kind = "script" if "script" in episode else "waypoints" if "waypoints" in episode else "still"
    if kind == "waypoints":
        episode = {"waypoints": [_drawn_waypoint(w, rng["motion"]) for w in episode["waypoints"]]}
    return EpisodePlan(
        index=index,
        seed=seed,
        anatomy={"index": 0, "name": scene["name"], "source": {"scene": scene}},
        scenario={"index": 0, "kind": kind, "rig": rig_index},
        frames=int(frames),
        capture_every=int(data["capture"]["every"]),
        passes=list(data["capture"]["passes"]),
        scene=plan_scene,
        camera_path=None,
        label_color_jitter=0.0,
        rgb_noise=_noise(appearance, rng["noise"]),
        rngs=rng,
        episode=dict(episode),
    )


def _drawn_waypoint(point: dict, rng: np.random.Generator) -> dict:
    """A waypoint with every varying value drawn (in the spec's order)."""
    out: dict = {"time": point["time"]}
    for group in ("joints", "bodies", "cameras"):
        if group not in point:
            continue
        out[group] = {}
        for name, target in point[group].items():
            if group == "joints":
                out[group][name] = float(draw(target, rng))
            else:
                out[group][name] = {k: [float(c) for c in draw(v, rng)] for k, v in target.items()}
    return out


def _anatomy_source(entry: dict, rng: np.random.Generator) -> dict:
    if "phantom" in entry:
        return {"phantom": {k: draw(v, rng) for k, v in entry["phantom"].items()}}
    return {k: v for k, v in entry.items() if k not in ("name", "weight")}


def _symmetric(amount: float, rng: np.random.Generator) -> float:
    """Uniform in [-amount, amount] (always one draw, so later draws do not shift)."""
    return float(rng.uniform(-1.0, 1.0)) * float(amount)


def _lights(spec: dict | None, rng: np.random.Generator) -> list | None:
    """Lights around the anatomy's centre, or None (the built-in key and fill lights)."""
    if spec is None:
        return None
    lights = []
    for _ in range(draw(spec["count"], rng)):
        kind = spec["types"][int(rng.integers(len(spec["types"])))]
        azimuth, elevation = draw(spec["azimuth"], rng), draw(spec["elevation"], rng)
        towards = np.array(
            [
                math.cos(elevation) * math.cos(azimuth),
                math.cos(elevation) * math.sin(azimuth),
                math.sin(elevation),
            ]
        )
        distance = draw(spec["distance"], rng)
        light = {
            "type": kind,
            "intensity": draw(spec["intensity"], rng),
            "color": [float(c) for c in draw(spec["color"], rng)],
            # Every light shines at the anatomy's centre; directional ones have no position.
            "direction": [float(v) for v in -towards],
        }
        if kind != "directional":
            light["position"] = [float(v) for v in distance * towards]
        lights.append(light)
    return lights


def _materials(appearance: dict, rng: np.random.Generator) -> dict:
    out: dict[str, dict | None] = {
        "volume_material": None,
        "drill_metal": None,
        "drill_handle": None,
    }
    material = appearance.get("material")
    if material:
        out["volume_material"] = {k: draw(v, rng) for k, v in material.items()}
    drill = appearance.get("drill")
    if drill:
        jitter = draw(drill.get("color_jitter", 0.0), rng)
        metal = {k: draw(drill[k], rng) for k in ("specular", "shininess") if k in drill}
        metal["color"] = _jittered(METAL_COLOR, jitter, rng)
        out["drill_metal"] = metal
        out["drill_handle"] = {"color": _jittered(HANDLE_COLOR, jitter, rng)}
    return out


def _jittered(color, amount: float, rng: np.random.Generator) -> list[float]:
    return [float(np.clip(c + _symmetric(amount, rng), 0.0, 1.0)) for c in color]


def jitter_label_colors(table, amount: float, rng: np.random.Generator) -> dict | None:
    """{label id: RGB 0..255}: each label's colour moved by up to +-amount per channel (None
    when amount is 0, the table's own colours)."""
    if amount <= 0:
        return None
    out = {}
    for label in sorted(table, key=lambda entry: entry.id):
        offsets = rng.uniform(-amount, amount, size=3)
        out[str(label.id)] = [
            int(np.clip(round(c + o), 0, 255)) for c, o in zip(label.color, offsets)
        ]
    return out
