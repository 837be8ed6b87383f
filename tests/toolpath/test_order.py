"""Cutting order: precedence, travel, backlash-aware reversals and mirror ordering.

Expected values are derived in each test from the reversal model of
camtool.toolpath.reversals (UNAM-GMM §5.1, L1707–L1709: the controller compensates
"whenever any axis changes direction") and checked against the pic-mmh simulator.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import GeometryError, ToolpathError, UsageError
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import Arc, Contour, Line, Point
from camtool.post.registry import load_target
from camtool.toolpath.cuts import Cut
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.order import Nesting, Ordering, nesting, order_cuts
from camtool.toolpath.reversals import count_reversals, weights
from camtool.verify.verifier import Verification, verify_code


def polygon(points: Sequence[Point], *, clockwise: bool = False) -> Contour:
    """A closed polygon through ``points`` (reversed order when ``clockwise``)."""
    pts = list(reversed(points)) if clockwise else list(points)
    n = len(pts)
    return Contour(tuple(Line(pts[i], pts[(i + 1) % n]) for i in range(n)), True)


def rect(x0: float, y0: float, x1: float, y1: float, *, clockwise: bool = False) -> Contour:
    """Rectangle starting at its lower-left corner, counter-clockwise unless ``clockwise``."""
    if clockwise:
        return polygon([(x0, y0), (x0, y1), (x1, y1), (x1, y0)])
    return polygon([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def circle(cx: float, cy: float, r: float, *, start_deg: float = 0.0, cw: bool = False) -> Contour:
    a = math.radians(start_deg)
    p = (cx + r * math.cos(a), cy + r * math.sin(a))
    return Contour((Arc(p, p, (cx, cy), cw),), True)


def cuts_of(contours: Sequence[Contour]) -> tuple[list[Cut], Nesting]:
    """One cut per contour (group = index), and the contours' nesting."""
    return [Cut(c, i) for i, c in enumerate(contours)], nesting(contours)


def options(order: str, origin: Point = (0.0, 0.0)) -> PlanOptions:
    return PlanOptions(feed_mm_min=0.8, order=order, origin=origin)


def inside_first(out: Sequence[Cut], nest: Nesting) -> bool:
    """Never an outer contour before a contour it contains."""
    return all(
        out[q].group not in nest.parents[out[p].group] for p in range(len(out)) for q in range(p)
    )


def program_of(cuts: Sequence[Cut], feed: float = 0.8) -> Program:
    """A rapid to each cut's start, then its lines and arcs (contours numbered from 1)."""
    moves: list[Move] = []
    for n, cut in enumerate(cuts, 1):
        moves.append(Rapid(*cut.path.start, contour=n))
        for seg in cut.path.segments:
            if isinstance(seg, Arc):
                moves.append(ArcMove(*seg.end, *seg.centre, seg.clockwise, feed, contour=n))
            else:
                moves.append(Linear(*seg.end, feed, contour=n))
    return Program(tuple(moves))


def simulate(cuts: Sequence[Cut], machine_file: Path | None = None) -> Verification:
    """Post ``cuts`` for pic-mmh, read the code back and simulate it."""
    target = load_target("pic-mmh", machine_file=machine_file)
    code = target.emit(program_of(cuts)).code
    return verify_code(code, target)


# ------------------------------------------------------------------ the reversal model


def test_square_from_its_corner_reverses_each_axis_once() -> None:
    # CCW from (0, 0): +X, +Y, -X (X reverses), -Y (Y reverses); the rapid is empty.
    assert count_reversals([Cut(rect(0, 0, 1, 1), 0)], (0.0, 0.0)) == (1, 1)


def test_rapid_into_a_cut_counts() -> None:
    # From (2, 2) the rapid to (0, 0) moves -X -Y; the square then starts +X, +Y: both
    # reverse, then once more each inside the square.
    assert count_reversals([Cut(rect(0, 0, 1, 1), 0)], (2.0, 2.0)) == (2, 2)


def test_circle_reverses_x_at_left_and_right_and_y_at_top_and_bottom() -> None:
    # CCW from the rightmost point: X moves - until the leftmost point, then + (1
    # reversal); Y moves +, - after the top, + after the bottom (2 reversals).
    assert count_reversals([Cut(circle(0, 0, 1), 0)], (1.0, 0.0)) == (1, 2)
    # From 45°: X -, + (at 180°), - (at 360°); Y +, - (at 90°), + (at 270°): 2 and 2.
    assert count_reversals(
        [Cut(circle(0, 0, 1, start_deg=45), 0)], circle(0, 0, 1, start_deg=45).start
    ) == (2, 2)


