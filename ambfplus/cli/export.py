"""``ambfplus export``: a recording or a dataset folder to MCAP, rosbag2, the original's HDF5
layout or COCO."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any


def add_parser(commands) -> None:
    """Declares ``ambfplus export``, its options and the function that runs it."""
    exporter = commands.add_parser(
        "export",
        help="export a recording or a dataset folder to MCAP or rosbag2 (ROS 2 messages), the "
        "original system's HDF5 layout or COCO masks",
    )
    exporter.add_argument("source", type=Path, help="a recording (name.h5) or a dataset folder")
    exporter.add_argument("--to", required=True, metavar="FORMAT",
                          help="mcap, rosbag2, original-h5 or coco")  # fmt: skip
    exporter.add_argument("out", type=Path, help="the output file (mcap) or folder")
    exporter.add_argument("--force", action="store_true", help="replace an existing output")
    exporter.add_argument("--quiet", action="store_true", help="no progress bar")
    exporter.add_argument("--verbose", action="store_true", help="print message counts")
    exporter.add_argument("--no-points", action="store_true",
                          help="mcap/rosbag2: no point clouds")  # fmt: skip
    exporter.add_argument("--compression", default="zstd", choices=("zstd", "lz4", "none"),
                          help="mcap: chunk compression")  # fmt: skip
    exporter.add_argument("--image-topics", default="raw", choices=("raw", "compressed", "both"),
                          help="mcap/rosbag2: sensor_msgs/Image topics, CompressedImage topics "
                          "(<topic>/compressed: PNG or TIFF, lossless) or both")  # fmt: skip
    exporter.add_argument("--rgb-codec", default="png", choices=("png", "jpeg"),
                          help="mcap/rosbag2: compressed rgb as png or jpeg (lossy)")  # fmt: skip
    exporter.add_argument("--jpeg-quality", type=int, default=90,
                          help="mcap/rosbag2: JPEG quality 1..100 (default 90)")  # fmt: skip
    exporter.add_argument("--depth-no-hit", default="nan", choices=("nan", "zero"),
                          help="mcap/rosbag2: depth where nothing was hit: NaN (REP 118, the "
                          "default) or 0 as recorded")  # fmt: skip
    exporter.add_argument("--stamp", default="sim", choices=("sim", "wall"),
                          help="mcap/rosbag2: stamps and log times in simulation time (the "
                          "default) or wall-clock time (the recording's start + simulation "
                          "time)")  # fmt: skip
    exporter.add_argument("--chunk-size", type=int, default=500,
                          help="original-h5: samples per file (the original's 500)")  # fmt: skip
    exporter.add_argument("--no-images", action="store_true",
                          help="coco: annotations only, no PNG frames")  # fmt: skip
    exporter.add_argument("--skip-bad-frames", action="store_true",
                          help="leave out (and count) frames and step rows whose values are "
                          "not valid (NaN or negative depth, a pose that is not rigid, an id "
                          "not in the legend, ...) instead of refusing the export")  # fmt: skip
    exporter.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Exports a recording or a dataset folder (errors reach the CLI's one error path)."""
    from ..export import export

    options: dict[str, Any] = {"bad_frames": "skip" if args.skip_bad_frames else "refuse"}
    if args.to in ("mcap", "rosbag2"):
        options["point_clouds"] = not args.no_points
        options["image_topics"] = args.image_topics
        options["rgb_codec"] = args.rgb_codec
        options["jpeg_quality"] = args.jpeg_quality
        options["depth_no_hit"] = args.depth_no_hit
        options["stamp"] = args.stamp
    if args.to == "mcap":
        options["compression"] = None if args.compression == "none" else args.compression
    if args.to == "original-h5":
        options["chunk_size"] = args.chunk_size
    if args.to == "coco":
        options["images"] = not args.no_images
    results = export(args.source, args.out, args.to, force=args.force,
                     progress=False if args.quiet else None, **options)  # fmt: skip
    results = results if isinstance(results, list) else [results]
    for result in results:
        line = result.to_dict()
        if not args.verbose:
            line.pop("topics", None)
            line.pop("messages", None)
        print(json.dumps(line))
    return 0
