"""Arcs the controller accepts after rounding: the GRBL 1.1 and LinuxCNC centre-format checks.

A centre-format arc ``G2/G3 X Y I J`` is over-determined: the controller takes
the radius from the start point it holds, and refuses the block when the end
point is too far off that circle. camtool computes arcs exactly, but the
writer prints X, Y, I and J rounded to its resolution (1 µm at 3 decimals in
mm), so the printed numbers may fail the check although the exact arc is
perfect. :func:`arc_error` is the controller's check on the numbers as written;
:func:`conform_arc` chooses printable numbers that pass it. All values are mm
(the targets write ``G21``), absolute, Y up; I/J are ``centre − start``
(``G91.1``, the default of both controllers).

Rules, with their sources (read in the controllers' code, not copied):

- ``grbl`` — GRBL 1.1, ``grbl/gcode.c`` (``gc_execute_line``, "Arc Center
  Format Offset Mode"): ``r = hypot(I, J)`` (the radius from the current
  position), ``target_r = hypot(X − x0 − I, Y − y0 − J)``; the block fails with
  error 33 ("Motion command target is invalid", ``doc/csv/error_codes_en_US.csv``;
  the comment says "[Arc definition error]") when
  ``|target_r − r| > 0.005 mm`` and (``> 0.5 mm`` or ``> 0.001·r``). Inch
  words are converted to mm first, so the limits are in mm whatever the units.
  GRBL computes in float32 (AVR ``float``), and so does :func:`arc_error`.
  ``motion_control.c`` (``mc_arc``): the sweep is ``atan2`` of the start and end
  radius vectors, a travel within ``ARC_ANGULAR_TRAVEL_EPSILON`` = 5e-7 rad of
  zero becomes a full turn, so ``X Y`` equal to the start is a full circle; the
  arc is traced on the start radius and the last segment goes to the target.
  An arc needs at least one in-plane axis word (error 32) and one offset word
  (error 35). GRBL does not check ``I0 J0``; its segment count would then be
  undefined, so camtool refuses a zero radius too.
- ``linuxcnc`` — LinuxCNC ``src/emc/rs274ngc/interp_arc.cc``
  (``arc_data_ijk``) with the defaults of ``interp_internal.hh``:
  ``r1 = |centre − start|``, ``r2 = |centre − end|``; "Zero-radius arc" when
  either is below ``RADIUS_TOLERANCE_MM`` = 0.00005 in = 0.00127 mm; "Radius to
  end of arc differs from radius to start" when ``|r1 − r2| > 100·tol`` or
  (``|r1 − r2|/max(r1, r2) > SPIRAL_RELATIVE_TOLERANCE`` = 0.001 and
  ``|r1 − r2| > tol``), with ``tol`` = ``CENTER_ARC_RADIUS_TOLERANCE_MM`` =
  2·0.01·√2 = 0.0283 mm (``_INCH``: 2·0.001·√2 in; both can be changed in the
  INI file's ``[RS274NGC]``). In doubles. The documentation ("G2, G3 Arc Move",
  ``docs/src/gcode/g-code.adoc``) still states the older, stricter rule:
  error when the radii differ by more than 0.5 mm (0.05 in) or by more than
  0.005 mm (0.0005 in) and 0.1 % of the radius — the rule GRBL copied. An
  older interpreter (2.7-era ``arc_data_ijk``) failed when ``|r1 − r2| > tol``
  OR the relative error exceeded 0.1 %. ``posemath`` (``pmCircleInit``): an end
  equal to the start is a full circle; the radius changes linearly with the
  angle between ``r1`` and ``r2`` (a spiral).

:func:`conform_arc` keeps every printed number on the grid of the writer's
resolution and every block within a safety margin (:data:`MARGIN_MM`) of the
limits, so float32 noise and work offsets do not tip a block over. GRBL's
float32 is modelled as the nearest float32 of each printed number (GRBL's
``read_float`` may be an ulp off that; the margin covers it). At 3 decimals
(1 µm) rounding changes the radii by at most about 2.8 µm, inside both rules,
so the rounded centre is kept unless the path would stray more than
:data:`DEVIATION_QUANTA` quanta. On coarser grids the centre is nudged or the
arc split. Two different radii on a grid of step ``q`` differ by at least about
``q²/(2r)``, so below ``r ≈ q²/(2·0.005 mm)`` (1 mm at 0.1 mm) GRBL accepts
only exactly equal grid radii and a small arc may have no printable form
(:class:`~camtool.model.errors.DialectError`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtool.model.errors import DialectError
from camtool.model.shapes import Point
from camtool.post.arccheck_rules import (
    GRBL_ANGULAR_EPSILON,
    GRBL_CEILING_MM,
    GRBL_RELATIVE,
    GRBL_TOLERANCE_MM,
    LINUXCNC_CEILING_MM,
    LINUXCNC_MIN_RADIUS_MM,
    LINUXCNC_RELATIVE,
    LINUXCNC_TOLERANCE_MM,
    MARGIN_MM,
    RULE_TEXT,
    RULES,
    arc_error,
    check_rule,
)
from camtool.post.arccheck_search import (
    DEVIATION_QUANTA,
    MAX_SPLIT_DEPTH,
    SAMPLES,
    Grid,
    Reference,
    Solver,
    Unsolvable,
)

__all__ = [
    "DEVIATION_QUANTA",
    "GRBL_ANGULAR_EPSILON",
    "GRBL_CEILING_MM",
    "GRBL_RELATIVE",
    "GRBL_TOLERANCE_MM",
    "LINUXCNC_CEILING_MM",
    "LINUXCNC_MIN_RADIUS_MM",
    "LINUXCNC_RELATIVE",
    "LINUXCNC_TOLERANCE_MM",
    "MARGIN_MM",
    "MAX_SPLIT_DEPTH",
    "RULES",
    "ArcPiece",
    "arc_error",
    "conform_arc",
]


@dataclass(frozen=True)
class ArcPiece:
    """One arc block to write: end point and absolute centre (mm, on the print grid).

    The block starts where the previous one ended; ``clockwise=True`` is G2.
    """

    end: Point
    centre: Point
    clockwise: bool


def conform_arc(
    start: Point,
    end: Point,
    centre: Point,
    clockwise: bool,
    *,
    rule: str,
    quantum_mm: float,
    exact_start: Point | None = None,
) -> list[ArcPiece]:
    """Arc blocks on the print grid that the controller accepts, following the exact arc.

    The exact end is rounded to the grid (halves away from zero, as the writer
    rounds) and, if the rounded centre fails :func:`arc_error` or strays, the
    nearby grid centres are tried — the one that best equalises the two radii,
    then the one nearest the exact centre. If none passes (a radius of a few
    quanta, or a coarse grid), the exact arc is halved at its mid angle, the
    mid point rounded to the grid, and each half conformed (recursively, at
    most :data:`MAX_SPLIT_DEPTH` times); a part whose halves fail tries, last,
    grid centres further along its chord's bisector (up to one radius away). A
    full circle stays one block when it passes. Every returned block passes
    :func:`arc_error` from the previous end (with :data:`MARGIN_MM` to spare),
    keeps the direction, sweeps within 90° of its part of the exact arc, and
    its path (as the controller moves) stays within :data:`DEVIATION_QUANTA`
    quanta of it.

    Args:
        start: the printed start the controller holds, mm (must be on the grid).
        end: the exact end, mm.
        centre: the exact absolute centre, mm; the exact radius is ``|end − centre|``.
        clockwise: G2 when True, G3 otherwise.
        rule: ``"grbl"`` or ``"linuxcnc"`` (:data:`RULES`).
        quantum_mm: the writer's resolution, mm (``0.001`` for 3 decimals in mm).
        exact_start: the exact start before rounding, mm. Pass it whenever
            ``start`` was rounded: the arc is a full circle exactly when it equals
            ``end`` (the :class:`~camtool.model.program.ArcMove` convention), and an
            arc whose ends print the same but that is not a full circle gives no
            block. Without it ``start`` is taken as the exact start (a full
            circle is then ``end == start``), and an ``end`` that prints as
            ``start`` without being equal to it is a ValueError: it cannot be
            told from a full circle.

    Returns:
        The blocks in cutting order, ``[]`` when the arc rounds away to nothing
        (its ends print the same and it lies within the deviation limit of its
        start). The last block ends at the rounded exact end. Coordinates are
        clean multiples of the quantum (``round(k·q, decimals)``).

    Raises:
        DialectError: even halved, the arc cannot be written (its radius is a
            few quanta or less); the message names the radius and the rule.
        UsageError: unknown ``rule`` or a quantum that is not a positive number.
        ValueError: ``start`` is not on the grid, more than a quantum from
            ``exact_start``, or ambiguous as above (caller bugs).
    """
    check_rule(rule)
    grid = Grid.of(quantum_mm)
    s = grid.on_grid(start, "start")
    if exact_start is not None and math.dist(start, exact_start) > grid.mm:
        raise ValueError(f"the arc start {start} is not the rounded exact start {exact_start}")
    e = grid.indices(end)
    if exact_start is None and e == s and start != tuple(end):
        raise ValueError(
            f"the arc end {end} prints as its start {start}: pass exact_start to tell a full "
            "circle from an arc that rounds away"
        )
    ref = _reference(start, end, centre, clockwise, exact_start)
    solver = Solver(grid, rule, clockwise, centre)
    if e == s and abs(ref.sweep) < 2 * math.pi:
        samples = np.array([ref.at(t) for t in np.linspace(0.0, 1.0, SAMPLES)])
        if np.max(np.hypot(samples[:, 0] - start[0], samples[:, 1] - start[1])) <= solver.limit:
            return []
    try:
        blocks = solver.solve(s, e, ref)
    except Unsolvable as exc:
        raise DialectError(
            f"an arc of radius {ref.radius:.4f} mm cannot be written for {rule} at "
            f"{grid.quantum} mm resolution: {exc} — even split in halves, no printable centre "
            f"passes the controller's arc check ({RULE_TEXT[rule]}); write more decimals"
        ) from None
    return [ArcPiece(grid.point(k), grid.point(c), clockwise) for k, c in blocks]


def _reference(
    start: Point, end: Point, centre: Point, clockwise: bool, exact_start: Point | None
) -> Reference:
    """The exact arc: radius from the exact end, from the start's angle to the end's."""
    radius = math.dist(end, centre)
    if radius == 0.0:
        raise DialectError(f"arc ending at its centre {centre}: radius 0")
    first = start if exact_start is None else exact_start
    full = math.dist(first, end) <= 1e-12 * max(1.0, radius)
    a0 = math.atan2(first[1] - centre[1], first[0] - centre[0])
    a1 = math.atan2(end[1] - centre[1], end[0] - centre[0])
    sweep = 2 * math.pi if full else (a0 - a1 if clockwise else a1 - a0) % (2 * math.pi)
    return Reference(centre, radius, a0, -sweep if clockwise else sweep)
