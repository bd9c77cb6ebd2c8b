"""``ambfplus-launch``: an interactive training session in a window, AMBF's simulator command.

    ambfplus-launch --launch_file volumetric_drilling/launch.yaml -l 0,2 [--record session.h5]

Loads a launch file as AMBF does (its options: ``-l``, ``-a``, ``-i``, ``-p``, ``-t``, ``-g``,
``--ns``, ``--plugins``; unknown options go to simulator plugins, e.g. ``--removal
compatible``), steps it in real time (a 1 kHz thread) and shows the scene's main camera in a
window (GLFW, its X11 window presented by the engine's own context). A ``labels.csv`` beside
the launch file names the anatomy for the drilling plugin (``--labels``). Keyboard and mouse:

- the drill, through a keyboard device: Ctrl+W/S/A/D/I/K move it 1 mm up, down, left, right,
  into and out of the view; keypad 8/5/4/6 turn it; Space spins the burr; C takes the next burr;
- plugins get every key (the drilling plugin: B shows or hides the drill, X shows the goal
  instead of the proxy, Ctrl+C the cursors, Ctrl+R resets the drill, Ctrl+T / Alt+T change the
  voxels per step in compatible removal);
- the session: Ctrl+N resets the volumes, Alt+R resets the world (volumes, drill, plugins),
  Esc or Q quits;
- the camera: left drag orbits about the point it looks at, right (or Shift+left) drag pans,
  the wheel zooms.

``--stereo side-by-side`` shows a stereo pair riding on the camera (``--ipd`` apart, zero
disparity at the depth the camera looks at or ``--convergence``) for 3D monitors and
projectors; ``--stereo hmd`` shows OpenHMD's first head-mounted display's eyes (its null device
without hardware), turned by the head, each with the eye's projection and seen through the
lens's distortion correction, in a window of the HMD's screen size; ``--stereo openxr`` shows
the eyes in the OpenXR runtime's headset (Monado, SteamVR, ...; head pose and each eye's field
of view from the runtime, the images into its swapchains) with the window mirroring them, and
says why it falls back to OpenHMD where there is no runtime or headset.

``--device`` chooses what moves the drill: the keyboard, ``network[:PORT]`` (poses from a
bridge process over UDP on loopback, forces sent back every step; see ``ambfplus.devices.network`` and
``examples/network_bridge.py``) or ``joystick[:PATH]`` (a gamepad's sticks); ``--pedal PATH``
adds a foot pedal's buttons (``--pedal-map drill=0,clutch=1,burr=2``: held spins the burr, held
clutches, pressed takes the next burr). The keyboard's Space and C keep working with any device.

``--foxglove [PORT]`` serves the session live over the Foxglove WebSocket protocol (port 8765 by
default, loopback unless ``--foxglove-host`` says otherwise): TF, the camera's calibration, the
drill's force and the nearest critical structure at ``--foxglove-rate`` Hz (10 by default), and
the camera's images at up to ``--foxglove-image-rate`` Hz (the same by default), as fast as the
renderer makes them (``ambfplus.export.live``; needs ``ambfplus[foxglove]``).

The status line shows the burr, whether it spins, the control mode, the distance to the nearest
critical structure (a warning under 2 mm or when one is cut), and the graphics and physics
rates. ``--record`` writes the session (every step's drill state, the keyboard's readings and
the camera's pose; removed voxels; events), which ``ambfplus replay`` re-simulates exactly.
"""

from __future__ import annotations

import argparse
import ctypes
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import (
    AssetNotFound,
    Device,
    JoystickDevice,
    JoystickMapping,
    KeyboardDevice,
    MergedDevice,
    NetworkDevice,
    RealTimeLoop,
    Simulator,
    __version__,
)
from ._core import OpenXrSession, RenderError, Window, use_x11_display
from .devices.hmd import HmdError, HmdView, OpenHMD, XrView
from .fileio import write_text
from .stereo import StereoRig

# GLFW's codes for the keys and buttons the launcher handles itself.
KEY_ESCAPE, KEY_Q, KEY_N, KEY_R = 256, 81, 78, 82
MOD_SHIFT, MOD_CONTROL, MOD_ALT = 0x1, 0x2, 0x4
PRESS, RELEASE = 1, 0
MOUSE_LEFT, MOUSE_RIGHT = 0, 1
# How close a critical structure may come before the status warns, metres.
WARN_DISTANCE = 0.002
STEREO_MODES = ("off", "side-by-side", "hmd", "openxr")