def test_weights_default_to_one_each() -> None:
    assert weights((0.0, 0.0)) == (1.0, 1.0)
    assert weights((204.0, 178.0)) == (204.0, 178.0)


# ------------------------------------------------------------------ grids of holes


def plate_with_grid(n: int, *, pitch: float = 1.0, hole: float = 0.4) -> list[Contour]:
    """A plate with n × n square holes, lower-left corner at (2, 2) (mm, inside pic-mmh)."""
    size = n * pitch + pitch / 2
    holes = [
        rect(
            2 + pitch * (i + 0.5),
            2 + pitch * (j + 0.5),
            2 + pitch * (i + 0.5) + hole,
            2 + pitch * (j + 0.5) + hole,
        )
        for j in range(n)
        for i in range(n)
    ]
    return [rect(2, 2, 2 + size, 2 + size, clockwise=True), *holes]


def test_plate_with_two_diagonal_holes_needs_exactly_four_reversals_per_axis() -> None:
    """Lower bound: a closed path moves each axis both ways, so each of the 3 closed cuts
    reverses each axis at least once inside; the plate's start is a corner K reached by a
    rapid from inside it (moving towards K on both axes) while its path leaves K (away on
    both): one more per axis. So >= 4 per axis. Reached: the upper hole from its lower-left
    corner (first motions +X +Y as the rapid from the origin), ending moving -X -Y; the
    lower hole from its upper-right corner (rapid and first motions -X -Y); then the plate.
    """
    contours = [rect(1, 1, 10, 10), rect(6, 6, 8, 8), rect(3, 3, 5, 5)]
    cuts, nest = cuts_of(contours)
    got = order_cuts(cuts, nest, options("reversals"), (0.0, 0.0))
    assert got.reversals["planned"] == (4, 4)
    assert [c.group for c in got.cuts] == [1, 2, 0]
    assert got.cuts[0].path.start == (6, 6) and got.cuts[1].path.start == (5, 5)
    assert count_reversals(got.cuts, (0.0, 0.0)) == (4, 4)


@pytest.mark.parametrize("backlash", [(0.0, 0.0), (204.0, 178.0)])
def test_grid_of_holes_reversals_beat_travel_and_drawn(backlash: tuple[float, float]) -> None:
    """3 × 3 square holes: 10 closed cuts, so >= 10 reversals per axis, plus one per axis
    at the plate's start (see the test above): >= 11 each."""
    cuts, nest = cuts_of(plate_with_grid(3))
    got = order_cuts(cuts, nest, options("reversals"), backlash)
    w = weights(backlash)
    cost = {k: w[0] * v[0] + w[1] * v[1] for k, v in got.reversals.items()}
    assert cost["planned"] <= cost["travel"] and cost["planned"] <= cost["drawn"]
    assert cost["planned"] < cost["travel"]
    assert min(got.reversals["planned"]) >= 11
    assert inside_first(got.cuts, nest)
    assert got.cuts[-1].group == 0


def test_each_orders_reversals_are_counted_once_when_read(monkeypatch: pytest.MonkeyPatch) -> None:
    """``Ordering.reversals`` counts an order when it is read, once; travel = planned once."""
    import camtool.toolpath.order as order

    calls: list[int] = []

    def counting(cuts: Sequence[Cut], start: Point) -> tuple[int, int]:
        calls.append(len(cuts))
        return count_reversals(cuts, start)

    monkeypatch.setattr(order, "count_reversals", counting)
    cuts, nest = cuts_of(plate_with_grid(3))
    got = order_cuts(cuts, nest, options("travel"), (0.0, 0.0))
    assert calls == []  # a 3.5 mm plate, over 1 mm: the small-part finding counts nothing
    assert got.reversals["planned"] == count_reversals(got.cuts, (0.0, 0.0))
    assert got.reversals["travel"] == got.reversals["planned"] and len(calls) == 1
    drawn = got.reversals["drawn"]
    assert len(calls) == 2 and dict(got.reversals) == {
        "drawn": drawn,
        "travel": got.reversals["planned"],
        "planned": got.reversals["planned"],
    }
    assert len(calls) == 2


