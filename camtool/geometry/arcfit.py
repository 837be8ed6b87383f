"""Arc fitting: smooth curves and dense polylines become arcs and lines within a tolerance.

Design notes: docs/internals.md, ``camtool/geometry/arcfit.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from typing import Any, TypeAlias

import numpy as np
from numpy._core import umath as _umath
from numpy.typing import ArrayLike, NDArray

from camtool.accel.loader import KernelsOnDemand
from camtool.geometry import fiterror
from camtool.model.errors import GeometryError, InputError, UsageError
from camtool.model.shapes import TAU, Arc, Line, Point, Segment, chord_count, make_arc, make_line

__all__ = [
    "CORNER_ANGLE_DEG",
    "FIT_KERNELS",
    "KERNEL_FROM",
    "MAX_DEPTH",
    "MAX_SWEEP",
    "FitStats",
    "chord_equivalent",
    "distances",
    "fit_curve",
    "fit_limits",
    "fit_polyline",
    "fit_stats",
    "segments_of",
]

FloatArray: TypeAlias = NDArray[np.float64]
PointsFn: TypeAlias = Callable[[FloatArray], FloatArray]
"""A curve evaluated at ``(N,)`` parameters: ``(N, 2)`` points (see :func:`fit_curve`)."""

_clip = getattr(_umath, "clip", np.clip)
"""``np.clip``'s own ufunc, without its Python wrapper (~10 µs a call): the same floats."""

MAX_SWEEP = math.pi
"""Largest sweep of one output arc, radians: 180° arcs are safe in every dialect (I/J or R)."""


def check_tolerance(tolerance: float) -> float:
    """``tolerance`` as a float, mm.

    Raises:
        UsageError: it is not a positive finite number.
    """
    tol = float(tolerance)
    if not (math.isfinite(tol) and tol > 0):
        raise UsageError(
            f"arc fitting tolerance must be a positive number of mm, got {tolerance!r}"
        )
    return tol


# Two sets of exact distances, on purpose: these (hypot, atan2) are the polyline fit's and
# the tests' judge, their floats held by tests/geometry/test_arcfit_columns.py; the curve
# fit measures with :mod:`camtool.geometry.fiterror` (square roots, cross products), whose
# floats the compiled fitter reproduces. One set for both would move the polyline fit's
# decisions at the tolerance by an ulp.


def distances(xy: ArrayLike, segments: Sequence[Segment]) -> FloatArray:
    """Distance from each point to the nearest of ``segments`` (exact for lines and arcs).

    Args:
        xy: ``(N, 2)`` float64 points, mm.
        segments: at least one line or arc.

    Returns:
        ``(N,)`` float64 distances, mm.
    """
    pts = np.asarray(xy, dtype=np.float64).reshape(-1, 2)
    first, *rest = segments
    out = dist_segment(pts, first)
    for seg in rest:  # what np.min(..., axis=0) of the stack gives, one minimum at a time
        out = np.minimum(out, dist_segment(pts, seg))
    return out


def dist_segment(xy: FloatArray, seg: Segment) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to one line or arc, mm."""
    return dist_line(xy, seg.start, seg.end) if isinstance(seg, Line) else dist_arc(xy, seg)


def dist_line(xy: FloatArray, a: Point, b: Point) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to the segment ``a``–``b``."""
    dx, dy = b[0] - a[0], b[1] - a[1]
    rx, ry = xy[:, 0] - a[0], xy[:, 1] - a[1]
    ll = dx * dx + dy * dy
    u = _clip((rx * dx + ry * dy) / ll, 0.0, 1.0) if ll > 0 else np.zeros(len(xy))
    return np.hypot(rx - u * dx, ry - u * dy)


def dist_arc(xy: FloatArray, arc: Arc) -> FloatArray:
    """``(N,)`` distances from ``xy`` ``(N, 2)`` to ``arc``: radial inside the sweep, else ends."""
    x, y = xy[:, 0], xy[:, 1]
    (cx, cy), (sx, sy), (ex, ey) = arc.centre, arc.start, arc.end
    rx, ry = x - cx, y - cy
    sweep = arc.sweep
    ang = np.arctan2(ry, rx) - math.atan2(sy - cy, sx - cx)  # Arc.start_angle
    inside = np.mod(ang if sweep > 0 else -ang, TAU) <= abs(sweep)
    ends = np.minimum(np.hypot(x - sx, y - sy), np.hypot(x - ex, y - ey))
    return np.where(inside, np.abs(np.hypot(rx, ry) - math.hypot(sx - cx, sy - cy)), ends)


