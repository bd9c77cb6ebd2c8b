"""The debrief report: one self-contained HTML file (images inlined, no script, nothing fetched)
with a summary and traffic lights, the final cavity from the surgeon's view and standard views
(over-drilled voxels red, under-drilled blue), a timeline, a table per structure, the
comparison with the references, and the task and software version."""

from __future__ import annotations

import base64
import html
import math
import tempfile
from pathlib import Path

import numpy as np

from .._core import Label, VolumeData, World, write_image
from ..fileio import write_text
from ..scenes import DEFAULT_LIGHTS

MM = 1e-3
OVER, UNDER = 65001, 65002  # the report's own labels for the cavity views
COLOURS = {"pass": "#1a7f37", "warn": "#bf8700", "fail": "#cf222e", "none": "#6e7781"}
CURVE_COLOURS = ["#0969da", "#8250df", "#bc4c00", "#1a7f37", "#cf222e", "#6e7781"]


def light(item: dict) -> str:
    if item["score"] is None:
        return "none"
    if item["passed"]:
        return "pass"
    return "warn" if item["score"] >= 0.5 else "fail"


def cavity_views(assessment, width: int = 480, height: int = 360) -> dict[str, np.ndarray]:
    """The anatomy after the session, with the voxels removed outside the plan (outside the
    target, or not removed by the references) kept and coloured red, and the plan's voxels left
    in place coloured blue; rendered from the surgeon's last view and three standard views.
    {view name: RGB image}."""
    s = assessment.session
    data = s.anatomy
    labels = np.array(data.labels).astype(np.uint16)
    cavity = assessment.cavity
    plan = assessment.reference if assessment.reference is not None else assessment.target
    grid = labels.copy()
    grid[cavity] = 0
    if plan is not None:
        grid[cavity & ~plan] = OVER
        grid[plan & ~cavity & (labels > 0)] = UNDER
    table = [
        Label(int(e.id), e.name, tuple(e.color), e.removable, e.critical) for e in data.label_table
    ]
    table += [
        Label(OVER, "Over-drilled", (220, 30, 30), True, False),
        Label(UNDER, "Under-drilled", (40, 90, 230), True, False),
    ]
    volume = VolumeData(
        np.asfortranarray(grid), dimensions=np.asarray(data.dimensions), label_table=table
    )
    world = World()
    for light in DEFAULT_LIGHTS:
        world.add_light(**light)
    world.add_volume("anatomy", volume, pose=s.volume_pose)
    centre = s.volume_pose[:3, 3]
    size = float(np.max(np.asarray(data.dimensions)))
    views = {}
    camera = world.add_camera(
        "view", width, height, fov_y=0.6, near=0.005, far=2.0, background=(0.12, 0.12, 0.14)
    )
    if s.camera is not None:
        k, pose = s.camera["intrinsics"][-1], s.camera["poses"][-1]
        fy, rows = float(k[1, 1]), 2.0 * float(k[1, 2])
        surgeon = world.add_camera(
            "surgeon",
            width,
            height,
            fov_y=2 * math.atan(rows / 2 / fy),
            near=0.005,
            far=2.0,
            pose=pose,
            background=(0.12, 0.12, 0.14),
        )
        views["surgeon"] = np.array(surgeon.capture(passes=["rgb"]).rgb)
    distance = 1.15 * (size / 2) / math.tan(0.3)  # the anatomy fills the view
    up_z = np.array([0.0, 0.0, 1.0])
    standard = {
        "lateral": (np.array([0.0, -0.2, 1.0]), np.array([0.0, 1.0, 0.0])),
        "posterior": (np.array([-1.0, -0.3, 0.5]), up_z),
        "superior": (np.array([0.2, 1.0, 0.5]), up_z),
    }
    for name, (direction, up) in standard.items():
        direction = s.volume_pose[:3, :3] @ (direction / np.linalg.norm(direction))
        camera.look_at(centre + distance * direction, centre, s.volume_pose[:3, :3] @ up)
        views[name] = np.array(camera.capture(passes=["rgb"]).rgb)
    return views


