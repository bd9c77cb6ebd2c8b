"""Dataset specs: a YAML file (versioned schema) that says which episodes a dataset holds, checked
completely before anything runs. ``load_spec(path)`` returns a ``DatasetSpec``; errors are
``SpecError`` (a ``ConfigError``, so a ``ValueError``) naming the file, the key and what was
expected.

A spec films either the built-in drilling scene (``anatomies``, ``scenarios``) or any scene
(``scene``: an AMBF launch file or a Python factory) driven by an ``episode`` script (a Python
function or declarative waypoints); see ``ambfplus.dataset.sources``.

A value that may vary is a fixed value, ``{uniform: [low, high]}`` (integers for integer keys,
both ends included; ``low`` and ``high`` may be lists for vectors, one range per component) or
``{choice: [a, b, ...], weights: [...]}``. See ``SCHEMA_TEXT`` (and the README) for every key.
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .._core import MAX_ANTIALIASING, ConfigError
from ..config import (
    MAX_SEED,
    Where,
    anatomy,
    boolean,
    describe,
    existing,
    fixed,
    integer,
    keys,
    load_yaml,
    mapping,
    non_negative,
    number,
    positive,
    unit,
)

SCHEMA_VERSION = 1
SCENARIO_KINDS = ("camera", "drilling", "mixed")
LIGHT_TYPES = ("directional", "point", "spot")
PASS_NAMES = ("rgb", "depth", "label", "instance", "voxel", "segmentation", "points")
# Limits a 2-core, 24 GB machine honours, each with what a larger value would cost.
MAX_EPISODES = 1_000_000
EPISODES_LIMIT = "a dataset's manifest and plan hold a line per episode"
MAX_EVERY = 60_000
EVERY_LIMIT = "one minute of 1 ms steps between stereo pairs; an episode steps every frame"
MAX_SIDE = 4096
SIDE_LIMIT = "a 4096x4096 stereo pair of every pass takes about 0.6 GB"
MAX_WEIGHT = 1e9
WEIGHT_LIMIT = "weights are relative: scale them down"

# The paper's camera: f = 1135 px at 480 rows.
PAPER_FOV_Y = 2.0 * math.atan(240.0 / 1135.0)

SCHEMA_TEXT = """\
version: 1                      # required: the spec's schema version
name: text                      # optional
episodes: 12                    # required, 1..1000000
seed: 0                         # base seed (default 0; 0..2^63-1)
capture:
  every: 40                     # 1 ms steps between stereo pairs (default 40; 1..60000)
  frames: 25                    # stereo pairs per episode (default 25; a scenario may say)
  passes: [rgb, depth, label, instance, voxel]   # (the default)
anatomies:                      # required, one drawn per episode by weight
  - phantom: {resolution: 128, seed: 0}          # values may vary; resolution 16..512
    weight: 1
  - file: ear.seg.nrrd          # NRRD, Slicer .seg.nrrd, slice folder or volume ADF,
    weight: 1                   # relative to the spec's folder; prefix, labels, dimensions,
                                # voxel_size, threshold as for ambfplus.load_volume
scenarios:                      # default [{kind: camera}]
  - kind: camera                # camera: the rig swings along a random path, the drill rests;
    weight: 1                   # drilling: a still rig, a scripted hand drills; mixed: both
    frames: 25                  # may vary
    distance: {uniform: [0.23, 0.27]}   # rig to its target, metres
rigs:                           # default [the paper's rig]
  - baseline: 0.065             # metres, may vary
    working_distance: 0.25      # off-axis, zero disparity at this depth; null: parallel
    resolution: [640, 480]      # may vary ({choice: [[640, 480], [320, 240]]}); 8..4096
    fov_y: 0.4169               # radians (default: f = 1135 px at 480 rows)
    weight: 1
