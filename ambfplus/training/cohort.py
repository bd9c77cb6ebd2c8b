"""Cohorts: many sessions assessed against one task, as a table (one row per session: who,
which group, when, the score and the main metrics) and a group report (learning curves per
participant, each metric's distribution by group).

Sessions come from a folder (every recording in it; participant, group and date from each
recording's metadata keys ``participant`` and ``group`` and its creation time) or from a CSV
with the columns ``session, participant, group, date`` (paths relative to the CSV).
"""

from __future__ import annotations

import csv
import html
import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..fileio import write_text
from .assess import assess, load_session

MM = 1e-3
# The table's metric columns: (column, unit, how to read it from an assessment's data).
COLUMNS = (
    ("score", "", lambda d: d["score"]),
    ("total_time_s", "s", lambda d: d["metrics"]["total_time"]),
    ("cutting_time_s", "s", lambda d: d["metrics"]["cutting_time"]),
    (
        "removed_mm3",
        "mm³",
        lambda d: (
            sum(d["metrics"]["removed_by_label"].values()) * d["metrics"]["voxel_volume"] / MM**3
        ),
    ),
    ("target_fraction", "", lambda d: (d.get("target") or {}).get("removed_fraction")),
    ("outside_fraction", "", lambda d: (d.get("target") or {}).get("outside_fraction")),
    ("force_p95_n", "N", lambda d: d["metrics"]["cutting_force_p95"]),
    ("excess_force_s", "s", lambda d: d["metrics"]["time_above_excess_force"]),
    ("strokes", "", lambda d: len(d["metrics"]["strokes"])),
    ("breached_voxels", "", lambda d: sum(s["voxels_removed"] for s in d["metrics"]["structures"])),
    (
        "time_in_margins_s",
        "s",
        lambda d: sum(s["time_in_margin"] for s in d["metrics"]["structures"]),
    ),
    ("visibility", "", lambda d: (d.get("visibility") or {}).get("fraction")),
    ("efficiency_mm3_per_min", "mm³/min", lambda d: d["metrics"]["efficiency"] / MM**3),
)


@dataclass
class CohortSession:
    path: Path
    participant: str
    group: str
    date: str


