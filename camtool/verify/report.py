"""The verify report: a JSON-ready dict with the keys of ../shared/DESIGN.md.

Stable keys other tools read: ``target``, ``blocks``, ``steps`` {x, y, z},
``iterations``, ``reversals`` {x, y}, ``compensations``, ``deviation_um``
{max, rms}, ``closure_um`` (one value per closed contour, the gap's length),
``size_error_um`` (one ``[dx, dy]`` per contour, bounding box), ``time_s``,
``warnings``. Added here: ``machine``, ``compensation_steps``, the location of
the worst deviation, ``contours`` (every measure per contour, circles with
their fitted diameter), ``against`` (the drawing comparison, over what was
cut as drawn), ``not_cut_as_drawn`` (the features the planner reported it
cannot cut with this tool, each ``{kind, label, at: {x_mm, y_mm}, error_um,
samples, value}``), ``strict_error_um`` (the largest error with them) and
``against_skipped`` (why a drawing given was not compared, else null). Numbers are
rounded (µm to 4 decimals, mm to 6) so the same input gives the same bytes.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from camtool import __version__
from camtool.verify.metrics import ContourMeasure
from camtool.verify.verifier import Verification


def _um(value: float) -> float:
    return round(float(value), 4) + 0.0  # + 0.0 turns a -0.0 into 0.0


def _mm(value: float) -> float:
    return round(float(value), 6) + 0.0


def build_report(v: Verification) -> dict[str, Any]:
    """The report of a verification (see the module docstring for the keys)."""
    t = v.trace
    steps = t.block_steps.sum(axis=0) if len(t.block_steps) else np.zeros(3, dtype=np.int64)
    comp_rows = t.rows[t.compensation]
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
        "iterations": int((~t.compensation).sum()),
        "compensation_steps": {
            "x": int(np.abs(comp_rows[:, 0]).sum()),
            "y": int(np.abs(comp_rows[:, 1]).sum()),
        },
        "reversals": {"x": t.reversals[0], "y": t.reversals[1]},
        "compensations": t.compensations,
        "deviation_um": {"max": _um(dev.max_um), "rms": _um(dev.rms_um), "at": at},
        "closure_um": [
            _um(math.hypot(*c.closure_um)) for c in v.contours if c.closure_um is not None
        ],
        "size_error_um": [[_um(c.size_error_um[0]), _um(c.size_error_um[1])] for c in v.contours],
        "contours": [_contour(c) for c in v.contours],
        "against": None,
        "not_cut_as_drawn": [],
        "against_skipped": v.against_skipped,
        "max_error_um": _um(v.max_error_um),
        "strict_error_um": _um(v.strict_error_um),
        "time_s": round(v.time_s, 3),
        "warnings": list(v.warnings),
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


def _contour(c: ContourMeasure) -> dict[str, Any]:
    out: dict[str, Any] = {
        "number": c.number,
        "blocks": [c.blocks[0] + 1, c.blocks[1] + 1],
        "closed": c.closed,
        "closure_um": None,
        "size_um": [_um(c.size_um[0]), _um(c.size_um[1])],
        "size_error_um": [_um(c.size_error_um[0]), _um(c.size_error_um[1])],
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