def parse_args(argv: list[str] | None) -> tuple[argparse.Namespace, list[str]]:
    """AMBF's simulator options plus ambfplus's; the rest is for simulator plugins."""

    def boolean(text: str) -> bool:
        if text.lower() in ("1", "true", "yes", "on"):
            return True
        if text.lower() in ("0", "false", "no", "off"):
            return False
        raise argparse.ArgumentTypeError(f"expected true or false, got '{text}'")

    def indices(text: str) -> list[int]:
        try:
            return [int(p) for p in text.replace(" ", "").split(",") if p]
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected indices like 0,2, got '{text}'") from None

    p = argparse.ArgumentParser(prog="ambfplus-launch", description=__doc__.split("\n\n")[0])
    p.add_argument("launch", nargs="?", type=Path, help="launch file (or --launch_file)")
    p.add_argument("--launch_file", type=Path, help="launch file (AMBF's option)")
    p.add_argument("-l", "--load_multibodies", type=indices, help="launch indices, e.g. 0,2")
    p.add_argument("-a", "--load_multibody_files", help="more model files, comma separated")
    p.add_argument("-i", "--load_devices", type=indices, help="input devices of the launch file")
    p.add_argument("-p", "--phx_frequency", type=float, default=1000.0, help="steps per second")
    p.add_argument("-t", "--fixed_phx_timestep", type=boolean, default=True,
                   help="accepted for AMBF; ambfplus always steps 1 / phx_frequency")  # fmt: skip
    p.add_argument("-g", "--show_gui", type=boolean, default=True, help="false: headless")
    p.add_argument("--ns", default="", help="namespace prefix")
    p.add_argument("--plugins", default="", help="simulator plugins, comma separated")
    p.add_argument("--camera", help="the camera to show (default: the world's first)")
    p.add_argument("--width", type=int, help="window width (default 1536, an HMD's screen)")
    p.add_argument("--height", type=int, help="window height (default 540, an HMD's screen)")
    p.add_argument("--stereo", choices=STEREO_MODES, default="off",
                   help="side-by-side: a stereo pair riding on the camera; hmd: OpenHMD's "
                   "first head-mounted display (its null device without one), head tracked, "
                   "lens corrected; openxr: an OpenXR runtime where one exists, else as hmd",
                   )  # fmt: skip
    p.add_argument("--ipd", type=float,
                   help="metres between the eyes (default: the HMD's; else the scene's stereoL "
                   "to stereoR; else 0.065)")  # fmt: skip
    p.add_argument("--convergence", type=float,
                   help="side-by-side: the depth (m) shown with zero disparity (default: where "
                   "the camera looks; 0: parallel cameras)")  # fmt: skip
    p.add_argument("--device", default="keyboard",
                   help="what moves the drill: keyboard, network[:PORT] (a bridge's UDP poses, "
                   "loopback) or joystick[:PATH] (default /dev/input/js0)")  # fmt: skip
    p.add_argument("--pedal", help="a foot pedal or gamepad for the drill's buttons "
                   "(/dev/input/jsN)")  # fmt: skip
    p.add_argument("--pedal-map", default="drill=0,clutch=1,burr=2",
                   help="which pedal buttons spin the burr (held), clutch (held) and take the "
                   "next burr (pressed)")  # fmt: skip
    p.add_argument("--record", type=Path, help="record the session to this HDF5 file")
    p.add_argument("--foxglove", nargs="?", type=int, const=8765, metavar="PORT",
                   help="serve the session live over the Foxglove WebSocket protocol (default "
                   "port 8765): camera, calibration, TF, drill force, nearest critical "
                   "structure")  # fmt: skip
    p.add_argument(
        "--foxglove-host",
        default="127.0.0.1",
        help="the address the live view listens on (default: loopback only)",
    )
    p.add_argument(
        "--foxglove-rate",
        type=float,
        default=10.0,
        help="live view: TF, calibration, force and critical structures per second (default 10)",
    )
    p.add_argument(
        "--foxglove-image-rate",
        type=float,
        help="live view: the most images per second (default: --foxglove-rate); rendering may "
        "make fewer",
    )
    p.add_argument("--seconds", type=float, help="quit after this many seconds")
    p.add_argument("--status", type=Path, help="write the status (JSON) here as it changes")
    p.add_argument("--latency-log", type=Path, help="log key-to-screen latencies (JSON lines)")
    return p.parse_known_args(argv)


