"""The verification's checks of the program's place, and its report: summary lines, JSON."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from camtool.model.errors import DialectError
from camtool.model.machine import Machine
from camtool.model.program import Home, Program, Rapid
from camtool.model.shapes import BBox, Drawing
from camtool.model.units import fmt_num
from camtool.model.version import __version__
from camtool.verify import budget as eb
from camtool.verify.clock import block_times_s, time_assumption
from camtool.verify.contour_measures import ContourMeasure
from camtool.verify.drawing_compare import (
    Against,
)
from camtool.verify.motion import StepTrace
from camtool.verify.path_shortfall import AlongPath

if TYPE_CHECKING:
    from camtool.toolpath.plan import PlanReport
    from camtool.verify.verifier import Part, Verification


SMALL_PART_MM = 1.0
"""Parts under this size suffer most from compensations (UNAM-GMM §5.3, S000-19)."""


MAX_COMPENSATIONS_SMALL = 16
"""Compensations above which a small part is warned about (the puma: 15-16; the logo: 45)."""


MIN_OVERLAP = 0.1
"""Least overlap of the program's and the drawing's boxes (of the larger box's area) for
``--against`` to compare them; below it they are in different places or scales."""


def _no_overlap(program: Program, drawing: Drawing, radius_mm: float) -> str | None:
    """Why the program and the drawing cannot be compared (boxes apart), or ``None``.

    Both boxes are grown by the tool radius and 1 % of their size (so a line
    still has an area); they overlap when the shared area is at least
    :data:`MIN_OVERLAP` of the larger box's.
    """
    if not drawing.contours or not any(not isinstance(m, Rapid) for m in program.moves):
        return None
    cut, drawn = program.bbox(cutting_only=True), drawing.bbox()
    a, b = _grown(cut, radius_mm), _grown(drawn, radius_mm)
    w = min(a[2], b[2]) - max(a[0], b[0])
    h = min(a[3], b[3]) - max(a[1], b[1])
    shared = max(w, 0.0) * max(h, 0.0)
    larger = max(_area(a), _area(b))
    if shared >= MIN_OVERLAP * larger:
        return None
    return (
        f"the program ({_span(cut)}) and the drawing ({_span(drawn)}) do not overlap: "
        "different scale or origin? post with the same --origin/--scale (--against takes "
        "the drawing in the program's coordinates); not compared"
    )


def _grown(box: BBox, radius_mm: float) -> BBox:
    m = radius_mm + 0.01 * max(box[2] - box[0], box[3] - box[1], 1e-3)
    return (box[0] - m, box[1] - m, box[2] + m, box[3] + m)


def _area(box: BBox) -> float:
    return (box[2] - box[0]) * (box[3] - box[1])


def _span(box: BBox) -> str:
    """``"X 0…100 Y -1.5…60 mm"``: a box's extent for messages."""
    x0, y0, x1, y1 = (_short(v) for v in box)
    return f"X {x0}…{x1} Y {y0}…{y1} mm"


def _short(value: float) -> str:
    """At most 3 decimals, trailing zeros dropped, never ``-0``."""
    text = fmt_num(value, 3).rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def check_area(
    program: Program, machine: Machine, source: str = "", *, reposted: bool = True
) -> tuple[str, ...]:
    """The rule ``post`` applies (:func:`camtool.post.base.check_placement`), on read code.

    Work coordinates: the toolpath must fit the travel (warnings where work zero needs
    care); machine coordinates: every move inside the work area, named by its line.

    Args:
        program: the code as read.
        machine: the machine it is checked against.
        source: the file the code was read from; every refusal then starts with it
            (``FILE: line 7: reaches …``, ``FILE: the toolpath is …``).
        reposted: the code was not planned here from a drawing (a file verified or sent
            as it is): a work-zero warning names the program that wrote it, not
            ``--origin`` (the writer's and the planner's own words otherwise).

    Raises:
        DialectError: the program cannot run on ``machine`` (with the remedy).
    """
    from camtool.post.base import check_placement, check_work_area

    try:
        if machine.coordinates != "work":  # in work coordinates any position runs
            for index, (start, move) in enumerate(program.steps()):
                line = program.line_of(index)
                where = f"line {line}" if line is not None else f"move {index + 1}"
                check_work_area(start, move, machine, where, program)
        return check_placement(program, machine, reposted=reposted)
    except DialectError as exc:
        if not source:
            raise
        raise DialectError(f"{source}: {exc}") from None


def block_times(trace: StepTrace, program: Program, machine: Machine) -> np.ndarray:
    """Estimated time of each move, s (:func:`camtool.verify.clock.block_times_s`)."""
    return block_times_s(trace, program, machine)


def _warnings(program: Program, trace: StepTrace) -> list[str]:
    out = list(program.warnings)
    homes = sum(isinstance(c, Home) for _, c in program.commands)
    if homes:
        out.append(
            f"{homes} return(s) to a machine position (G28, G30, G53) not simulated: that "
            "position is not the part zero, so the move after each is simulated from where "
            "the one before ended"
        )
    box = program.bbox(cutting_only=True)
    size = max(box[2] - box[0], box[3] - box[1])
    if trace.compensations > MAX_COMPENSATIONS_SMALL and size < SMALL_PART_MM:
        out.append(
            f"{trace.compensations} backlash compensations on a part of {size:.3f} mm: parts "
            f"under {SMALL_PART_MM:g} mm fail after about {MAX_COMPENSATIONS_SMALL} "
            "(UNAM-GMM §5.3); try --order mirror or fewer reversals"
        )
    return out


def summary_lines(v: Verification) -> list[str]:
    """A one-screen text summary of a verification (for stderr); never prints ``-0``."""
    t = v.trace
    steps = t.block_steps.sum(axis=0) if len(t.block_steps) else np.zeros(3, dtype=np.int64)
    dev = v.deviation
    lines = [
        f"verified {len(v.program.moves)} moves on {v.target} ({v.machine.name})",
        f"  steps x {steps[0]}, y {steps[1]}, z {steps[2]}; {t.iterations} iterations",
        f"  reversals x {t.reversals[0]}, y {t.reversals[1]}; "
        f"{t.compensations} compensations ({t.row_count - t.iterations} steps)",
        f"  deviation from the path: max {fmt_num(dev.max_um, 2)} µm at "
        f"({fmt_num(dev.at_mm[0])}, {fmt_num(dev.at_mm[1])}) mm, "
        f"rms {fmt_num(dev.rms_um, 2)} µm",
    ]
    if v.along is not None:
        lines.append(_along_text(v, v.along))
    for shown, c in enumerate(v.contours, 1):
        ex, ey = c.size_error_um
        text = f"  contour {c.number}: size error {_signed(ex)} x {_signed(ey)} µm"
        if c.closure_um is not None:
            text += f", closure gap ({_signed(c.closure_um[0])}, {_signed(c.closure_um[1])}) µm"
        if c.circle is not None:
            text += f", diameter {fmt_num(c.circle[1])} mm (nominal {fmt_num(c.circle[0])})"
        lines.append(text)
        if len(lines) > 14:
            if len(v.contours) > shown:
                lines.append(f"  ... {len(v.contours) - shown} more contours in the report")
            break
    if v.against is not None:
        a = v.against
        lines.append(
            f"  against the drawing: max {fmt_num(a.max_um, 2)} µm, rms {fmt_num(a.rms_um, 2)} µm, "
            f"overcut {fmt_num(a.overcut_um, 2)} µm"
            + (" (where it was cut as drawn)" if a.not_cut else "")
        )
        if a.not_cut:
            lines.append("  " + not_cut_text(a))
    lines.extend(part_lines(v))
    assumed = time_assumption(v.trace, v.machine)
    lines.append(f"  estimated time {time_text(v.time_s)}" + (f" ({assumed})" if assumed else ""))
    lines.extend(f"  {line}" for line in eb.text_lines(v.error_budget))
    return lines


def time_text(seconds: float) -> str:
    """``"172.5 s"``; a short program keeps 3 significant digits (``"0.0735 s"``)."""
    if seconds >= 0.1 or seconds <= 0:
        return f"{fmt_num(seconds, 1)} s"
    return f"{seconds:.3g} s"


def _along_text(v: Verification, a: AlongPath) -> str:
    """``"  along the path: shortfall 190.00 µm at (0, 0) mm (line 7); ..."``."""

    def where(block: int, at: tuple[float, float]) -> str:
        line = v.program.line_of(block)
        return f"({fmt_num(at[0])}, {fmt_num(at[1])}) mm" + (
            f" (line {line})" if line is not None else f" (move {block + 1})"
        )

    text = f"  along the path: shortfall max {fmt_num(a.shortfall_um, 2)} µm"
    if a.shortfall_block >= 0:
        text += f" at {where(a.shortfall_block, a.shortfall_at_mm)}"
    text += f"; move-end error max {fmt_num(a.block_end_um, 2)} µm"
    if a.block_end_block >= 0:
        text += f" at {where(a.block_end_block, a.block_end_at_mm)}"
    return text


def not_cut_text(a: Against) -> str:
    """``"2 features not cut as drawn: tight corner at (20, 27) mm, ...; max 7.8 mm"``."""
    n = len(a.not_cut)
    shown = [f"{f.label} at ({_short(f.at[0])}, {_short(f.at[1])}) mm" for f in a.not_cut[:6]]
    if n > 6:
        shown.append(f"{n - 6} more")
    worst = max(f.error_um for f in a.not_cut)
    return (
        f"{n} feature{'s' if n > 1 else ''} not cut as drawn with this tool: "
        f"{', '.join(shown)}; max {error_text(worst)} (--strict counts them)"
    )


def error_text(um: float) -> str:
    """An error for people: ``"4.95 µm"`` under 1 mm, ``"7.8 mm"`` from 1 mm on."""
    return f"{fmt_num(um, 2)} µm" if um < 1000.0 else f"{fmt_num(um / 1000.0, 1)} mm"


def _signed(value: float, decimals: int = 1) -> str:
    """``"+1.5"``, ``"-0.3"``, ``"+0.0"`` (a negative zero gets the plus sign)."""
    text = fmt_num(value, decimals)
    return text if text.startswith("-") else "+" + text


def report_dict(v: Verification, plan: PlanReport | None = None) -> dict[str, Any]:
    """The verify report (the keys of docs/verify.md, plus details), JSON-ready.

    ``plan``, what planning found when the code was planned in the same run, goes
    under the ``plan`` key (:meth:`camtool.toolpath.plan.PlanReport.to_json`).
    """
    report = build_report(v)
    if plan is not None:
        report["plan"] = plan.to_json()
    return report


def _um(value: float) -> float:
    return round(float(value), 4) + 0.0  # + 0.0 turns a -0.0 into 0.0


def _mm(value: float) -> float:
    return round(float(value), 6) + 0.0


def _part(p: Part) -> dict[str, Any]:
    """One ``operations`` entry of the report: a part verified alone."""
    v = p.verification
    against = None
    if v.against is not None:
        against = {"max_um": _um(v.against.max_um), "overcut_um": _um(v.against.overcut_um)}
    return {
        "operation": p.label,
        "moves": [p.moves[0] + 1, p.moves[1]],
        "deviation_um": {"max": _um(v.deviation.max_um), "rms": _um(v.deviation.rms_um)},
        "against": against,
        "against_skipped": v.against_skipped,
        "tool_diameter_mm": _mm(v.tool_diameter),
        "max_error_um": _um(v.max_error_um),
        "time_s": seconds_6(v.time_s),
    }


def part_lines(v: Verification) -> list[str]:
    """A line per part of ``v`` for the summary: deviation, the drawing, time."""
    lines = []
    for p in v.parts:
        pv = p.verification
        text = f"  {p.label}: deviation max {fmt_num(pv.deviation.max_um, 2)} µm"
        if pv.against is not None:
            text += f", against its drawing max {fmt_num(pv.against.max_um, 2)} µm"
        elif pv.against_skipped is not None:
            text += ", not compared with its drawing"
        lines.append(text + f", {fmt_num(pv.time_s, 1)} s")
    return lines


def build_report(v: Verification) -> dict[str, Any]:
    """The report of a verification (see the module docstring for the keys)."""
    t = v.trace
    steps = t.block_steps.sum(axis=0) if len(t.block_steps) else np.zeros(3, dtype=np.int64)
    comp_steps = t.compensation_steps
    dev = v.deviation
    at = None
    if dev.block >= 0:
        at = {
            "x_mm": _mm(dev.at_mm[0]),
            "y_mm": _mm(dev.at_mm[1]),
            "block": dev.block + 1,
            "line": v.program.line_of(dev.block),
        }
    report: dict[str, Any] = {
        "camtool": __version__,
        "target": v.target,
        "machine": v.machine.name,
        "blocks": len(v.program.moves),
        "steps": {"x": int(steps[0]), "y": int(steps[1]), "z": int(steps[2])},
        "iterations": t.iterations,
        "compensation_steps": {"x": comp_steps[0], "y": comp_steps[1]},
        "reversals": {"x": t.reversals[0], "y": t.reversals[1]},
        "compensations": t.compensations,
        "deviation_um": {"max": _um(dev.max_um), "rms": _um(dev.rms_um), "at": at},
        **_along_json(v),
        "closure_um": [
            _um(math.hypot(*c.closure_um)) for c in v.contours if c.closure_um is not None
        ],
        "size_error_um": [[_um(c.size_error_um[0]), _um(c.size_error_um[1])] for c in v.contours],
        "contours": [_contour(c, _contour_end(v, i)) for i, c in enumerate(v.contours)],
        "against": None,
        "not_cut_as_drawn": [],
        "against_skipped": v.against_skipped,
        "max_error_um": _um(v.max_error_um),
        "strict_error_um": _um(v.strict_error_um),
        "time_s": seconds_6(v.time_s),
        "warnings": list(v.warnings),
        "error_budget": eb.to_json(v.error_budget, _um),
        "operations": [_part(p) for p in v.parts],
    }
    if v.against is not None:
        a = v.against
        report["against"] = {
            "max_um": _um(a.max_um),
            "rms_um": _um(a.rms_um),
            "at": {"x_mm": _mm(a.at_mm[0]), "y_mm": _mm(a.at_mm[1])},
            "overcut_um": _um(a.overcut_um),
            "samples": a.samples,
        }
        report["not_cut_as_drawn"] = [
            {
                "kind": f.kind,
                "label": f.label,
                "at": {"x_mm": _mm(f.at[0]), "y_mm": _mm(f.at[1])},
                "error_um": _um(f.error_um),
                "samples": f.samples,
                "value": None if f.value is None else _mm(f.value),
            }
            for f in a.not_cut
        ]
    return report


def seconds_6(value: float) -> float:
    """A time to 6 significant digits, never fewer than 3 decimals (7 steps are not 0.001 s)."""
    if value <= 0 or not math.isfinite(value):
        return round(float(value), 3) + 0.0
    decimals = max(3, 5 - math.floor(math.log10(value)))
    return round(float(value), decimals) + 0.0


def _where(v: Verification, block: int, at_mm: tuple[float, float]) -> dict[str, Any] | None:
    if block < 0:
        return None
    return {
        "x_mm": _mm(at_mm[0]),
        "y_mm": _mm(at_mm[1]),
        "block": block + 1,
        "line": v.program.line_of(block),
    }


def _along_json(v: Verification) -> dict[str, Any]:
    """The ``shortfall_um`` and ``block_end_um`` keys (``None`` without along-path measures)."""
    a = v.along
    if a is None:
        return {"shortfall_um": None, "block_end_um": None}
    return {
        "shortfall_um": {
            "max": _um(a.shortfall_um),
            "at": _where(v, a.shortfall_block, a.shortfall_at_mm),
            "samples": a.samples,
        },
        "block_end_um": {
            "max": _um(a.block_end_um),
            "at": _where(v, a.block_end_block, a.block_end_at_mm),
        },
    }


def _contour_end(v: Verification, index: int) -> float | None:
    if v.along is None or index >= len(v.along.contour_end_um):
        return None
    return _um(v.along.contour_end_um[index])


def _contour(c: ContourMeasure, end_error_um: float | None = None) -> dict[str, Any]:
    out: dict[str, Any] = {
        "number": c.number,
        "blocks": [c.blocks[0] + 1, c.blocks[1] + 1],
        "closed": c.closed,
        "closure_um": None,
        "size_um": [_um(c.size_um[0]), _um(c.size_um[1])],
        "size_error_um": [_um(c.size_error_um[0]), _um(c.size_error_um[1])],
        "end_error_um": end_error_um,
        "circle": None,
    }
    if c.closure_um is not None:
        dx, dy = c.closure_um
        out["closure_um"] = {"dx": _um(dx), "dy": _um(dy), "gap": _um(math.hypot(dx, dy))}
    if c.circle is not None:
        nominal, fitted, horizontal, vertical = c.circle
        out["circle"] = {
            "nominal_diameter_mm": _mm(nominal),
            "fitted_diameter_mm": _mm(fitted),
            "diameter_error_um": _um((fitted - nominal) * 1000.0),
            "horizontal_mm": _mm(horizontal),
            "vertical_mm": _mm(vertical),
        }
    return out
