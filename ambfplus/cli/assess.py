"""``ambfplus assess``: assess a recorded session against a task and expert references, or a
cohort of sessions."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def add_parser(commands) -> None:
    """Declares ``ambfplus assess``, its options and the function that runs it."""
    p = commands.add_parser(
        "assess",
        help="assess a recorded session (any recording the package makes) against a task and "
        "expert references: metrics, rubric, score, a debrief report; or a cohort (--group)",
    )
    p.add_argument("session", nargs="?", type=Path, help="the recording to assess")
    p.add_argument(
        "--task",
        help="a task YAML file, or a built-in task: cortical_mastoidectomy, "
        "facial_recess (default: protect every critical structure by 1 mm)",
    )
    p.add_argument(
        "--reference",
        type=Path,
        action="append",
        default=[],
        help="an expert recording of the same anatomy to compare with (repeatable)",
    )
    p.add_argument("--report", type=Path, help="write the debrief report (HTML) here")
    p.add_argument("--json", type=Path, help="write the assessment (JSON) here")
    p.add_argument(
        "--no-views", action="store_true", help="leave the rendered cavity views out of the report"
    )
    p.add_argument(
        "--group",
        type=Path,
        help="assess a cohort: a folder of recordings, or a CSV "
        "(session, participant, group, date)",
    )
    p.add_argument(
        "--out",
        type=Path,
        default=Path("cohort"),
        help="--group: the folder for metrics.csv (and .parquet) and report.html",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Assesses one session (printing the score and the rubric) or a cohort."""
    from .._core import ArgumentError
    from ..training import assess, load_task
    from ..training.cohort import assess_cohort, write_group_report, write_table

    task = load_task(args.task) if args.task else None
    if args.group is not None:
        if args.session is not None:
            raise ArgumentError("give a session or --group, not both")
        rows = assess_cohort(args.group, task, args.reference)
        args.out.mkdir(parents=True, exist_ok=True)
        written = write_table(rows, args.out / "metrics.csv")
        report = write_group_report(
            rows,
            args.out / "report.html",
            title=f"Cohort: {task.name if task else 'free drilling'}",
        )
        print(
            json.dumps(
                {"sessions": len(rows), "files": [str(p) for p in [*written, report]]}, indent=2
            )
        )
        return 0
    if args.session is None:
        raise ArgumentError("name a session (a recording) or --group")
    result = assess(args.session, task, args.reference)
    d = result.data
    print(
        f"{d['task']['name']}: score {d['score']:.1f} / 100"
        if d["score"] is not None
        else f"{d['task']['name']}: no item measured"
    )
    for item in d["rubric"]:
        mark = "n/a " if item["passed"] is None else "PASS" if item["passed"] else "FAIL"
        value = "not measured" if item["value"] is None else f"{item['value']:.3g} {item['unit']}"
        print(f"  {mark} {item['title']}: {value.strip()} ({item['detail']})")
    for v in d["violations"]:
        if v["kind"] == "breach":
            print(
                f"  VIOLATION {v['structure']}: breached at {v['time']:.2f} s, "
                f"{v['voxels']} voxels removed"
            )
    if args.json:
        print(f"assessment: {result.write_json(args.json)}")
    if args.report:
        print(f"report: {result.write_report(args.report, views=not args.no_views)}")
    return 0
