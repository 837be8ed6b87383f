"""Arc fitting: analytic shapes, two-sided tolerance properties, corners, stats.

Distances here are computed independently of camtool.geometry.arcfit: the exact distance from
a point to a line or arc, and from a point to the TRUE curve as the distance to a real curve
point, found near the nearest chord of a dense polyline by golden-section search.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence

import numpy as np
import pytest
import shapely
from hypothesis import example, given, settings
from hypothesis import strategies as st

from camtool.geometry.arcfit import (
    MAX_SWEEP,
    FitStats,
    chord_equivalent,
    fit_curve,
    fit_polyline,
    fit_stats,
)
from camtool.model.errors import InputError, ToolpathError, UsageError
from camtool.model.shapes import Arc, Line, Segment

VecCurve = Callable[[np.ndarray], np.ndarray]  # (N,) params -> (N, 2) points, mm
SLACK = 1e-9


# ------------------------------------------------------------------ independent geometry


def seg_distance(xy: np.ndarray, seg: Segment) -> np.ndarray:
    if isinstance(seg, Line):
        a, b = np.array(seg.start), np.array(seg.end)
        d = b - a
        ll = float(d @ d)
        u = np.clip((xy - a) @ d / ll, 0, 1) if ll else np.zeros(len(xy))
        return np.linalg.norm(xy - a - u[:, None] * d, axis=1)
    c = np.array(seg.centre)
    rel = xy - c
    ang = np.arctan2(rel[:, 1], rel[:, 0])
    travelled = (ang - seg.start_angle) % (2 * math.pi)
    if seg.sweep < 0:
        travelled = (seg.start_angle - ang) % (2 * math.pi)
    on_sweep = travelled <= abs(seg.sweep)
    ends = np.minimum(
        np.linalg.norm(xy - np.array(seg.start), axis=1),
        np.linalg.norm(xy - np.array(seg.end), axis=1),
    )
    return np.where(on_sweep, np.abs(np.linalg.norm(rel, axis=1) - seg.radius), ends)


def dist_to_fit(xy: np.ndarray, segs: Sequence[Segment]) -> np.ndarray:
    return np.min([seg_distance(xy, s) for s in segs], axis=0)


def sample_fit(segs: Sequence[Segment], n: int = 60) -> np.ndarray:
    pts: list[tuple[float, float]] = []
    for s in segs:
        if isinstance(s, Line):
            (x0, y0), (x1, y1) = s.start, s.end
            pts += [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n + 1)]
        else:
            pts += [s.point_at(k / n) for k in range(n + 1)]
    return np.array(pts)


def dist_to_curve(xy: np.ndarray, curve: VecCurve, t0: float, t1: float) -> np.ndarray:
    """Upper bound of each point's distance to the curve: the distance to a real curve point.

    The nearest chord of a 20001-point polyline (shapely STRtree) picks the branch; golden-section
    search on the parameter around that chord finds the nearest curve point on it.
    """
    ts = np.linspace(t0, t1, 20001)
    dense = curve(ts)
    chords = shapely.STRtree(shapely.linestrings(np.stack([dense[:-1], dense[1:]], axis=1)))
    which, chord = chords.query_nearest(shapely.points(xy), all_matches=False)
    k = np.empty(len(xy), dtype=int)
    k[which] = chord + 1  # chord i joins dense[i] and dense[i + 1]
    lo, hi = ts[np.clip(k - 2, 0, len(ts) - 1)], ts[np.clip(k + 1, 0, len(ts) - 1)]
    g = (math.sqrt(5) - 1) / 2
    for _ in range(60):  # golden section on each bracket, vectorised
        a, b = hi - g * (hi - lo), lo + g * (hi - lo)
        fa = np.linalg.norm(curve(a) - xy, axis=1)
        fb = np.linalg.norm(curve(b) - xy, axis=1)
        left = fa < fb
        hi, lo = np.where(left, b, hi), np.where(left, lo, a)
    refined = np.linalg.norm(curve(0.5 * (lo + hi)) - xy, axis=1)
    nearest_vertex = np.linalg.norm(dense[np.clip(k, 0, len(ts) - 1)] - xy, axis=1)
    return np.minimum(refined, nearest_vertex)


def assert_chain(segs: Sequence[Segment], first: tuple[float, float], last: tuple[float, float]):
    assert segs, "expected at least one segment"
    assert segs[0].start == first
    assert segs[-1].end == last
    for a, b in itertools.pairwise(segs):
        assert a.end == b.start  # bit for bit
    for s in segs:
        if isinstance(s, Arc):
            assert math.dist(s.centre, s.end) == pytest.approx(s.radius, rel=1e-9, abs=1e-12)
            assert abs(s.sweep) <= MAX_SWEEP + 1e-9


def assert_two_sided(segs: Sequence[Segment], curve: VecCurve, t0: float, t1: float, tol: float):
    true_pts = curve(np.linspace(t0, t1, 401))
    forward = dist_to_fit(true_pts, segs)
    assert forward.max() <= tol + SLACK, f"curve {forward.max():.3g} mm from fit, tol {tol}"
    backward = dist_to_curve(sample_fit(segs), curve, t0, t1)
    assert backward.max() <= tol + SLACK, f"fit {backward.max():.3g} mm from curve, tol {tol}"


def scalar(curve: VecCurve) -> Callable[[float], tuple[float, float]]:
    """``curve`` at one parameter, as the fitter calls it: its plain-float form where it has
    one (``curve.scalar``: a Bézier's, an ellipse's), else the array form on one point."""
    plain = getattr(curve, "scalar", None)
    if plain is not None:
        return plain  # type: ignore[no-any-return]

    def point_at(t: float) -> tuple[float, float]:
        x, y = curve(np.array([t]))[0]
        return (float(x), float(y))

    return point_at


def bezier(ctrl: np.ndarray) -> tuple[VecCurve, VecCurve]:
    p0, p1, p2, p3 = ctrl

    def point(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)[:, None]
        u = 1 - t
        return u**3 * p0 + 3 * u**2 * t * p1 + 3 * u * t**2 * p2 + t**3 * p3

    def deriv(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)[:, None]
        u = 1 - t
        return 3 * (u**2 * (p1 - p0) + 2 * u * t * (p2 - p1) + t**2 * (p3 - p2))

    (x0, y0), (x1, y1), (x2, y2), (x3, y3) = ctrl.tolist()

    def point_scalar(t: float) -> tuple[float, float]:
        u = 1 - t
        a, b, c, d = u**3, 3 * u**2 * t, 3 * u * t**2, t**3
        return (a * x0 + b * x1 + c * x2 + d * x3, a * y0 + b * y1 + c * y2 + d * y3)

    def deriv_scalar(t: float) -> tuple[float, float]:
        u = 1 - t
        a, b, c = u**2, 2 * u * t, t**2
        return (
            3 * (a * (x1 - x0) + b * (x2 - x1) + c * (x3 - x2)),
            3 * (a * (y1 - y0) + b * (y2 - y1) + c * (y3 - y2)),
        )

    point.scalar = point_scalar  # type: ignore[attr-defined]
    deriv.scalar = deriv_scalar  # type: ignore[attr-defined]
    return point, deriv


def ellipse(cx: float, cy: float, a: float, b: float, rot: float) -> tuple[VecCurve, VecCurve]:
    c, s = math.cos(rot), math.sin(rot)

    def point(t: np.ndarray) -> np.ndarray:
        x, y = a * np.cos(t), b * np.sin(t)
        return np.column_stack([cx + c * x - s * y, cy + s * x + c * y])

    def deriv(t: np.ndarray) -> np.ndarray:
        dx, dy = -a * np.sin(t), b * np.cos(t)
        return np.column_stack([c * dx - s * dy, s * dx + c * dy])

    def point_scalar(t: float) -> tuple[float, float]:
        x, y = a * math.cos(t), b * math.sin(t)
        return (cx + c * x - s * y, cy + s * x + c * y)

    def deriv_scalar(t: float) -> tuple[float, float]:
        dx, dy = -a * math.sin(t), b * math.cos(t)
        return (c * dx - s * dy, s * dx + c * dy)

    point.scalar = point_scalar  # type: ignore[attr-defined]
    deriv.scalar = deriv_scalar  # type: ignore[attr-defined]
    return point, deriv


# ------------------------------------------------------------------ fit_curve: analytic


def circle(cx: float, cy: float, r: float) -> tuple[VecCurve, VecCurve]:
    return ellipse(cx, cy, r, r, 0.0)


@pytest.mark.parametrize("with_tangent", [True, False])
@pytest.mark.parametrize(
    ("start", "sweep", "max_arcs"),
    [(0.0, math.pi / 2, 1), (0.7, -math.pi / 2, 1), (0.2, math.pi, 1), (1.0, 2 * math.pi, 2)],
)
def test_circle_comes_back_as_its_own_arcs(start, sweep, max_arcs, with_tangent):
    tol = 0.01
    pt, dt = circle(1.0, 2.0, 5.0)
    if sweep < 0:  # run the parameter backwards: clockwise

        def pt_cw(t):
            return pt(2 * start - t)

        def dt_cw(t):
            return -dt(2 * start - t)

        curve, deriv, t0, t1 = pt_cw, dt_cw, start, start - sweep
    else:
        curve, deriv, t0, t1 = pt, dt, start, start + sweep
    segs = fit_curve(scalar(curve), scalar(deriv) if with_tangent else None, t0, t1, tol)
    assert 1 <= len(segs) <= max_arcs
    assert all(isinstance(s, Arc) for s in segs)
    for s in segs:
        assert isinstance(s, Arc)
        assert math.dist(s.centre, (1.0, 2.0)) <= tol
        assert abs(s.radius - 5.0) <= tol
        assert s.clockwise == (sweep < 0)
    assert sum(s.sweep for s in segs if isinstance(s, Arc)) == pytest.approx(sweep, abs=1e-6)
    assert_chain(segs, scalar(curve)(t0), scalar(curve)(t1))


def test_straight_curve_is_one_line_even_with_uneven_speed():
    segs = fit_curve(lambda t: (1 + 2 * t**3, 3 - t**3), None, 0.0, 1.0, 0.001)
    assert segs == [Line((1.0, 3.0), (3.0, 2.0))]


def test_huge_radius_becomes_a_line():
    # an arc of radius 1e6 mm over 10 mm bulges 1.25e-5 mm, far below tolerance / 10
    r = 1e6
    segs = fit_curve(lambda t: (r * math.sin(t), r - r * math.cos(t)), None, 0.0, 1e-5, 0.01)
    assert len(segs) == 1
    assert isinstance(segs[0], Line)


def test_point_curve_gives_nothing():
    assert fit_curve(lambda t: (2.0, 3.0), None, 0.0, 1.0, 0.01) == []


def test_cusp_with_zero_tangent():
    ctrl = np.array([(0.0, 0.0), (10.0, 10.0), (0.0, 10.0), (10.0, 0.0)])  # cusp at t = 0.5
    pt, dt = bezier(ctrl)
    assert np.allclose(dt(np.array([0.5])), 0.0)
    for deriv in (scalar(dt), None):
        segs = fit_curve(scalar(pt), deriv, 0.0, 1.0, 0.005)
        assert_chain(segs, (0.0, 0.0), (10.0, 0.0))
        assert_two_sided(segs, pt, 0.0, 1.0, 0.005)


def test_s_curve_is_fitted_within_tolerance():
    pt, dt = bezier(np.array([(0.0, 0.0), (5.0, 6.0), (5.0, -6.0), (10.0, 0.0)]))
    segs = fit_curve(scalar(pt), scalar(dt), 0.0, 1.0, 0.01)
    assert any(isinstance(s, Arc) and s.clockwise for s in segs)
    assert any(isinstance(s, Arc) and not s.clockwise for s in segs)
    assert_two_sided(segs, pt, 0.0, 1.0, 0.01)


def test_depth_limit_raises():
    pt, dt = ellipse(0, 0, 3, 1, 0)
    with pytest.raises(ToolpathError, match="did not converge"):
        fit_curve(scalar(pt), scalar(dt), 0.0, 2 * math.pi, 0.001, max_depth=2)


@pytest.mark.parametrize("bad", [0.0, -0.1, math.nan, math.inf])
def test_bad_tolerance(bad):
    with pytest.raises(UsageError, match="tolerance"):
        fit_curve(lambda t: (t, 0.0), None, 0.0, 1.0, bad)
    with pytest.raises(UsageError, match="tolerance"):
        fit_polyline([(0, 0), (1, 0)], bad)


def test_bad_range_and_points():
    with pytest.raises(UsageError, match="t1 > t0"):
        fit_curve(lambda t: (t, 0.0), None, 1.0, 1.0, 0.01)
    with pytest.raises(ToolpathError, match="not finite"):
        fit_curve(lambda t: (t, math.nan), None, 0.0, 1.0, 0.01)


# ------------------------------------------------------------------ fit_curve: properties

grid = st.integers(-50, 50).map(lambda v: v / 5)  # coincident/collinear controls happen
ctrl_points = st.lists(st.tuples(grid, grid), min_size=4, max_size=4).map(np.array)
tolerances = st.floats(0.001, 0.1)


@settings(max_examples=80, deadline=None)
@given(ctrl=ctrl_points, tol=tolerances, with_tangent=st.booleans())
@example(  # found by this search: a 0.087 mm loop at tol 0.094 mm fits as its start point
    ctrl=np.array([(0.0, 0.2), (0.0, 0.0), (0.0, 0.2), (0.0, 0.2)]), tol=0.09375, with_tangent=False
)
def test_cubic_bezier_two_sided_within_tolerance(ctrl, tol, with_tangent):
    pt, dt = bezier(ctrl)
    segs = fit_curve(scalar(pt), scalar(dt) if with_tangent else None, 0.0, 1.0, tol)
    if np.all(ctrl == ctrl[0]):
        assert segs == []
        return
    if not segs:  # a loop that never leaves the tolerance of its start: the fit is that point
        start = scalar(pt)(0.0)
        assert scalar(pt)(1.0) == start
        away = np.hypot(*(pt(np.linspace(0.0, 1.0, 401)) - start).T)
        assert away.max() <= tol + SLACK, f"curve {away.max():.3g} mm from its start, tol {tol}"
        return
    assert_chain(segs, scalar(pt)(0.0), scalar(pt)(1.0))
    assert_two_sided(segs, pt, 0.0, 1.0, tol)


@settings(max_examples=60, deadline=None)
@given(
    centre=st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
    rot=st.floats(0, math.pi),
    t0=st.floats(-math.pi, math.pi),
    span=st.floats(0.05, 2 * math.pi),
    tol=tolerances,
)
def test_ellipse_two_sided_within_tolerance(centre, rot, t0, span, tol):
    pt, dt = ellipse(centre[0], centre[1], 3.0, 1.0, rot)
    segs = fit_curve(scalar(pt), scalar(dt), t0, t0 + span, tol)
    assert_chain(segs, scalar(pt)(t0), scalar(pt)(t0 + span))
    assert_two_sided(segs, pt, t0, t0 + span, tol)


def test_svgpathtools_bezier_at_10_um_is_few_arcs():
    from svgpathtools import CubicBezier

    bez = CubicBezier(0 + 0j, 10 + 20j, 30 + 20j, 40 + 0j)

    def curve(t: np.ndarray) -> np.ndarray:
        z = np.array([bez.point(float(v)) for v in t])
        return np.column_stack([z.real, z.imag])

    segs = fit_curve(scalar(curve), None, 0.0, 1.0, 0.01)
    assert_two_sided(segs, curve, 0.0, 1.0, 0.01)
    assert sum(isinstance(s, Arc) for s in segs) == len(segs)
    # far fewer than the G01 chords the same tolerance needs
    assert len(segs) * 3 < chord_equivalent(segs, 0.01)


# ------------------------------------------------------------------ fit_polyline


def test_dense_circle_polyline_is_a_handful_of_arcs():
    th = np.linspace(0, 2 * math.pi, 1000, endpoint=False)
    pts = np.column_stack([3 + 5 * np.cos(th), -1 + 5 * np.sin(th)])
    segs = fit_polyline(pts, 0.01, closed=True)
    assert 2 <= len(segs) <= 4
    for s in segs:
        assert isinstance(s, Arc)
        assert abs(s.radius - 5.0) <= 0.01
        assert math.dist(s.centre, (3.0, -1.0)) <= 0.01
        assert not s.clockwise
    first = (float(pts[0, 0]), float(pts[0, 1]))
    assert_chain(segs, first, first)
    assert dist_to_fit(pts, segs).max() <= 0.01


def test_open_clockwise_arc_polyline():
    th = np.linspace(math.pi, 0.25 * math.pi, 400)  # decreasing angle: clockwise
    pts = np.column_stack([2 * np.cos(th), 2 * np.sin(th)])
    segs = fit_polyline(pts, 0.001)
    assert len(segs) <= 2
    assert all(isinstance(s, Arc) and s.clockwise and abs(s.radius - 2) <= 1e-3 for s in segs)
    assert_chain(segs, tuple(pts[0]), tuple(pts[-1]))


def test_rectangle_corners_are_kept():
    corners = [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (0.0, 5.0)]
    segs = fit_polyline(corners, 0.01, closed=True)
    assert segs == [Line(a, b) for a, b in zip(corners, corners[1:] + corners[:1], strict=True)]


@pytest.mark.parametrize("tol", [0.001, 0.05, 0.5])
def test_densely_sampled_rectangle_is_four_lines(tol):
    edges = [
        np.column_stack([np.arange(0, 10, 0.1), np.zeros(100)]),
        np.column_stack([np.full(50, 10.0), np.arange(0, 5, 0.1)]),
        np.column_stack([np.arange(10, 0, -0.1), np.full(100, 5.0)]),
        np.column_stack([np.zeros(50), np.arange(5, 0, -0.1)]),
    ]
    pts = np.vstack([*edges, [[0.0, 0.0]]])  # closing point repeated
    segs = fit_polyline(pts, tol, closed=True)
    assert all(isinstance(s, Line) for s in segs)
    got = [tuple(np.round(s.start, 9)) for s in segs]
    assert got == [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0), (0.0, 5.0)]


def test_buffered_rectangle_gives_lines_and_radius_1_arcs():
    ring = shapely.box(0, 0, 10, 5).buffer(1.0, quad_segs=64).exterior
    pts = np.asarray(ring.coords)
    segs = fit_polyline(pts, 0.01, closed=True)
    arcs = [s for s in segs if isinstance(s, Arc)]
    assert 4 <= len(arcs) <= 5 and len(segs) <= 10
    box_corners = [(0, 0), (10, 0), (10, 5), (0, 5)]
    for s in arcs:
        assert abs(s.radius - 1.0) <= 0.01
        assert min(math.dist(s.centre, c) for c in box_corners) <= 0.01
    assert dist_to_fit(pts, segs).max() <= 0.01


@settings(max_examples=60, deadline=None)
@given(
    seed=st.integers(0, 2**32 - 1),
    tol=st.floats(0.001, 0.1),
    noise=st.floats(0.0, 1.0),
    closed=st.booleans(),
)
def test_noisy_polyline_within_tolerance_both_ways(seed, tol, noise, closed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 1, int(rng.integers(20, 400)))
    amp = rng.uniform(-3, 3, size=(3, 2))
    smooth = np.column_stack([20 * t, np.zeros_like(t)]) + sum(
        np.column_stack([amp[k, 0] * np.sin((k + 1) * 3 * t), amp[k, 1] * np.cos((k + 2) * t)])
        for k in range(3)
    )
    pts = smooth + rng.normal(scale=noise * tol, size=smooth.shape)
    segs = fit_polyline(pts, tol, closed=closed)
    first, last = (float(pts[0, 0]), float(pts[0, 1])), (float(pts[-1, 0]), float(pts[-1, 1]))
    assert_chain(segs, first, first if closed else last)
    assert dist_to_fit(pts, segs).max() <= tol + SLACK
    poly = np.vstack([pts, pts[:1]]) if closed else pts
    back = shapely.distance(shapely.points(sample_fit(segs)), shapely.LineString(poly))
    assert back.max() <= tol + SLACK


def test_bad_polylines():
    with pytest.raises(InputError, match=r"\(N, 2\)"):
        fit_polyline([1.0, 2.0, 3.0], 0.01)
    with pytest.raises(InputError, match="finite"):
        fit_polyline([(0, 0), (math.nan, 1)], 0.01)
    with pytest.raises(InputError, match="2 distinct"):
        fit_polyline([(1, 1), (1, 1)], 0.01)
    with pytest.raises(InputError, match="2 distinct"):
        fit_polyline(np.zeros((0, 2)), 0.01)
    with pytest.raises(InputError, match="3 distinct"):
        fit_polyline([(0, 0), (1, 0), (0, 0)], 0.01, closed=True)


# ------------------------------------------------------------------ stats


def test_stats_count_what_was_saved():
    th = np.linspace(0, math.pi, 1000)
    pts = np.column_stack([5 * np.cos(th), 5 * np.sin(th)])
    segs = fit_polyline(pts, 0.01)
    stats = fit_stats(999, segs)
    assert stats == FitStats(replaced=999, arcs=len(segs), lines=0)
    assert stats.segments == len(segs)
    assert stats.saved == 999 - len(segs)
    assert stats.summary() == (
        f"arc fitting replaced 999 segments by {len(segs)} ({len(segs)} arcs, 0 lines)"
    )
    both = stats + fit_stats(4, [Line((0, 0), (1, 0))] * 4)
    assert both == FitStats(replaced=1003, arcs=len(segs), lines=4)


def test_chord_equivalent_is_the_sagitta_chord_count():
    r, tol = 5.0, 0.01
    quarter = Arc((5.0, 0.0), (0.0, 5.0), (0.0, 0.0), False)
    expected = math.ceil((math.pi / 2) / (2 * math.acos(1 - tol / r)))
    assert chord_equivalent([quarter, Line((0, 5), (0, 9))], tol) == expected + 1
