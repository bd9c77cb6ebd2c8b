"""The rubric: items that can be computed from an assessment, modelled on the published
mastoidectomy scales (Welling, Melbourne): each has the measured value, a threshold, pass or
fail, and a graded score in 0..1: 0.5 exactly at the threshold, 1 at the ideal value (none of
a thing to avoid; a whole fraction, or twice the threshold, of a thing to achieve), falling
linearly toward 0 on the failing side (halving every `scale` past a "no more than" threshold).
The composite score is the weighted mean of the measured items' scores, 0..100; items that
could not be measured (no frames with depth, no target, no structure to skeletonise) are
listed and left out.

Weights: violating a protected structure 4, its margin 2, force near structures 2, every
other item 1.
"""

from __future__ import annotations

import math
import statistics
from dataclasses import asdict, dataclass

MM = 1e-3


@dataclass
class RubricItem:
    key: str
    title: str
    value: float | None  # None: not measured
    threshold: float
    unit: str
    passed: bool | None
    score: float | None
    weight: float
    detail: str = ""

    def as_dict(self) -> dict:
        return asdict(self)


def _at_most(value: float, threshold: float, scale: float) -> float:
    """1 at 0, falling linearly to 0.5 at the threshold, then halving every `scale` beyond it
    (a zero threshold: 1 at 0, halving every `scale`)."""
    if threshold <= 0:
        return 0.5 ** (value / scale)
    if value <= threshold:
        return 1.0 - 0.5 * value / threshold
    return 0.5 * 0.5 ** ((value - threshold) / scale)


def _at_least(value: float, threshold: float, ideal: float) -> float:
    """0 at 0, rising linearly to 0.5 at the threshold and on to 1 at `ideal`."""
    if threshold <= 0:
        return 1.0
    if value < threshold:
        return 0.5 * max(value, 0.0) / threshold
    return 0.5 + 0.5 * min(1.0, (value - threshold) / max(ideal - threshold, 1e-12))


def _item(
    key, title, value, threshold, unit, higher_is_better, weight, scale=None, detail="", ideal=None
):
    if value is None:
        return RubricItem(key, title, None, threshold, unit, None, None, weight, detail)
    if higher_is_better:
        ideal = ideal if ideal is not None else (1.0 if unit == "" else 2.0 * threshold)
        passed, score = value >= threshold, _at_least(value, threshold, ideal)
    else:
        passed = value <= threshold
        score = _at_most(value, threshold, scale if scale else max(threshold, 1e-12))
    return RubricItem(
        key, title, float(value), float(threshold), unit, bool(passed), score, weight, detail
    )


def rubric(assessment: dict, task) -> list[RubricItem]:
    """The rubric's items for an assessment's parts (metrics, target, exposure, visibility)."""
    t = task.thresholds
    m = assessment["metrics"]
    items = []
    for s in m["structures"]:
        breach = s["voxels_removed"]
        when = (
            f"first at {s['first_breach_time']:.2f} s (step {s['first_breach_step']}), "
            f"{breach} voxels"
            if breach
            else "never touched"
        )
        items.append(
            _item(
                f"no_breach:{s['name']}",
                f"{s['name']} not violated",
                breach,
                0,
                "voxels",
                False,
                4.0,
                scale=1.0,
                detail=when,
            )
        )
        closest = s["closest"]
        near = "never near" if closest is None else f"closest {closest / MM:.2f} mm"
        items.append(
            _item(
                f"margin:{s['name']}",
                f"{s['margin'] / MM:g} mm margin kept around {s['name']}",
                s["time_in_margin"],
                t["max_time_in_margin"],
                "s",
                False,
                2.0,
                scale=max(t["max_time_in_margin"], 0.5),
                detail=f"{s['contacts']} entries, {near}",
            )
        )
    if m["structures"]:
        force = max(s["force_in_margin_max"] for s in m["structures"])
        items.append(
            _item(
                "force_near",
                "No excessive force near structures",
                force,
                task.excess_force,
                "N",
                False,
                2.0,
            )
        )
    items.append(
        _item(
            "excess_force",
            "Cutting force controlled",
            m["time_above_excess_force"],
            t["max_excess_force_time"],
            "s",
            False,
            1.0,
            scale=max(t["max_excess_force_time"], 0.5),
            detail=f"p95 {m['cutting_force_p95']:.2f} N, max {m['cutting_force_max']:.2f} N",
        )
    )
    strokes = m["strokes"]
    length = median([s["length"] for s in strokes])
    straight = median([s["straightness"] for s in strokes])
    items.append(
        _item(
            "stroke_length",
            "Broad saucerising strokes",
            None if length is None else length / MM,
            t["min_stroke_length"],
            "mm",
            True,
            1.0,
            detail=f"{len(strokes)} strokes",
        )
    )
    items.append(
        _item(
            "straightness",
            "Smooth, straight strokes",
            straight,
            t["min_straightness"],
            "",
            True,
            1.0,
        )
    )
    vis = assessment.get("visibility")
    items.append(
        _item(
            "visibility",
            "Burr kept visible",
            None if not vis else vis["fraction"],
            t["min_visibility"],
            "",
            True,
            1.0,
            detail="no frame with depth"
            if not vis
            else f"{vis['visible_frames']}/{vis['frames']} frames",
        )
    )
    target = assessment.get("target")
    if target is not None:
        items.append(
            _item(
                "target",
                "Target region drilled",
                target["removed_fraction"],
                t["min_target_fraction"],
                "",
                True,
                1.0,
            )
        )
        items.append(
            _item(
                "outside",
                "Drilling kept inside the target",
                target["outside_fraction"],
                t["max_outside_fraction"],
                "",
                False,
                1.0,
                scale=0.1,
            )
        )
    for name, e in (assessment.get("exposure") or {}).items():
        removed = e["voxels_removed"]
        value = e["exposed_fraction"] if removed == 0 else 0.0
        items.append(
            _item(
                f"skeletonised:{name}",
                f"{name} skeletonised without breach",
                value,
                t["min_exposed_fraction"],
                "",
                True,
                1.0,
                detail=f"{removed} voxels breached"
                if removed
                else "not near the target"
                if e["exposed_fraction"] is None
                else f"median residual bone {e['thickness_median'] / MM:.2f} mm",
            )
        )
    if task.burrs is not None:
        used = sorted(assessment["burrs_cutting"])
        wrong = [d for d in used if not any(math.isclose(d, a, rel_tol=1e-6) for a in task.burrs)]
        items.append(
            _item(
                "burrs",
                "Burr chosen for the site",
                len(wrong),
                0,
                "burrs",
                False,
                1.0,
                scale=1.0,
                detail="cut with "
                + ", ".join(f"{d / MM:g} mm" for d in used)
                + f"; allowed {', '.join(f'{d / MM:g}' for d in task.burrs)} mm",
            )
        )
    if task.time_limit is not None:
        items.append(
            _item(
                "time",
                "Within the time limit",
                m["total_time"],
                task.time_limit,
                "s",
                False,
                1.0,
                scale=task.time_limit / 4,
            )
        )
    return items


def composite(items: list[RubricItem]) -> float | None:
    """The weighted mean of the measured items' scores, 0..100."""
    measured = [(i.weight, i.score) for i in items if i.score is not None]
    total = sum(w for w, _ in measured)
    return 100.0 * sum(w * s for w, s in measured) / total if total else None


def median(values):
    return float(statistics.median(values)) if values else None