@dataclass
class Orbit:
    """Mouse navigation of a camera about the point it looks at."""

    target: np.ndarray
    rotate: float = 0.005  # rad per pixel
    pan: float = 0.0005  # metres per pixel per metre of distance
    zoom: float = 0.1  # fraction of the distance per wheel step
    last: tuple | None = None
    dragging: int | None = None

    def drag(self, pose: np.ndarray, dx: float, dy: float, button: int) -> dict:
        """What a drag of (dx, dy) pixels does to a camera at `pose`: {'look_at': (eye, target,
        up)} to turn about the target (left button), else {'pose': the new pose} to pan (the
        target moves with it). Computed off the world's lock; applying it is one engine call."""
        pose = np.array(pose, dtype=float)
        eye = pose[:3, 3]
        if button == MOUSE_LEFT:
            # Turn the eye about the target: yaw about world z, pitch about the camera's x.
            offset = eye - self.target
            yaw, pitch = -dx * self.rotate, -dy * self.rotate
            offset = _rotate(offset, np.array([0.0, 0.0, 1.0]), yaw)
            offset = _rotate(offset, pose[:3, 0], pitch)
            return {"look_at": (self.target + offset, self.target, -pose[:3, 1])}
        distance = np.linalg.norm(eye - self.target)
        shift = (-dx * pose[:3, 0] - dy * pose[:3, 1]) * self.pan * distance
        self.target = self.target + shift
        pose[:3, 3] = eye + shift
        return {"pose": pose}

    def scroll(self, pose: np.ndarray, steps: float) -> np.ndarray:
        """The pose of a camera at `pose` after `steps` wheel steps towards the target."""
        pose = np.array(pose, dtype=float)
        eye = pose[:3, 3]
        pose[:3, 3] = self.target + (eye - self.target) * (1.0 - self.zoom) ** steps
        return pose


def _rotate(v: np.ndarray, axis: np.ndarray, angle: float) -> np.ndarray:
    axis = axis / np.linalg.norm(axis)
    return (
        v * math.cos(angle)
        + np.cross(axis, v) * math.sin(angle)
        + axis * np.dot(axis, v) * (1 - math.cos(angle))
    )


@dataclass
class Status:
    """What the status line shows, kept up to date by the session."""

    burr_mm: float = 0.0
    spinning: bool = False
    mode: str = "keyboard"
    critical: str = ""
    critical_mm: float = math.inf
    warning: str = ""
    fps: float = 0.0
    physics_hz: float = 0.0
    physics_p99_ms: float = 0.0
    physics_max_ms: float = 0.0
    cpu_s_per_frame: float = 0.0
    frames: int = 0
    drill_position: list = field(default_factory=list)

    def lines(self) -> list[str]:
        burr = f"burr {self.burr_mm:g} mm {'ON' if self.spinning else 'off'}"
        critical = (
            f"nearest critical: {self.critical} {self.critical_mm:.1f} mm"
            if math.isfinite(self.critical_mm)
            else "no critical structure"
        )
        rates = f"graphics {self.fps:.1f} fps | physics {self.physics_hz:.0f} Hz"
        return [f"{burr} | {self.mode} | {critical} | {rates}"]


def draw_overlay(status: Status, width: int, height: int) -> np.ndarray:
    """An RGBA image of the status line (top left) and the warning (centred, red)."""
    from PIL import Image, ImageDraw

    image = Image.new("RGBA", (width, height), (0, 0, 0, 0))
    draw = ImageDraw.Draw(image)
    font = _font(16)
    y = 8
    for line in status.lines():
        box = draw.textbbox((10, y), line, font=font)
        draw.rectangle((box[0] - 4, box[1] - 3, box[2] + 4, box[3] + 3), fill=(0, 0, 0, 140))
        draw.text((10, y), line, font=font, fill=(255, 255, 255, 255))
        y = box[3] + 8
    if status.warning:
        big = _font(28)
        box = draw.textbbox((0, 0), status.warning, font=big)
        x = (width - (box[2] - box[0])) // 2
        top = height // 2 - 20
        draw.rectangle((x - 10, top - 8, x + box[2] - box[0] + 10, top + box[3] - box[1] + 12),
                       fill=(150, 0, 0, 170))  # fmt: skip
        draw.text((x, top), status.warning, font=big, fill=(255, 255, 255, 255))
    return np.asarray(image)


_fonts: dict = {}


def _font(size: int):
    from PIL import ImageFont

    if size not in _fonts:
        try:
            _fonts[size] = ImageFont.load_default(size)
        except TypeError:  # Pillow < 10.1 has one bitmap size
            _fonts[size] = ImageFont.load_default()
    return _fonts[size]