def sessions(source) -> list[CohortSession]:
    """The sessions of a folder or a CSV (see the module)."""
    source = Path(source)
    if source.is_dir():
        out = []
        for path in sorted(p for p in source.iterdir() if p.suffix == ".h5"):
            s = load_session(path)
            meta = s.metadata
            out.append(
                CohortSession(
                    path,
                    str(meta.get("participant", "unknown")),
                    str(meta.get("group", "all")),
                    s.created,
                )
            )
        if not out:
            raise ValueError(f"{source}: no recording (*.h5) in the folder")
        return out
    if not source.is_file():
        raise ValueError(f"{source}: no such folder or CSV file")
    with source.open(newline="") as f:
        reader = csv.DictReader(f)
        required = ["session", "participant", "group", "date"]
        missing = [c for c in required if c not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(
                f"{source}: the CSV has no column {missing[0]!r}; it needs {', '.join(required)}"
            )
        rows = []
        for line, row in enumerate(reader, start=2):
            path = Path(row["session"])
            path = path if path.is_absolute() else source.parent / path
            if not path.exists():
                raise ValueError(f"{source}: line {line}: no such recording {path}")
            rows.append(CohortSession(path, row["participant"], row["group"], row["date"]))
    if not rows:
        raise ValueError(f"{source}: the CSV lists no session")
    return rows


def assess_cohort(source, task=None, references=()) -> list[dict]:
    """One row per session: session, participant, group, date and the COLUMNS."""
    rows = []
    for s in sessions(source):
        data = assess(s.path, task, references).data
        row: dict = {
            "session": str(s.path),
            "participant": s.participant,
            "group": s.group,
            "date": s.date,
        }
        row.update({name: read(data) for name, _, read in COLUMNS})
        rows.append(row)
    return rows


def write_table(rows: list[dict], path) -> list[Path]:
    """The rows as CSV at `path`, and as Parquet beside it (.parquet) when pyarrow is present.
    Returns the files written."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=list(rows[0]) if rows else ["session"])
    writer.writeheader()
    writer.writerows(rows)
    write_text(path, text.getvalue())
    written = [path]
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return written
    parquet = path.with_suffix(".parquet")
    pq.write_table(pa.Table.from_pylist(rows), parquet)
    written.append(parquet)
    return written


def _curve_svg(rows: list[dict], metric: str, width=440, height=220) -> str:
    """A learning curve per participant: `metric` by session order (their dates)."""
    people = sorted({r["participant"] for r in rows})
    values = [r[metric] for r in rows if r[metric] is not None]
    if not values:
        return "<p>not measured</p>"
    lo, hi = min(values), max(values)
    hi = hi if hi > lo else lo + 1.0
    runs = max(len([r for r in rows if r["participant"] == p]) for p in people)
    left, top, w, h = 40, 10, width - 60, height - 40
    colours = ["#0969da", "#cf222e", "#1a7f37", "#8250df", "#bc4c00", "#6e7781"]
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}">',
        f'<rect x="{left}" y="{top}" width="{w}" height="{h}" fill="#fff" stroke="#d0d7de"/>',
        f'<text x="4" y="{top + 10}" font-size="10">{hi:.3g}</text>',
        f'<text x="4" y="{top + h}" font-size="10">{lo:.3g}</text>',
    ]
    for i, person in enumerate(people):
        mine = sorted((r for r in rows if r["participant"] == person), key=lambda r: r["date"])
        pts = [
            (left + w * (n / max(runs - 1, 1)), top + h - h * (r[metric] - lo) / (hi - lo))
            for n, r in enumerate(mine)
            if r[metric] is not None
        ]
        colour = colours[i % len(colours)]
        parts.append(
            f'<polyline fill="none" stroke="{colour}" stroke-width="1.5" points="'
            + " ".join(f"{x:.1f},{y:.1f}" for x, y in pts)
            + '"/>'
        )
        parts += [
            f'<circle cx="{x:.1f}" cy="{y:.1f}" r="3" fill="{colour}"><title>'
            f"{html.escape(person)}</title></circle>"
            for x, y in pts
        ]
    parts.append("</svg>")
    keys = " ".join(
        f'<span style="color:{colours[i % len(colours)]}">● {html.escape(p)}</span>'
        for i, p in enumerate(people)
    )
    return "".join(parts) + f"<div>{keys}</div>"


def _distribution_svg(rows: list[dict], metric: str, width=440, height=60) -> str:
    """Each group's values of `metric` as a strip with its median."""
    groups = sorted({r["group"] for r in rows})
    values = [r[metric] for r in rows if r[metric] is not None]
    if not values:
        return "<p>not measured</p>"
    lo, hi = min(values), max(values)
    hi = hi if hi > lo else lo + 1.0
    row_h = 22
    height = row_h * len(groups) + 20
    left, w = 90, width - 110
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}">']
    for g, group in enumerate(groups):
        y = 14 + g * row_h
        parts.append(f'<text x="0" y="{y + 4}" font-size="11">{html.escape(group)}</text>')
        mine = [r[metric] for r in rows if r["group"] == group and r[metric] is not None]
        for v in mine:
            parts.append(
                f'<circle cx="{left + w * (v - lo) / (hi - lo):.1f}" cy="{y}" r="3" '
                'fill="#0969da" fill-opacity="0.6"/>'
            )
        if mine:
            xm = left + w * (float(np.median(mine)) - lo) / (hi - lo)
            parts.append(
                f'<line x1="{xm:.1f}" x2="{xm:.1f}" y1="{y - 8}" y2="{y + 8}" '
                'stroke="#24292f" stroke-width="2"/>'
            )
    parts.append(
        f'<text x="{left}" y="{height - 2}" font-size="10">{lo:.3g}</text>'
        f'<text x="{left + w}" y="{height - 2}" font-size="10" text-anchor="end">'
        f"{hi:.3g}</text></svg>"
    )
    return "".join(parts)


def write_group_report(rows: list[dict], path, title: str = "Cohort") -> Path:
    """A self-contained HTML page: learning curves per participant (score and each metric) and
    each metric's distribution by group."""
    sections = []
    for name, unit, _ in COLUMNS:
        label = f"{name} ({unit})" if unit else name
        sections.append(
            f"<section><h3>{html.escape(label)}</h3><div class='pair'>"
            f"<div>{_curve_svg(rows, name)}</div>"
            f"<div>{_distribution_svg(rows, name)}</div></div></section>"
        )
    table = "".join(
        "<tr>" + "".join(f"<td>{html.escape(_cell(r[c]))}</td>" for c in r) + "</tr>" for r in rows
    )
    header = "".join(f"<th>{html.escape(c)}</th>" for c in (rows[0] if rows else {}))
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>body {{ font: 14px/1.4 system-ui, sans-serif; margin: 24px; color: #24292f; }}
.pair {{ display: flex; gap: 24px; flex-wrap: wrap; }} table {{ border-collapse: collapse; }}
td, th {{ padding: 2px 6px; border-bottom: 1px solid #eaeef2; font-size: 12px; }}</style>
</head><body><h1>{html.escape(title)}</h1>
<p>{len(rows)} sessions, {len({r["participant"] for r in rows})} participants,
{len({r["group"] for r in rows})} groups. Left: learning curves per participant (sessions in
date order); right: each group's values, its median marked.</p>
{"".join(sections)}
<h2>Sessions</h2><table><tr>{header}</tr>{table}</table></body></html>
"""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(path, page)
    return path


def _cell(value) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    return "" if value is None else str(value)
