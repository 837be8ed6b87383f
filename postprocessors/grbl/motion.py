"""Motion model of GRBL 1.1 (``grbl``) for the verifier: ``mc_arc`` chords and its planner.

GRBL's stepper runs the generic Bresenham with AMASS
(:func:`camtool.verify.interpolators.bresenham_line`, ``bresenham``). What is
GRBL's own:

Design notes: docs/internals.md, ``postprocessors/grbl/motion.py``.
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError, UsageError
from camtool.model.machine import Motion
from camtool.model.program import ArcMove
from camtool.model.shapes import Point
from camtool.verify.interpolators import arc_offsets, freeze_points
from camtool.verify.motion import MotionHooks, timing_class
from camtool.verify.timing import (
    DEFAULT_ACCELERATION_MM_S2,
    FloatArray,
    TrapezoidTiming,
    positive,
    seconds,
)

GRBL_ARC_TOLERANCE_MM = 0.002
"""GRBL 1.1 default ``$12`` arc tolerance, mm."""
GRBL_N_ARC_CORRECTION = 12
"""GRBL ``config.h``: exact sin/cos every this many rotated segments."""
GRBL_ARC_ANGULAR_TRAVEL_EPSILON = 5e-7
"""GRBL ``config.h``: below this (rad) an offset arc counts as a full circle."""
GRBL_DEFAULT_JUNCTION_DEVIATION_MM = 0.010
"""GRBL 1.1 default ``$11``, mm."""


def grbl_arc_segments(radius_mm: float, angular_travel_rad: float, arc_tolerance_mm: float) -> int:
    """Segment count of GRBL 1.1 ``mc_arc``: ⌊|½·θ·r| / √(tol·(2r − tol))⌋.

    √(tol·(2r − tol)) is half the chord whose sagitta is ``tol``; the arc length
    divided by that chord length gives the count (grbl ``motion_control.c``).
    May be 0, in which case GRBL goes straight to the end point.

    Args:
        radius_mm: Radius from the start point, mm.
        angular_travel_rad: Signed swept angle, rad.
        arc_tolerance_mm: GRBL ``$12``, mm, ``> 0``.

    Returns:
        Segment count, ``>= 0``.

    Raises:
        UsageError: If ``arc_tolerance_mm`` is not positive.
        InputError: If ``2·radius_mm ≤ arc_tolerance_mm`` (GRBL's count is undefined).
    """
    if not arc_tolerance_mm > 0:
        raise UsageError(f"arc tolerance must be > 0 mm, got {arc_tolerance_mm!r}")
    if not 2.0 * radius_mm - arc_tolerance_mm > 0:
        raise InputError(
            f"an arc of radius {radius_mm:.6g} mm is not over half of grbl's arc tolerance "
            f"$12 = {arc_tolerance_mm:g} mm: mc_arc divides by √($12·(2r − $12)), which is 0 "
            "or not a number, so what grbl does is undefined; write the arc as a G1 line "
            "(camtool's grbl writer does) or lower $12"
        )
    chord_half = math.sqrt(arc_tolerance_mm * (2.0 * radius_mm - arc_tolerance_mm))
    return math.floor(abs(0.5 * angular_travel_rad * radius_mm) / chord_half)


def _grbl_travel(u0: float, v0: float, u1: float, v1: float, clockwise: bool) -> float:
    """Signed angular travel of a GRBL offset arc; (near-)zero means a full circle."""
    travel = math.atan2(u0 * v1 - v0 * u1, u0 * u1 + v0 * v1)
    eps = GRBL_ARC_ANGULAR_TRAVEL_EPSILON
    if clockwise and travel >= -eps:
        travel -= 2.0 * math.pi
    elif not clockwise and travel <= eps:
        travel += 2.0 * math.pi
    return travel


def grbl_arc_points(
    start: Point,
    end: Point,
    centre: Point,
    clockwise: bool,
    *,
    arc_tolerance_mm: float = GRBL_ARC_TOLERANCE_MM,
) -> npt.NDArray[np.float64]:
    """Chord end points of an offset-mode arc as GRBL 1.1 ``mc_arc`` produces them.

    Radius from the start point; the target radius may differ by at most
    0.005 mm, or else by at most 0.5 mm and 0.1 % of the radius (GRBL's
    ``gcode.c`` check, error 33). Interior points come from rotating the radius
    vector by θ/n with GRBL's third-order small-angle rotation
    (cos ≈ 1 − θ²/2, sin ≈ θ − θ³/6) and an exact sin/cos every 12th point; the
    last point is the programmed end. GRBL computes in float32; this runs in
    float64 (differences are far below a step).

    Args:
        start: Arc start, mm.
        end: Arc end, mm.
        centre: Arc centre, mm (absolute; I/J are ``centre − start``).
        clockwise: True for G02, False for G03.
        arc_tolerance_mm: GRBL ``$12``, mm.

    Returns:
        Read-only ``(n, 2) float64`` chord end points, mm, ``n >= 1``; the last
        row equals ``end``.

    Raises:
        InputError: If the radius is 0 or GRBL would reject the end point.
        UsageError: If ``arc_tolerance_mm`` is not positive.
    """
    u0, v0, u1, v1, r = arc_offsets(start, end, centre)
    delta_r = abs(math.hypot(u1, v1) - r)
    if delta_r > 0.005 and (delta_r > 0.5 or delta_r > 0.001 * r):
        raise InputError(
            f"arc end {tuple(end)} is {delta_r:.4f} mm off the radius {r:.4f} mm from start "
            f"{tuple(start)}; grbl rejects it (error 33, invalid target)"
        )
    travel = _grbl_travel(u0, v0, u1, v1, clockwise)
    n = grbl_arc_segments(r, travel, arc_tolerance_mm)
    points: list[Point] = []
    if n:
        theta = travel / n
        cos_t = 2.0 - theta * theta
        sin_t = theta * 0.16666667 * (cos_t + 4.0)
        cos_t *= 0.5
        ru, rv, count = u0, v0, 0
        for i in range(1, n):
            if count < GRBL_N_ARC_CORRECTION:
                ru, rv = ru * cos_t - rv * sin_t, ru * sin_t + rv * cos_t
                count += 1
            else:
                c, s = math.cos(i * theta), math.sin(i * theta)
                ru, rv = u0 * c - v0 * s, u0 * s + v0 * c
                count = 0
            points.append((centre[0] + ru, centre[1] + rv))
    points.append((float(end[0]), float(end[1])))
    return freeze_points(points)


def grbl_junction_speed_mm_s(
    turn_angle_rad: npt.ArrayLike,
    *,
    acceleration_mm_s2: float = DEFAULT_ACCELERATION_MM_S2,
    junction_deviation_mm: float = GRBL_DEFAULT_JUNCTION_DEVIATION_MM,
) -> FloatArray:
    """GRBL 1.1 junction-deviation speed limit at a corner, mm/s (``planner.c``).

    ``v_j = √(a·δ·c/(1 − c))`` with ``c = cos(turn/2)`` (GRBL's ``sin(θ/2)``,
    θ = π − turn). The planner further caps it by both blocks' nominal speeds;
    that cap is the caller's.

    Args:
        turn_angle_rad: Angle between the incoming and outgoing directions, rad,
            any shape: 0 = straight on (returns ``inf``), π = reversal (0).
        acceleration_mm_s2: Junction acceleration, mm/s², ``> 0``.
        junction_deviation_mm: GRBL ``$11``, mm, ``> 0``.

    Returns:
        Speeds, mm/s, float64, same shape, read-only.

    Raises:
        UsageError: If a parameter is not positive.
    """
    a = positive("acceleration_mm_s2", acceleration_mm_s2)
    d = positive("junction_deviation_mm", junction_deviation_mm)
    c = np.abs(np.cos(np.asarray(turn_angle_rad, dtype=np.float64) / 2.0))
    c = np.where(c < 1e-12, 0.0, c)  # a reversal stops exactly
    with np.errstate(divide="ignore"):
        v2 = np.where(c >= 1.0 - 1e-12, np.inf, a * d * c / np.maximum(1.0 - c, 1e-300))
    return seconds(np.sqrt(v2))


def _chords(start: Point, move: ArcMove, motion: Motion) -> npt.NDArray[np.float64]:
    end, centre = (move.x, move.y), (move.cx, move.cy)
    return grbl_arc_points(
        start, end, centre, move.clockwise, arc_tolerance_mm=motion.chord_tolerance_mm
    )


MOTION = MotionHooks(chords={"grbl": _chords}, timing={"grbl": timing_class(TrapezoidTiming)})
"""What ``grbl`` adds to the verifier: ``mc_arc`` chords, its (rest-to-rest) timing model."""
