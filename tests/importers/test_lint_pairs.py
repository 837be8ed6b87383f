"""`inspect`'s duplicate and overlap search: its pairs in arrays miss none the exact tests find.

The reference is every pair of segments put to the exact tests (``_same``, ``_overlap``),
no boxes or arrays in between; the arc boxes are checked against :meth:`Arc.bbox`.
"""

from __future__ import annotations

import math
import random

import numpy as np
import pytest

from camtool.importers import lint
from camtool.model.shapes import Arc, Contour, Drawing, Line, Segment


def _point(rng: random.Random, c: tuple[float, float], r: float, a: float) -> tuple[float, float]:
    return (c[0] + r * math.cos(a), c[1] + r * math.sin(a))


def _segments(seed: int) -> tuple[list[Segment], float]:
    """Lines and arcs at one scale, half of them near copies or pieces of an earlier one."""
    rng = random.Random(seed)
    scale = rng.choice([1.0, 100.0, 1e5])
    tol = rng.choice([0.01, 0.1, 1e-6])
    segs: list[Segment] = []
    for _ in range(rng.randint(2, 50)):
        jig = tol * rng.choice([0.0, 0.5, 0.99, 2.0])
        if segs and rng.random() < 0.5:
            s = rng.choice(segs)
            if isinstance(s, Line):
                (x0, y0), (x1, y1) = s.start, s.end
                t0, t1 = rng.uniform(-0.5, 1.5), rng.uniform(-0.5, 1.5)
                a = (x0 + (x1 - x0) * t0 + jig, y0 + (y1 - y0) * t0 - jig)
                b = (x0 + (x1 - x0) * t1, y0 + (y1 - y0) * t1 + jig)
                segs.append(Line(a, b) if a != b else Line(s.end, s.start))
            else:  # on the same circle within the jig, across the 0°/360° seam too
                c, r = (s.centre[0] + jig, s.centre[1]), s.radius + jig
                a0, sweep = rng.uniform(-7, 7), rng.choice([rng.uniform(-6.3, 6.3), math.tau])
                end = _point(rng, c, r, a0 + sweep)
                segs.append(Arc(_point(rng, c, r, a0), end, c, sweep < 0))
            continue
        c = (rng.uniform(-10, 10) * scale, rng.uniform(-10, 10) * scale)
        if rng.random() < 0.4:
            d = rng.choice([1.0, scale])
            segs.append(Line(c, (c[0] + d * rng.uniform(-1, 1), c[1] + d * rng.uniform(-1, 1))))
        else:
            r = rng.choice([1e-3, 1.0, scale])
            a0 = rng.choice([0.0, math.pi / 2, math.pi, -math.pi / 2, rng.uniform(-7, 7)])
            sweep = rng.choice([math.pi / 2, -math.pi, rng.uniform(-6.3, 6.3), math.tau])
            end = _point(rng, c, r, a0 + sweep)
            segs.append(Arc(_point(rng, c, r, a0), end, c, sweep < 0))
    return segs, tol


@pytest.mark.parametrize("seed", range(60))
def test_the_candidate_pairs_hold_every_pair_the_exact_tests_accept(seed: int) -> None:
    segs, tol = _segments(seed)
    found = lint._candidates(segs, tol)
    pairs = set(zip(found[0].tolist(), found[1].tolist(), strict=True))
    accepted = {
        (i, j)
        for i in range(len(segs))
        for j in range(i + 1, len(segs))
        if lint._same(segs[i], segs[j], tol) or lint._overlap(segs[i], segs[j], tol) is not None
    }
    assert accepted <= pairs
    assert found.shape[0] == 2 and all(i < j for i, j in pairs)
    order = np.lexsort((found[1], found[0]))
    assert (order == np.arange(found.shape[1])).all()  # by i, then j


@pytest.mark.parametrize("seed", range(20))
def test_the_boxes_in_arrays_are_the_segments_own(seed: int) -> None:
    segs, _ = _segments(seed)
    ends = np.array([(*s.start, *s.end) for s in segs])
    circle = np.array(
        [(*s.centre, float(s.clockwise)) if isinstance(s, Arc) else (np.nan,) * 3 for s in segs]
    )
    got = lint._boxes(ends, circle)
    for s, box in zip(segs, got, strict=True):
        size = max(1.0, *(abs(v) for v in s.bbox()))
        assert box == pytest.approx(s.bbox(), abs=1e-9 * size), s


def test_an_arc_through_its_circle_s_extremes_has_them_in_its_box() -> None:
    # a CCW half circle from 270° to 90° passes 0° only: x reaches 15; a CW one passes 180°
    ccw = Arc((10, -5), (10, 5), (10, 0), False)
    cw = Arc((10, -5), (10, 5), (10, 0), True)
    got = lint._boxes(
        np.array([(*ccw.start, *ccw.end), (*cw.start, *cw.end)]),
        np.array([(*ccw.centre, 0.0), (*cw.centre, 1.0)]),
    )
    assert got.tolist() == [[10.0, -5.0, 15.0, 5.0], [5.0, -5.0, 10.0, 5.0]]


def test_two_points_near_each_other_are_neither_duplicate_nor_overlap() -> None:
    specks = [Contour((Line((x, 0.0), (x, 0.0)),), False, "0", f"p{x}") for x in (0.0, 0.015)]
    assert lint.duplicates(specks, 0.01) == []


def test_two_specks_apart_are_one_gap_not_one_per_pair_of_ends() -> None:
    # each speck's two ends lie within a nanometre: four pairs of ends, one gap
    drawing = Drawing(
        tuple(
            Contour((Line((x, 0.0), (x, 1e-9)),), False, "0", name)
            for x, name in ((0.0, "a"), (0.015, "b"))
        )
    )
    _, findings = lint.check_drawing(drawing, 0.01)
    (gap,) = [f for f in findings if f.kind == "gap"]
    assert gap.sources == ("a", "b") and "gap of 0.015 mm" in gap.message
