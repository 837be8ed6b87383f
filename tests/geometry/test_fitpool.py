"""Curve fits in worker processes (issue 17): the very fits made here, in order.

Expected values are :func:`fit_key` run in this process (the serial fit the workers stand in
for): the pool must change the speed only, so every segment must be the same, float for float.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from typing import Any

import numpy as np
import pytest

from camtool.accel import pool
from camtool.accel.cores import in_worker
from camtool.geometry import fitpool
from camtool.geometry.fitpool import CurveKey, fit_key, fit_many

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")


@pytest.fixture(autouse=True)
def _plain_fitter() -> Iterator[None]:
    """The pool's tests keep the compiled fitter unloaded (once loaded, fits run here)."""
    with fitpool.FIT_KERNELS.off():
        yield


def spy_pool(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """Record, for each pool :func:`fit_many` starts, whether its workers answered.

    ``fitpool._in_pool`` falls back to the serial fits (``None``) on any worker error, so
    a test comparing pooled and serial drawings alone would pass without a pool at all.
    """
    pooled: list[bool] = []
    in_pool = fitpool._in_pool

    def spy(*args: Any) -> Any:
        out = in_pool(*args)
        pooled.append(out is not None)
        return out

    monkeypatch.setattr(fitpool, "_in_pool", spy)
    return pooled


def _keys(n: int) -> list[CurveKey]:
    rng = np.random.default_rng(1717)
    out: list[CurveKey] = []
    for k in range(n):
        scale = 10.0 ** rng.uniform(-1, 2)
        pts = tuple((float(x), float(y)) for x, y in rng.normal(0.0, scale, (4, 2)))
        if k % 3 == 0:
            out.append(("cubic", pts))
        elif k % 3 == 1:
            out.append(("quadratic", pts[:3]))
        else:
            a = (float(rng.normal(0, 20)), float(rng.normal(0, 20)))
            b = (-a[1] * 0.3, a[0] * 0.3)
            t0, sweep = float(rng.uniform(-3, 3)), float(rng.uniform(-6, 6))
            c = pts[0]
            p0 = (c[0] + a[0] * math.cos(t0) + b[0] * math.sin(t0),
                  c[1] + a[1] * math.cos(t0) + b[1] * math.sin(t0))  # fmt: skip
            t1 = t0 + sweep
            p1 = (c[0] + a[0] * math.cos(t1) + b[0] * math.sin(t1),
                  c[1] + a[1] * math.cos(t1) + b[1] * math.sin(t1))  # fmt: skip
            out.append(("ellipse_arc", (c, a, b, t0, sweep, p0, p1)))
    return out


def test_parallel_fits_equal_serial_fits(monkeypatch: pytest.MonkeyPatch) -> None:
    """300 random Béziers and elliptical arcs: the workers' fits are the serial fits."""
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "_CHUNK", 7)  # many chunks, gathered in order
    pooled = spy_pool(monkeypatch)
    keys = _keys(300)
    serial = [fit_key(k, 0.01) for k in keys]
    assert repr(fit_many(keys, 0.01, jobs=2)) == repr(serial)
    assert pooled == [True]  # the workers answered (not the serial fallback)
    assert repr(fit_many(keys, 0.01, jobs=1)) == repr(serial)
    assert pooled == [True]  # one job: no pool


def test_done_counts_the_fits_as_they_come_in(monkeypatch: pytest.MonkeyPatch) -> None:
    """``done`` hears the count so far: per chunk from the workers, per fit here; same fits."""
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "_CHUNK", 7)
    keys = _keys(30)
    serial = [fit_key(k, 0.01) for k in keys]
    pooled: list[int] = []
    assert repr(fit_many(keys, 0.01, jobs=2, done=pooled.append)) == repr(serial)
    assert pooled == [7, 14, 21, 28, 30]  # five chunks of at most 7, in order
    here: list[int] = []
    assert repr(fit_many(keys, 0.01, jobs=1, done=here.append)) == repr(serial)
    assert here == list(range(1, 31))


def test_a_fit_that_raises_is_none_and_the_others_stay(monkeypatch: pytest.MonkeyPatch) -> None:
    """A failing fit answers None (the caller fits it again and raises in order)."""
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    keys = _keys(20)
    bad: CurveKey = ("cubic", ((0.0, 0.0), (1.0, 1.0), (2.0, 1.0), (3.0, 0.0)))
    got = fit_many([*keys[:5], bad, *keys[5:]], -1.0, jobs=2)  # a bad tolerance fails all
    assert got == [None] * 21
    got = fit_many([*keys[:5], ("nurbs", ()), *keys[5:]], 0.01, jobs=2)
    assert got[5] is None
    assert got[:5] + got[6:] == [fit_key(k, 0.01) for k in keys]