def test_model_matches_the_pic_mmh_compensations_on_lines() -> None:
    """The mmh-gmm profile compensates every reversal (UNAM-GMM §5.1): the simulated
    reversals and compensation count equal the model's for the planned grid order."""
    cuts, nest = cuts_of(plate_with_grid(3))
    for mode in ("travel", "reversals"):
        got = order_cuts(cuts, nest, options(mode), (204.0, 178.0))
        trace = simulate(got.cuts).trace
        assert trace.reversals == got.reversals["planned"]
        assert trace.compensations == sum(got.reversals["planned"])


@pytest.mark.parametrize(("start_deg", "cw"), [(30, False), (45, False), (45, True), (60, True)])
def test_model_matches_the_pic_mmh_on_a_circle(start_deg: float, cw: bool) -> None:
    """A circle cut with the DSM interpolator (posted as two half arcs) reverses X at its
    left/right extremes and Y at its top/bottom, as the model says."""
    cut = Cut(circle(4, 3, 0.4, start_deg=start_deg, cw=cw), 0)
    assert simulate([cut]).trace.reversals == count_reversals([cut], (0.0, 0.0))


def test_dsm_arc_ends_can_add_reversals_the_model_does_not_see() -> None:
    """On a grid of circles the simulator finds more X/Y reversals than the model: the DSM
    reaches an arc's end point from the step lattice with a last corrective step that can
    go against the arc's direction (and the next move turns back). The model is geometric,
    so it is a lower bound, short by at most 2 per arc block."""
    holes = [
        circle(3 + 1.2 * i, 3 + 1.2 * j, 0.4, start_deg=45) for i in range(3) for j in range(2)
    ]
    cuts, nest = cuts_of([rect(2, 2, 7, 6), *holes])
    got = order_cuts(cuts, nest, options("travel"), (204.0, 178.0))
    v = simulate(got.cuts)
    arcs = sum(isinstance(m, ArcMove) for m in v.program.moves)
    for sim, model in zip(v.trace.reversals, got.reversals["planned"], strict=True):
        assert model <= sim <= model + 2 * arcs


# ------------------------------------------------------------------ random layouts


@st.composite
def layouts(draw: st.DrawFn) -> list[Cut]:
    """A plate with holes on a grid, islands in some holes and open cuts in some cells,
    random directions, freedoms and input order."""
    n = draw(st.integers(1, 3))
    cut_list: list[Contour] = [rect(0, 0, 4 * n, 4 * n, clockwise=draw(st.booleans()))]
    for i in range(n):
        for j in range(n):
            x, y = 4 * i, 4 * j
            kind = draw(st.sampled_from(["none", "hole", "island", "open"]))
            if kind in ("hole", "island"):
                w = draw(st.floats(1.5, 3.0))
                cut_list.append(
                    rect(x + 0.5, y + 0.5, x + 0.5 + w, y + 0.5 + w, clockwise=draw(st.booleans()))
                )
                if kind == "island":
                    cut_list.append(
                        rect(x + 1, y + 1, x + 1.3, y + 1.3, clockwise=draw(st.booleans()))
                    )
            elif kind == "open":
                cut_list.append(
                    Contour(
                        (
                            Line((x + 1, y + 1), (x + 3, y + 2)),
                            Line((x + 3, y + 2), (x + 1, y + 3)),
                        ),
                        False,
                    )
                )
    cuts = [
        Cut(
            c,
            g,
            "profile" if c.closed else "open",
            may_reverse=c.closed and draw(st.booleans()),
            may_rotate=c.closed and draw(st.booleans()),
        )
        for g, c in enumerate(cut_list)
    ]
    return draw(st.permutations(cuts))


