"""open_gaps in bulk (numpy, math.dist only where it decides) says what the pair loop said.

The reference is the loop it replaced (math.dist for every near pair, a dict of them sorted
by gap), kept here as :func:`_reference`. The drawings: loose lines on a grid (many equal
gaps: the ties keep the tree's order), gaps a few ulps either side of the chaining distance,
and "C"s whose own gap sits at GAP_SHARE of their length.
"""

from __future__ import annotations

import itertools
import math
import random
from collections.abc import Sequence

import numpy as np
import pytest

from camtool.geometry.chain import FREE_JOINT_MM, JOINT_SHARE, joint_distance
from camtool.model.shapes import Contour, Line
from camtool.model.units import fmt_num
from camtool.toolpath.chain import GAP_SHARE
from camtool.toolpath.cuts import Finding
from camtool.toolpath.gaps import MAX_REPORTED, NEAR_GAP_FACTOR, _finding, open_gaps, option_value
from camtool.toolpath.options import PlanOptions


def _reference(contours: Sequence[Contour], options: PlanOptions) -> list[Finding]:
    import shapely

    ends = []
    for index, contour in enumerate(contours):
        if not contour.closed:
            ends += [(index, contour.start), (index, contour.end)]
    if len(ends) < 2:
        return []
    joint = joint_distance(options.chain_tolerance)
    near = max(0.1, NEAR_GAP_FACTOR * joint)
    xy = np.array([p for _, p in ends], dtype=np.float64)
    points = shapely.points(xy)
    pairs = shapely.STRtree(points).query(points, predicate="dwithin", distance=near)
    best: dict[tuple[int, int], float] = {}
    for a, b in zip(*pairs, strict=True):
        if a >= b:
            continue
        gap = math.dist(xy[a], xy[b])
        if gap > joint:
            best[(int(a), int(b))] = gap
    found = []
    for (a, b), gap in sorted(best.items(), key=lambda item: item[1]):
        if ends[a][0] == ends[b][0] and gap >= GAP_SHARE * contours[ends[a][0]].length:
            continue
        shorter = min(contours[ends[a][0]].length, contours[ends[b][0]].length)
        if ends[a][0] != ends[b][0] and gap > max(FREE_JOINT_MM, JOINT_SHARE * shorter):
            continue  # drawn apart: no chaining tolerance joins them
        found.append((gap, _finding(contours, ends[a], ends[b], gap, options)))
    out = [f for _, f in found[:MAX_REPORTED]]
    if len(found) > MAX_REPORTED:
        largest = max(g for g, _ in found)
        out.append(
            Finding(
                "open-gap",
                f"{len(found) - MAX_REPORTED} more open end(s) lie near another (gaps up to "
                f"{fmt_num(largest, 4)} mm); --chain-tolerance {option_value(largest)} joins "
                "them all",
                value=largest,
            )
        )
    return out


def _line(x0: float, y0: float, x1: float, y1: float) -> Contour:
    return Contour((Line((x0, y0), (x1, y1)),), False)


def _grid(n: int, seed: int, length: float) -> list[Contour]:
    """Loose lines ``length`` mm long on a 1 mm grid, some drawn backwards.

    0.5 mm: bench_large's "disjoint", every gap too wide beside its lines to join; 0.95 mm:
    gaps of 0.05 mm between a row's lines, which chaining would bridge.
    """
    rng = random.Random(seed)
    out = []
    side = math.ceil(math.sqrt(n))
    for k in range(n):
        x, y = float(k % side), float(k // side)
        out.append(_line(x + length, y, x, y) if rng.random() < 0.3 else _line(x, y, x + length, y))
    rng.shuffle(out)
    return out


def _at_the_limits(seed: int) -> list[Contour]:
    """Pairs of lines whose ends are a few ulps either side of the chaining distance, and "C"s."""
    rng = random.Random(seed)
    joint = joint_distance(PlanOptions().chain_tolerance)
    out = []
    for k in range(40):
        x = 10.0 * k + rng.random()
        gap = joint * (1.0 + rng.choice([-4, -1, 0, 1, 4]) * 2.2e-16)
        out += [_line(x, 0.0, x + 1.0, 0.0), _line(x + 1.0 + gap, 0.0, x + 3.0, 0.0)]
        # a "U" whose own ends are GAP_SHARE of its length apart, give or take an ulp:
        # sides L, gap g = GAP_SHARE·(2L + g)
        side = 0.2 + 0.2 * rng.random()
        g = GAP_SHARE * 2 * side / (1 - GAP_SHARE) * (1.0 + rng.choice([-1, 0, 1]) * 2.2e-16)
        corners = [(x, 5.0), (x + side, 5.0), (x + side, 5.0 + g), (x, 5.0 + g)]
        out.append(Contour(tuple(Line(p, q) for p, q in itertools.pairwise(corners)), False))
    return out


@pytest.mark.parametrize("seed", range(4))
def test_loose_lines_on_a_grid_give_the_same_findings(seed: int) -> None:
    options = PlanOptions(chain_tolerance=0.01 * (seed + 1))
    near = _grid(900 + 37 * seed, seed, 0.95)
    found = open_gaps(near, options)
    assert found == _reference(near, options)
    assert len(found) == MAX_REPORTED + 1  # the row's gaps, and the line counting the rest
    apart = _grid(900 + 37 * seed, seed, 0.5)
    assert open_gaps(apart, options) == _reference(apart, options) == []


@pytest.mark.parametrize("seed", range(6))
def test_gaps_at_the_limits_give_the_same_findings(seed: int) -> None:
    contours = _at_the_limits(seed)
    options = PlanOptions()
    got = open_gaps(contours, options)
    assert got == _reference(contours, options)
    assert got  # the drawing has near gaps


def test_few_or_no_ends() -> None:
    options = PlanOptions()
    assert open_gaps([], options) == _reference([], options) == []
    one = [_line(0.0, 0.0, 1.0, 0.0)]
    assert open_gaps(one, options) == _reference(one, options)


def _differing_pairs(
    count: int, above: bool
) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """End pairs about 0.3 mm apart whose ``np.hypot`` is one bit above (or below) ``math.dist``."""
    rng = random.Random(7 if above else 8)
    found = []
    while len(found) < count:
        p = (rng.uniform(0.0, 300.0), rng.uniform(0.0, 300.0))
        q = (p[0] + rng.uniform(-0.2, 0.2), p[1] + rng.uniform(-0.2, 0.2))
        rough = float(np.hypot(q[0] - p[0], q[1] - p[1]))
        if (rough > math.dist(p, q)) if above else (rough < math.dist(p, q)):
            found.append((p, q))
    return found


@pytest.mark.parametrize("above", [True, False], ids=["hypot-above", "hypot-below"])
def test_a_gap_exactly_at_the_chaining_distance_is_decided_by_math_dist(above: bool) -> None:
    """Two lines whose ends are exactly --chain-tolerance apart by math.dist (not reported:
    joined) but one bit further (or nearer) by numpy's hypot: only math.dist decides."""
    for p, q in _differing_pairs(5, above):
        exact = math.dist(p, q)
        rough = float(np.hypot(q[0] - p[0], q[1] - p[1]))
        tolerance = exact if above else rough  # exact == limit, or exact one bit above it
        contours = [  # their far ends are out of reach (100 tolerances, ~20 mm)
            _line(p[0] - 50.0, p[1], p[0], p[1]),
            _line(q[0], q[1], q[0], q[1] + 50.0),
        ]
        options = PlanOptions(chain_tolerance=tolerance)
        got = open_gaps(contours, options)
        assert got == _reference(contours, options)
        assert len(got) == (0 if above else 1)