# ---------------------------------------------------------------------------- fit stats

MAX_DEPTH = 40
"""Default limit of midpoint subdivisions in :func:`fit_curve` (2**-40 of the range)."""

_SAMPLES = 32  # coarse intervals per curve piece; the curve is evaluated at 2*_SAMPLES + 1 params
_SAFETY = 0.97  # share of the tolerance the sampled error may use (room for sampling gaps)
_FLAT = 0.1  # an arc whose sagitta is below _FLAT * tolerance is emitted as a Line


@dataclass(frozen=True)
class FitStats:
    """How much a fit saved: ``replaced`` input segments became ``arcs + lines`` segments.

    ``replaced`` counts polyline edges for :func:`fit_polyline` and, for :func:`fit_curve`,
    the chords a G01-only path would need at the same tolerance (:func:`chord_equivalent`).
    Stats add up with ``+`` over contours.
    """

    replaced: int
    arcs: int
    lines: int

    @property
    def segments(self) -> int:
        """Output segments, ``arcs + lines``."""
        return self.arcs + self.lines

    @property
    def saved(self) -> int:
        """``replaced - segments`` (negative if the fit made more segments than it replaced)."""
        return self.replaced - self.segments

    def __add__(self, other: FitStats) -> FitStats:
        return FitStats(
            self.replaced + other.replaced, self.arcs + other.arcs, self.lines + other.lines
        )

    def summary(self) -> str:
        """User message: ``arc fitting replaced 999 segments by 3 (3 arcs, 0 lines)``."""
        return (
            f"arc fitting replaced {self.replaced} segments by {self.segments} "
            f"({self.arcs} arcs, {self.lines} lines)"
        )


def fit_stats(replaced: int, segments: Iterable[Segment]) -> FitStats:
    """Stats of a fit that turned ``replaced`` input segments into ``segments``."""
    segs = list(segments)
    arcs = sum(isinstance(s, Arc) for s in segs)
    return FitStats(replaced, arcs, len(segs) - arcs)


def chord_equivalent(segments: Iterable[Segment], tolerance: float) -> int:
    """Chords (G01 moves) the segments would need at ``tolerance`` mm: lines 1, arcs by sagitta.

    Raises:
        UsageError: ``tolerance`` is not a positive finite number.
    """
    tol = check_tolerance(tolerance)
    return sum(
        chord_count(s.radius, abs(s.sweep), tol) if isinstance(s, Arc) else 1 for s in segments
    )


# ---------------------------------------------------------------------------- fit_curve

KERNEL_FROM = 400
"""Curve fits asked for in this process (this one's included) from which the compiled
fitter is loaded (``camtool/accel/fitkernels.py``: the same fits; loading numba and its
cache costs about as much as 400 plain fits of SVG curves). Below it, and with
``CAMTOOL_ACCEL=0``, every fit is the plain one."""

FIT_KERNELS = KernelsOnDemand("camtool.accel.fitkernels", KERNEL_FROM)
"""The compiled fitter, once enough curves were fitted."""