@settings(max_examples=40, deadline=None)
@given(layouts(), st.sampled_from([(0.0, 0.0), (204.0, 178.0), (50.0, 300.0)]))
def test_every_order_cuts_holes_first_and_reversals_never_lose(
    cuts: list[Cut], backlash: tuple[float, float]
) -> None:
    nest = nesting([c.path for c in cuts])
    renumbered = [Cut(c.path, i, c.kind, c.may_reverse, c.may_rotate) for i, c in enumerate(cuts)]
    results = {
        m: order_cuts(renumbered, nest, options(m, (-1.0, -2.0)), backlash)
        for m in ("travel", "reversals")
    }
    w = weights(backlash)
    for got in results.values():
        assert inside_first(got.cuts, nest)
        assert sorted(c.group for c in got.cuts) == list(range(len(cuts)))
        for cut in got.cuts:  # same path, possibly rotated or reversed
            src = renumbered[cut.group]
            assert cut.path.length == pytest.approx(src.path.length)
            if not src.may_rotate and not src.may_reverse:
                assert cut.path == src.path
    cost = {k: w[0] * v[0] + w[1] * v[1] for k, v in results["reversals"].reversals.items()}
    assert cost["planned"] <= cost["drawn"] + 1e-9 and cost["planned"] <= cost["travel"] + 1e-9
    travel = results["travel"].travel_mm
    assert travel["planned"] <= travel["drawn"] + 1e-9


def test_pocket_cuts_keep_their_order() -> None:
    ring = [rect(1 + k * 0.2, 1 + k * 0.2, 5 - k * 0.2, 5 - k * 0.2) for k in range(4)]
    nest = Nesting(((),))
    cuts = [Cut(r, 0, "pocket") for r in reversed(ring)]
    for mode in ("travel", "reversals"):
        got = order_cuts(cuts, nest, options(mode, (3.0, 3.0)), (0.0, 0.0))
        assert [c.path.bbox() for c in got.cuts] == [c.path.bbox() for c in cuts]


def test_travel_visits_a_row_of_holes_in_order() -> None:
    # Holes along X, given shuffled: nearest neighbour from the origin walks the row. A
    # closed hole is left where it was entered (a corner on y = 0), so the rapids run
    # monotonically from x = -1 to a corner of the last hole, x >= 4: 5 mm at best.
    holes = [rect(x, 0, x + 0.4, 0.4) for x in (3.0, 1.0, 4.0, 2.0, 0.0)]
    cuts = [Cut(h, i) for i, h in enumerate(holes)]
    got = order_cuts(cuts, Nesting(((),) * 5), options("travel", (-1.0, 0.0)), (0.0, 0.0))
    assert [c.path.bbox()[0] for c in got.cuts] == [0.0, 1.0, 2.0, 3.0, 4.0]
    assert got.travel_mm["planned"] == pytest.approx(5.0)


def test_open_cuts_flip_only_in_travel_mode() -> None:
    line = Contour((Line((5, 0), (1, 0)),), False)
    cut = Cut(line, 0, "open", may_rotate=False)
    travel = order_cuts([cut], Nesting(((),)), options("travel"), (0.0, 0.0))
    assert travel.cuts[0].path.start == (1, 0)
    reversals = order_cuts([cut], Nesting(((),)), options("reversals"), (0.0, 0.0))
    assert reversals.cuts[0].path.start == (5, 0)


@pytest.mark.parametrize("reverse_open", [False, True])
def test_reversals_flip_open_cuts_with_reverse_open(reverse_open: bool) -> None:
    # From (0, 0): drawn, the rapid (10, 0) → (0, 1) goes -X between two +X lines:
    # X/Y reversals 2/0, rapids √101 mm. Cutting the second line back from (10, 1)
    # reverses X once (the +Y rapid sets Y): 1/0, rapids 1 mm. Second line first is
    # 2/1 either way.
    lines = [Contour((Line((0, 0), (10, 0)),), False), Contour((Line((0, 1), (10, 1)),), False)]
    cuts = [Cut(c, i, "open", may_rotate=False) for i, c in enumerate(lines)]
    opts = PlanOptions(feed_mm_min=0.8, order="reversals", reverse_open=reverse_open)
    got = order_cuts(cuts, Nesting(((), ())), opts, (0.0, 0.0))
    assert [c.path.start for c in got.cuts] == [(0, 0), (10, 1) if reverse_open else (0, 1)]
    assert got.reversals["drawn"] == (2, 0)
    assert got.reversals["planned"] == ((1, 0) if reverse_open else (2, 0))
    assert got.travel_mm["planned"] == pytest.approx(1.0 if reverse_open else math.sqrt(101))
    assert sum(got.reversals["planned"]) <= sum(got.reversals["drawn"])


# ------------------------------------------------------------------ report