class Session:
    """A loaded launch file, its drill bound to a keyboard device, and its real-time loop."""

    def __init__(self, args: argparse.Namespace, plugin_args: list[str]) -> None:
        launch = args.launch or args.launch_file
        if launch is None:
            raise SystemExit("ambfplus-launch: give a launch file (positional or --launch_file)")
        extra = [Path(p) for p in args.load_multibody_files.split(",") if p] if (
            args.load_multibody_files
        ) else []  # fmt: skip
        # The original keeps its anatomy's names beside its launch file; the drilling plugin
        # reads them from --labels.
        labels = Path(launch).parent / "labels.csv"
        if "--labels" not in plugin_args and labels.is_file():
            plugin_args = plugin_args + ["--labels", str(labels.resolve())]
        self.sim = Simulator.from_launch(
            launch,
            models=args.load_multibodies,
            extra=extra,
            devices=args.load_devices or [],
            namespace_prefix=args.ns,
            time_step=1.0 / args.phx_frequency,
            plugins=[p for p in args.plugins.split(",") if p],
            arguments=plugin_args,
        )
        for file, message in self.sim.load_report.errors:
            print(f"error: {file}: {message}", file=sys.stderr)
        self.world = self.sim.world
        cameras = self.world.cameras
        if args.camera:
            self.camera = self.world[args.camera]
        elif cameras:
            self.camera = cameras[0]
        else:
            raise SystemExit(f"ambfplus-launch: {launch} has no camera to show")
        self.drill = self.world.drills[0] if self.world.drills else None
        self.keyboard = KeyboardDevice()
        self.device, self.device_name = make_device(args, self.keyboard)
        self.binding = None
        self.spec = {
            "builder": "launch",
            "params": {
                "file": str(Path(launch).resolve()),
                "models": args.load_multibodies,
                "extra": [str(p.resolve()) for p in extra],
                "namespace_prefix": args.ns,
                "plugins": [p for p in args.plugins.split(",") if p],
                "arguments": plugin_args,
                "time_step": 1.0 / args.phx_frequency,
            },
        }
        self.device_options = {
            "reference": self.camera.name,
            "drill_button": 0,
            "clutch_button": 1,
            "burr_button": 2,
        }
        if self.drill is not None:
            options = dict(self.device_options, reference=self.camera)
            # Named "keyboard" whatever drives it: the name replay looks for (scenes.launch_scene).
            self.binding = self.world.add_input_device("keyboard", self.device, self.drill,
                                                       **options)  # fmt: skip
        self.initial_goal = self.drill.goal.copy() if self.drill is not None else None
        self.loop = RealTimeLoop(self.world, rate=args.phx_frequency)
        self.recorder = None
        if args.record is not None:
            self.start_recording(args.record)
        self.live = None
        self.live_options = None
        if args.foxglove is not None:
            self.live_options = {"port": args.foxglove, "host": args.foxglove_host,
                                 "rate": args.foxglove_rate,
                                 "image_rate": args.foxglove_image_rate}  # fmt: skip

    def start_live(self) -> None:
        """Starts the Foxglove live view (--foxglove), once the real-time loop runs."""
        if self.live_options is None:
            return
        from .export import MissingExtra
        from .export.live import FoxgloveServer

        try:
            self.live = FoxgloveServer(self.world, [self.camera], drill=self.drill,
                                       **self.live_options).start()  # fmt: skip
        except (MissingExtra, RuntimeError) as error:
            raise SystemExit(f"ambfplus-launch: --foxglove: {error}") from None
        print(f"ambfplus-launch: live view on {self.live.url}: TF, force and critical "
              f"structures at {self.live.rate:g} Hz, images at up to {self.live.image_rate:g} "
              "Hz as rendering allows (Foxglove: open a WebSocket connection)",
              flush=True)  # fmt: skip

    def stop_live(self) -> None:
        if self.live is not None:
            self.live.stop()
            self.live = None

    def start_recording(self, path: Path) -> None:
        from .recording import Recorder

        logged = [self.camera] + ([self.drill, self.binding] if self.drill is not None else [])
        self.world.start_step_log(logged)
        meta = {
            "scene": self.spec,
            "device": {
                "name": "keyboard",
                "kind": type(self.device).__name__,
                "source": self.device_name,
                "options": self.device_options,
            },  # fmt: skip
            "camera": self.camera.name,
            "launcher": {"version": __version__},
        }
        self.recorder = Recorder(path, metadata=meta)
        self.recorder.set_legend(self.world)

    def drain(self) -> None:
        """Hands what the steps logged to the recorder."""
        if self.recorder is None:
            return
        from .scenes import drain

        drain(self.world, self.drill, self.recorder)

    def reset_volumes(self) -> None:
        with self.world.lock():
            for volume in self.world.volumes:
                volume.data.reset()

    def reset_world(self) -> None:
        """Volumes back to their start, the drill to its first pose, plugins reset."""
        with self.world.lock():
            for volume in self.world.volumes:
                volume.data.reset()
            if self.drill is not None:
                self.drill.goal = self.initial_goal
            self.world.reset_plugins()

    def status(self, status: Status, fps: float) -> Status:
        s = self.loop.stats
        status.fps = fps
        status.physics_hz = s["mean_rate"]
        status.physics_p99_ms = s["p99"] * 1e3
        status.physics_max_ms = s["max"] * 1e3
        if self.drill is None:
            status.mode = "no drill"
            return status
        status.mode = "clutch" if self.binding.clutched else self.device_name
        status.burr_mm = self.drill.burr_diameters[self.drill.burr] * 1000
        status.spinning = self.drill.on
        status.drill_position = self.drill.cursor_proxies[0].round(6).tolist()
        distances = self.drill.critical_distances
        if distances:
            name, distance = min(distances.items(), key=lambda kv: kv[1])
            status.critical, status.critical_mm = name, distance * 1000
        events = self.drill.events
        cut = [e for e in events if e["kind"] == "critical"]
        if cut or status.critical_mm < WARN_DISTANCE * 1000:
            status.warning = f"WARNING! {status.critical} {status.critical_mm:.1f} mm"
        else:
            status.warning = ""
        return status