def fit_curve(
    point_at: Callable[[float], Point],
    tangent_at: Callable[[float], Point] | None,
    t0: float,
    t1: float,
    tolerance: float,
    *,
    max_depth: int = MAX_DEPTH,
    points_at: PointsFn | None = None,
) -> list[Segment]:
    """Fit a smooth parametric curve with biarcs and lines within ``tolerance`` mm.

    The range is split at midpoint parameters until each piece fits: first as one
    :class:`~camtool.model.shapes.Line` (every sample within tolerance of the chord), else as a
    biarc through the piece's ends tangent to the curve there, its junction chosen by the
    equal-tangent-length rule (d1 = d2, Bolton 1975). The error is sampled at 65 parameters
    per piece both ways (curve -> arcs exactly, arcs -> curve against the sampled polyline plus
    its chord sagitta) and must stay within 97 % of ``tolerance``. A piece whose end tangents
    point away from its chord (loops, closed curves, sweeps over 180°) is split before fitting;
    S-shaped pieces get an S biarc or are split like any other. Arcs flatter than a tenth of
    the tolerance become lines. Finally neighbouring arcs on one circle (and collinear lines)
    are merged when the merged segment stays within tolerance (arcs up to :data:`MAX_SWEEP`).

    Args:
        point_at: curve point ``(x, y)`` in mm at a parameter in ``[t0, t1]``; the curve
            must be continuous.
        tangent_at: derivative (any length, pointing towards increasing ``t``) or ``None``.
            Where it is ``None``, zero or tiny (cusps) the tangent is estimated by one-sided
            differences inside the piece.
        t0: first parameter.
        t1: last parameter, ``> t0``.
        tolerance: largest distance between the curve and the output, mm (> 0).
        max_depth: subdivision limit.
        points_at: optional, ``point_at`` on an ``(N,)`` array of parameters at once
            (``(N, 2)``), bit for bit equal to calling ``point_at`` on each (e.g.
            :func:`camtool.geometry.curves.cubic_bezier_points`): the 63 inner samples of
            each piece are then evaluated in one call. The fit is the same with or without
            it; where it gives a non-finite point the samples are taken one by one again
            (so the error names the parameter).

    Returns:
        Segments from ``point_at(t0)`` to ``point_at(t1)`` (exactly), each starting at the end
        of the one before; empty when the curve ends where it starts and never leaves the
        tolerance of that point (one point, or a loop smaller than the tolerance).

    Raises:
        UsageError: bad ``tolerance`` or parameter range.
        GeometryError: a curve point is not finite, or the fit needs more than ``max_depth``
            subdivisions (the message gives the parameter where).
    """
    tol = check_tolerance(tolerance)
    if not (math.isfinite(t0) and math.isfinite(t1) and t1 > t0):
        raise UsageError(f"curve parameters must be finite with t1 > t0, got {t0!r}, {t1!r}")
    kernels = FIT_KERNELS.get(1)
    curve = _Curve(point_at, tangent_at, _SAFETY * tol, max_depth, tolerance, points_at, kernels)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is an error, raised
        pieces = _fit_piece(curve, t0, curve.point(t0), t1, curve.point(t1), 0)
    if kernels is None:
        return _merge(pieces, curve.tol)
    rows = [_row(seg) for p in pieces for seg in p.segs]
    if not rows:
        return []
    piece = np.array([k for k, p in enumerate(pieces) for _ in p.segs], dtype=np.int64)
    errors = np.array([p.error for p in pieces])
    return segments_of(kernels.merge(np.array(rows), piece, errors, curve.tol))


def _row(seg: Segment) -> tuple[float, ...]:
    """A segment as the compiled fitter's row: kind (0 line, 1 ccw, 2 cw), start, end, centre."""
    if isinstance(seg, Line):
        return (0.0, *seg.start, *seg.end, 0.0, 0.0)
    return (2.0 if seg.clockwise else 1.0, *seg.start, *seg.end, *seg.centre)


def segments_of(rows: FloatArray) -> list[Segment]:
    """Segments from the compiled fitter's ``(M, 7)`` rows (kind, start, end, centre), in order."""
    return [
        make_line((x0, y0), (x1, y1))
        if kind == 0
        else make_arc((x0, y0), (x1, y1), (cx, cy), kind == 2)
        for kind, x0, y0, x1, y1, cx, cy in rows.tolist()
    ]


def fit_limits(tolerance: float) -> tuple[float, float]:
    """``(error limit, flat)`` of :func:`fit_curve` at ``tolerance`` mm: 97 % of it, a tenth.

    A piece fits when its sampled error is within the first; an arc whose sagitta is
    within the second is written as a line.

    Raises:
        UsageError: ``tolerance`` is not a positive finite number.
    """
    tol = check_tolerance(tolerance)
    return _SAFETY * tol, _FLAT * tol


@dataclass(frozen=True)
class _Piece:
    """Segments fitted to one parameter piece and their two-sided error there, mm."""

    segs: tuple[Segment, ...]
    error: float