def _png(image: np.ndarray) -> str:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "view.png"
        write_image(str(path), np.ascontiguousarray(image))
        return base64.b64encode(path.read_bytes()).decode()


def _timeline_svg(timeline: dict, violations: list[dict], width=900, height=260) -> str:
    t = np.asarray(timeline["time"], float)
    if not len(t):
        return "<p>No ticks.</p>"
    left, right, top, bottom = 50, 60, 10, 30
    w, h = width - left - right, height - top - bottom
    t0, t1 = float(t[0]), float(max(t[-1], t[0] + 1e-3))

    def x(v):
        return left + w * (np.asarray(v, float) - t0) / (t1 - t0)

    force = np.asarray(timeline["force"], float)
    fmax = max(float(force.max()) if len(force) else 0.0, 1.0)
    parts = [
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
        f'viewBox="0 0 {width} {height}" role="img" aria-label="timeline">',
        f'<rect x="{left}" y="{top}" width="{w}" height="{h}" fill="#fff" stroke="#d0d7de"/>',
    ]
    on = np.asarray(timeline["on"], bool)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
    for a, b in zip(edges[::2], edges[1::2]):
        xa, xb = x(t[a]), x(t[min(b, len(t) - 1)])
        parts.append(
            f'<rect x="{xa:.1f}" y="{top}" width="{max(xb - xa, 0.5):.1f}" '
            f'height="{h}" fill="#ddf4ff"/>'
        )

    def polyline(values, scale, colour, label):
        ys = top + h - h * np.clip(np.asarray(values, float) / scale, 0, 1)
        points = " ".join(f"{a:.1f},{b:.1f}" for a, b in zip(x(t), ys))
        return (
            f'<polyline fill="none" stroke="{colour}" stroke-width="1.2" '
            f'points="{points}"><title>{html.escape(label)}</title></polyline>'
        )

    parts.append(polyline(force, fmax, "#24292f", "force (N)"))
    legend = [("#24292f", f"force (0..{fmax:.1f} N)")]
    for i, (name, d) in enumerate(timeline["distance"].items()):
        colour = CURVE_COLOURS[i % len(CURVE_COLOURS)]
        parts.append(polyline(np.asarray(d) / MM, 10.0, colour, f"{name} distance (mm)"))
        legend.append((colour, f"{name} (0..10 mm)"))
    for v in violations:
        if v["kind"] == "breach" and v["time"] is not None and math.isfinite(v["time"]):
            xv = float(x(v["time"]))
            parts.append(
                f'<line x1="{xv:.1f}" x2="{xv:.1f}" y1="{top}" y2="{top + h}" '
                f'stroke="#cf222e" stroke-width="2"><title>breach of '
                f"{html.escape(v['structure'])}</title></line>"
            )
    for i in range(6):
        tv = t0 + (t1 - t0) * i / 5
        parts.append(
            f'<text x="{x(tv):.1f}" y="{height - 8}" font-size="11" '
            f'text-anchor="middle">{tv:.0f} s</text>'
        )
    parts.append("</svg>")
    keys = " ".join(
        f'<span class="key"><span style="background:{c}"></span>{html.escape(n)}</span>'
        for c, n in legend + [("#ddf4ff", "burr on"), ("#cf222e", "breach")]
    )
    return "".join(parts) + f'<div class="legend">{keys}</div>'


def _fmt(value, unit="", scale=1.0, digits=2) -> str:
    if value is None:
        return "–"
    if isinstance(value, float) and not math.isfinite(value):
        return "∞"
    return f"{value / scale:.{digits}f}{(' ' + unit) if unit else ''}"


