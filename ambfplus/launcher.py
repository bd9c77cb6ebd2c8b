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

from . import KeyboardDevice, RealTimeLoop, Simulator, __version__
from ._core import Window, use_x11_display

# GLFW's codes for the keys and buttons the launcher handles itself.
KEY_ESCAPE, KEY_Q, KEY_N, KEY_R = 256, 81, 78, 82
MOD_SHIFT, MOD_CONTROL, MOD_ALT = 0x1, 0x2, 0x4
PRESS, RELEASE = 1, 0
MOUSE_LEFT, MOUSE_RIGHT = 0, 1
# How close a critical structure may come before the status warns, metres.
WARN_DISTANCE = 0.002


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
    p.add_argument("--width", type=int, default=1536)
    p.add_argument("--height", type=int, default=540)
    p.add_argument("--record", type=Path, help="record the session to this HDF5 file")
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

    def drag(self, camera, dx: float, dy: float, button: int) -> None:
        pose = camera.pose.copy()
        eye = pose[:3, 3]
        if button == MOUSE_LEFT:
            # Turn the eye about the target: yaw about world z, pitch about the camera's x.
            offset = eye - self.target
            yaw, pitch = -dx * self.rotate, -dy * self.rotate
            offset = _rotate(offset, np.array([0.0, 0.0, 1.0]), yaw)
            offset = _rotate(offset, pose[:3, 0], pitch)
            camera.look_at(self.target + offset, self.target, up=-pose[:3, 1])
        else:
            distance = np.linalg.norm(eye - self.target)
            shift = (-dx * pose[:3, 0] - dy * pose[:3, 1]) * self.pan * distance
            self.target = self.target + shift
            pose[:3, 3] = eye + shift
            camera.pose = pose

    def scroll(self, camera, steps: float) -> None:
        pose = camera.pose.copy()
        eye = pose[:3, 3]
        pose[:3, 3] = self.target + (eye - self.target) * (1.0 - self.zoom) ** steps
        camera.pose = pose


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
            "clutch_button": -1,
            "burr_button": 2,
        }
        if self.drill is not None:
            options = dict(self.device_options, reference=self.camera)
            self.binding = self.world.add_input_device("keyboard", self.keyboard, self.drill,
                                                       **options)  # fmt: skip
        self.initial_goal = self.drill.goal.copy() if self.drill is not None else None
        self.loop = RealTimeLoop(self.world, rate=args.phx_frequency)
        self.recorder = None
        if args.record is not None:
            self.start_recording(args.record)

    def start_recording(self, path: Path) -> None:
        from .recording import Recorder

        logged = [self.camera] + ([self.drill, self.binding] if self.drill is not None else [])
        self.world.start_step_log(logged)
        meta = {
            "scene": self.spec,
            "device": {
                "name": "keyboard",
                "kind": "KeyboardDevice",
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
        from .session import _drain

        _drain(self.world, self.drill, self.recorder)

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
            while args.seconds is None or time.perf_counter() - started < args.seconds:
                time.sleep(0.1)
                session.drain()
    except KeyboardInterrupt:
        pass
    finally:
        session.drain()
        if session.recorder is not None:
            session.recorder.close()
    return 0


def run_window(glfw, args: argparse.Namespace, plugin_args: list[str]) -> int:
    glfw.window_hint(glfw.CLIENT_API, glfw.NO_API)
    window = glfw.create_window(args.width, args.height, "ambfplus", None, None)
    if not window:
        print("ambfplus-launch: GLFW could not create a window", file=sys.stderr)
        return 2
    use_x11_display(ctypes.cast(glfw.get_x11_display(), ctypes.c_void_p).value)
    session = Session(args, plugin_args)
    world, camera = session.world, session.camera
    views: dict[tuple[int, int], object] = {}  # the camera seen at each window size
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

    def on_move(_window, x, y):
        if orbit.dragging is not None and orbit.last is not None:
            with world.lock():
                orbit.drag(camera, x - orbit.last[0], y - orbit.last[1], orbit.dragging)
            orbit.last = (x, y)
        world.mouse_move(x, y)

    def on_scroll(_window, dx, dy):
        with world.lock():
            orbit.scroll(camera, dy)
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
    views[(width, height)] = _view_of(world, camera, width, height, 0)
    _window_of(window).present([views[(width, height)]], width, height)
    with session.loop:
        print(f"ambfplus-launch: {camera.name} in a {args.width}x{args.height} window; "
              f"physics: {session.loop.scheduling}", flush=True)  # fmt: skip
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
            if (width, height) not in views:
                views[(width, height)] = _view_of(world, camera, width, height, len(views))
            overlay = draw_overlay(status, width, height)
            shown = _window_of(window).present([views[(width, height)]], width, height, overlay)
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
                current = {**status.__dict__, "step": step}
                if current != last_status:
                    args.status.write_text(json.dumps(current))
                    last_status = current
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


def _view_of(world, camera, width: int, height: int, index: int):
    """A camera riding on `camera` with its optics at the window's size (a camera's own size is
    what it publishes; the window shows its view at the window's)."""
    with world.lock():
        view = world.add_camera(
            f"{camera.name}_window{index}", width, height, fov_y=camera.fov_y, near=camera.near,
            far=camera.far,
        )  # fmt: skip
        view.attach_to(camera, np.eye(4))
        view.pose = camera.pose
    return view


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
