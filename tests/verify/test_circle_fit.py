"""The least-squares circle of a trace, fed block by block (camtool.verify.circlefit).

The expected circle is computed independently: the normal equations of Kåsa's fit
summed and solved in exact rational arithmetic (fractions), then rounded once. A
streamed verification feeds the fit its rows as they come and holds no contour's trace.
"""

from __future__ import annotations

import dataclasses
import math
import tracemalloc
from fractions import Fraction

import numpy as np
import pytest

from camtool.accel import cores
from camtool.model.machine import Backlash, Machine
from camtool.model.program import ArcMove, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify import budget_run, circlefit, verifier
from camtool.verify.chunked import count_rows
from camtool.verify.circlefit import CircleFit, fit_circle
from camtool.verify.sources import ALL

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

pytest.importorskip("camtool.accel.kernels")


def _exact_fit(points: np.ndarray) -> tuple[float, float, float]:
    """Kåsa's circle of ``points`` from exactly summed and solved normal equations.

    Minimises ``sum((x² + y² − p·x − q·y − s)²)`` (the same residual as any centring):
    ``G = AᵀA``, ``g = Aᵀb`` with rows ``(x, y, 1)`` and ``b = x² + y²`` in rationals,
    solved by Cramer's rule; ``a = p/2``, ``b = q/2``, ``r² = s + a² + b²``.
    """
    xs = [Fraction(float(x)) for x in points[:, 0]]
    ys = [Fraction(float(y)) for y in points[:, 1]]
    cols = [xs, ys, [Fraction(1)] * len(xs)]
    rhs = [x * x + y * y for x, y in zip(xs, ys, strict=True)]
    g = [[sum(a * b for a, b in zip(ci, cj, strict=True)) for cj in cols] for ci in cols]
    h = [sum(a * b for a, b in zip(ci, rhs, strict=True)) for ci in cols]

    def det(m: list[list[Fraction]]) -> Fraction:
        return (
            m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
            - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
        )

    d = det(g)
    p, q, s = (
        det([[h[r] if c == k else g[r][c] for c in range(3)] for r in range(3)]) / d
        for k in range(3)
    )
    a, b = p / 2, q / 2
    return float(a), float(b), math.sqrt(float(s + a * a + b * b))


def _noisy_circle(seed: int, n: int, turns: float = 1.0) -> tuple[np.ndarray, tuple[float, float]]:
    """``n`` points on ``turns`` of a circle with µm noise, and its nominal centre."""
    rng = np.random.default_rng(seed)
    cx, cy, r = rng.uniform(-50, 50), rng.uniform(-50, 50), rng.uniform(0.5, 20)
    t = np.linspace(0.0, 2 * math.pi * turns, n)
    noise = rng.normal(0.0, 0.001, (n, 2))
    points = np.column_stack((cx + r * np.cos(t), cy + r * np.sin(t))) + noise
    return points, (float(cx), float(cy))


@pytest.mark.parametrize("seed", range(4))
@pytest.mark.parametrize("block", [7, 64, circlefit.FIT_BLOCK])
def test_the_fit_is_the_exact_least_squares_circle(
    seed: int, block: int, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Within a few ulps of the exactly solved circle, however many blocks the points make.

    The points' coordinates are rounded once when taken about the centre, so the bound
    is in ulps of the largest coordinate (the mean-centred ``lstsq`` it replaced: within
    one; taken about the nominal centre in blocks of 64: within four).
    """
    monkeypatch.setattr(circlefit, "FIT_BLOCK", block)
    points, centre = _noisy_circle(seed, 3001, turns=1 + seed)
    expected = _exact_fit(points)
    ulp = math.ulp(float(np.max(np.abs(points))))
    for about in (centre, None):  # the nominal centre, or the points' mean
        got = fit_circle(points, about)
        for value, exact in zip(got, expected, strict=True):
            assert abs(value - exact) <= 6 * ulp, (got, expected)


def test_points_handed_in_any_pieces_give_the_same_bits(monkeypatch: pytest.MonkeyPatch) -> None:
    """The blocks start at fixed offsets: a streamed contour's fit is the whole trace's."""
    monkeypatch.setattr(circlefit, "FIT_BLOCK", 100)
    points, centre = _noisy_circle(7, 2345, turns=3)
    whole = fit_circle(points, centre)
    rng = np.random.default_rng(1)
    for _ in range(5):
        cuts = np.sort(rng.integers(0, len(points), 12))
        fit = CircleFit(centre)
        for piece in np.split(points, cuts):
            fit.add(piece)
        assert fit.result() == whole


def test_fewer_than_three_points_have_no_circle() -> None:
    fit = CircleFit((0.0, 0.0))
    fit.add(np.asarray([[1.0, 0.0], [0.0, 1.0]]))
    assert fit.result() is None
    with pytest.raises(ValueError, match="3 points"):
        fit_circle(np.asarray([[1.0, 0.0]]))


def _circle_turns(turns: int, radius: float = 0.25) -> Program:
    """One contour going round a circle ``turns`` times in half circles (a hole in passes)."""
    cx, cy = 3.0, 3.0
    moves: list[Rapid | ArcMove] = [Rapid(cx - radius, cy, contour=1)]
    for k in range(2 * turns):
        x = cx + radius if k % 2 == 0 else cx - radius
        moves.append(ArcMove(x, cy, cx, cy, True, 300.0, contour=1))
    return Program(tuple(moves), origin=(0.0, 0.0))


def _budget_peak(turns: int, machine: Machine) -> tuple[int, int]:
    """tracemalloc's peak of the budget of :func:`_circle_turns` and its ideal rows."""
    program = _circle_turns(turns)
    rows = int(count_rows(program, machine, sources=ALL.without("interpolation"))[-1])
    v = verifier.verify_program(program, machine, name="pic-mmh", stream_above=4096)
    assert v.contours[0].circle is not None
    tracemalloc.start()
    try:
        budget = v.measure_budget()
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert "contour 1 diameter error" in budget.without["interpolation"]
    return peak, rows


def test_a_streamed_circle_of_many_turns_holds_no_trace(monkeypatch: pytest.MonkeyPatch) -> None:
    """The budget of a circle of 8 and of 32 turns: what the extra rows cost is not a trace.

    With the interpolation off (four rows a step) the circle's run was held whole for
    the fit, 16 bytes a row, and its figures made from it: the budget's peak grew by
    57 bytes a row. Fed to the fit as the chunks come, what grows is the thinned trace
    and the path samples of the shortfall (every 0.5 and 1 µm: ~12 bytes a row).
    """
    machine = dataclasses.replace(load_target("pic-mmh").machine, backlash=Backlash())
    monkeypatch.setattr(cores, "default_jobs", lambda: 1)  # one source, here
    monkeypatch.setattr(budget_run, "CHUNK_ROWS", 4096)
    small, small_rows = _budget_peak(8, machine)
    big, big_rows = _budget_peak(32, machine)
    assert big_rows > 3 * small_rows
    per_row = (big - small) / (big_rows - small_rows)
    assert per_row < 24, (small, big, per_row)