def make_device(args: argparse.Namespace, keyboard: KeyboardDevice) -> tuple[Device, str]:
    """The device --device names (its buttons merged with the keyboard's and --pedal's), and
    how the status line names it."""
    kind, _, where = args.device.partition(":")
    if kind == "keyboard" and not where:
        pose: Device = keyboard
    elif kind == "network":
        try:
            pose = NetworkDevice(int(where) if where else 0)
        except ValueError as error:
            raise SystemExit(f"ambfplus-launch: --device {args.device}: {error}") from None
        except RuntimeError as error:
            raise SystemExit(f"ambfplus-launch: {error}") from None
        print(f"ambfplus-launch: network device on 127.0.0.1:{pose.port} (UDP)", flush=True)
        kind = f"network :{pose.port}"
    elif kind == "joystick":
        pose = _joystick(where or "/dev/input/js0")
    else:
        raise SystemExit(
            f"ambfplus-launch: --device is keyboard, network[:PORT] or joystick[:PATH], got "
            f"'{args.device}'"
        )
    buttons = [] if pose is keyboard else [keyboard]
    if args.pedal:
        buttons.append(_joystick(args.pedal, pedal_mapping(args.pedal_map)))
        kind += " + pedal"
    return (MergedDevice(pose, buttons) if buttons else pose), kind


def pedal_mapping(text: str) -> JoystickMapping:
    """--pedal-map: "drill=0,clutch=1,burr=2" (a role left out: no button); no axes."""
    roles = {"drill": -1, "clutch": -1, "burr": -1}
    for item in text.replace(" ", "").split(","):
        role, _, number = item.partition("=")
        if role not in roles or not number.lstrip("-").isdigit():
            raise SystemExit(
                f"ambfplus-launch: --pedal-map takes drill=N,clutch=N,burr=N, got '{text}'"
            )
        roles[role] = int(number)
    return JoystickMapping(**roles, axes=(-1, -1, -1))


def _joystick(path: str, mapping: JoystickMapping | None = None) -> JoystickDevice:
    try:
        return JoystickDevice(path, mapping or JoystickMapping())
    except AssetNotFound as error:
        raise SystemExit(f"ambfplus-launch: {error.strerror}") from None


def run(argv: list[str] | None = None) -> int:
    args, plugin_args = parse_args(argv)
    if not args.show_gui:
        return run_headless(args, plugin_args)
    try:
        import glfw
    except ImportError:
        print("ambfplus-launch needs GLFW for its window: pip install 'ambfplus[gui]' (or run "
              "headless with -g false)", file=sys.stderr)  # fmt: skip
        return 2
    if not glfw.init():
        print("ambfplus-launch: GLFW cannot open a display (is DISPLAY set? run headless with "
              "-g false)", file=sys.stderr)  # fmt: skip
        return 2
    try:
        return run_window(glfw, args, plugin_args)
    finally:
        glfw.terminate()