def test_small_part_with_many_reversals_is_warned() -> None:
    """UNAM-GMM S000-19 (L3205–L3211): under 1 mm, more than 16 compensations fail."""
    holes = [
        rect(0.1 + 0.2 * i, 0.1 + 0.2 * j, 0.2 + 0.2 * i, 0.2 + 0.2 * j)
        for i in range(4)
        for j in range(4)
    ]
    cuts, nest = cuts_of([rect(0, 0, 0.9, 0.9), *holes])
    got = order_cuts(cuts, nest, options("travel"), (0.0, 0.0))
    assert sum(got.reversals["planned"]) > 16
    (finding,) = got.findings
    assert finding.kind == "ordering" and "--order reversals or --order mirror" in finding.message
    big = order_cuts(
        *cuts_of([rect(0, 0, 9, 9), *(h.transformed(10, 0, 0) for h in holes)]),
        options("travel"),
        (0.0, 0.0),
    )
    assert big.findings == ()


def test_summary_and_json() -> None:
    cuts, nest = cuts_of(plate_with_grid(2))
    got = order_cuts(cuts, nest, options("reversals"), (204.0, 178.0))
    (line,) = got.summary()
    d, t, p = got.reversals["drawn"], got.reversals["travel"], got.reversals["planned"]
    assert line.startswith(
        f"order reversals: X/Y reversals {d[0]}/{d[1]} → {p[0]}/{p[1]} (travel order {t[0]}/{t[1]})"
    )
    js = got.to_json()
    assert js["mode"] == "reversals" and js["mirror_axis"] is None
    assert js["reversals"]["planned"] == {"x": p[0], "y": p[1]}
    assert set(js["travel_mm"]) == {"drawn", "travel", "planned"}


# ------------------------------------------------------------------ mirror


def slotted_plate() -> Contour:
    """A 2 × 1.5 mm plate at (3, 2) with a 0.4 × 0.5 mm slot into each side, cut clockwise
    from its lower-left corner; symmetric about x = 4."""
    return polygon(
        [
            (3, 2),
            (3, 2.5),
            (3.4, 2.5),
            (3.4, 3.0),
            (3, 3.0),
            (3, 3.5),
            (5, 3.5),
            (5, 3.0),
            (4.6, 3.0),
            (4.6, 2.5),
            (5, 2.5),
            (5, 2),
        ]
    )


def test_mirror_splits_the_outline_at_the_axis_and_cuts_holes_first() -> None:
    outline = slotted_plate()
    centre_hole = circle(4, 2.75, 0.2, start_deg=-90)  # crosses the axis: split exactly
    left, right = rect(3.6, 3.1, 3.8, 3.3), rect(4.2, 3.1, 4.4, 3.3)
    cuts, nest = cuts_of([outline, left, right, centre_hole])
    got = order_cuts(cuts, nest, options("mirror"), (204.0, 178.0))
    assert got.mirror_axis == "x = 4.0000" and got.mirror_point == (4.0, 3.5)
    groups = [c.group for c in got.cuts]
    assert groups[-2:] == [0, 0] and sorted(groups[:-2]) == [1, 2, 3, 3]
    assert inside_first(got.cuts, nest)
    for a, b in ((got.cuts[-2], got.cuts[-1]),):  # the outline's halves from Ie
        assert a.path.start == b.path.start == (4.0, 3.5)
        assert a.path.end == b.path.end == (4.0, 2.0)
        assert a.path.bbox()[0] >= 4.0 and b.path.bbox()[2] <= 4.0
        assert a.path.length + b.path.length == pytest.approx(outline.length)
        assert not (a.may_reverse or a.may_rotate or b.may_reverse or b.may_rotate)
    halves = [c for c in got.cuts if c.group == 3]
    assert all(isinstance(s, Arc) for h in halves for s in h.path.segments)
    assert halves[0].path.start == halves[1].path.start
    assert {round(h.path.start[0], 12) for h in halves} == {4.0}
    assert sum(h.path.length for h in halves) == pytest.approx(2 * math.pi * 0.2)
    pair = [c for c in got.cuts if c.group in (1, 2)]
    assert pair[0].group == 2  # the right one first, its mirror image next
    (x0, y0), (x1, y1) = pair[0].path.start, pair[1].path.start
    assert (x0 + x1, y0) == (pytest.approx(8.0), pytest.approx(y1))
    assert (pair[0].path.signed_area() > 0) != (pair[1].path.signed_area() > 0)
    assert "mirror about x = 4.0000 mm from (4.0000, 3.5000) mm" in got.summary()[1]