def render_report(assessment, views: bool = True) -> str:
    """The report's HTML (see the module)."""
    d = assessment.data
    m = d["metrics"]
    esc = html.escape
    score = d["score"]
    colour = (
        COLOURS["none"]
        if score is None
        else (
            COLOURS["pass"] if score >= 80 else COLOURS["warn"] if score >= 60 else COLOURS["fail"]
        )
    )
    rows = "".join(
        f'<tr><td><span class="dot" style="background:{COLOURS[light(i)]}"></span></td>'
        f"<td>{esc(i['title'])}</td><td>{_fmt(i['value'], i['unit'])}</td>"
        f"<td>{'≥' if i['key'] in _AT_LEAST or i['key'].startswith('skeletonised') else '≤'} "
        f"{_fmt(i['threshold'], i['unit'])}</td>"
        f"<td>{'not measured' if i['passed'] is None else 'pass' if i['passed'] else 'fail'}</td>"
        f"<td>{esc(i['detail'])}</td></tr>"
        for i in d["rubric"]
    )
    structures = "".join(
        f"<tr><td>{esc(s['name'])}</td><td>{_fmt(s['margin'], 'mm', MM, 1)}</td>"
        f"<td>{s['voxels_removed']}</td><td>{s['contacts']}</td>"
        f"<td>{_fmt(s['time_in_margin'], 's')}</td>"
        f"<td>{_fmt(s['closest'], 'mm', MM)} at {_fmt(s['closest_time'], 's', digits=1)}</td>"
        f"<td>{_fmt(s['force_in_margin_max'], 'N')}</td>"
        f"<td>{_fmt(s['burr_diameter_in_margin'], 'mm', MM, 1)}</td></tr>"
        for s in m["structures"]
    )
    violations = (
        "".join(
            f"<li><b>{esc(v['structure'])}</b>: "
            + (
                f"breached at {v['time']:.2f} s, {v['voxels']} voxels removed"
                if v["kind"] == "breach"
                else f"margin entered {v['contacts']} times, {v['time_in_margin']:.2f} s inside"
            )
            + "</li>"
            for v in d["violations"]
        )
        or "<li>None: every margin was kept.</li>"
    )
    references = "".join(
        f"<tr><td>{esc(Path(r['recording']).name)}</td><td>{_fmt(r['dice'])}</td>"
        f"<td>{_fmt(r['dice_in_target'])}</td><td>{_fmt(r['over'], 'mm³', MM**3, 1)}</td>"
        f"<td>{_fmt(r['under'], 'mm³', MM**3, 1)}</td>"
        f"<td>{_fmt(r['over_weighted'], 'mm³', MM**3, 1)}</td>"
        f"<td>{_fmt(r['surface_mean'], 'mm', MM)} / {_fmt(r['surface_max'], 'mm', MM)}</td></tr>"
        for r in d["references"]
    )
    exposure = "".join(
        f"<tr><td>{esc(n)}</td><td>{_fmt(e['thickness_target'], 'mm', MM)}</td>"
        f"<td>{_fmt(e['thickness_median'], 'mm', MM)}</td>"
        f"<td>{_fmt(e['thickness_min'], 'mm', MM)}</td><td>{_fmt(e['exposed_fraction'])}</td>"
        f"<td>{e['voxels_removed']}</td></tr>"
        for n, e in d["exposure"].items()
    )
    images = ""
    if views:
        images = "".join(
            f'<figure><img alt="{esc(name)} view" src="data:image/png;base64,{_png(image)}">'
            f"<figcaption>{esc(name)}</figcaption></figure>"
            for name, image in cavity_views(assessment).items()
        )
    vis = d["visibility"]
    target = d.get("target")
    summary = [
        (
            "Time",
            f"{m['total_time']:.1f} s (burr on {m['burr_on_time']:.1f} s, cutting "
            f"{m['cutting_time']:.1f} s)",
        ),
        (
            "Removed",
            f"{sum(m['removed_by_label'].values()) * m['voxel_volume'] / MM**3:.1f} mm³"
            + (
                ""
                if target is None
                else f", {target['removed_fraction'] * 100:.0f} % of the target, "
                f"{target['outside_fraction'] * 100:.0f} % of it outside"
            ),
        ),
        (
            "Force while cutting",
            f"mean {m['cutting_force_mean']:.2f} N, p95 "
            f"{m['cutting_force_p95']:.2f} N, max {m['cutting_force_max']:.2f} N",
        ),
        ("Strokes", f"{len(m['strokes'])}"),
        (
            "Burr visible",
            "not measured"
            if not vis or vis["fraction"] is None
            else f"{vis['fraction'] * 100:.0f} % of cutting time",
        ),
        ("Efficiency", f"{m['efficiency'] / MM**3:.1f} mm³ of target per minute of cutting"),
    ]
    summary_rows = "".join(f"<tr><th>{esc(a)}</th><td>{esc(b)}</td></tr>" for a, b in summary)
    task = d["task"]
    plan_text = "the references' cavity" if d["references"] else "the task's target region"
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>Debrief: {esc(task["name"])}</title>
<style>
body {{ font: 14px/1.45 system-ui, sans-serif; margin: 24px auto; max-width: 980px;
  color: #24292f; }}
h1 {{ font-size: 22px; margin-bottom: 4px; }} h2 {{ font-size: 17px; margin-top: 28px;
  border-bottom: 1px solid #d0d7de; }}
table {{ border-collapse: collapse; width: 100%; }} td, th {{ padding: 4px 8px;
  border-bottom: 1px solid #eaeef2; text-align: left; vertical-align: top; }}
.score {{ display: inline-block; font-size: 34px; font-weight: 700; color: #fff;
  background: {colour}; border-radius: 8px; padding: 6px 16px; }}
.dot {{ display: inline-block; width: 14px; height: 14px; border-radius: 50%; }}
figure {{ display: inline-block; margin: 6px; }} figure img {{ width: 300px;
  border-radius: 4px; }}
figcaption {{ text-align: center; color: #57606a; }}
.legend .key {{ margin-right: 14px; }} .legend .key span {{ display: inline-block; width: 12px;
  height: 12px; margin-right: 4px; vertical-align: middle; }}
pre {{ background: #f6f8fa; padding: 8px; overflow-x: auto; }}
.muted {{ color: #57606a; }}
</style></head><body>
<h1>Debrief: {esc(task["name"])}</h1>
<p class="muted">{esc(Path(d["recording"]).name)} · {esc(d["session"]["kind"])} ·
recorded {esc(d["session"]["created"])}</p>
<p><span class="score" id="score">{_fmt(score, digits=0)}</span>
<span class="muted">composite score out of 100, the weighted mean of the items below</span></p>
<h2>Summary</h2><table>{summary_rows}</table>
<h2>Violations</h2><ul id="violations">{violations}</ul>
<h2>Rubric</h2>
<table><tr><th></th><th>Item</th><th>Measured</th><th>Threshold</th><th>Result</th>
<th>Detail</th></tr>{rows}</table>
<h2>Final cavity</h2>
<p class="muted">Red: removed outside the plan. Blue: the plan's bone left in place. The plan
is {plan_text}.</p>
<div id="views">{images}</div>
<h2>Timeline</h2>{_timeline_svg(assessment.timeline, d["violations"])}
<h2>Protected structures</h2>
<table><tr><th>Structure</th><th>Margin</th><th>Voxels removed</th><th>Entries</th>
<th>Time inside</th><th>Closest</th><th>Max force inside</th><th>Burr inside</th></tr>
{structures}</table>
{
        "<h2>Structures to skeletonise</h2><table><tr><th>Structure</th><th>Target</th>"
        "<th>Median residual</th><th>Thinnest</th><th>Exposed fraction</th><th>Breached voxels</th>"
        "</tr>" + exposure + "</table>"
        if exposure
        else ""
    }
<h2>Comparison with references</h2>
{
        "<table><tr><th>Reference</th><th>Dice</th><th>Dice in target</th><th>Over-drilled</th>"
        "<th>Under-drilled</th><th>Over, weighted by nearness</th><th>Surface distance mean / max"
        "</th></tr>" + references + "</table>"
        if references
        else "<p>No reference given.</p>"
    }
<h2>Task</h2><p>{esc(task["description"])}</p>
<pre>{esc(task["text"] or task["source"])}</pre>
<p class="muted">ambfplus {esc(d["software_version"])}; recorded with
{esc(d["session"]["software_version"])}.</p>
</body></html>
"""


_AT_LEAST = {"stroke_length", "straightness", "visibility", "target"}


def write_report(assessment, path, views: bool = True) -> Path:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_text(path, render_report(assessment, views=views))
    return path