@dataclass(frozen=True)
class _Curve:
    point_at: Callable[[float], Point]
    tangent_at: Callable[[float], Point] | None
    tol: float  # internal tolerance (safety share applied)
    max_depth: int
    user_tol: float
    points_at: PointsFn | None = None
    kernels: Any = None  # the compiled fitter's module, for the distances (the same floats)

    def line_error(self, fine: FloatArray, pa: Point, pb: Point) -> float:
        """Largest distance of the samples ``fine`` from the chord ``pa``–``pb``, mm."""
        if self.kernels is not None:
            return float(self.kernels.line_error(fine, pa[0], pa[1], pb[0], pb[1]))
        return float(fiterror.dist_line(fine, pa, pb).max())

    def error(self, segs: tuple[Segment, ...], fine: FloatArray, pa: Point) -> float:
        """:func:`~camtool.geometry.fiterror.piece_error` of ``segs`` up to :attr:`tol`."""
        if self.kernels is not None:
            rows = np.array([_row(s) for s in segs]).reshape(-1, 7)
            return float(self.kernels.piece_error(rows, len(segs), fine, *pa, self.tol))
        return fiterror.piece_error(segs, fine, pa, self.tol)

    def point(self, t: float) -> Point:
        return _as_point(self.point_at(t), f"curve point at t={t!r}")

    def samples(self, ta: float, pa: Point, tb: float, pb: Point) -> FloatArray:
        """``(2n+1, 2)`` curve points at evenly spaced parameters from ``ta`` to ``tb``."""
        ts = _linspace(ta, tb)
        if self.points_at is not None:
            fine = np.empty((len(ts), 2))
            fine[1:-1] = self.points_at(ts[1:-1])
            if np.isfinite(fine[1:-1]).all():
                fine[0], fine[-1] = pa, pb
                return fine
        inner = [self.point(float(t)) for t in ts[1:-1]]
        return np.array([pa, *inner, pb], dtype=np.float64)

    def tangent(self, t: float, p: Point, span: float, speed: float) -> Point | None:
        """Unit tangent at ``t``, one-sided into the piece: ``span`` > 0 ahead, < 0 behind."""
        if self.tangent_at is not None:
            dx, dy = _as_point(self.tangent_at(t), f"curve tangent at t={t!r}")
            norm = fiterror.norm(dx, dy)
            if norm > 1e-9 * speed:
                return (dx / norm, dy / norm)
        for share in (1e-4, 1e-2, 0.25):  # t + 2h stays inside the piece
            h = span * share
            p1, p2 = self.point(t + h), self.point(t + 2 * h)
            d1 = ((p1[0] - p[0]) / h, (p1[1] - p[1]) / h)
            d2 = (
                (4 * p1[0] - 3 * p[0] - p2[0]) / (2 * h),
                (4 * p1[1] - 3 * p[1] - p2[1]) / (2 * h),
            )
            n1, n2 = fiterror.norm(*d1), fiterror.norm(*d2)
            best, norm = (d2, n2) if n2 >= 0.5 * n1 else (d1, n1)  # cusp: first order
            if norm > 0:
                return (best[0] / norm, best[1] / norm)
        return None


_STEPS = np.arange(0, 2 * _SAMPLES + 1, dtype=np.float64)
_STEPS.setflags(write=False)


def _linspace(ta: float, tb: float) -> FloatArray:
    """``np.linspace(ta, tb, 2 * _SAMPLES + 1)`` without its ~20 µs of Python: its float steps.

    numpy 2 computes ``arange(num) * ((tb - ta) / div) + ta`` (``/ div`` then ``* delta``
    when the step underflows to 0) and sets the last to ``tb``; so does this.
    """
    delta = tb - ta
    step = delta / (2 * _SAMPLES)
    if step == 0:
        y = _STEPS / (2 * _SAMPLES)
        y *= delta
    else:
        y = _STEPS * step
    y += ta
    y[-1] = tb
    return y


def _fit_piece(c: _Curve, ta: float, pa: Point, tb: float, pb: Point, depth: int) -> list[_Piece]:
    fine = c.samples(ta, pa, tb, pb)
    segs = _candidate(c, ta, pa, tb, pb, fine)
    if segs is not None:
        error = c.error(segs, fine, pa)
        if error <= c.tol:
            return [_Piece(segs, error)]
    if depth >= c.max_depth:
        raise GeometryError(
            f"arc fitting did not converge near t={ta!r}..{tb!r} after {depth} subdivisions "
            f"at tolerance {c.user_tol!r} mm; is the curve continuous?"
        )
    tm = 0.5 * (ta + tb)
    pm = c.point(tm)
    return _fit_piece(c, ta, pa, tm, pm, depth + 1) + _fit_piece(c, tm, pm, tb, pb, depth + 1)