def test_mirror_about_a_horizontal_axis() -> None:
    # Symmetric about y = 1.5 only (a notch in the right side breaks the vertical
    # symmetry). The outline meets the axis at (0, 1.5) and at the notch apex (3, 1.5);
    # with X and Y swapped the "highest" crossing is the one with the largest x.
    shape = polygon([(0, 0), (4, 0), (4, 1), (3, 1.5), (4, 2), (4, 3), (0, 3)])
    cuts, nest = cuts_of([shape])
    got = order_cuts(cuts, nest, options("mirror"), (0.0, 0.0))
    assert got.mirror_axis == "y = 1.5000" and got.mirror_point == (3.0, 1.5)
    a, b = got.cuts
    assert a.path.start == b.path.start == (3.0, 1.5)
    assert a.path.end == b.path.end == (0.0, 1.5)
    assert a.path.bbox()[1] >= 1.5 and b.path.bbox()[3] <= 1.5


def test_mirror_of_an_asymmetric_drawing_names_the_cut() -> None:
    cuts, nest = cuts_of([rect(0, 0, 4, 3), rect(0.5, 0.5, 1.0, 1.0)])
    with pytest.raises(
        ToolpathError,
        match=r"x = 2\.0000 mm \(contour at \(0\.5000, 0\.5000\).*y = 1\.5000.*--order travel",
    ):
        order_cuts(cuts, nest, options("mirror"), (0.0, 0.0))


def test_mirror_order_makes_mirrored_features_equal_under_residual_backlash(tmp_path: Path) -> None:
    """UNAM-GMM S000-20 (L2816–L2841): h/j asymmetry 59 → 3 µm on the thesis's puma.

    This is not the puma, so only the reduction is expected. The machine keeps 100 µm of X
    backlash uncompensated (true 204, compensation 104 µm, uniform). The carriage then sits
    e = 100 µm to the right of the command while X moves -, and on the command while it
    moves + (the first direction, the rapid from the origin). h = right extreme - right slot
    wall, j = left slot wall - left extreme (both 0.4 mm drawn).

    travel (clockwise from (3, 2)): the left edge below the slot and the left wall are cut
    moving +X (exact), the right wall after entering the slot moving -X (+e), the right
    edge moving +X: h = 0.4 - e, j = 0.4: |h - j| = e.
    mirror (right half from Ie = (4, 3.5) moving +X, then the left half from Ie moving -X):
    the right wall is cut moving -X (+e) and the right edge +X, as in travel; the left
    edge is cut moving -X (+e) and the left wall +X (exact): h = j = 0.4 - e.
    """
    machine = tmp_path / "residual.toml"
    machine.write_text(
        "[machine.backlash]\ntrue_um = [204.0, 178.0, 0.0]\ncompensation_um = [104.0, 178.0, 0.0]\n"
        "regions = []\n",
        encoding="utf-8",
    )
    e_mm = 0.1
    cuts, nest = cuts_of([slotted_plate()])
    asym = {}
    for mode in ("travel", "mirror"):
        got = order_cuts(cuts, nest, options(mode), (204.0, 178.0))
        v = simulate(got.cuts, machine)
        h, j = _slot_depths(v)
        asym[mode] = abs(h - j)
        assert h == pytest.approx(0.4 - e_mm, abs=0.005)
    assert asym["travel"] == pytest.approx(e_mm, abs=0.005)
    assert asym["mirror"] < 0.005
    assert asym["mirror"] < asym["travel"] / 20


def _slot_depths(v: Verification) -> tuple[float, float]:
    """h and j of the slotted plate from the simulated carriage (cutting moves only), mm."""
    rapid = np.asarray([isinstance(m, Rapid) for m in v.program.moves])
    pts = v.trace.carriage_mm[~rapid[v.trace.block_of_row]]
    x, y = pts[:, 0], pts[:, 1]
    band = (y > 2.6) & (y < 2.9)
    right_wall = float(np.median(x[band & (x > 4.4) & (x < 4.8)]))
    left_wall = float(np.median(x[band & (x > 3.2) & (x < 3.6)]))
    return float(x.max()) - right_wall, left_wall - float(x.min())


