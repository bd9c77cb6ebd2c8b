"""``ambfplus generate``: a dataset from a YAML spec, with local workers or on a Ray cluster."""

from __future__ import annotations

import argparse
import atexit
import gc
from pathlib import Path

from .values import number, within


def add_parser(commands) -> None:
    """Declares ``ambfplus generate``, its options and the function that runs it."""
    generate = commands.add_parser(
        "generate",
        help="generate a dataset from a YAML spec with local workers or on a Ray cluster; "
        "running it again resumes",
    )
    generate.add_argument("spec", type=Path, help="the dataset spec (YAML)")
    generate.add_argument("--out", type=Path, required=True, help="the dataset folder")
    generate.add_argument(
        "--workers", type=within(1, 256), default=1, help="local worker processes (default 1)"
    )
    generate.add_argument(
        "--ray",
        metavar="ADDRESS",
        help="run on a Ray cluster instead: host:port, ray://host:port, auto (this machine's "
        'cluster) or local (a new one); needs pip install "ambfplus[ray]"',
    )
    generate.add_argument(
        "--ray-cpus",
        type=number(0, above=True),
        default=1.0,
        help="CPUs each Ray task asks for (default 1)",
    )
    generate.add_argument(
        "--ray-gpus",
        type=number(0),
        default=0.0,
        help="GPUs each Ray task asks for (default 0); a task given a GPU renders on it",
    )
    generate.add_argument(
        "--retries", type=within(0, 100), default=3, help="attempts after the first per episode"
    )
    generate.add_argument(
        "--timeout", type=number(0, above=True), help="seconds an episode may take"
    )
    generate.add_argument("--quiet", action="store_true", help="no progress bar")
    generate.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Generates (or resumes) a dataset from a spec; its errors (SpecError, GenerateError, ...)
    end in ``main``'s one line."""
    from ..dataset import generate

    # At exit, everything is written and closed: spare the driver the collection Python
    # runs then over every object (with Ray's modules loaded it costs about 0.3 CPU-s).
    atexit.register(gc.freeze)
    report = generate(
        args.spec, args.out, workers=args.workers, ray=args.ray, retries=args.retries,
        timeout=args.timeout, progress=not args.quiet,
        ray_options={"cpus": args.ray_cpus, "gpus": args.ray_gpus},
    )  # fmt: skip
    print(
        f"{report.folder}: {report.generated} episodes made ({report.frames} stereo pairs), "
        f"{report.skipped} already there, {report.retries} retries, {report.seconds:.1f} s; "
        f"check it with: ambfplus validate {report.folder}"
    )
    return 0
