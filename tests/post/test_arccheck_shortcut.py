"""The arc-check shortcut gives exactly what the search gives (camtool.post.arccheck).

``conform_arc`` tests the rounded centre with :func:`plainly_passes` (a bound, no
numpy) before the search; ``shortcut=False`` runs the search alone, as the code
did before the shortcut (issue 17). The analysis that the two agree is in
``plainly_passes``'s docstring; these tests check it on random arcs of every
kind the writer meets (radii from a few quanta to metres, grids from 1 µm to
0.1 mm, starts off the circle as another CAM's rounding leaves them, tiny
sweeps, near and full circles, both rules and directions): the blocks, or the
error message, are identical. The claim itself is checked on many more blocks:
whenever :func:`plainly_passes` answers ``True``, the search's own vectorised
tests (``Solver._passes``) pass the rounded centre. ``CAMTOOL_ARC_PROPERTY_N``
sets the number of random blocks per rule for the claim (default 4 000; the
issue-17 run used 50 000 per rule, 100 000 in all) and a 60th of it for whole
arcs.
"""

from __future__ import annotations

import math
import os

import numpy as np
import pytest

import camtool.post.arcconform as arcconform
from camtool.model.errors import CamtoolError
from camtool.post.arcconform import ArcPiece, conform_arc
from camtool.post.numfmt import NumberFormat

