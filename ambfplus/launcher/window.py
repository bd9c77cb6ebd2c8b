"""The session in a GLFW window: keys and mouse, the views, the status overlay and file."""

from __future__ import annotations

import argparse
import ctypes
import json
import sys
import time

from .._core import Window, use_x11_display
from ..fileio import write_text
from .navigation import MOUSE_LEFT, MOUSE_RIGHT, Orbit
from .session import LaunchSession
from .status import Status, draw_overlay
from .views import Views, look_distance

# GLFW's codes for the keys and buttons the launcher handles itself.
KEY_ESCAPE, KEY_Q, KEY_N, KEY_R, KEY_G, KEY_M = 256, 81, 78, 82, 71, 77
MOD_SHIFT, MOD_CONTROL, MOD_ALT = 0x1, 0x2, 0x4
PRESS, RELEASE = 1, 0


def run_window(glfw, args: argparse.Namespace, plugin_args: list[str]) -> int:
    display = ctypes.cast(glfw.get_x11_display(), ctypes.c_void_p).value
    if display is None:
        raise SystemExit("ambfplus-launch: GLFW has no X11 display to render on")
    use_x11_display(display)
    session = LaunchSession(args, plugin_args)
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
    target = camera.pose[:3, 3] + camera.pose[:3, 2] * look_distance(session)
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
        elif action == PRESS and key == KEY_G and mods == MOD_CONTROL:
            session.toggle_fixtures()
        elif action == PRESS and key == KEY_M and mods == MOD_CONTROL:
            session.toggle_mute()
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
    session.finish()
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
