"""Datasets of any scene: the scene a spec's ``scene`` names (an AMBF launch file or a Python
factory), the dataset's stereo rig placed in it, and what drives it during an episode (a Python
episode script or declarative waypoints).

An episode builds its scene afresh, places the rig where the scene's stereo pair is (riding on
the same body) or at the spec's ``view``, adds the sampled lights and hands the scene to the
episode's script with the episode's own random stream, so that the episode stays a pure
function of (spec, seed, index). ``check_scene`` does all of it once in the driver, without
rendering, so that a spec whose scene does not load, whose functions do not import or whose
waypoints name no object fails before any worker starts.
"""

from __future__ import annotations

import contextlib
import importlib
import inspect
import sys
from collections.abc import Callable, Iterator
from typing import Any

import numpy as np

from .._core import Simulator, World
from ..scenes.builders import FilmedScene, paper_fov
from ..stereo import StereoRig
from ..transforms import make_pose
from .spec import SpecError

#: the dataset's rig: cameras rig_left and rig_right, as in the built-in scene
RIG_NAME = "rig"
# A rig the spec places freely (scene.view) and whose rigs entry leaves values out.
FREE_RIG = {"baseline": 0.065, "width": 640, "height": 480}


class SceneSourceError(SpecError):
    """A spec's scene that cannot be built or driven: names the spec's key and why."""


@contextlib.contextmanager
def _import_path(folders: list[str]) -> Iterator[None]:
    """`folders` first on sys.path while importing (they stay importable from modules that
    import lazily: the path is restored only where it was changed)."""
    added = [f for f in folders if f not in sys.path]
    sys.path[:0] = added
    try:
        yield
    finally:
        for folder in added:
            with contextlib.suppress(ValueError):
                sys.path.remove(folder)


def load_function(reference: str, python_path: list[str], where: str) -> Callable:
    """The function ``module:function`` names, imported with `python_path` first on sys.path;
    a reference that does not import or name a callable is a SceneSourceError naming
    `where`."""
    module_name, _, attribute = reference.partition(":")
    with _import_path(python_path):
        try:
            target = importlib.import_module(module_name)
        except Exception as error:  # the user's module: any error it raises on import
            raise SceneSourceError(
                f"{where}: cannot import {module_name!r} for {reference!r}: "
                f"{type(error).__name__}: {error}"
            ) from error
    for part in attribute.split("."):
        if not hasattr(target, part):
            raise SceneSourceError(f"{where}: {module_name} has no {attribute!r} ({reference!r})")
        target = getattr(target, part)
    if not callable(target):
        raise SceneSourceError(f"{where}: {reference!r} is not a function")
    return target


def _accepts(function: Callable, name: str) -> bool:
    try:
        parameters = inspect.signature(function).parameters
    except (TypeError, ValueError):
        return False
    return name in parameters or any(p.kind is p.VAR_KEYWORD for p in parameters.values())


def build_simulator(scene: dict, rng: np.random.Generator, where: str = "scene") -> Simulator:
    """The scene of a normalised spec's ``scene``: loaded from its launch file (strictly: a
    model or plugin that fails is an error) or made by its factory (given ``params`` as
    keywords, and `rng` if it takes an ``rng`` argument)."""
    if "launch" in scene:
        return Simulator.from_launch(
            scene["launch"],
            models=scene["models"],
            namespace_prefix=scene["namespace_prefix"],
            strict=True,
        )
    factory = load_function(scene["factory"], scene["python_path"], f"{where}.factory")
    params = dict(scene["params"])
    if _accepts(factory, "rng"):
        params["rng"] = rng
    made = factory(**params)
    if isinstance(made, World):
        return made.simulator
    if isinstance(made, Simulator):
        return made
    raise SceneSourceError(
        f"{where}.factory: {scene['factory']} returned {type(made).__name__}; expected an "
        "ambfplus Simulator or World"
    )