Point = tuple[float, float]
N = int(os.environ.get("CAMTOOL_ARC_PROPERTY_N", "4000"))
N_WHOLE = max(1, N // 60)
QUANTA = (0.001, 0.001, 0.001, 0.01, 0.0254, 0.1)


def _printed(p: Point, quantum: float) -> Point:
    """``p`` on the writer's grid (halves away from zero, as NumberFormat rounds)."""
    decimals = round(-math.log10(quantum))
    if math.isclose(10.0**-decimals, quantum):
        fmt = NumberFormat(decimals=decimals)
        return (float(fmt.quantize(p[0])), float(fmt.quantize(p[1])))
    grid = arcconform.Grid.of(quantum)
    return grid.point(grid.indices(p))


def _arc(rng: np.random.Generator) -> tuple[Point, Point, Point, Point, bool, float]:
    """(printed start, exact start, exact end, exact centre, clockwise, quantum)."""
    q = float(rng.choice(QUANTA))
    radius = float(10 ** rng.uniform(math.log10(q), 3.3))
    centre = (float(rng.uniform(-600, 600)), float(rng.uniform(-600, 600)))
    kind = rng.integers(0, 5)
    if kind == 0:
        sweep = float(rng.uniform(0, 2 * math.pi))
    elif kind == 1:
        sweep = float(10 ** rng.uniform(-6, -1))  # tiny
    elif kind == 2:
        sweep = 2 * math.pi - float(10 ** rng.uniform(-6, -1))  # nearly full
    elif kind == 3:
        sweep = 2 * math.pi  # full circle
    else:
        sweep = float(rng.uniform(0, math.pi / 2))
    a0 = float(rng.uniform(-math.pi, math.pi))
    clockwise = bool(rng.integers(0, 2))
    a1 = a0 - sweep if clockwise else a0 + sweep
    end = (centre[0] + radius * math.cos(a1), centre[1] + radius * math.sin(a1))
    off = float(rng.choice([0.0, 0.0, 1e-6, q / 3, q, 5 * q]))  # another CAM's start
    r_start = radius + off * float(rng.uniform(-1, 1))
    exact_start = (centre[0] + r_start * math.cos(a0), centre[1] + r_start * math.sin(a0))
    if sweep == 2 * math.pi:
        exact_start = end
    return _printed(exact_start, q), exact_start, end, centre, clockwise, q


def _outcome(args: tuple[Point, Point, Point, Point, bool, float], rule: str, shortcut: bool):
    start, exact_start, end, centre, clockwise, q = args
    try:
        pieces: list[ArcPiece] | str = conform_arc(
            start,
            end,
            centre,
            clockwise,
            rule=rule,
            quantum_mm=q,
            exact_start=exact_start,
            shortcut=shortcut,
        )
    except (CamtoolError, ValueError) as exc:
        pieces = f"{type(exc).__name__}: {exc}"
    return pieces


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
def test_shortcut_equals_the_search_on_random_arcs(
    rule: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    seen = {True: 0, False: 0}
    plain = arcconform.plainly_passes

    def counted(*args: object) -> bool:
        ok = plain(*args)  # type: ignore[arg-type]
        seen[ok] += 1
        return ok

    monkeypatch.setattr(arcconform, "plainly_passes", counted)
    rng = np.random.default_rng(17 if rule == "grbl" else 1717)
    for k in range(N_WHOLE):
        args = _arc(rng)
        answered = seen[True]
        fast = _outcome(args, rule, shortcut=True)
        if seen[True] == answered:
            continue  # the shortcut said "not sure" every time: the search alone ran
        slow = _outcome(args, rule, shortcut=False)
        assert fast == slow, f"arc {k}: {args}"
    # both sides of the shortcut are exercised: it answers most arcs, not all
    assert seen[True] > N_WHOLE / 4
    assert seen[False] > N_WHOLE / 50
    print(f"{rule}: shortcut answered {seen[True]}, left {seen[False]} to the search")


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
def test_shortcut_equals_the_search_along_a_spiral(
    rule: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    # arcspiral.ngc (LinuxCNC's example): R-form arcs whose radius shrinks 2 thou a block,
    # each through the previous end (its centre on the chord's bisector), written from
    # the previous printed end as the writer chains them
    answered = []
    plain = arcconform.plainly_passes

    def counted(*args: object) -> bool:
        ok = plain(*args)  # type: ignore[arg-type]
        answered.append(ok)
        return ok

    monkeypatch.setattr(arcconform, "plainly_passes", counted)
    q = 0.001
    exact = (50.8, 0.0)
    here = _printed(exact, q)
    for k in range(300):
        radius = 50.8 - 0.0508 * k
        a = 0.05 * (k + 1)
        end = (radius * math.cos(a), radius * math.sin(a))
        half = math.dist(exact, end) / 2
        mid = ((exact[0] + end[0]) / 2, (exact[1] + end[1]) / 2)
        ux, uy = (end[0] - exact[0]) / (2 * half), (end[1] - exact[1]) / (2 * half)
        h = math.sqrt(radius * radius - half * half)
        centre = (mid[0] - uy * h, mid[1] + ux * h)  # left of the chord: counter-clockwise
        args = (here, exact, end, centre, False, q)
        fast = _outcome(args, rule, shortcut=True)
        assert fast == _outcome(args, rule, shortcut=False), k
        exact, here = end, _printed(end, q)
    assert sum(answered) > 250  # the shortcut answers nearly every block (the bench: all)


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
def test_whenever_the_shortcut_says_yes_the_search_passes_the_rounded_centre(rule: str) -> None:
    rng = np.random.default_rng(4242 if rule == "grbl" else 424242)
    answered = 0
    for k in range(N):
        start, exact_start, end, centre, clockwise, q = _arc(rng)
        grid = arcconform.Grid.of(q)
        ref = arcconform._reference(start, end, centre, clockwise, exact_start)
        if rng.integers(0, 3) == 0:  # a part of a split arc, between printed points
            lo, hi = sorted(rng.uniform(0, 1, size=2))
            ref = ref.part(float(lo), float(hi))
            start, end = ref.at(0.0), ref.at(1.0)
        s, e = grid.indices(start), grid.indices(end)
        solver = arcconform.Solver(grid, rule, clockwise, centre)
        c = grid.indices(centre)
        if not arcconform.plainly_passes(solver, s, e, c, ref):
            continue
        answered += 1
        _, ok = solver._passes(s, e, np.array([c], dtype=np.int64), ref)
        assert ok[0], f"block {k}: s={s} e={e} c={c} {ref} {rule} q={q}"
    assert answered > N / 4
    print(f"{rule}: the shortcut answered {answered} of {N} blocks")


@pytest.mark.parametrize("quantum", [0.001, 0.01, 0.1, 1.0, 0.0254, 1e-6, 2e-7])
def test_grid_digits_equal_decimal(quantum: float) -> None:
    grid = arcconform.Grid.of(quantum)
    rng = np.random.default_rng(7)
    values = [0.0, -0.0, 0.0005, -0.0005, 1e-5, 1e16, -1e22, 2.0005, 1234.5675]
    values += [float(v) for v in rng.uniform(-2000, 2000, 3000)]
    values += [round(float(v), int(rng.integers(0, 7))) for v in rng.uniform(-600, 600, 3000)]
    values += [(int(k) + 0.5) * quantum for k in rng.integers(-(10**6), 10**6, 2000)]
    # the floats next to decimal halves (2.675 is 2.67499999… in binary) and big indices,
    # where Grid.index's float rounding must hand over to the digits
    halves = [(int(k) + 0.5) * quantum for k in rng.integers(-(10**13), 10**13, 500)]
    halves += [2.675, -2.675, 1.0005, 0.0015, 1e14 * quantum + 0.5 * quantum]
    values += [math.nextafter(h, towards) for h in halves for towards in (-math.inf, math.inf)]
    values += [*halves, math.inf, -math.inf, 2.0**50 * quantum, 2.0**52 * quantum]
    for v in values:
        assert _called(grid.index, v) == _called(grid._index_slow, v), v
    for k in [0, 1, -1, 10**12, -(10**19), 10**21, *map(int, rng.integers(-(10**9), 10**9, 3000))]:
        assert grid.value(k) == grid._value_slow(k), k


def _called(call: object, arg: float) -> object:
    """The result, or the exception's type (a value too large for Decimal's 28 digits)."""
    try:
        return call(arg)  # type: ignore[operator]
    except ArithmeticError as exc:
        return type(exc)


@pytest.mark.parametrize("rule", ["grbl", "linuxcnc"])
def test_a_centre_a_subnormal_off_the_grid_goes_to_the_search(rule: str) -> None:
    """δ·σ underflows to 0 (a centre 5e-324 mm from its grid point): no ZeroDivisionError.

    Found by test_arccheck's hypothesis search; the blocks are the search's own.
    """
    centre, r, decimals = (0.0, 5e-324), math.exp(1.0625), 1
    a0, a1 = math.radians(1.0), math.radians(30.0)
    ex_start = (centre[0] + r * math.cos(a0), centre[1] + r * math.sin(a0))
    ex_end = (centre[0] + r * math.cos(a1), centre[1] + r * math.sin(a1))
    start = (round(ex_start[0], decimals), round(ex_start[1], decimals))
    args = (start, ex_end, centre, False)
    kw = {"rule": rule, "quantum_mm": 0.1, "exact_start": ex_start}
    assert conform_arc(*args, **kw) == conform_arc(*args, **kw, shortcut=False)
