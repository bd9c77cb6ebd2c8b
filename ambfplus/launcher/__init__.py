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
  Ctrl+G turns the virtual fixtures (``--fixtures``) off and on, Ctrl+M mutes the drill's sound
  (``--audio``), Esc or Q quits;
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
bridge process over UDP on loopback, forces sent back every step; see
``ambfplus.devices.network`` and ``examples/network_bridge.py``) or ``joystick[:PATH]`` (a
gamepad's sticks); ``--pedal PATH`` adds a foot pedal's buttons (``--pedal-map
drill=0,clutch=1,burr=2``: held spins the burr, held clutches, pressed takes the next burr).
The keyboard's Space and C keep working with any device.

``--foxglove [PORT]`` serves the session live over the Foxglove WebSocket protocol (port 8765 by
default, loopback unless ``--foxglove-host`` says otherwise): TF, the camera's calibration, the
drill's force and the nearest critical structure at ``--foxglove-rate`` Hz (10 by default), and
the camera's images at up to ``--foxglove-image-rate`` Hz (the same by default), as fast as the
renderer makes them (``ambfplus.export.live``; needs ``ambfplus[foxglove]``).

The status line shows the burr, whether it spins, the control mode, the distance to the nearest
critical structure (a warning under 2 mm or when one is cut), and the graphics and physics
rates. ``--record`` writes the session (every step's drill state, the keyboard's readings and
the camera's pose; removed voxels; events), which ``ambfplus replay`` re-simulates exactly.

Modules: ``options`` (the command line), ``session`` (the launched session), ``inputs`` (the
drill's devices), ``views`` (what the window shows), ``navigation`` (the mouse), ``status``
(the status line), ``window`` (the GLFW loop) and ``app`` (headless or windowed).
"""

from .app import main
from .options import build_parser

__all__ = ["build_parser", "main"]