def _candidate(
    c: _Curve, ta: float, pa: Point, tb: float, pb: Point, fine: FloatArray
) -> tuple[Segment, ...] | None:
    """One line, or a biarc, for the piece; ``None`` when it must be split first."""
    if c.line_error(fine, pa, pb) <= c.tol:
        return () if pa == pb else (Line(pa, pb),)
    vx, vy = pb[0] - pa[0], pb[1] - pa[1]
    chord = fiterror.norm(vx, vy)
    if chord == 0.0:
        return None
    speed = chord / (tb - ta)
    s0 = c.tangent(ta, pa, tb - ta, speed)
    s1 = c.tangent(tb, pb, ta - tb, speed)
    if s0 is None or s1 is None:
        return None
    if s0[0] * vx + s0[1] * vy <= 0.0 or s1[0] * vx + s1[1] * vy <= 0.0:
        return None
    return _biarc(pa, s0, pb, s1, _FLAT * c.user_tol)


def _biarc(pa: Point, s0: Point, pb: Point, s1: Point, flat: float) -> tuple[Segment, ...]:
    """Biarc from ``pa`` (unit tangent ``s0``) to ``pb`` (unit tangent ``s1``), d1 = d2.

    With ``v = pb - pa`` and ``t = s0 + s1`` the common tangent length ``d`` solves
    ``2(1 - s0·s1) d² + 2 (v·t) d - v·v = 0``; the junction is the midpoint of
    ``pa + d s0`` and ``pb - d s1``. Needs ``v·s0 > 0`` and ``v·s1 > 0``.
    """
    vx, vy = pb[0] - pa[0], pb[1] - pa[1]
    vv = vx * vx + vy * vy
    vt = vx * (s0[0] + s1[0]) + vy * (s0[1] + s1[1])
    one_minus_cos = max(0.0, 1.0 - (s0[0] * s1[0] + s0[1] * s1[1]))
    d = vv / (vt + math.sqrt(vt * vt + 2.0 * one_minus_cos * vv))  # stable root
    j = (0.5 * (pa[0] + pb[0] + d * (s0[0] - s1[0])), 0.5 * (pa[1] + pb[1] + d * (s0[1] - s1[1])))
    tiny = 1e-9 * math.sqrt(vv)
    if (
        fiterror.norm(j[0] - pa[0], j[1] - pa[1]) <= tiny
        or fiterror.norm(pb[0] - j[0], pb[1] - j[1]) <= tiny
    ):
        return (_arc_from(pa, s0, pb, flat),)
    first = _arc_from(pa, s0, j, flat)
    second = _arc_from(pb, (-s1[0], -s1[1]), j, flat).reversed()
    return (first, second)


def _arc_from(p: Point, s: Point, q: Point, flat: float) -> Segment:
    """Arc from ``p`` leaving along unit ``s`` to ``q``; a Line when its sagitta ≤ ``flat``."""
    vx, vy = q[0] - p[0], q[1] - p[1]
    chord = fiterror.norm(vx, vy)
    nv = -s[1] * vx + s[0] * vy  # left normal · chord
    sin_a, cos_a = nv / chord, (s[0] * vx + s[1] * vy) / chord
    if abs(sin_a) < 1e-12:
        return Line(p, q)
    radius = chord / (2.0 * abs(sin_a))
    sagitta = chord * abs(sin_a) / (2.0 * (1.0 + cos_a)) if cos_a > 0 else radius * (1 - cos_a)
    if sagitta <= flat:
        return Line(p, q)
    k = (vx * vx + vy * vy) / (2.0 * nv)  # signed radius along the left normal
    return Arc(p, q, (p[0] - k * s[1], p[1] + k * s[0]), k < 0)


def _merge(pieces: Sequence[_Piece], tol: float) -> list[Segment]:
    """Merge neighbouring arcs on one circle and collinear lines where it stays within tol.

    The merged segment's error is bounded by the pieces' error plus its two-sided distance
    to the segments it replaces (triangle inequality), so the curve is not sampled again.
    """
    groups: list[tuple[Segment, tuple[Segment, ...], float]] = []
    for piece in pieces:
        for seg in piece.segs:
            if groups:
                prev, originals, error = groups[-1]
                joined = _join(prev, seg, tol)
                if joined is not None:
                    err = max(error, piece.error)
                    group = (*originals, seg)
                    if err + _hausdorff(joined, group) <= tol:
                        groups[-1] = (joined, group, err)
                        continue
            groups.append((seg, (seg,), piece.error))
    return [g[0] for g in groups]