appearance:                     # optional; every entry may vary
  lights: {count: 2, types: [directional, point], intensity: 0.8, color: [1, 1, 1],
           azimuth: {uniform: [-3.1416, 3.1416]}, elevation: {uniform: [0.6, 1.4]},
           distance: {uniform: [0.15, 0.4]}}      # radians; point and spot lights' distance
  labels: {color_jitter: 20}    # +-, per label and channel, in 0..255
  material: {specular: 0.15, shininess: 24}       # the anatomy's surface
  drill: {color_jitter: 0.05, specular: 0.6, shininess: 24}
  background: [0, 0, 0]         # RGB 0..1 where nothing is hit
  intrinsics: {fov_y_jitter: 0.02, principal_point_jitter: 2.0}  # relative; pixels
  noise: {rgb_sigma: 0}         # Gaussian sensor noise on RGB, 8-bit levels (ground truth exact)
  rendering: {shadows: true, antialiasing: 2, looks: true}   # the rig's rgb (fixed values;
                                # default all off; with a scene, the scene pair's)
"""

SCENE_SCHEMA_TEXT = """\
# Any scene instead of the built-in one (no anatomies or scenarios then):
scene:
  launch: arms/launch.yaml      # an AMBF launch file, relative to the spec, or
  factory: my_scenes:two_arms   # module:function returning a Simulator or World (given
                                # params as keywords, and rng if it takes one)
  models: [0, 1, 2]             # launch only: the model files' indices (AMBF's -l)
  namespace_prefix: ""          # launch only
  params: {}                    # factory only: keyword arguments
  python_path: [.]              # folders (relative to the spec) factory and script import from
  name: two_arms                # what the manifest calls the scene (default: file or function)
  cameras: [stereoL, stereoR]   # the stereo pair the dataset's rig replaces and rides with
                                # (default: stereoL and stereoR, or a stereo camera's two eyes)
  view: {eye: [x, y, z], target: [x, y, z]}  # or: where a free rig stands (world frame)
  lights_at: [0, 0, 0]          # the point appearance.lights shine at (world frame, metres)
  logged: [psm1/tool, ...]      # objects the step log records (default: every body and joint)
episode:                        # what moves (default: nothing but the scene's own physics)
  script: my_scenes:drive       # module:function(sim, rng, appearance), called once before
                                # the first step; it may return control(t), called every step
  waypoints:                    # or: joint, body and camera waypoints over time
    - time: 0.0                 # seconds, increasing; values may vary
      joints: {psm1/baselink-yawlink: 0.2}              # joint controller targets
      bodies: {needle: {position: [0, 0, 0.1], rpy: [0, 0, 0]}}
      cameras: {rig: {eye: [0.3, 0, 0.2], target: [0, 0, 0]}}   # rig: the dataset's rig
rigs:                           # with a scene, what a rig leaves out is the scene pair's
  - resolution: [320, 240]