def run_headless(args: argparse.Namespace, plugin_args: list[str]) -> int:
    """The real-time session without a window (until --seconds or Ctrl+C)."""
    session = Session(args, plugin_args)
    started = time.perf_counter()
    try:
        with session.loop:
            print(f"ambfplus-launch: headless; physics: {session.loop.scheduling}", flush=True)
            session.start_live()
            while args.seconds is None or time.perf_counter() - started < args.seconds:
                time.sleep(0.1)
                session.drain()
    except KeyboardInterrupt:
        pass
    finally:
        session.stop_live()
        session.drain()
        if session.recorder is not None:
            session.recorder.close()
    return 0


def run_window(glfw, args: argparse.Namespace, plugin_args: list[str]) -> int:
    use_x11_display(ctypes.cast(glfw.get_x11_display(), ctypes.c_void_p).value)
    session = Session(args, plugin_args)
    world, camera = session.world, session.camera
    views = Views(session, args)
    for note in views.notes:
        print(f"ambfplus-launch: {note}", flush=True)
    glfw.window_hint(glfw.CLIENT_API, glfw.NO_API)
    window_size = views.window_size(args)
    window = glfw.create_window(*window_size, "ambfplus", None, None)
    if not window:
        print("ambfplus-launch: GLFW could not create a window", file=sys.stderr)
        return 2
    lens = views.lens()
    if lens is not None:
        _window_of(window).set_lens(**lens)
    target = camera.pose[:3, 3] + camera.pose[:3, 2] * _look_distance(session)
    orbit = Orbit(target)
    status = Status()
    pending_keys: list[tuple[float, int]] = []  # (time, step) of keys not yet on screen
    latency_log = open(args.latency_log, "w") if args.latency_log else None  # noqa: SIM115

    def on_key(_window, key, scancode, action, mods):
        if action == PRESS and (key == KEY_ESCAPE or (key == KEY_Q and not mods)):
            glfw.set_window_should_close(window, True)
            return
        if action == PRESS and key == KEY_N and mods == MOD_CONTROL:
            session.reset_volumes()
        elif action == PRESS and key == KEY_R and mods == MOD_ALT:
            session.reset_world()
        if session.keyboard.key(key, action, mods) and action != RELEASE:
            pending_keys.append((time.perf_counter(), world.step_index))
        world.keyboard(key, scancode, action, mods)

    def on_button(_window, button, action, mods):
        if action == PRESS:
            orbit.dragging = MOUSE_RIGHT if (button == MOUSE_LEFT and mods & MOD_SHIFT) else button
            orbit.last = glfw.get_cursor_pos(window)
        elif action == RELEASE:
            orbit.dragging = None
        world.mouse_button(button, action, mods)

    # The camera's moves are worked out off the world's lock, from a pose read in one engine
    # call, and applied in one: Python under the lock may lose the GIL to another thread, and the
    # physics loop would wait for that thread.
    def camera_pose():
        return world.read_state([camera])["objects"][0]["pose"]

    def on_move(_window, x, y):
        if orbit.dragging is not None and orbit.last is not None:
            move = orbit.drag(camera_pose(), x - orbit.last[0], y - orbit.last[1], orbit.dragging)
            turn = move.get("look_at")
            with world.lock():
                if turn is not None:
                    camera.look_at(*turn)
                else:
                    camera.pose = move["pose"]
            orbit.last = (x, y)
        world.mouse_move(x, y)

    def on_scroll(_window, dx, dy):
        pose = orbit.scroll(camera_pose(), dy)
        with world.lock():
            camera.pose = pose
        world.mouse_scroll(dx, dy)

    glfw.set_key_callback(window, on_key)
    glfw.set_mouse_button_callback(window, on_button)
    glfw.set_cursor_pos_callback(window, on_move)
    glfw.set_scroll_callback(window, on_scroll)

    started = time.perf_counter()
    frame_times: list[float] = []
    last_status: dict | None = None
    cpu_started: float | None = None  # process CPU time at the first frame
    # A first frame before the clock starts: uploading the anatomy whole takes far longer than a
    # physics period, and would stall the loop.
    width, height = glfw.get_framebuffer_size(window)
    views.show(_window_of(window), width, height)
    with session.loop:
        print(f"ambfplus-launch: {camera.name} in a {window_size[0]}x{window_size[1]} window "
              f"({views.mode}); physics: {session.loop.scheduling}", flush=True)  # fmt: skip
        session.start_live()
        while not glfw.window_should_close(window):
            glfw.poll_events()
            now = time.perf_counter()
            if args.seconds is not None and now - started > args.seconds:
                break
            fps = (
                len(frame_times) / (frame_times[-1] - frame_times[0]) if len(frame_times) > 1 else 0
            )
            session.status(status, fps)
            width, height = glfw.get_framebuffer_size(window)
            overlay = draw_overlay(status, width, height)
            shown = views.show(_window_of(window), width, height, overlay)
            shown_at = time.perf_counter()
            status.frames += 1
            # CPU per frame of the whole process (rendering threads, physics and all).
            if cpu_started is None:
                cpu_started = time.process_time()
            elif status.frames > 1:
                status.cpu_s_per_frame = (time.process_time() - cpu_started) / (status.frames - 1)
            frame_times = (frame_times + [shown_at])[-30:]
            # A key is on screen once a frame of a later step than its own is shown.
            step = shown[0]["step"]
            for when, key_step in [k for k in pending_keys if step > k[1]]:
                pending_keys.remove((when, key_step))
                if latency_log is not None:
                    latency_log.write(json.dumps({"latency_s": shown_at - when}) + "\n")
                    latency_log.flush()
            session.drain()
            if args.status is not None:
                current = {**status.__dict__, "step": step,
                           "stereo": views.describe(width, height)}  # fmt: skip
                if current != last_status:
                    # Atomically: whoever reads the status never sees it half written.
                    write_text(args.status, json.dumps(current))
                    last_status = current
    session.stop_live()
    session.drain()
    if session.recorder is not None:
        session.recorder.close()
    if latency_log is not None:
        latency_log.close()
    return 0