def _join(a: Segment, b: Segment, tol: float) -> Segment | None:
    """One segment from ``a.start`` to ``b.end`` when both are lines or arcs of one circle.

    In :mod:`~camtool.geometry.fiterror`'s operations (the compiled fitter's twin).
    """
    if isinstance(a, Line) and isinstance(b, Line):
        return Line(a.start, b.end)
    if not (isinstance(a, Arc) and isinstance(b, Arc)) or a.clockwise != b.clockwise:
        return None
    (acx, acy), (bcx, bcy) = a.centre, b.centre
    ra = fiterror.norm(a.start[0] - acx, a.start[1] - acy)
    rb = fiterror.norm(b.start[0] - bcx, b.start[1] - bcy)
    if fiterror.norm(bcx - acx, bcy - acy) > tol or abs(ra - rb) > tol:
        return None
    (x0, y0), (x1, y1) = a.start, b.end
    ux, uy = x1 - x0, y1 - y0
    chord = fiterror.norm(ux, uy)
    if chord <= 1e-9 * ra:
        return None
    nx, ny = -uy / chord, ux / chord
    mx, my = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    cx, cy = 0.5 * (acx + bcx), 0.5 * (acy + bcy)
    lam = (cx - mx) * nx + (cy - my) * ny  # centre on the bisector, nearest the mean centre
    arc = Arc(a.start, b.end, (mx + lam * nx, my + lam * ny), a.clockwise)
    sweep = fiterror.arc_sweep(arc)
    if abs(sweep) > MAX_SWEEP + 1e-9:
        return None
    if abs(sweep - fiterror.arc_sweep(a) - fiterror.arc_sweep(b)) > 1e-6:
        return None
    return arc


def _hausdorff(seg: Segment, others: Sequence[Segment]) -> float:
    """Sampled two-sided distance between ``seg`` and the union of ``others``, mm."""
    there = float(fiterror.distances(fiterror.sample(seg, 4 * fiterror.SEG_SAMPLES), others).max())
    back = np.vstack([fiterror.sample(o) for o in others])
    return max(there, float(fiterror.distances(back, (seg,)).max()))


def _as_point(value: Iterable[float], what: str) -> Point:
    try:
        x, y = (float(v) for v in value)
    except (TypeError, ValueError) as exc:
        raise GeometryError(f"{what} must be two numbers, got {value!r}") from exc
    if not (math.isfinite(x) and math.isfinite(y)):
        raise GeometryError(f"{what} is not finite: ({x!r}, {y!r})")
    return (x, y)


# ---------------------------------------------------------------------------- fit_polyline

CORNER_ANGLE_DEG = 30.0
"""Default turn, degrees, above which :func:`fit_polyline` keeps a vertex as a corner."""

_CORNER_SPAN = 5.0  # polyline corners are judged over this many tolerances of length
_DUPLICATE = 1e-9  # mm: polyline points closer than this to the previous one are dropped