"""
SOURCE_KEYS = ("launch", "factory")
SCENE_KEYS = SOURCE_KEYS + ("models", "namespace_prefix", "params", "python_path", "name",
                            "cameras", "view", "lights_at", "logged")  # fmt: skip
WAYPOINT_KEYS = ("joints", "bodies", "cameras")
MAX_WAYPOINTS = 10_000
WAYPOINTS_LIMIT = "an episode's waypoints are drawn and stored with its plan"
# What a spec with a scene cannot use: the built-in scene's anatomy and drill.
BUILT_IN_ONLY = {
    "anatomies": "a scene brings its own objects",
    "scenarios": "its episode script says what moves",
}
BUILT_IN_LOOKS = {
    "labels": "label colours",
    "material": "the anatomy's material",
    "drill": "the drill's look",
}


class SpecError(ConfigError):
    """A dataset spec that cannot be used: names the file, the key and what was expected."""


@dataclass
class DatasetSpec:
    """A checked dataset spec: ``data`` (normalised: defaults filled, paths absolute), the
    ``text`` it was read from (stored as the dataset's spec.yaml) and ``sha256`` of ``data``."""

    data: dict
    text: str
    source: str = "<spec>"

    @property
    def episodes(self) -> int:
        return int(self.data["episodes"])

    @property
    def seed(self) -> int:
        return int(self.data["seed"])

    @property
    def sha256(self) -> str:
        return spec_hash(self.data)


def spec_hash(data: dict) -> str:
    """SHA-256 of a normalised spec's canonical JSON."""
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()


def load_spec(source) -> DatasetSpec:
    """Reads and checks a spec: a YAML file's path, or a dict (relative paths are then taken
    from the current folder)."""
    if isinstance(source, dict):
        import yaml

        return parse_spec(source, Path.cwd(), "<spec>", yaml.safe_dump(source, sort_keys=False))
    path = Path(source)
    data, text = load_yaml(path, SpecError, "spec")
    return parse_spec(data, path.resolve().parent, str(path), text)


def parse_spec(data, base: Path, source: str, text: str) -> DatasetSpec:
    """Checks a spec's parsed YAML and normalises it (see the module)."""
    where = Where(source, error=SpecError)
    mapping(data, where, "the spec")
    with_scene = isinstance(data, dict) and "scene" in data
    keys(
        data,
        where,
        required=("version", "episodes") if with_scene else ("version", "episodes", "anatomies"),
        optional=("name", "seed", "capture", "anatomies", "scenarios", "rigs", "appearance",
                  "scene", "episode"),
    )  # fmt: skip
    version = data["version"]
    if version != SCHEMA_VERSION:
        raise where.error(
            "version",
            f"spec schema version {version!r} is not supported; this ambfplus reads "
            f"version {SCHEMA_VERSION}",
        )
    out = {"version": SCHEMA_VERSION, "name": str(data.get("name", ""))}
    out["episodes"] = integer(data["episodes"], where.at("episodes"), minimum=1,
                              maximum=MAX_EPISODES, limit=EPISODES_LIMIT)  # fmt: skip
    out["seed"] = integer(data.get("seed", 0), where.at("seed"), minimum=0, maximum=MAX_SEED)
    out["capture"] = _capture(data.get("capture", {}), where.at("capture"))
    if with_scene:
        for key, why in BUILT_IN_ONLY.items():
            if key in data:
                raise where.error(
                    key, f"applies to the built-in drilling scene only, not to a scene ({why})"
                )
        out["scene"] = _scene(data["scene"], where.at("scene"), base)
        out["episode"] = _episode(data.get("episode", {}), where.at("episode"))
    else:
        if "episode" in data:
            raise where.error(
                "episode", "an episode script drives a scene: give the spec a scene too"
            )
        out["anatomies"] = _weighted_list(
            data["anatomies"], where.at("anatomies"), lambda e, w: anatomy(e, w, base, _varying)
        )
        out["scenarios"] = _weighted_list(
            data.get("scenarios", [{"kind": "camera"}]), where.at("scenarios"), _scenario
        )
    out["rigs"] = _weighted_list(
        data.get("rigs", [{}]), where.at("rigs"), lambda e, w: _rig(e, w, with_scene)
    )
    out["appearance"] = _appearance(data.get("appearance", {}), where.at("appearance"), with_scene)
    return DatasetSpec(out, text, source)


def _varying(value, where: Where, check: Callable, size: int | None = None, integer=False):
    """A fixed value, {uniform: [low, high]} or {choice: [...], weights: [...]}, each value
    passed through check(value, where). `size` > 0: values are vectors of that many numbers."""
    if isinstance(value, dict) and "uniform" in value:
        keys(value, where, required=("uniform",), optional=("integer",))
        bounds = value["uniform"]
        if not isinstance(bounds, list) or len(bounds) != 2:
            raise where.error("uniform", f"expected [low, high], got {describe(bounds)}")
        low, high = (
            _component_bounds(b, where.at("uniform").at(i), size, check)
            for i, b in enumerate(bounds)
        )
        for lo, hi in zip(low, high):
            if lo > hi:
                raise where.error("uniform", f"empty range: low {lo} > high {hi}")
        pack = (lambda v: v[0]) if size is None else (lambda v: v)
        return {"uniform": [pack(low), pack(high)], **({"integer": True} if integer else {})}
    if isinstance(value, dict) and "choice" in value:
        keys(value, where, required=("choice",), optional=("weights",))
        options = value["choice"]
        if not isinstance(options, list) or not options:
            raise where.error("choice", f"expected a non-empty list, got {describe(options)}")
        checked = [fixed(o, where.at("choice").at(i), check, size) for i, o in enumerate(options)]
        weights = _weights(value.get("weights"), len(options), where.at("weights"))
        return {"choice": checked, "weights": weights}
    if isinstance(value, dict) or (size is None and isinstance(value, list)):
        raise where.error(
            None,
            f"expected a {'vector' if size else 'value'}, {{uniform: [low, "
            f"high]}} or {{choice: [...]}}, got {describe(value)}",
        )
    return fixed(value, where, check, size)


def _component_bounds(bound, where: Where, size: int | None, check: Callable) -> list:
    if size is not None and isinstance(bound, list):
        return fixed(bound, where, check, size)
    value = check(bound, where)
    return [value] * (size or 1)


def _weights(weights, count: int, where: Where) -> list[float]:
    if weights is None:
        return [1.0] * count
    if not isinstance(weights, list) or len(weights) != count:
        raise where.error(None, f"expected a list of {count} weights, got {describe(weights)}")
    checked = [_weight(w, where.at(i)) for i, w in enumerate(weights)]
    if sum(checked) <= 0:
        raise where.error(None, "the weights add up to 0")
    return checked


def _weight(value, where: Where) -> float:
    """A draw's weight: weights are relative, and their sum must stay a finite number."""
    return number(value, where, minimum=0, maximum=MAX_WEIGHT, limit=WEIGHT_LIMIT)


def _weighted_list(value, where: Where, entry: Callable) -> list[dict]:
    if not isinstance(value, list) or not value:
        raise where.error(None, f"expected a non-empty list, got {describe(value)}")
    out = []
    for i, item in enumerate(value):
        mapping(item, where.at(i), "an entry")
        weight = _weight(item.get("weight", 1.0), where.at(i).at("weight"))
        body = {k: v for k, v in item.items() if k != "weight"}
        out.append({**entry(body, where.at(i)), "weight": weight})
    if sum(e["weight"] for e in out) <= 0:
        raise where.error(None, "every entry has weight 0")
    return out


def _capture(value, where: Where) -> dict:
    mapping(value, where, "capture")
    keys(value, where, optional=("every", "frames", "passes"))
    passes = value.get("passes", ["rgb", "depth", "label", "instance", "voxel"])
    if not isinstance(passes, list) or not passes:
        raise where.error("passes", f"expected a non-empty list of passes, got {describe(passes)}")
    for i, name in enumerate(passes):
        if name not in PASS_NAMES:
            raise where.error(
                f"passes[{i}]", f"unknown pass {name!r}; expected one of {', '.join(PASS_NAMES)}"
            )
    if len(set(passes)) != len(passes):
        raise where.error("passes", f"a pass is listed twice: {passes}")
    return {
        "every": integer(
            value.get("every", 40),
            where.at("every"),
            minimum=1,
            maximum=MAX_EVERY,
            limit=EVERY_LIMIT,
        ),  # fmt: skip
        "frames": _varying(value.get("frames", 25), where.at("frames"), _frames, integer=True),
        "passes": list(passes),
    }


def _frames(value, where: Where) -> int:
    return integer(value, where, minimum=1, maximum=100000)


def _scenario(entry: dict, where: Where) -> dict:
    keys(entry, where, required=("kind",), optional=("frames", "distance"))
    if entry["kind"] not in SCENARIO_KINDS:
        raise where.error(
            "kind",
            f"unknown scenario {entry['kind']!r}; expected one of {', '.join(SCENARIO_KINDS)}",
        )
    out = {"kind": entry["kind"]}
    if "frames" in entry:
        out["frames"] = _varying(entry["frames"], where.at("frames"), _frames, integer=True)
    out["distance"] = _varying(
        entry.get("distance", {"uniform": [0.23, 0.27]}), where.at("distance"), positive
    )
    return out


RIG_DEFAULTS = {
    "baseline": 0.065,
    "working_distance": 0.25,
    "resolution": [640, 480],
    "fov_y": PAPER_FOV_Y,
}


def _rig(entry: dict, where: Where, with_scene: bool = False) -> dict:
    """A rig entry. With a scene, what the entry leaves out is None (the scene's stereo pair's
    value; a parallel rig for the working distance)."""
    keys(entry, where, optional=tuple(RIG_DEFAULTS))
    checks: dict[str, tuple[Callable, dict]] = {
        "baseline": (positive, {}),
        "working_distance": (positive, {}),
        "resolution": (
            lambda v, w: integer(v, w, minimum=8, maximum=MAX_SIDE, limit=SIDE_LIMIT),
            {"size": 2, "integer": True},
        ),
        "fov_y": (lambda v, w: number(v, w, minimum=0.01, maximum=3.0), {}),
    }
    out = {}
    for key, (check, options) in checks.items():
        value = entry.get(key, None if with_scene else RIG_DEFAULTS[key])
        out[key] = None if value is None else _varying(value, where.at(key), check, **options)
    return out


def _appearance(value, where: Where, with_scene: bool = False) -> dict:
    mapping(value, where, "appearance")
    keys(
        value,
        where,
        optional=(
            "lights", "labels", "material", "drill", "background", "intrinsics", "noise",
            "rendering",
        ),
    )  # fmt: skip
    if with_scene:
        for key, what in BUILT_IN_LOOKS.items():
            if key in value:
                raise where.error(
                    key,
                    f"{what} apply to the built-in drilling scene only; a scene's looks come "
                    "from its files, or its factory and episode script draw them from their rng",
                )
    out = {}
    if "lights" in value:
        out["lights"] = _lights(value["lights"], where.at("lights"))
    if "background" in value:
        out["background"] = _varying(value["background"], where.at("background"), unit, size=3)
    shininess = (None, lambda v, w: number(v, w, 1, 1024))
    sections: dict[str, tuple[str, dict]] = {
        "labels": ("label colours", {"color_jitter": (0.0, lambda v, w: number(v, w, 0, 255))}),
        "material": ("the anatomy's material", {"specular": (None, unit),
                                                "shininess": shininess}),
        "drill": ("the drill's material", {"color_jitter": (0.0, unit), "specular": (None, unit),
                                           "shininess": shininess}),
        "intrinsics": ("intrinsics jitter", {
            "fov_y_jitter": (0.0, lambda v, w: number(v, w, 0, 0.5)),
            "principal_point_jitter": (0.0, non_negative)}),
        "noise": ("sensor noise", {"rgb_sigma": (0.0, lambda v, w: number(v, w, 0, 128))}),
    }  # fmt: skip
    for key, (what, fields) in sections.items():
        if key in value:
            out[key] = _section(value[key], where.at(key), what, fields)
    if "rendering" in value:
        out["rendering"] = _rendering(value["rendering"], where.at("rendering"))
    return out


def _rendering(value, where: Where) -> dict:
    """The rig cameras' shadows, antialiasing and looks (Camera's), as given: fixed values."""
    mapping(value, where, "rendering")
    keys(value, where, optional=("shadows", "antialiasing", "looks"))
    checks = {
        "shadows": boolean,
        "antialiasing": lambda v, w: integer(v, w, minimum=1, maximum=MAX_ANTIALIASING),
        "looks": boolean,
    }
    return {key: check(value[key], where.at(key)) for key, check in checks.items() if key in value}


def _section(value, where: Where, what: str, fields: dict) -> dict:
    """A mapping of varying numbers: `fields` maps each key to (default, check); a key whose
    default is None is left out unless given."""
    mapping(value, where, what)
    keys(value, where, optional=tuple(fields))
    return {
        key: _varying(value.get(key, default), where.at(key), check)
        for key, (default, check) in fields.items()
        if key in value or default is not None
    }


def _lights(value, where: Where) -> dict:
    mapping(value, where, "lights")
    keys(
        value,
        where,
        optional=("count", "types", "intensity", "color", "azimuth", "elevation", "distance"),
    )
    types = value.get("types", ["directional", "point"])
    if not isinstance(types, list) or not types:
        raise where.error(
            "types", f"expected a non-empty list of light types, got {describe(types)}"
        )
    for i, kind in enumerate(types):
        if kind not in LIGHT_TYPES:
            raise where.error(
                f"types[{i}]",
                f"unknown light type {kind!r}; expected one of {', '.join(LIGHT_TYPES)}",
            )
    return {
        "count": _varying(
            value.get("count", 2),
            where.at("count"),
            lambda v, w: integer(v, w, minimum=1, maximum=8),
            integer=True,
        ),
        "types": list(types),
        "intensity": _varying(
            value.get("intensity", 0.8), where.at("intensity"), lambda v, w: number(v, w, 0, 10)
        ),
        "color": _varying(value.get("color", [1.0, 1.0, 1.0]), where.at("color"), unit, size=3),
        "azimuth": _varying(
            value.get("azimuth", {"uniform": [-math.pi, math.pi]}),
            where.at("azimuth"),
            lambda v, w: number(v, w, -10, 10),
        ),
        "elevation": _varying(
            value.get("elevation", {"uniform": [0.6, 1.4]}),
            where.at("elevation"),
            lambda v, w: number(v, w, -math.pi / 2, math.pi / 2),
        ),
        "distance": _varying(
            value.get("distance", {"uniform": [0.15, 0.4]}), where.at("distance"), positive
        ),
    }


def _function_reference(value, where: Where) -> str:
    """``module:function`` (a dotted module path and a dotted attribute path)."""
    if not isinstance(value, str):
        raise where.error(None, f"expected module:function, got {describe(value)}")
    module, colon, function = value.partition(":")
    dotted = (module, function)
    if not colon or not all(all(p.isidentifier() for p in part.split(".")) for part in dotted):
        raise where.error(None, f"expected module:function (e.g. my_scenes:build), got {value!r}")
    return value


def _point(value, where: Where) -> list[float]:
    return fixed(value, where, number, 3)


def _scene(value, where: Where, base: Path) -> dict:
    mapping(value, where, "scene")
    keys(value, where, optional=SCENE_KEYS)
    sources = [k for k in SOURCE_KEYS if k in value]
    if len(sources) != 1:
        raise where.error(
            None, f"expected exactly one of {', '.join(SOURCE_KEYS)}, got {sorted(value) or 'none'}"
        )
    source = sources[0]
    wrong = [k for k in (("params",) if source == "launch" else ("models", "namespace_prefix"))
             if k in value]  # fmt: skip
    if wrong:
        raise where.error(wrong[0], f"does not apply to a scene made by {source}")
    out: dict = {}
    python_path = value.get("python_path", [])
    if not isinstance(python_path, list):
        raise where.error("python_path", f"expected a list of folders, got {describe(python_path)}")
    out["python_path"] = [
        str(existing(p, base, where.at("python_path").at(i))) for i, p in enumerate(python_path)
    ]
    if source == "launch":
        path = existing(value["launch"], base, where.at("launch"))
        out["launch"] = str(path)
        models = value.get("models")
        if models is not None:
            if not isinstance(models, list):
                raise where.error("models", f"expected a list of indices, got {describe(models)}")
            models = [integer(m, where.at("models").at(i), minimum=0)
                      for i, m in enumerate(models)]  # fmt: skip
        out["models"] = models
        prefix = value.get("namespace_prefix", "")
        if not isinstance(prefix, str):
            raise where.error("namespace_prefix", f"expected text, got {describe(prefix)}")
        out["namespace_prefix"] = prefix
        name = path.name.split(".")[0]
        if name == "launch":  # AMBF projects name every launch file so: name their folder
            name = path.parent.name or name
    else:
        out["factory"] = _function_reference(value["factory"], where.at("factory"))
        params = value.get("params", {})
        mapping(params, where.at("params"), "the factory's keyword arguments")
        out["params"] = params
        name = out["factory"]
    out["name"] = str(value.get("name", name))
    cameras = value.get("cameras")
    if cameras is not None:
        if (
            not isinstance(cameras, list)
            or len(cameras) != 2
            or not all(isinstance(c, str) and c for c in cameras)
        ):
            raise where.error(
                "cameras", f"expected two camera names [left, right], got {describe(cameras)}"
            )
        if "view" in value:
            raise where.error("view", "give cameras or view, not both")
    out["cameras"] = cameras
    view = value.get("view")
    if view is not None:
        mapping(view, where.at("view"), "a view")
        keys(view, where.at("view"), required=("eye", "target"))
        view = {k: _point(view[k], where.at("view").at(k)) for k in ("eye", "target")}
    out["view"] = view
    out["lights_at"] = _point(value.get("lights_at", [0.0, 0.0, 0.0]), where.at("lights_at"))
    logged = value.get("logged")
    if logged is not None and (
        not isinstance(logged, list) or not all(isinstance(n, str) and n for n in logged)
    ):
        raise where.error("logged", f"expected a list of object names, got {describe(logged)}")
    out["logged"] = logged
    return out


def _episode(value, where: Where) -> dict:
    mapping(value, where, "episode")
    keys(value, where, optional=("script", "waypoints"))
    if "script" in value and "waypoints" in value:
        raise where.error(None, "expected one of script, waypoints, not both")
    if "script" in value:
        return {"script": _function_reference(value["script"], where.at("script"))}
    if "waypoints" not in value:
        return {}
    waypoints = value["waypoints"]
    if not isinstance(waypoints, list) or not waypoints:
        raise where.error("waypoints", f"expected a non-empty list, got {describe(waypoints)}")
    if len(waypoints) > MAX_WAYPOINTS:
        raise where.error(
            "waypoints",
            f"expected at most {MAX_WAYPOINTS} waypoints, got {len(waypoints)} ({WAYPOINTS_LIMIT})",
        )
    out, last = [], -1.0
    for i, point in enumerate(waypoints):
        at = where.at("waypoints").at(i)
        mapping(point, at, "a waypoint")
        keys(point, at, required=("time",), optional=WAYPOINT_KEYS)
        time = number(point["time"], at.at("time"), minimum=0)
        if time <= last:
            raise at.error("time", f"waypoint times must increase: {time} follows {last}")
        last = time
        entry: dict = {"time": time}
        for group in WAYPOINT_KEYS:
            if group not in point:
                continue
            targets = point[group]
            mapping(targets, at.at(group), f"{group} by name")
            entry[group] = {
                str(name): _waypoint_target(group, target, at.at(group).at(name))
                for name, target in targets.items()
            }
        out.append(entry)
    return {"waypoints": out}


def _waypoint_target(group: str, value, where: Where):
    if group == "joints":
        return _varying(value, where, number)
    fields = ("position", "rpy") if group == "bodies" else ("eye", "target")
    mapping(value, where, "a body's pose" if group == "bodies" else "a camera's view")
    keys(value, where, required=fields[:1] if group == "bodies" else fields, optional=fields[1:])
    return {k: _varying(value[k], where.at(k), number, size=3) for k in fields if k in value}
