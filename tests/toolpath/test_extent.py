"""The toolpath extent without the boxes of arcs that cannot widen it (issue 17).

Reference: the union of every move's box, as before (``_union_of_boxes``); the fast one must
give the same four floats (compared by ``repr``: the sign of a zero too) or leave it to it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from camtool.model.program import ArcMove, Linear, Move, Rapid
from camtool.toolpath import placement


def _moves(rng: np.random.Generator, n: int, scale: float) -> list[Move]:
    out: list[Move] = []
    here = (0.0, 0.0)
    for _ in range(n):
        x, y = (float(v) for v in rng.normal(0.0, scale, 2))
        kind = rng.random()
        if kind < 0.1:
            out.append(Rapid(x, y))
        elif kind < 0.4:
            out.append(Linear(x, y, 100.0))
        else:
            # a centre on the bisector of here → (x, y), so both ends are on one circle
            mx, my = (here[0] + x) / 2, (here[1] + y) / 2
            nx, ny = -(y - here[1]), x - here[0]
            lam = float(rng.normal(0.0, 1.0))
            full = rng.random() < 0.05
            end = here if full else (x, y)
            out.append(ArcMove(*end, mx + lam * nx, my + lam * ny, bool(rng.random() < 0.5), 100.0))
        here = (out[-1].x, out[-1].y)
    return out


@pytest.mark.parametrize("seed", range(6))
def test_the_extent_of_ends_is_the_union_of_every_box(seed: int) -> None:
    rng = np.random.default_rng(seed)
    checked = 0
    for _ in range(300):
        scale = 10.0 ** rng.uniform(-3, 3)
        moves = _moves(rng, int(rng.integers(1, 40)), scale)
        start = (float(rng.normal(0, scale)), float(rng.normal(0, scale)))
        union = placement._union_of_boxes(start, moves)
        fast = placement._extent_of_ends(start, moves)
        if fast is not None:
            checked += 1
            assert repr(fast) == repr(union)
    assert checked > 250


def test_zero_or_non_finite_sides_go_to_the_union() -> None:
    moves: list[Move] = [Linear(0.0, 1.0, 100.0), Linear(-0.0, 2.0, 100.0)]
    assert placement._extent_of_ends((1.0, 1.0), moves) is None
    assert placement._extent_of_ends((1.0, 1.0), [Linear(math.nan, 1.0, 100.0)]) is None
    arc = ArcMove(2.0, 0.0, 1.0, 0.0, True, 100.0)  # the half circle over (1, 1)
    assert repr(placement._extent_of_ends((0.0, 0.0), [arc])) == "None"
    assert placement._extent_of_ends(
        (3.0, 3.0), [Linear(4.0, 4.0, 1.0), ArcMove(6.0, 4.0, 5.0, 4.0, True, 1.0)]
    ) == placement._union_of_boxes(
        (3.0, 3.0), [Linear(4.0, 4.0, 1.0), ArcMove(6.0, 4.0, 5.0, 4.0, True, 1.0)]
    )


@pytest.mark.parametrize("seed", range(6))
def test_zero_sides_kept_only_when_they_are_the_union(seed: int) -> None:
    """Programs shifted so that a side is exactly 0 (``--origin lower-left``), some with -0.0."""
    rng = np.random.default_rng(100 + seed)
    kept = 0
    for _ in range(300):
        scale = 10.0 ** rng.uniform(-3, 3)
        moves = _moves(rng, int(rng.integers(1, 40)), scale)
        start = (float(rng.normal(0, scale)), float(rng.normal(0, scale)))
        box = placement._union_of_boxes(start, moves)
        dx, dy = -box[0], -box[1]  # as placement_shift does for lower-left
        if rng.random() < 0.5:
            dx = 0.0  # only Y on zero
        shifted = [placement._shifted(m, dx, dy) for m in moves]
        here = (start[0] + dx, start[1] + dy)
        if rng.random() < 0.2:  # a -0.0 somewhere: the order decides, so it must decline
            k = int(rng.integers(0, len(shifted)))
            m = shifted[k]
            shifted[k] = dataclasses.replace(m, x=-0.0)
        union = placement._union_of_boxes(here, shifted)
        fast = placement._extent_of_ends(here, shifted, zero_sides=True)
        if fast is not None:
            kept += 1
            assert repr(fast) == repr(union)
        assert placement._extent_of_ends(here, shifted) is None or 0.0 not in union
    assert kept > 150


def test_a_negative_zero_side_goes_to_the_union() -> None:
    moves: list[Move] = [Linear(0.0, 1.0, 100.0), Linear(-0.0, 2.0, 100.0)]
    assert placement._extent_of_ends((1.0, 1.0), moves, zero_sides=True) is None
    ok: list[Move] = [Linear(0.0, 1.0, 100.0), Linear(0.0, 2.0, 100.0)]
    assert repr(placement._extent_of_ends((1.0, 1.0), ok, zero_sides=True)) == repr(
        placement._union_of_boxes((1.0, 1.0), ok)
    )


def test_the_quadrant_extremes_are_within_the_two_that_decide() -> None:
    # _extent_of_ends tests an arc's extremes c + r·q against the box by c - r and c + r
    # alone: that holds when the quadrants' cosines and sines are within [-1, 1] and
    # include 1 and -1 exactly, the very floats Arc.bbox multiplies by
    from camtool.model.shapes import _QUADRANTS

    cosines = [c for _, c, _ in _QUADRANTS]
    sines = [s for _, _, s in _QUADRANTS]
    for values in (cosines, sines):
        assert all(-1.0 <= v <= 1.0 for v in values)
        assert 1.0 in values and -1.0 in values
