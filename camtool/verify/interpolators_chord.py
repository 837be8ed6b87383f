"""Chord generators: arcs as the controllers that cannot interpolate them cut them.

Each function returns the segment **end points** of the chords, in mm, as a
read-only ``(N, 2) float64`` array (the start point is not included; each pair of
consecutive points, starting from the arc start, is executed as a line by the
machine's line interpolator after conversion to steps). Angles are radians,
counter-clockwise positive; ``clockwise=True`` is G02.

- :func:`grbl_arc_points` — GRBL 1.1 ``mc_arc`` (``grbl`` target).
- :func:`flashcut_arc_points` — the seed-001 VB6 application (§4.4, ``flashcut``).
- :func:`valcnc_arc_points` — the seed-004 ValCNC GUI/firmware (§4.2, ``valcnc``).
"""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError, UsageError

Point = tuple[float, float]
"""A point ``(x, y)`` in mm."""

GRBL_ARC_TOLERANCE_MM = 0.002
"""GRBL 1.1 default ``$12`` arc tolerance, mm."""
GRBL_N_ARC_CORRECTION = 12
"""GRBL ``config.h``: exact sin/cos every this many rotated segments."""
GRBL_ARC_ANGULAR_TRAVEL_EPSILON = 5e-7
"""GRBL ``config.h``: below this (rad) an offset arc counts as a full circle."""


def _freeze(points: list[Point] | npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    arr = np.array(points, dtype=np.float64).reshape(-1, 2)
    arr.flags.writeable = False
    return arr


def _offsets(start: Point, end: Point, centre: Point) -> tuple[float, float, float, float, float]:
    """Start and end offsets from the centre and the radius from the start.

    Raises:
        InputError: If the start point is the centre.
    """
    u0, v0 = start[0] - centre[0], start[1] - centre[1]
    u1, v1 = end[0] - centre[0], end[1] - centre[1]
    r = math.hypot(u0, v0)
    if r == 0.0:
        raise InputError(f"arc start {tuple(start)} is its centre: radius 0")
    return u0, v0, u1, v1, r


def chord_sagitta(radius_mm: float, angle_rad: float) -> float:
    """Largest distance between an arc of ``angle_rad`` and its chord: R(1 − cos(β/2)), mm.

    Args:
        radius_mm: Radius, mm.
        angle_rad: Angle subtended by the chord, rad (sign ignored).

    Returns:
        Sagitta, mm (seed-004 §4.2 "chord error per segment").
    """
    return radius_mm * (1.0 - math.cos(abs(angle_rad) / 2.0))


# ------------------------------------------------------------------------------ GRBL


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
    """
    if not arc_tolerance_mm > 0:
        raise UsageError(f"arc tolerance must be > 0 mm, got {arc_tolerance_mm!r}")
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
    u0, v0, u1, v1, r = _offsets(start, end, centre)
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
    return _freeze(points)


# --------------------------------------------------------------------------- seed-001


def flashcut_arc_points(
    start: Point, end: Point, centre: Point, clockwise: bool, *, segments: int
) -> npt.NDArray[np.float64]:
    """Arc points of the seed-001 VB6 application (seed-001 §4.4, reconstructed routine).

    Start angle from ``angulo(I, J, "inicio")`` = atan2(−J, −I), end angle from
    the end offset; the sweep is normalised to [−2π, 0) for G02 and (0, 2π] for
    G03, a zero sweep (start == end) being a full circle (an assumption of the
    notes). Points at ``a0 + k·sweep/n``, k = 1..n, on the radius from the start;
    the last one is not snapped to the programmed end (not stated). The thesis
    gives no point count ("un determinado número de puntos"), hence ``segments``
    (see :func:`camtool.model.shapes.chord_count` to derive it from a chord tolerance).

    Args:
        start: Arc start, mm.
        end: Arc end, mm.
        centre: Arc centre, mm (``start + (I, J)``).
        clockwise: True for G02, False for G03.
        segments: Number of chords n, ``>= 1``.

    Returns:
        Read-only ``(segments, 2) float64`` chord end points, mm.

    Raises:
        InputError: If the radius is 0.
        UsageError: If ``segments < 1``.
    """
    if segments < 1:
        raise UsageError(f"segments must be >= 1, got {segments!r}")
    u0, v0, u1, v1, r = _offsets(start, end, centre)
    a0 = math.atan2(v0, u0)
    sweep = math.atan2(v1, u1) - a0
    if clockwise:
        sweep = sweep % -(2.0 * math.pi) or -2.0 * math.pi
    else:
        sweep = sweep % (2.0 * math.pi) or 2.0 * math.pi
    k = np.arange(1, segments + 1, dtype=np.float64)
    ang = a0 + k * (sweep / segments)
    return _freeze(np.column_stack((centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang))))


# --------------------------------------------------------------------------- seed-004


def valcnc_arc_points(
    start: Point, end: Point, centre: Point, clockwise: bool, *, beta_rad: float
) -> npt.NDArray[np.float64]:
    """Chord points of the ValCNC arc routine (seed-004 §4.2, S004-R12).

    α = 2·asin(min(1, C/2R)) from the chord C and R = √(i² + j²); a sweep over π
    in the commanded sense uses 2π − α (the thesis' reflex test is lost with
    Figs. 4.12–4.13; it is decided here geometrically). θ starts at
    atan2(−j, −i) and steps by −β (G02) or +β (G03); points at
    θ0 ∓ kβ for every k with kβ < α, then the programmed end point, so the last
    chord is the shorter remainder (snapping is not stated in the thesis). A
    full circle (start == end) has α = 0 and moves nowhere, as the thesis'
    formula implies (S004-R05 has the post-processor split such arcs).

    Args:
        start: Arc start, mm.
        end: Arc end, mm.
        centre: Arc centre, mm (``start + (i, j)``).
        clockwise: True for G02, False for G03.
        beta_rad: Chord angle β, rad, ``> 0`` (a profile parameter; unknown in
            the thesis; chord error R(1 − cos(β/2)), see :func:`chord_sagitta`).

    Returns:
        Read-only ``(N, 2) float64`` chord end points, mm; the last row is ``end``.

    Raises:
        InputError: If the radius is 0.
        UsageError: If ``beta_rad`` is not positive.
    """
    if not beta_rad > 0:
        raise UsageError(f"chord angle beta must be > 0 rad, got {beta_rad!r}")
    u0, v0, u1, v1, r = _offsets(start, end, centre)
    chord = math.hypot(end[0] - start[0], end[1] - start[1])
    alpha = 2.0 * math.asin(min(1.0, chord / (2.0 * r)))
    cross = u0 * v1 - v0 * u1
    if (cross > 0) if clockwise else (cross < 0):
        alpha = 2.0 * math.pi - alpha
    theta0 = math.atan2(v0, u0)
    k = np.arange(1, max(0, math.ceil(alpha / beta_rad - 1e-12)), dtype=np.float64)
    ang = theta0 + (-1.0 if clockwise else 1.0) * beta_rad * k
    inner = np.column_stack((centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)))
    return _freeze(np.vstack((inner, [[float(end[0]), float(end[1])]])))
