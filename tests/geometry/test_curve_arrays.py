"""The curve fit's array evaluation gives the point-by-point results bit for bit.

On many random inputs: the array evaluators of :mod:`camtool.geometry.curves` against the
scalar ``point_at`` they mirror, ``fit_curve`` with ``points_at`` against ``fit_curve``
without it (a curve that has only ``point_at``, as a plugin's may), and the early exit of
the piece error against the full two-sided error. Exact equality
(``==`` on floats and segments), never a tolerance: the emitted G-code must not change.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.geometry import arcfit, fiterror
from camtool.geometry.arcfit import fit_curve
from camtool.geometry.curves import (
    cubic_bezier,
    cubic_bezier_points,
    ellipse_arc,
    ellipse_arc_points,
    quadratic_bezier,
    quadratic_bezier_points,
)
from camtool.model.shapes import Point

coord = st.floats(-200.0, 200.0, allow_nan=False, allow_infinity=False)
point = st.tuples(coord, coord)


def _params(rng: np.random.Generator) -> np.ndarray:
    """Parameters as the fitter makes them: linspace over random sub-ranges, and ends."""
    ta, tb = np.sort(rng.random(2))
    return np.concatenate([np.linspace(ta, tb, 65), [0.0, 1.0, 0.5], rng.random(20)])


def _same(
    points_at: arcfit.PointsFn, point_at: arcfit.Callable[[float], Point], u: np.ndarray
) -> None:
    fast = points_at(u)
    slow = np.array([point_at(float(t)) for t in u])
    assert fast.shape == slow.shape
    assert np.array_equal(fast, slow), np.max(np.abs(fast - slow))


@settings(max_examples=200, deadline=None)
@given(st.tuples(point, point, point, point), st.integers(0, 2**32 - 1))
def test_cubic_points_bit_for_bit(ctrl: tuple[Point, Point, Point, Point], seed: int) -> None:
    _same(cubic_bezier_points(ctrl), cubic_bezier(ctrl)[0], _params(np.random.default_rng(seed)))


@settings(max_examples=200, deadline=None)
@given(st.tuples(point, point, point), st.integers(0, 2**32 - 1))
def test_quadratic_points_bit_for_bit(ctrl: tuple[Point, Point, Point], seed: int) -> None:
    fast, slow = quadratic_bezier_points(ctrl), quadratic_bezier(ctrl)[0]
    _same(fast, slow, _params(np.random.default_rng(seed)))


@settings(max_examples=200, deadline=None)
@given(
    point,
    point,
    point,
    st.floats(-10.0, 10.0),
    st.floats(-2 * math.pi, 2 * math.pi).filter(lambda s: abs(s) > 1e-6),
    st.integers(0, 2**32 - 1),
)
def test_ellipse_arc_points_bit_for_bit(
    centre: Point, a: Point, b: Point, t0: float, sweep: float, seed: int
) -> None:
    p0, p1 = (1.0, 2.0), (3.0, 4.0)  # the ends as the path data gives them
    fast = ellipse_arc_points(centre, a, b, t0, sweep, p0, p1)
    slow = ellipse_arc(centre, a, b, t0, sweep, p0, p1)[0]
    _same(fast, slow, _params(np.random.default_rng(seed)))


def _random_curves(n: int) -> list[tuple[str, tuple[Point, ...]]]:
    rng = np.random.default_rng(17)
    out: list[tuple[str, tuple[Point, ...]]] = []
    for k in range(n):
        scale = 10.0 ** rng.uniform(-2, 2)
        pts = tuple((float(x), float(y)) for x, y in rng.normal(0.0, scale, (4, 2)))
        if k % 5 == 0:  # a cusp: a control point on an end point
            pts = (pts[0], pts[0], pts[2], pts[3])
        out.append(("cubic" if k % 3 else "quadratic", pts if k % 3 else pts[:3]))
    return out


@pytest.mark.parametrize("tolerance", [0.01, 0.001, 0.1])
def test_fit_curve_with_points_at_equals_point_by_point(tolerance: float) -> None:
    """300 random Béziers (cusps too): the same segments, float for float."""
    for kind, ctrl in _random_curves(100):
        if kind == "cubic":
            pair, many = cubic_bezier(ctrl), cubic_bezier_points(ctrl)  # type: ignore[arg-type]
        else:
            pair, many = quadratic_bezier(ctrl), quadratic_bezier_points(ctrl)  # type: ignore[arg-type]
        slow = fit_curve(*pair, 0.0, 1.0, tolerance)
        fast = fit_curve(*pair, 0.0, 1.0, tolerance, points_at=many)
        assert fast == slow, (kind, ctrl)


def test_fit_curve_ellipse_arc_fast_equals_slow() -> None:
    rng = np.random.default_rng(3)
    for _ in range(60):
        centre = tuple(rng.normal(0, 50, 2).tolist())
        a = tuple(rng.normal(0, 20, 2).tolist())
        b = tuple(rng.normal(0, 5, 2).tolist())
        t0, sweep = float(rng.uniform(-3, 3)), float(rng.uniform(-6, 6))
        pair = ellipse_arc(centre, a, b, t0, sweep, (0.0, 0.0), (0.0, 0.0))  # type: ignore[arg-type]
        p0, p1 = pair[0](0.5 * 1e-300), pair[0](1.0 - 1e-16)
        args = (centre, a, b, t0, sweep, p0, p1)
        slow = fit_curve(*ellipse_arc(*args), 0.0, 1.0, 0.01)  # type: ignore[arg-type]
        fast = fit_curve(*ellipse_arc(*args), 0.0, 1.0, 0.01, points_at=ellipse_arc_points(*args))  # type: ignore[arg-type]
        assert fast == slow


def test_non_finite_array_points_fall_back_to_the_scalar_error() -> None:
    """A points_at that gives NaN: the samples are taken one by one, and the error names t."""
    pair = cubic_bezier(((0, 0), (1, 2), (3, 2), (4, 0)))

    def bad(u: np.ndarray) -> np.ndarray:
        return np.full((len(u), 2), np.nan)

    assert fit_curve(*pair, 0.0, 1.0, 0.01, points_at=bad) == fit_curve(*pair, 0.0, 1.0, 0.01)


def test_piece_error_early_exit_is_exact_where_it_matters() -> None:
    """With a limit the piece error is the full one when ≤ limit, and > limit otherwise."""
    rng = np.random.default_rng(5)
    for kind, ctrl in _random_curves(60):
        point_at = (cubic_bezier if kind == "cubic" else quadratic_bezier)(ctrl)[0]  # type: ignore[arg-type]
        u = np.linspace(0.0, 1.0, 65)
        fine = np.array([point_at(float(t)) for t in u])
        segs = fit_curve(
            *(cubic_bezier if kind == "cubic" else quadratic_bezier)(ctrl), 0.0, 1.0, 0.05
        )  # type: ignore[arg-type]
        if not segs:
            continue
        full = fiterror.piece_error(segs, fine, tuple(fine[0]))
        for limit in (full, full * 0.5, full * 2, float(rng.uniform(0, 2 * full + 1e-9))):
            fast = fiterror.piece_error(segs, fine, tuple(fine[0]), limit)
            if fast <= limit or full <= limit:
                assert fast == full
            else:
                assert fast > limit