def test_ordering_is_a_frozen_record() -> None:
    got = order_cuts(*cuts_of([rect(0, 0, 1, 1)]), options("travel"), (0.0, 0.0))
    assert isinstance(got, Ordering)
    with pytest.raises(AttributeError):
        got.mode = "mirror"  # type: ignore[misc]
    with pytest.raises(TypeError):
        got.reversals["x"] = (0, 0)  # type: ignore[index]


@st.composite
def symmetric_layouts(draw: st.DrawFn) -> list[Contour]:
    """A plate symmetric about x = 0 with holes mirrored in pairs, centred holes crossing
    the axis and islands in some holes, in random order and directions."""
    out = [rect(-10, 0, 10, 12, clockwise=draw(st.booleans()))]
    for row in range(draw(st.integers(1, 3))):
        y = 1 + 4 * row
        if draw(st.booleans()):  # a centred hole, maybe with an island
            w = draw(st.floats(0.5, 2.0))
            out.append(rect(-w, y, w, y + 3, clockwise=draw(st.booleans())))
            if draw(st.booleans()):
                out.append(rect(-0.25, y + 1, 0.25, y + 2, clockwise=draw(st.booleans())))
        x = draw(st.floats(3.0, 6.0))
        right = rect(x, y, x + 2, y + 2.5, clockwise=draw(st.booleans()))
        left = rect(-x - 2, y, -x, y + 2.5, clockwise=draw(st.booleans()))
        out += [right, left]
    return draw(st.permutations(out))


@settings(max_examples=25, deadline=None)
@given(symmetric_layouts())
def test_mirror_order_cuts_holes_first(contours: list[Contour]) -> None:
    cuts, nest = cuts_of(contours)
    got = order_cuts(cuts, nest, options("mirror", (-12.0, -1.0)), (204.0, 178.0))
    assert got.mirror_axis == "x = 0.0000"
    assert inside_first(got.cuts, nest)
    for g, contour in enumerate(contours):
        mine = [c.path.length for c in got.cuts if c.group == g]
        assert sum(mine) == pytest.approx(contour.length)


def _nest_scene(seed: int) -> list[Contour]:
    """Random squares, circles, touching and duplicate outlines, bow-ties and open lines, mm."""
    rng = np.random.default_rng(seed)
    out: list[Contour] = []
    for _ in range(60):
        x, y = (float(v) for v in rng.integers(0, 20, 2))
        a = float(rng.choice([1.0, 2.0, 4.0, 8.0, 0.5]))
        kind = int(rng.integers(0, 6))
        if kind == 0:
            out.append(rect(x, y, x + a, y + a, clockwise=bool(rng.integers(0, 2))))
        elif kind == 1:
            r = a / 2
            cw = bool(rng.integers(0, 2))
            out.append(Contour((Arc((x + r, y), (x + r, y), (x, y), cw),), True))
        elif kind == 2:  # a bow-tie (self-crossing: buffer(0) repairs it)
            out.append(polygon([(x, y), (x + a, y + a), (x + a, y), (x, y + a)]))
        elif kind == 3:
            out.append(Contour((Line((x, y), (x + a, y + a / 3)),), False))
        elif kind == 4 and out:
            out.append(out[int(rng.integers(0, len(out)))])  # a duplicate
        else:  # a half-disc: an arc and its chord
            arc = Arc((x + a, y), (x - a, y), (x, y), False)
            out.append(Contour((arc, Line((x - a, y), (x + a, y))), True))
    return out


@pytest.mark.parametrize("seed", range(8))
def test_bulk_nesting_is_the_one_by_one_nesting(
    seed: int, accel: bool, monkeypatch: pytest.MonkeyPatch
) -> None:
    # the vectorised shapely path must give exactly the per-contour queries' relation,
    # its pairs asked in parts of a few on threads (accel) or in this thread
    from camtool.toolpath import order

    monkeypatch.setattr(order, "COVER_PART", 5)
    contours = _nest_scene(seed)
    reference = order._nesting_one_by_one(contours)
    monkeypatch.setattr(order, "_nesting_one_by_one", None)  # no fallback taken
    got = nesting(contours)
    assert got == reference
    assert any(got.parents)  # the scenes do nest


