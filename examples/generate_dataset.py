"""Generates the example dataset spec (examples/dataset_spec.yaml) into a folder with local
workers, checks it and prints its counts; then reads it back as PyTorch stereo samples if the
torch extra is installed.

    python examples/generate_dataset.py OUT [--workers 2] [--ray auto]

Running it again resumes (complete shards are kept). Workers import this script again (as
spawned processes do), which is why everything runs under the `if __name__ == "__main__":`
guard.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from ambfplus.dataset import dataset_info, format_info, generate, validate_dataset

SPEC = Path(__file__).resolve().with_name("dataset_spec.yaml")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("out", type=Path, help="output folder (the dataset goes in out/dataset)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--ray", help="a Ray address (auto, local, host:port) instead")
    args = parser.parse_args()
    folder = args.out / "dataset"
    report = generate(SPEC, folder, workers=args.workers, ray=args.ray)
    print(
        f"{report.generated} episodes made, {report.skipped} already there, "
        f"{report.retries} retries, {report.seconds:.1f} s"
    )
    check = validate_dataset(folder, match_images=False)
    print(check)
    print(format_info(dataset_info(folder)))
    if not check.ok:
        raise SystemExit(1)
    try:
        from ambfplus.learning import RecordingStereoDataset
    except ImportError:
        return
    samples = RecordingStereoDataset(folder)
    first = samples[0]
    summary = {name: list(value.shape) for name, value in first.items() if value.ndim >= 2}
    print(f"{len(samples)} stereo samples; the first: {json.dumps(summary)}")


if __name__ == "__main__":
    main()
