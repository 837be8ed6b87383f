"""Travel order of large jobs (camtool.toolpath.travel, windowed search) and the order-mode limit.

The grid nearest neighbour must choose exactly what the full scan chooses (same
distances, ties to the lower entry); the windowed search must give a valid order
(every cut once, inside before outside) no longer than the drawn one, and reach
analytic optima where they are obvious.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from camtool.model.errors import UsageError
from camtool.model.shapes import Contour, Line
from camtool.toolpath import travel
from camtool.toolpath.cuts import Cut
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import MAX_SEARCH_CUTS, Nesting, order_cuts
from tests.toolpath.contours import rect


def _mixed_cuts(n: int, seed: int) -> list[Cut]:
    """Random squares (any start vertex) and short open lines (some reversible), mm."""
    rng = random.Random(seed)
    cuts = []
    for i in range(n):
        x, y = rng.uniform(0, 100), rng.uniform(0, 100)
        if i % 2:
            line = Contour((Line((x, y), (x + rng.uniform(-1, 1), y + 1)),), False)
            cuts.append(Cut(line, i, kind="open", may_rotate=False, may_reverse=i % 3 == 0))
        else:
            a = rng.uniform(0.1, 2)
            cuts.append(Cut(rect(x, y, x + a, y + a), i))
    return cuts


def _before(n: int) -> list[tuple[int, ...]]:
    """Every 50th cut after the three before it (as a contour after its holes)."""
    return [tuple(range(max(0, i - 3), i)) if i % 50 == 0 else () for i in range(n)]


def test_grid_nearest_neighbour_chooses_as_the_full_scan() -> None:
    cuts = _mixed_cuts(1200, seed=1)
    before = _before(len(cuts))
    full = travel._nearest_neighbour(cuts, before, (0.0, 0.0), True)
    table, steps = travel.entries(cuts, True)
    grid = travel.grid_nearest_neighbour(table, before, (0.0, 0.0))
    assert [steps[p] for p in grid.tolist()] == full


def test_grid_nearest_neighbour_takes_the_lower_entry_on_ties() -> None:
    # four identical squares: every vertex of every square is a tie; the full scan takes
    # cut 0 vertex 0 first, then cut 1 at the vertex where cut 0 ended, and so on
    cuts = [Cut(rect(10, 10, 12, 12), i) for i in range(4)]
    table, steps = travel.entries(cuts, True)
    grid = travel.grid_nearest_neighbour(table, [()] * 4, (10.0, 10.0))
    assert [steps[p] for p in grid.tolist()] == [(i, 0, False) for i in range(4)]


def test_large_order_is_valid_and_close_to_the_full_search(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    cuts = _mixed_cuts(400, seed=2)
    before = _before(len(cuts))
    origin = (0.0, 0.0)
    full = travel.travel_order(cuts, before, origin)
    monkeypatch.setattr(travel, "FULL_SEARCH_MAX_CUTS", 10)
    seq = travel.travel_order(cuts, before, origin)
    order = [i for i, _, _ in seq]
    assert sorted(order) == list(range(len(cuts)))
    assert travel.respects(order, before)
    drawn = travel.drawn_order(cuts, before)
    got = travel.rapid_mm(cuts, seq, origin)
    assert got <= travel.rapid_mm(cuts, drawn, origin)
    assert got <= 1.05 * travel.rapid_mm(cuts, full, origin)
    for i, k, rev in seq:  # only allowed variants
        assert k == 0 or cuts[i].may_rotate
        assert not rev or (cuts[i].may_reverse and not cuts[i].path.closed)


def test_large_order_of_a_shuffled_row_is_the_row(monkeypatch: pytest.MonkeyPatch) -> None:
    # n upright unit lines at x = 0..n-1, drawn shuffled, cut upwards: from (k, 1) any other
    # start (j, 0) is at least √2 away, so the shortest rapids are 1 + (n - 1)·√2 (origin at
    # (-1, 0)), in the order of x
    n = 3000
    xs = list(range(n))
    random.Random(3).shuffle(xs)
    cuts = [
        Cut(Contour((Line((x, 0.0), (x, 1.0)),), False), g, "open", False, False)
        for g, x in enumerate(xs)
    ]
    assert n > travel.FULL_SEARCH_MAX_CUTS
    seq = travel.travel_order(cuts, [()] * n, (-1.0, 0.0))
    assert [xs[i] for i, _, _ in seq] == list(range(n))
    assert travel.rapid_mm(cuts, seq, (-1.0, 0.0)) == pytest.approx(1 + (n - 1) * math.sqrt(2))


def test_reversing_runs_turns_open_cuts_round() -> None:
    cuts = _mixed_cuts(6, seed=4)
    table, _ = travel.entries(cuts, True)
    seq = table.first[:-1].copy()
    out = travel._reverse_runs(table, seq, np.asarray([1]), np.asarray([3]))
    assert table.owner[out].tolist() == [0, 3, 2, 1, 4, 5]
    assert out[1] == table.partner[seq[3]]  # cut 3 (open, reversible) now runs backwards
    assert out[2] == seq[2]  # cut 2 (closed) keeps its entry


@pytest.mark.parametrize("mode", ["reversals", "mirror"])
def test_search_orders_refuse_more_cuts_than_their_limit(mode: str) -> None:
    n = MAX_SEARCH_CUTS + 1
    cuts = [
        Cut(Contour((Line((i, 0.0), (i, 1.0)),), False), i, "open", False, False) for i in range(n)
    ]
    options = PlanOptions(feed_mm_min=100.0, order=mode)
    with pytest.raises(UsageError, match=f"--order {mode} plans at most {MAX_SEARCH_CUTS} cuts"):
        order_cuts(cuts, Nesting(((),) * n), options, (0.0, 0.0))


@pytest.mark.parametrize("seed", range(6))
def test_cell_nearest_neighbour_is_the_full_scan_bit_for_bit(seed: int) -> None:
    # the full search's nearest neighbour by grid cells must choose exactly what the scan of
    # every candidate chooses: same np.hypot distances, ties to the lower cut, then vertex
    rng = random.Random(seed)
    cuts = _mixed_cuts(300, seed=seed)
    # exact ties: duplicated squares, and a polygon whose vertices all lie on one circle
    cuts += [Cut(rect(5, 5, 6, 6), 300 + k) for k in range(3)]
    angles = [k * math.pi / 4 for k in range(8)]
    ring = [(50 + 3 * math.cos(a), 50 + 3 * math.sin(a)) for a in angles]
    poly = Contour(tuple(Line(ring[k], ring[(k + 1) % 8]) for k in range(8)), True)
    cuts.append(Cut(poly, 303))
    before = _before(len(cuts))
    for origin in ((0.0, 0.0), (50.0, 50.0), (-1e4, 3e3), (rng.uniform(0, 100), 1e-300)):
        for flip in (True, False):
            assert travel._nearest_neighbour(cuts, before, origin, flip) == (
                travel._nearest_neighbour_scan(cuts, before, origin, flip)
            )


def test_cell_nearest_neighbour_on_one_point_and_on_a_line_of_points() -> None:
    # degenerate grids: every candidate at one point (zero-size box), all on one line
    same = [Cut(rect(1, 1, 1, 1), i) for i in range(3)]
    row = [
        Cut(Contour((Line((i, 0.0), (i + 0.5, 0.0)),), False), i, kind="open", may_rotate=False)
        for i in range(40)
    ]
    for cuts in (same, row):
        before: list[tuple[int, ...]] = [()] * len(cuts)
        for origin in ((0.0, 0.0), (20.0, 7.0)):
            assert travel._nearest_neighbour(cuts, before, origin, True) == (
                travel._nearest_neighbour_scan(cuts, before, origin, True)
            )


def test_candidates_are_every_allowed_variant_with_its_ends() -> None:
    cuts = _mixed_cuts(200, seed=3)
    cuts.append(Cut(rect(0, 0, 1, 1), 200, may_rotate=False))
    for flip in (True, False):
        starts, finish, steps, first = travel._candidates(cuts, flip)
        expected = []
        for i, cut in enumerate(cuts):
            if cut.path.closed:
                ks = range(len(cut.path.segments)) if cut.may_rotate else range(1)
                expected += [(i, k, False) for k in ks]
            else:
                expected += [(i, 0, False)] + ([(i, 0, True)] if flip and cut.may_reverse else [])
        assert steps == expected
        assert first == [
            next(p for p, s in enumerate(steps) if s[0] == i) for i in range(len(cuts))
        ] + [len(steps)]
        for p, (i, k, rev) in enumerate(steps):
            s, e = travel.ends(cuts[i], k, rev)
            assert (tuple(starts[p]), tuple(finish[p])) == (s, e)