def fit_polyline(
    points: ArrayLike,
    tolerance: float,
    *,
    closed: bool = False,
    corner_angle_deg: float = CORNER_ANGLE_DEG,
) -> list[Segment]:
    """Turn a dense polyline into lines and arcs within ``tolerance`` mm of it.

    Corners are kept: a vertex whose turn over ±5 tolerances of length exceeds
    ``corner_angle_deg`` (the sharpest in that neighbourhood, so noise and dense sampling
    near a corner give one corner), or whose own turn does so with both edges longer than the
    tolerance. A buffer with shapely's default 8 segments per quarter turns 11.25° per vertex
    and stays smooth. Between corners, segments grow greedily (doubling, then bisection) to
    the longest run that fits one Line (every point within tolerance of the chord) or one Arc
    through the run's end points, its centre fitted by least squares (Kåsa, constrained to
    the chord bisector) and verified: every point within tolerance, points in order along
    the sweep, each edge's sagitta plus radial error within tolerance, sweep ≤ :data:`MAX_SWEEP`.
    Points closer than 1e-9 mm to the previous one are dropped.

    Args:
        points: ``(N, 2)`` float64 vertices, mm; for ``closed`` the last may repeat the first.
        tolerance: largest distance between polyline and output, both ways, mm (> 0).
        closed: the polyline returns from the last vertex to the first.
        corner_angle_deg: turn in degrees above which a vertex is a corner.

    Returns:
        Segments from the first vertex through the last exactly (back to the first when
        ``closed``), each starting at the end of the one before.

    Raises:
        InputError: points are not ``(N, 2)`` finite numbers, or fewer than 2 distinct
            (3 when ``closed``).
        UsageError: bad ``tolerance``.
    """
    tol = check_tolerance(tolerance)
    xy = _clean(points, closed)
    tp = [(float(x), float(y)) for x, y in xy]
    if closed:
        tp[-1] = tp[0]
    breaks = _breaks(xy, tol, math.radians(corner_angle_deg), closed)
    out: list[Segment] = []
    for a, b in itertools.pairwise(breaks):
        out.extend(_fit_run(xy, tp, a, b, tol))
    return out


def _clean(points: ArrayLike, closed: bool) -> FloatArray:
    """Finite ``(M, 2)`` vertices without repeats; for ``closed`` the first is appended."""
    try:
        xy = np.array(points, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise InputError(f"polyline points must be numbers: {exc}") from exc
    if xy.size == 0:
        raise InputError("a polyline needs 2 distinct points, got none")
    if xy.ndim != 2 or xy.shape[1] != 2:
        raise InputError(f"polyline points must be an (N, 2) array, got shape {xy.shape}")
    if not np.all(np.isfinite(xy)):
        raise InputError("polyline points must be finite, found NaN or infinity")
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.hypot(*np.diff(xy, axis=0).T) > _DUPLICATE
    xy = xy[keep]
    if closed:
        while len(xy) > 1 and math.dist(xy[-1], xy[0]) <= _DUPLICATE:
            xy = xy[:-1]
        if len(xy) < 3:
            raise InputError(f"a closed polyline needs 3 distinct points, got {len(xy)}")
        xy = np.vstack([xy, xy[:1]])
    elif len(xy) < 2:
        raise InputError(f"a polyline needs 2 distinct points, got {len(xy)}")
    xy.setflags(write=False)
    return xy


def _breaks(xy: FloatArray, tol: float, corner: float, closed: bool) -> list[int]:
    """Sorted vertex indices where runs end: both ends and the corners.

    A closed ring is tripled so that turns and neighbourhoods near vertex 0 wrap around;
    its corners are read from the middle copy.
    """
    ring = xy[:-1] if closed else xy
    n = len(ring)
    ext = np.vstack([ring, ring, ring]) if closed else ring
    idx = np.arange(1, len(ext) - 1)
    if len(idx) == 0:
        return [0, len(xy) - 1]
    edge = np.hypot(*np.diff(ext, axis=0).T)
    s = np.concatenate([[0.0], np.cumsum(edge)])
    span = _CORNER_SPAN * tol
    back = np.minimum(np.searchsorted(s, s[idx] - span, side="right") - 1, idx - 1)
    ahead = np.maximum(np.searchsorted(s, s[idx] + span, side="left"), idx + 1)
    back, ahead = np.maximum(back, 0), np.minimum(ahead, len(ext) - 1)
    wide = _turn(ext[idx] - ext[back], ext[ahead] - ext[idx])
    near = _turn(ext[idx] - ext[idx - 1], ext[idx + 1] - ext[idx])
    sharp = (near > corner) & (np.minimum(edge[idx - 1], edge[idx]) > tol)
    corners = set(idx[sharp].tolist())
    cand = np.flatnonzero(wide > corner)
    where = s[idx[cand]]
    for k, pos in zip(cand, where, strict=True):  # the sharpest within ±span (ties: the first)
        lo, hi = np.searchsorted(where, [pos - span, pos + span])
        window = cand[lo:hi]
        if window[np.argmax(wide[window])] == k:
            corners.add(int(idx[k]))
    if closed:
        corners = {i - n for i in corners if n <= i < 2 * n}
    inner = sorted(i for i in corners if 0 < i < len(xy) - 1)
    return [0, *inner, len(xy) - 1]


def _turn(u: FloatArray, v: FloatArray) -> FloatArray:
    """Unsigned angle (radians) between direction rows ``u`` and ``v``, both ``(N, 2)``."""
    cross = u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]
    dot = u[:, 0] * v[:, 0] + u[:, 1] * v[:, 1]
    return np.abs(np.arctan2(cross, dot))