def stereo_pair(world: World, scene: dict, where: str = "scene"):
    """The scene's stereo pair (left, right cameras): the two ``cameras`` the spec names, else
    stereoL and stereoR, else the two eyes of the one stereo camera; None when the spec gives a
    ``view`` instead."""
    if scene["view"] is not None:
        return None
    if scene["cameras"] is not None:
        return tuple(resolve(world, n, "camera", f"{where}.cameras") for n in scene["cameras"])
    cameras = {c.key: c for c in world.cameras}
    if "stereoL" in cameras and "stereoR" in cameras:
        return cameras["stereoL"], cameras["stereoR"]
    eyes = [
        (cameras[k + "_left"], cameras[k + "_right"])
        for k in cameras
        if k + "_left" in cameras and k + "_right" in cameras
    ]
    if len(eyes) == 1:
        return eyes[0]
    found = ", ".join(sorted(cameras)) or "none"
    raise SceneSourceError(
        f"{where}: {'several' if eyes else 'no'} stereo pairs to film with (cameras: {found}); "
        "name two in scene.cameras or place a free rig with scene.view"
    )


def place_rig(world: World, scene: dict, params: dict, where: str = "scene") -> StereoRig:
    """The dataset's rig (cameras rig_left and rig_right) with the episode's drawn `params`
    (width, height, baseline, working_distance, fov_y and its scale, principal point offset,
    background): where the scene's stereo pair is, riding on the pair's body, with the pair's
    values for what the spec leaves out and the pair's shadows, antialiasing and looks; or at
    the spec's view, with those off. The spec's ``appearance.rendering`` overrides them."""
    pair = stereo_pair(world, scene, where)
    rendering = {}
    if pair is None:
        left = None
        defaults = {**FREE_RIG, "fov_y": paper_fov(int(params["height"] or FREE_RIG["height"]))}
        near, far = 0.01, 10.0
    else:
        left, right = pair
        defaults = {
            "baseline": float(np.linalg.norm(right.pose[:3, 3] - left.pose[:3, 3])),
            "width": left.width,
            "height": left.height,
            "fov_y": left.fov_y,
        }
        near, far = left.near, left.far
        rendering = {
            "shadows": left.shadows, "antialiasing": left.antialiasing, "looks": left.looks
        }  # fmt: skip
    rendering.update(params.get("rendering") or {})
    value = {k: (params[k] if params.get(k) is not None else v) for k, v in defaults.items()}
    rig = StereoRig(
        world,
        RIG_NAME,
        baseline=value["baseline"],
        width=int(value["width"]),
        height=int(value["height"]),
        fov_y=value["fov_y"] * params["fov_y_scale"],
        near=near,
        far=far,
        working_distance=params["working_distance"],
        background=params["background"],
        principal_point_offset=params["principal_point_offset"],
        **rendering,
    )
    if left is None:
        rig.aim(scene["view"]["eye"], scene["view"]["target"])
        return rig
    # The rig's midpoint where the pair's is, looking as the pair looks.
    middle = left.pose @ make_pose((defaults["baseline"] / 2, 0.0, 0.0))
    rig.pose = middle @ make_pose((-value["baseline"] / 2, 0.0, 0.0))
    parent = left.attached_to
    if parent is not None:
        rig.left.attach_to(parent, np.linalg.inv(parent.pose) @ rig.left.pose)
    return rig


def resolve(world: World, name: str, kind: str | None, where: str):
    """An object of the scene by any name ``World.get`` takes; a SceneSourceError naming the
    spec's key otherwise."""
    try:
        return world.get(name, kind)
    except (KeyError, ValueError) as error:
        message = error.args[0] if error.args else str(error)
        raise SceneSourceError(f"{where}: {message}") from None


