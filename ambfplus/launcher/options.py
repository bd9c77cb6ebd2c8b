"""``ambfplus-launch``'s options: AMBF's simulator options plus ambfplus's."""

from __future__ import annotations

import argparse
from pathlib import Path

DESCRIPTION = (
    "ambfplus-launch: an interactive training session in a window, AMBF's simulator command."
)
STEREO_MODES = ("off", "side-by-side", "hmd", "openxr")


def build_parser() -> argparse.ArgumentParser:
    """AMBF's simulator options plus ambfplus's (``parse_args`` leaves the rest to simulator
    plugins)."""

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

    p = argparse.ArgumentParser(prog="ambfplus-launch", description=DESCRIPTION)
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
    p.add_argument("--shadows", type=boolean, default=True,
                   help="shadows of the lights with a 'shadow quality' in what the cameras show "
                   "and record (default true)")  # fmt: skip
    p.add_argument("--looks", type=boolean, default=True,
                   help="volumes' ambient occlusion, bone texture and wet highlights in what the "
                   "cameras show and record (default true)")  # fmt: skip
    p.add_argument(
        "--antialiasing",
        type=int,
        default=2,
        choices=range(1, 5),
        metavar="K",
        help="supersample the cameras' rgb at edges: 1 = off, 2 = centre and corners, "
        "3 or 4 = K x K grid (default 2)",
    )
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
    p.add_argument("--task", help="a training task (YAML file, or cortical_mastoidectomy / "
                   "facial_recess on the built-in phantom): its metrics live on screen (time, "
                   "burr, force, the nearest protected structure, violations)")  # fmt: skip
    p.add_argument("--report", type=Path, help="with --task: write the debrief report (HTML) "
                   "here when the session ends (the session is recorded beside it unless "
                   "--record names a file)")  # fmt: skip
    p.add_argument("--metrics", type=Path, help="with --task: write the live metrics (JSON) "
                   "here when the session ends")  # fmt: skip
    p.add_argument("--fixtures", nargs="?", const="task", metavar="FILE",
                   help="virtual fixtures on the drill: a YAML list of {structure, start, "
                   "max_force, stop} (metres, N; a DRILL block's fixtures), or, alone, from "
                   "--task: each protected structure pushes the burr away from its margin + 1 mm "
                   "and stops it at half its margin. Ctrl+G turns them off and on")  # fmt: skip
    p.add_argument("--plan", choices=["stay", "follow"],
                   help="with --task, guidance from its target region: 'stay' holds the burr "
                   "inside it (a fixture on its boundary from 1 mm, no cutting beyond 0.3 mm), "
                   "'follow' also draws the burr toward the nearest target bone not yet removed. "
                   "Ctrl+G turns it off and on with the fixtures")  # fmt: skip
    p.add_argument("--audio", action="store_true", help="play the drill's sound (with --task, "
                   "proximity beeps from twice each structure's margin); a machine without an "
                   "audio device says so and carries on silent")  # fmt: skip
    p.add_argument(
        "--mute",
        action="store_true",
        help="start the drill's sound muted (implies --audio); Ctrl+M unmutes",
    )
    p.add_argument("--seconds", type=float, help="quit after this many seconds")
    p.add_argument("--status", type=Path, help="write the status (JSON) here as it changes")
    p.add_argument("--latency-log", type=Path, help="log key-to-screen latencies (JSON lines)")
    return p


def parse_args(argv: list[str] | None) -> tuple[argparse.Namespace, list[str]]:
    """The launcher's options, and the arguments it does not know (for simulator plugins)."""
    return build_parser().parse_known_args(argv)