def test_nesting_without_closed_contours_or_contours() -> None:
    line = Contour((Line((0, 0), (1, 1)),), False)
    assert nesting([line, line]).parents == ((), ())
    assert nesting([]).parents == ()


def _random_arcs(seed: int) -> list[Contour]:
    """Contours of random arcs (any size, sweep, direction; full circles, near-full, tiny)."""
    rng = np.random.default_rng(seed)
    out: list[Contour] = []
    for _ in range(200):
        cx, cy = (float(v) for v in rng.normal(0, 10.0 ** int(rng.integers(-2, 4)), 2))
        r = float(10.0 ** rng.uniform(-4, 3))
        a0 = float(rng.uniform(-4, 4))
        kind = int(rng.integers(0, 5))
        sweep = {0: 2 * math.pi, 1: float(rng.uniform(-6.28, 6.28)), 2: 1e-9}.get(kind, 0.5)
        a1 = a0 + sweep
        start = (cx + r * math.cos(a0), cy + r * math.sin(a0))
        end = start if kind == 0 else (cx + r * math.cos(a1), cy + r * math.sin(a1))
        if kind == 3:
            end = (start[0] + r * 1e-13, start[1])  # within the full-circle tolerance
        arc = Arc(start, end, (cx, cy), bool(rng.integers(0, 2)))
        tail = Line(end, (end[0] + 1.0, end[1])) if kind == 4 else None
        out.append(Contour((arc,) if tail is None else (arc, tail), False))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_outline_coords_are_the_contours_points(seed: int) -> None:
    from camtool.toolpath.order import _outline_coords

    contours = _random_arcs(seed) + _nest_scene(seed)
    for tol in (1e-4, 0.01, 5.0):
        coords, counts = _outline_coords(contours, tol)
        expected = [c.points(tol) for c in contours]
        assert counts.tolist() == [len(p) for p in expected]
        assert coords.tolist() == [list(xy) for pts in expected for xy in pts]


def test_chord_counts_are_chord_count_on_every_branch() -> None:
    # tolerance over the radius, a tiny ratio (asin form), zero sweep, full turns, and the
    # usual acos form: all as camtool.model.shapes.chord_count counts them
    from camtool.model.shapes import chord_count
    from camtool.toolpath.order import _chord_counts

    rng = np.random.default_rng(7)
    radius = np.concatenate([10.0 ** rng.uniform(-5, 4, 3000), [1e-4, 0.5, 1e-300, 3.0]])
    sweep = np.concatenate([rng.uniform(0, 2 * math.pi, 3000), [0.0, 2 * math.pi, 1.0, 0.0]])
    for tol in (1e-4, 1e-3, 0.1):
        ok = [
            i
            for i in range(len(radius))
            if radius[i] < 1e6 * tol  # the others need more than MAX_CHORDS chords
        ]
        got = _chord_counts(radius[ok], sweep[ok], tol).tolist()
        assert got == [chord_count(float(radius[i]), float(sweep[i]), tol) for i in ok]


def test_chord_counts_refuse_as_chord_count() -> None:
    from camtool.toolpath.order import _chord_counts

    with pytest.raises(UsageError, match="more than the limit"):
        _chord_counts(np.array([1.0, 1e9]), np.array([1.0, 6.0]), 1e-6)
    with pytest.raises(GeometryError, match="must be finite"):
        _chord_counts(np.array([1.0, math.nan]), np.array([1.0, 1.0]), 1e-3)


@pytest.mark.parametrize("seed", range(3))
def test_boxes_within_the_near_distance_are_every_such_pair(seed: int) -> None:
    """The near-copy search's candidates are exactly the pairs of boxes within 10 µm on all
    four sides (by comparing every pair), boxes packed 50 µm wide so that many are."""
    from camtool.toolpath.order import _same_boxes

    rng = np.random.default_rng(seed)
    boxes = rng.uniform(0.0, 0.05, (300, 4))
    boxes[:100, 0] = 0.0  # a hundred lined up on one edge
    a, b = _same_boxes(boxes, 0.01)
    every = {
        (i, j)
        for i in range(len(boxes))
        for j in range(i + 1, len(boxes))
        if np.abs(boxes[i] - boxes[j]).max() <= 0.01
    }
    assert set(zip(a.tolist(), b.tolist(), strict=True)) == every and len(every) > 100