def _fit_run(xy: FloatArray, tp: list[Point], a: int, b: int, tol: float) -> list[Segment]:
    """Greedy longest segments from vertex ``a`` to vertex ``b``."""
    out: list[Segment] = []
    s = a
    while s < b:
        ok, seg = s + 1, _try(xy, tp, s, s + 1, tol)
        fail = None
        step = 2
        while ok < b:  # doubling ...
            e = min(s + step, b)
            got = _try(xy, tp, s, e, tol)
            if got is None:
                fail = e
                break
            ok, seg, step = e, got, 2 * step
        while fail is not None and fail - ok > 1:  # ... then bisection
            mid = (ok + fail) // 2
            got = _try(xy, tp, s, mid, tol)
            if got is None:
                fail = mid
            else:
                ok, seg = mid, got
        assert seg is not None  # two vertices always make a line
        out.append(seg)
        s = ok
    return out


def _try(xy: FloatArray, tp: list[Point], s: int, e: int, tol: float) -> Segment | None:
    """A Line (preferred) or an Arc from vertex ``s`` to ``e`` within ``tol``, else None."""
    if e == s + 1:
        return Line(tp[s], tp[e])
    if math.dist(tp[s], tp[e]) <= _DUPLICATE:  # a loop back to its start is two segments
        return None
    pts = xy[s : e + 1]
    if float(np.max(dist_line(pts, tp[s], tp[e]))) <= tol:
        return Line(tp[s], tp[e])
    return _fit_arc(pts, tp[s], tp[e], tol)


def _fit_arc(pts: FloatArray, a: Point, b: Point, tol: float) -> Arc | None:
    """Arc from ``a`` to ``b`` (the ends of ``pts``) fitted to ``pts`` and verified."""
    rel = pts - pts[0]
    vx, vy = rel[-1]
    chord = math.hypot(vx, vy)
    nx, ny = -vy / chord, vx / chord
    # centre c = v/2 + lam n (origin at a): |r_i - c|² - |c|² = |r_i|² - r_i·v - 2 lam n·r_i
    rhs = np.einsum("ij,ij->i", rel, rel) - (rel[:, 0] * vx + rel[:, 1] * vy)
    coef = 2.0 * (rel[:, 0] * nx + rel[:, 1] * ny)
    den = float(coef @ coef)
    side = float(np.sum(vx * rel[:, 1] - vy * rel[:, 0]))
    if den == 0.0 or side == 0.0:
        return None
    lam = float(rhs @ coef) / den
    centre = (a[0] + 0.5 * vx + lam * nx, a[1] + 0.5 * vy + lam * ny)
    arc = Arc(a, b, centre, side > 0)  # points right of the chord: counter-clockwise
    if abs(arc.sweep) > MAX_SWEEP + 1e-9 or not _arc_fits(arc, pts, tol):
        return None
    return arc


def _arc_fits(arc: Arc, pts: FloatArray, tol: float) -> bool:
    """Every point within ``tol``, in order along the sweep, every edge's bulge within ``tol``."""
    if float(np.max(dist_arc(pts, arc))) > tol:
        return False
    r, sweep = arc.radius, abs(arc.sweep)
    rel = pts - np.asarray(arc.centre)
    ang = np.arctan2(rel[:, 1], rel[:, 0]) - arc.start_angle
    delta = np.mod(-ang if arc.clockwise else ang, TAU)
    delta = np.where(delta > 0.5 * (sweep + TAU), delta - TAU, delta)  # just before the start
    slack = tol / r
    if np.any(delta < np.maximum.accumulate(delta) - slack):
        return False
    radial = np.abs(np.hypot(rel[:, 0], rel[:, 1]) - r)
    step = np.minimum(np.abs(np.diff(delta)), math.pi)
    bulge = 2.0 * r * np.sin(0.25 * step) ** 2 + np.maximum(radial[:-1], radial[1:])
    return bool(np.max(bulge) <= tol)
