"""Arcs the controller accepts after rounding: the GRBL 1.1 and LinuxCNC centre-format checks.

Design notes: docs/internals.md, ``camtool/post/arccheck.py``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from camtool.importers.gcode_plain import ARC_TOL_MM, R_TOL_MM, SPIRAL_RELATIVE, arc_end_off
from camtool.model.errors import UsageError
from camtool.model.shapes import Point

if TYPE_CHECKING:  # numpy is imported in the functions that use it: a re-post whose arcs
    # all pass the shortcut (plainly_passes) never loads it (~0.1 s of CPU)
    import numpy as np
    import numpy.typing as npt

# -- the controllers' rules ------------------------------------------------------------

RULES = ("grbl", "linuxcnc")
"""The controllers whose arc check is known (the ``rule`` argument)."""

GRBL_TOLERANCE_MM = 0.005
"""GRBL ``gcode.c``: radius difference always accepted, mm."""
GRBL_RELATIVE = 0.001
"""GRBL ``gcode.c``: above 0.005 mm the difference may be 0.1 % of the start radius."""
GRBL_CEILING_MM = 0.5
"""GRBL ``gcode.c``: radius difference never accepted above this, mm."""
GRBL_ANGULAR_EPSILON = 5e-7
"""GRBL ``config.h`` ``ARC_ANGULAR_TRAVEL_EPSILON``, rad: below it a travel is a full turn."""
LINUXCNC_TOLERANCE_MM, LINUXCNC_CEILING_MM = ARC_TOL_MM
"""LinuxCNC ``CENTER_ARC_RADIUS_TOLERANCE_MM`` default (2·0.01·√2 ≈ 0.0283 mm), and the
difference ``arc_data_ijk`` refuses outright (100 × it, ≈ 2.83 mm): the rule the G-code
reader reads any program by (:data:`~camtool.importers.gcode_plain.ARC_TOL_MM`)."""
LINUXCNC_RELATIVE = SPIRAL_RELATIVE
"""LinuxCNC ``SPIRAL_RELATIVE_TOLERANCE``: relative to the larger radius."""
LINUXCNC_MIN_RADIUS_MM = R_TOL_MM
"""LinuxCNC ``RADIUS_TOLERANCE_MM`` (0.00127 mm): smaller radii are "zero-radius"."""
MARGIN_MM = 2e-4
"""Distance conformed blocks keep from every limit, mm (float32 noise at ±1000 mm)."""

RULE_TEXT = {
    "grbl": "radii within 0.005 mm, or 0.1 % of the radius up to 0.5 mm",
    "linuxcnc": f"radii within {LINUXCNC_TOLERANCE_MM:.4f} mm or 0.1 %",
}
"""Each rule in a few words, for messages."""


def check_rule(rule: str) -> None:
    """Validate a ``rule`` name.

    Raises:
        UsageError: ``rule`` is not one of :data:`RULES` (the message lists them).
    """
    if rule not in RULES:
        raise UsageError(f"unknown arc rule {rule!r}; choose one of: {', '.join(RULES)}")


def arc_error(start: Point, end: Point, centre: Point, *, rule: str) -> str | None:
    """The controller's own check of a centre-format arc block, on the numbers as written.

    Args:
        start: where the controller stands (the previous block's printed end), mm.
        end: the printed X, Y, mm.
        centre: the absolute centre (``start + (I, J)`` as printed), mm.
        rule: ``"grbl"`` (GRBL 1.1 ``gcode.c``, in float32) or ``"linuxcnc"``
            (``interp_arc.cc`` with the default INI tolerances, in doubles); see
            :mod:`camtool.post.arccheck`.

    Returns:
        ``None`` when the controller accepts the block, else its reason with
        the radii and the limit (lowercase, mm).

    Raises:
        UsageError: ``rule`` is not one of :data:`RULES`.
    """
    check_rule(rule)
    if rule == "grbl":
        return _grbl_error(start, end, centre)
    return _linuxcnc_error(start, end, centre)


def _grbl_error(start: Point, end: Point, centre: Point) -> str | None:
    """GRBL 1.1 ``gcode.c`` on float32 words (the nearest float32 of each printed number)."""
    import numpy as np  # imported where used (see the module's imports)

    f32 = np.float32
    i, j = f32(centre[0] - start[0]), f32(centre[1] - start[1])
    x = (f32(end[0]) - f32(start[0])) - i
    y = (f32(end[1]) - f32(start[1])) - j
    target_r, r = np.sqrt(x * x + y * y), np.sqrt(i * i + j * j)
    delta = abs(target_r - r)
    if delta > f32(GRBL_TOLERANCE_MM) and (
        delta > f32(GRBL_CEILING_MM) or delta > f32(GRBL_RELATIVE) * r
    ):
        if delta > f32(GRBL_CEILING_MM):
            limit = "0.5 mm"
        else:
            limit = f"0.005 mm and 0.1 % of the radius ({GRBL_RELATIVE * r:.4f} mm)"
        return (
            f"grbl error 33 (invalid target): the radius to the start {r:.4f} mm and to the end "
            f"{target_r:.4f} mm differ by {delta:.4f} mm, more than {limit}"
        )
    if r == 0:
        return "grbl: I and J are both 0 (radius 0): grbl does not check it, camtool refuses it"
    return None


def _linuxcnc_error(start: Point, end: Point, centre: Point) -> str | None:
    """LinuxCNC ``arc_data_ijk`` (incremental I/J, mm, default tolerances)."""
    i, j = centre[0] - start[0], centre[1] - start[1]
    cx, cy = start[0] + i, start[1] + j
    r1 = math.hypot(cx - start[0], cy - start[1])
    r2 = math.hypot(cx - end[0], cy - end[1])
    radii = f"r1={r1:.4f} r2={r2:.4f} mm"
    if r1 < LINUXCNC_MIN_RADIUS_MM or r2 < LINUXCNC_MIN_RADIUS_MM:
        return f"linuxcnc: zero-radius arc ({radii}, the limit is {LINUXCNC_MIN_RADIUS_MM} mm)"
    if arc_end_off(r1, r2, LINUXCNC_TOLERANCE_MM, LINUXCNC_CEILING_MM):
        abs_err = abs(r1 - r2)
        rel_err = abs_err / max(r1, r2)
        return (
            f"linuxcnc: radius to end of arc differs from radius to start ({radii}, "
            f"abs_err={abs_err:.4g} mm, rel_err={100 * rel_err:.4f} %; the limit is "
            f"{LINUXCNC_TOLERANCE_MM:.4f} mm or 0.1 %, never over {LINUXCNC_CEILING_MM:.2f} mm)"
        )
    return None


def rule_ok(
    rule: str,
    r0: npt.NDArray[np.float64],
    r1: npt.NDArray[np.float64],
) -> npt.NDArray[np.bool_]:
    """The rule on ``(K,)`` start and end radii (mm), :data:`MARGIN_MM` inside every limit."""
    import numpy as np  # imported where used (see the module's imports)

    m = MARGIN_MM
    delta = np.abs(r1 - r0)
    if rule == "grbl":
        relative = (delta <= GRBL_CEILING_MM - m) & (delta <= GRBL_RELATIVE * r0 - m)
        return ((delta <= GRBL_TOLERANCE_MM - m) | relative) & (r0 > 0)
    relative = delta <= LINUXCNC_RELATIVE * np.maximum(r0, r1) - m
    small = (delta <= LINUXCNC_TOLERANCE_MM - m) | relative
    big_enough = np.minimum(r0, r1) >= LINUXCNC_MIN_RADIUS_MM + m
    return small & (delta <= LINUXCNC_CEILING_MM - m) & big_enough


def max_difference(rule: str, radius: float) -> float:
    """Largest radius difference the rule allows at ``radius`` (mm), mm."""
    if rule == "grbl":
        return max(GRBL_TOLERANCE_MM, min(GRBL_CEILING_MM, GRBL_RELATIVE * radius))
    return max(LINUXCNC_TOLERANCE_MM, min(LINUXCNC_CEILING_MM, LINUXCNC_RELATIVE * radius))


def travel(
    u0: npt.NDArray[np.float64], u1: npt.NDArray[np.float64], clockwise: bool
) -> npt.NDArray[np.float64]:
    """Signed sweeps ``(K,)`` (rad, > 0 counter-clockwise) from radius vectors ``u0`` to ``u1``.

    As the controllers take it: GRBL ``mc_arc`` uses ``atan2`` of the cross and
    dot products of the ``(K, 2)`` vectors (mm) and makes a travel within
    :data:`GRBL_ANGULAR_EPSILON` of zero a full turn; LinuxCNC's
    ``pmCircleInit`` makes an end on the start a full turn too.
    """
    import numpy as np  # imported where used (see the module's imports)

    cross = u0[:, 0] * u1[:, 1] - u0[:, 1] * u1[:, 0]
    sweep = np.arctan2(cross, np.sum(u0 * u1, axis=1))
    if clockwise:
        return np.where(sweep >= -GRBL_ANGULAR_EPSILON, sweep - 2 * math.pi, sweep)
    return np.where(sweep <= GRBL_ANGULAR_EPSILON, sweep + 2 * math.pi, sweep)