class Waypoints:
    """Declarative motion: every joint, body and camera the waypoints name follows them. Before
    the first waypoint naming it, an object is left alone; between two it moves linearly (joint
    targets, positions, roll-pitch-yaw, eye and target); after the last it holds. Called with
    the simulation time before every step."""

    GROUPS = {"joints": "joint", "bodies": "body", "cameras": "camera"}

    def __init__(self, world: World, rig: StereoRig, waypoints: list[dict], where: str) -> None:
        self.tracks: list[tuple[str, Any, np.ndarray, list[np.ndarray]]] = []
        names: dict[tuple[str, str], list] = {}
        for i, point in enumerate(waypoints):
            for group in self.GROUPS:
                for name, target in point.get(group, {}).items():
                    names.setdefault((group, name), []).append((point["time"], target, i))
        for (group, name), track in names.items():
            at = f"{where}.waypoints[{track[0][2]}].{group}.{name}"
            if group == "cameras" and name == RIG_NAME:
                target = rig
            else:
                target = resolve(world, name, self.GROUPS[group], at)
            times = np.array([t for t, _, _ in track])
            values = [self._vector(group, v, at) for _, v, _ in track]
            self.tracks.append((group, target, times, values))

    @staticmethod
    def _vector(group: str, value, where: str) -> np.ndarray:
        if group == "joints":
            return np.array([value], dtype=float)
        if group == "bodies":
            return np.array([*value["position"], *value.get("rpy", [0.0, 0.0, 0.0])])
        return np.array([*value["eye"], *value["target"]])

    def __call__(self, t: float) -> None:
        for group, target, times, values in self.tracks:
            if t < times[0]:
                continue
            k = int(np.searchsorted(times, t, side="right"))
            if k >= len(times):
                value = values[-1]
            else:
                a = (t - times[k - 1]) / (times[k] - times[k - 1])
                value = (1.0 - a) * values[k - 1] + a * values[k]
            if group == "joints":
                target.set_position(float(value[0]))
            elif group == "bodies":
                target.pose = make_pose(value[:3].tolist(), rpy=value[3:].tolist())
            elif isinstance(target, StereoRig):
                target.aim(value[:3], value[3:])
            else:
                target.look_at(value[:3], value[3:])


def build_episode_scene(
    spec_data: dict, plan, where: str = "scene"
) -> tuple[FilmedScene, Callable | None]:
    """Episode `plan`'s scene of a spec with a scene (its world, the dataset's rig, the lights,
    what its step log records) and the controller its episode runs (called with the time before
    every step; None when nothing moves but the physics)."""
    scene = spec_data["scene"]
    sim = build_simulator(scene, plan.rngs["scene"], where)
    world = sim.world
    rig = place_rig(world, scene, plan.scene, where)
    for i, light in enumerate(plan.scene["lights"] or []):
        world.add_light(**{"name": f"dataset_light{i}", **light})
    if scene["logged"] is not None:
        logged = [resolve(world, n, None, f"{where}.logged") for n in scene["logged"]]
    else:
        logged = [*world.bodies, *world.joints]
    logged.append(rig.left)
    episode = plan.episode or {}
    controller: Callable | None = None
    if "waypoints" in episode:
        controller = Waypoints(world, rig, episode["waypoints"], "episode")
    elif "script" in episode:
        script = load_function(episode["script"], scene["python_path"], "episode.script")
        appearance = {**plan.scene, "rgb_noise": plan.rgb_noise}
        returned = script(sim, plan.rngs["script"], appearance)
        if returned is not None and not callable(returned):
            raise SceneSourceError(
                f"episode.script: {episode['script']} returned {type(returned).__name__}; "
                "expected None or a function of the time"
            )
        controller = returned
    drills = world.drills
    spec = {"builder": "dataset_scene", "params": {"scene": scene, "episode": plan.episode}}
    built = FilmedScene(
        world, drills[0] if drills else None, rig, "", {}, logged, spec, simulator=sim
    )
    return built, controller


def check_scene(spec) -> None:
    """Builds the first episode's scene once (no rendering, no stepping) so that a scene that
    does not load, a factory or script that does not import or a waypoint naming no object fails
    before any worker starts, naming the spec's file and key."""
    from .sampling import sample_episode

    plan = sample_episode(spec, 0)
    try:
        build_episode_scene(spec.data, plan, where=f"{spec.source}: scene")
    except SceneSourceError:
        raise
    except Exception as error:  # the scene's files or the user's code
        raise SceneSourceError(
            f"{spec.source}: scene: cannot build {spec.data['scene']['name']!r}: "
            f"{type(error).__name__}: {error}"
        ) from error


__all__ = [
    "SceneSourceError",
    "Waypoints",
    "build_episode_scene",
    "build_simulator",
    "check_scene",
    "load_function",
    "place_rig",
    "stereo_pair",
]
