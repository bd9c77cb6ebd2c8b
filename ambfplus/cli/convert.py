"""``ambfplus convert``: anatomy volumes between NRRD, slice stacks with their ADF, and surface
meshes."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..volumes import convert_volume
from .values import number, within


def add_parser(commands) -> None:
    """Declares ``ambfplus convert``, its options and the function that runs it."""
    convert = commands.add_parser(
        "convert",
        help="convert anatomy volumes: NRRD/Slicer segmentation -> slice stack + volume ADF, "
        "slice stack or ADF -> NRRD, any -> surface mesh (.stl/.ply)",
    )
    convert.add_argument(
        "input", type=Path, help=".nrrd, .seg.nrrd, a volume ADF (.yaml) or a slice folder"
    )
    convert.add_argument(
        "output", type=Path, help="a folder (slice stack + ADF), .nrrd, .stl or .ply"
    )
    convert.add_argument("--prefix", default="plane00", help="slice file prefix")
    convert.add_argument("--labels", type=Path, help="label table (CSV/YAML) for slices")
    size = convert.add_mutually_exclusive_group()
    size.add_argument(
        "--dimensions",
        type=number(0, above=True),
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="a slice folder's size, metres",
    )
    size.add_argument(
        "--voxel-size",
        type=number(0, above=True),
        nargs=3,
        metavar=("X", "Y", "Z"),
        help="a slice folder's voxel size, metres",
    )
    convert.add_argument(
        "--threshold", type=number(-math.inf), help="segment an intensity NRRD at this value"
    )
    convert.add_argument(
        "--label",
        type=within(0, 65535),
        default=0,
        help="mesh only this label id (default: every solid voxel)",
    )
    convert.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Converts an anatomy volume and prints what it wrote."""
    summary = convert_volume(
        args.input,
        args.output,
        prefix=args.prefix,
        labels=args.labels,
        dimensions=args.dimensions,
        voxel_size=args.voxel_size,
        threshold=args.threshold,
        label=args.label,
    )
    print(summary)
    return 0