_windows: dict = {}


def _window_of(window) -> Window:
    """The engine's window on GLFW's X11 window (made once)."""
    import glfw

    key = id(window)
    if key not in _windows:
        _windows[key] = Window(glfw.get_x11_window(window))
    return _windows[key]


def _view_of(world, camera, width: int, height: int, name: str, x: float = 0.0):
    """A camera riding on `camera` (x metres along its x axis) with its optics at the window's
    size (a camera's own size is what it publishes; the window shows its view at the
    window's)."""
    offset = np.eye(4)
    offset[0, 3] = x
    with world.lock():
        view = world.add_camera(
            name, width, height, fov_y=camera.fov_y, near=camera.near, far=camera.far
        )
        view.attach_to(camera, offset)
        view.pose = camera.pose @ offset
    return view


class Views:
    """What the window shows (--stereo): the camera; a stereo pair riding on it, side by side; or
    a head-mounted display's eyes, turned by the head and seen through its lenses."""

    def __init__(self, session: Session, args: argparse.Namespace) -> None:
        self.world, self.camera = session.world, session.camera
        self.mode = args.stereo
        self.notes: list[str] = []
        self.hmd = None
        self.xr = None  # an OpenXR session
        self.xr_view: XrView | None = None
        if self.mode == "openxr":
            try:
                self.xr = OpenXrSession("ambfplus-launch")
                self.xr_view = XrView(self.world, self.camera, name=f"{self.camera.name}_xr")
                self.notes.append(f"OpenXR: {self.xr.system} on {self.xr.runtime}")
            except RenderError as error:
                self.notes.append(f"{error}; using OpenHMD")
                self.mode = "hmd"
        if self.mode == "hmd":
            try:
                self.hmd = OpenHMD()
                self.notes.append(f"head-mounted display: {self.hmd.name}")
            except HmdError as error:
                self.notes.append(f"{error}; showing side-by-side stereo instead")
                self.mode = "side-by-side"
        self.ipd = args.ipd if args.ipd is not None else self._default_ipd()
        if not self.ipd > 0:
            raise SystemExit(f"ambfplus-launch: --ipd must be > 0 m, got {self.ipd}")
        self.convergence = args.convergence
        self.look_distance = _look_distance(session)
        self._views: dict[tuple[int, int], list] = {}
        self._hmd_views: dict[tuple[int, int], HmdView] = {}

    def _default_ipd(self) -> float:
        """The HMD's; else the baseline of the scene's stereo pair (stereoL and stereoR, as the
        original's drilling scene has); else 65 mm."""
        if self.hmd is not None:
            return self.hmd.ipd
        if "stereoL" in self.world and "stereoR" in self.world:
            try:
                return StereoRig.from_cameras(self.world["stereoL"], self.world["stereoR"]).baseline
            except ValueError:
                pass
        return 0.065

    def window_size(self, args: argparse.Namespace) -> tuple[int, int]:
        if self.xr is not None:
            # The eyes side by side, at most 1536 pixels wide.
            (w0, h0), (w1, _) = self.xr.eye_sizes
            shrink = min(1.0, 1536 / (w0 + w1))
            default = (int((w0 + w1) * shrink), int(h0 * shrink))
        elif self.hmd is not None:
            eye_width, eye_height = self.hmd.eye_resolution
            default = (2 * eye_width, eye_height)
        else:
            default = (1536, 540)
        return args.width or default[0], args.height or default[1]

    def lens(self) -> dict | None:
        return self.hmd.lens() if self.hmd is not None else None

    def show(self, window: Window, width: int, height: int, overlay=None) -> list[dict]:
        """Shows a frame: in the window, and with OpenXR in the headset (the window then mirrors
        the eyes without rendering them again). The frames shown, each with its step."""
        xr = self.xr
        if xr is not None:
            xr.poll_events()
            if xr.running:
                eyes = xr.wait_frame()
                cameras = self.xr_view.update(eyes) if eyes else []
                frames = xr.end_frame(cameras)
                if frames:
                    window.present(cameras, width, height, overlay, rendered=True)
                    return frames
        return window.present(self.cameras(width, height), width, height, overlay)

    def cameras(self, width: int, height: int) -> list:
        """The cameras shown left to right in a window of this size (made once per size); an
        HMD's eyes turned to where the head now looks; an OpenXR session's eyes as they were
        last (it is not running)."""
        if self.xr_view is not None and self.xr_view.cameras:
            return self.xr_view.cameras
        key = (width, height)
        if key not in self._views:
            self._views[key] = self._make(width, height, len(self._views))
        if key in self._hmd_views:
            with self.world.lock():
                self._hmd_views[key].update()
        return self._views[key]

    def _make(self, width: int, height: int, index: int) -> list:
        camera, world = self.camera, self.world
        name = f"{camera.name}_window{index}"
        if self.mode in ("off", "openxr"):
            return [_view_of(world, camera, width, height, name)]
        if self.mode == "hmd":
            with world.lock():
                view = HmdView(world, self.hmd, camera, name=name,
                               scale=(width // 2) / self.hmd.eye_resolution[0])  # fmt: skip
            self._hmd_views[(width, height)] = view
            return view.cameras
        # Side by side: each eye half the window, half the IPD either side of the camera.
        left = _view_of(world, camera, width // 2, height, f"{name}_left", -self.ipd / 2)
        right = _view_of(world, camera, width - width // 2, height, f"{name}_right", self.ipd / 2)
        convergence = self.look_distance if self.convergence is None else self.convergence
        if convergence > 0:
            with world.lock():
                StereoRig.from_cameras(left, right).set_working_distance(convergence)
        return [left, right]

    def describe(self, width: int, height: int) -> dict:
        """The views' geometry, for the status file: mode, IPD, each eye's focal length and
        principal point, and (side by side) the zero-disparity depth."""
        cameras = (self.xr_view.cameras if self.xr_view is not None else None) or (
            self._views.get((width, height)) or self.cameras(width, height)
        )
        out = {"mode": self.mode, "ipd": self.ipd, "views": len(cameras)}
        if self.hmd is not None:
            out["hmd"] = self.hmd.name
            out["head"] = [float(v) for v in self.hmd.rotation]
        if self.xr is not None:
            out["openxr"] = {"runtime": self.xr.runtime, "system": self.xr.system,
                             "state": self.xr.state, "frames": self.xr.frames}  # fmt: skip
            if len(cameras) == 2:  # the eyes' distance, as the runtime places them
                out["ipd"] = float(np.linalg.norm(cameras[1].pose[:3, 3] - cameras[0].pose[:3, 3]))
        out["eyes"] = [
            {
                "name": c.name,
                "size": [c.width, c.height],
                "focal": float(c.intrinsics[0, 0]),
                "principal_point": [float(v) for v in c.principal_point],
            }
            for c in cameras
        ]
        if self.mode == "side-by-side":
            out["convergence"] = self.look_distance if self.convergence is None else (
                self.convergence
            )  # fmt: skip
        return out


def _look_distance(session: Session) -> float:
    """How far the camera looks: to the first volume surface on its axis, else 0.3 m."""
    pose = session.camera.pose
    for volume in session.world.volumes:
        hit = volume.raycast(pose[:3, 3], pose[:3, 2])
        if hit is not None:
            return float(hit["distance"])
    return 0.3


def main() -> None:
    sys.exit(run())


if __name__ == "__main__":
    main()
