"""The compiled curve fitter (``camtool/accel/fitkernels.py``) gives the plain fit's segments.

Bit for bit (``==`` on segments, so every float) on random Béziers and elliptical arcs,
degenerate ones included (coincident control points, closed loops, tiny and huge scales,
arcs over a full turn); each compiled fit also stays within the tolerance of the true
curve, measured by ``tests/shapes.two_sided_error`` (dense samples, shapely chords), not
by the fitter's own error. A curve the compiled fitter cannot fit is given to the plain one,
which raises with its message.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import numpy as np
import pytest

from camtool.geometry import fitpool
from camtool.geometry.curves import cubic_bezier, ellipse_arc, quadratic_bezier
from camtool.model.errors import GeometryError
from tests.shapes import two_sided_error

pytest.importorskip("numba")


def _random_keys(seed: int, count: int) -> Iterator[fitpool.CurveKey]:
    rng = np.random.default_rng(seed)
    for _ in range(count):
        scale = 10.0 ** rng.uniform(-3, 3)
        roll = rng.random()
        if roll < 0.3:
            c, a, b = (tuple(v) for v in rng.normal(0.0, scale, (3, 2)).tolist())
            t0, sweep = float(rng.uniform(-7, 7)), float(rng.uniform(-8, 8))
            ends = []
            for t in (t0, t0 + sweep):
                ends.append(
                    (
                        c[0] + a[0] * math.cos(t) + b[0] * math.sin(t),
                        c[1] + a[1] * math.cos(t) + b[1] * math.sin(t),
                    )
                )
            yield ("ellipse_arc", (c, a, b, t0, sweep, ends[0], ends[1]))
            continue
        n = 4 if roll < 0.8 else 3
        pts = rng.normal(0.0, scale, (n, 2))
        if rng.random() < 0.1:
            pts[1] = pts[0]  # a zero tangent at the start: one-sided differences
        if rng.random() < 0.1:
            pts[-1] = pts[0]  # a loop back to the start
        if rng.random() < 0.05:
            pts[:] = pts[0]  # one point
        yield ("cubic" if n == 4 else "quadratic", tuple(map(tuple, pts.tolist())))


def _compiled_on(monkeypatch: pytest.MonkeyPatch) -> None:
    from camtool.accel import SWITCH, fitkernels

    monkeypatch.setenv(SWITCH, "1")
    monkeypatch.setattr(fitpool.FIT_KERNELS, "_loaded", (fitkernels,))


@pytest.mark.parametrize("seed", range(3))
@pytest.mark.parametrize("tolerance", [0.001, 0.05])
def test_compiled_fit_equals_the_plain_fit(
    monkeypatch: pytest.MonkeyPatch, seed: int, tolerance: float
) -> None:
    keys = list(_random_keys(seed, 150))
    with fitpool.FIT_KERNELS.off():
        plain = [fitpool.fit_key(k, tolerance) for k in keys]
    _compiled_on(monkeypatch)
    from camtool.accel import fitkernels

    for key, want in zip(keys, plain, strict=True):
        status, *_ = fitkernels.curve_pieces(
            fitpool._KINDS[key[0]],
            np.array([v for a in key[1] for v in (a if isinstance(a, tuple) else (a,))]),
            0.97 * tolerance,
            0.1 * tolerance,
            40,
        )
        assert status == fitkernels.OK, key  # the compiled fitter answered, not the plain one
        assert fitpool.fit_key(key, tolerance) == want, key


def _curve(key: fitpool.CurveKey):  # type: ignore[no-untyped-def]
    kind, args = key
    if kind == "ellipse_arc":
        return ellipse_arc(*args)[0]
    return (cubic_bezier if kind == "cubic" else quadratic_bezier)(args)[0]  # type: ignore[arg-type]


@pytest.mark.parametrize("seed", range(2))
def test_compiled_fit_holds_the_tolerance(monkeypatch: pytest.MonkeyPatch, seed: int) -> None:
    _compiled_on(monkeypatch)
    tolerance = 0.01
    for key in _random_keys(100 + seed, 40):
        segs = fitpool.fit_key(key, tolerance)
        if not segs:
            continue
        forward, backward = two_sided_error(_curve(key), 0.0, 1.0, segs, tolerance, n=2000)
        assert forward <= tolerance and backward <= tolerance, (key, forward, backward)


def test_a_curve_the_compiled_fitter_cannot_fit_raises_the_plain_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Control points whose curve overflows: the plain fit's message names the parameter."""
    _compiled_on(monkeypatch)
    key: fitpool.CurveKey = ("cubic", ((0.0, 0.0), (1e308, 1e308), (-1e308, 1e308), (1.0, 0.0)))
    with pytest.raises(GeometryError, match="not finite"):
        fitpool.fit_key(key, 0.01)


def test_many_curves_load_the_compiled_fitter_and_fit_the_same(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """fit_many over KERNEL_FROM curves loads the kernels, gives the plain fits, forks nothing."""
    from camtool.accel import SWITCH

    keys = list(_random_keys(7, fitpool.KERNEL_FROM))
    with fitpool.FIT_KERNELS.off():
        plain = fitpool.fit_many(keys, 0.01, jobs=1)
    monkeypatch.setenv(SWITCH, "1")
    monkeypatch.setattr(fitpool, "_in_pool", lambda *a, **k: pytest.fail("forked a pool"))
    fitpool.FIT_KERNELS.forget()
    try:
        assert fitpool.fit_many(keys, 0.01) == plain
        assert fitpool.FIT_KERNELS.loaded() is not None
    finally:
        fitpool.FIT_KERNELS.forget()