def test_few_curves_start_no_pool(monkeypatch: pytest.MonkeyPatch) -> None:
    def no_pool(*args: object) -> None:
        raise AssertionError("a pool for a few curves")

    monkeypatch.setattr(fitpool, "_in_pool", no_pool)
    keys = _keys(10)
    assert fit_many(keys, 0.01, jobs=4) == [fit_key(k, 0.01) for k in keys]


def _fits_in_a_child(keys: list[CurveKey], queue: object) -> None:
    def no_pool(*args: object, **kwargs: object) -> None:
        raise AssertionError("a pool in a worker process")

    fitpool.MIN_CURVES = 1
    pool.ProcessPoolExecutor = no_pool  # type: ignore[assignment,misc]
    try:
        queue.put(repr(fit_many(keys, 0.01, jobs=2)))  # type: ignore[attr-defined]
    except AssertionError as exc:
        queue.put(str(exc))  # type: ignore[attr-defined]


def test_a_worker_process_fits_serially_and_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    """In a child process (a batch worker) no pool is started; the fits are the same."""
    import multiprocessing

    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    keys = _keys(12)
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_fits_in_a_child, args=(keys, queue))
    child.start()
    got = queue.get(timeout=120)
    child.join(timeout=60)
    assert got == repr([fit_key(k, 0.01) for k in keys])
    assert not in_worker()


def test_switched_off_fits_serially_and_the_same(monkeypatch: pytest.MonkeyPatch) -> None:
    """``CAMTOOL_ACCEL=0``: no pool is started; the fits are the same."""

    def no_pool(*args: object, **kwargs: object) -> None:
        raise AssertionError("a pool with the accel layer switched off")

    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    monkeypatch.setattr(pool, "ProcessPoolExecutor", no_pool)
    keys = _keys(fitpool.MIN_CURVES)
    assert repr(fit_many(keys, 0.01, jobs=2)) == repr([fit_key(k, 0.01) for k in keys])


def _bezier(p: tuple[tuple[float, float], ...]) -> Any:
    """The cubic Bézier through control points ``p``, evaluated in Bernstein form (the judge)."""

    def point_at(t: float) -> tuple[float, float]:
        u = 1.0 - t
        w = (u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t)
        x = sum(wi * q[0] for wi, q in zip(w, p, strict=True))
        return (x, sum(wi * q[1] for wi, q in zip(w, p, strict=True)))

    return point_at


def test_copies_of_one_shape_are_fitted_once_and_each_holds_the_tolerance(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """A panel of one rounded corner placed 200 times at offsets no float adds exactly: one
    fit, moved onto every copy, each within the tolerance of its own curve, ending on its ends."""
    from tests.shapes import two_sided_error

    corner = ((0.0, 0.0), (0.2761, 0.0), (0.5, 0.2239), (0.5, 0.5))
    keys: list[CurveKey] = []
    for k in range(200):
        x, y = 0.1 * k + math.pi / 7, 123.456 - 0.37 * k
        keys.append(("cubic", tuple((x + cx, y + cy) for cx, cy in corner)))
    keys.append(("cubic", ((1.0, 1.0), (1.3, 1.0), (1.5, 1.2239), (1.5, 1.5))))  # another shape
    fitted: list[CurveKey] = []

    def counting(key: CurveKey, tolerance: float) -> Any:
        fitted.append(key)
        return fit_key(key, tolerance)

    monkeypatch.setattr(fitpool, "fit_key", counting)
    told: list[tuple[int, int]] = []
    fits = fitpool.fit_shared(keys, 0.001, jobs=1, done=lambda n, total: told.append((n, total)))
    assert fitted == [keys[0], keys[-1]]  # the first copy, and the other shape
    assert told == [(0, 2), (1, 2), (2, 2)]
    for key, segs in zip(keys, fits, strict=True):
        assert segs is not None
        p = key[1]
        assert segs[0].start == p[0] and segs[-1].end == p[-1]
        forward, backward = two_sided_error(_bezier(p), 0.0, 1.0, segs, 0.001, n=400)
        assert forward <= 0.001 and backward <= 0.001
