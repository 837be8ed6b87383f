"""Tests of the GRBL motion model: mc_arc chords and the junction speed
(camtool_postprocessors.grbl.motion).

Every expected value names its source: a section/requirement of
docs/references.md, or "analytic" for a property of the model's formula.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camtool.model.errors import InputError, UsageError
from camtool.verify.interpolators import chord_sagitta
from camtool_postprocessors.grbl.motion import (
    grbl_arc_points,
    grbl_arc_segments,
    grbl_junction_speed_mm_s,
)


def test_grbl_segment_count_formula():
    # GRBL 1.1 motion_control.c: floor(|½·θ·r| / √(tol·(2r − tol))); r = 10 mm full
    # circle at the default $12 = 0.002 mm
    expected = math.floor(0.5 * 2 * math.pi * 10 / math.sqrt(0.002 * (20 - 0.002)))
    assert grbl_arc_segments(10.0, -2 * math.pi, 0.002) == expected == 157


def test_grbl_arc_points_geometry():
    pts = grbl_arc_points((10.0, 0.0), (0.0, 10.0), (0.0, 0.0), False)
    n = grbl_arc_segments(10.0, math.pi / 2, 0.002)
    assert pts.shape == (n, 2) and not pts.flags.writeable
    assert tuple(pts[-1]) == (0.0, 10.0)  # GRBL: last segment goes to the target
    # analytic: points on the circle (GRBL's 3rd-order rotation drifts far below 1 µm)
    assert np.abs(np.hypot(pts[:, 0], pts[:, 1]) - 10.0).max() < 1e-4
    # analytic: CCW quarter from +X to +Y stays in the first quadrant, angle increasing
    assert np.all(np.diff(np.arctan2(pts[:, 1], pts[:, 0])) > 0)
    # analytic: chord error ≈ c²/8r grows with the square of the chord; floor() makes
    # chords at most (n+1)/n longer than the tolerance chord
    chords = np.diff(np.vstack(([[10.0, 0.0]], pts)), axis=0)
    beta = 2 * np.arcsin(np.hypot(chords[:, 0], chords[:, 1]) / 20.0)
    assert max(chord_sagitta(10.0, b) for b in beta) <= 0.002 * ((n + 1) / n) ** 2 + 1e-9


def test_grbl_full_circle_and_invalid_target():
    # GRBL: start == end is a full circle (angular travel −2π for G02)
    pts = grbl_arc_points((5.0, 0.0), (5.0, 0.0), (0.0, 0.0), True)
    assert len(pts) == grbl_arc_segments(5.0, 2 * math.pi, 0.002)
    assert pts[len(pts) // 4, 1] < 0  # G02 from +X goes through −Y first
    # GRBL gcode.c: end radius off by > 0.005 mm and > 0.1 % of r → error 33
    with pytest.raises(InputError):
        grbl_arc_points((5.0, 0.0), (0.0, 5.1), (0.0, 0.0), True)
    with pytest.raises(UsageError):
        grbl_arc_points((5.0, 0.0), (0.0, 5.0), (0.0, 0.0), True, arc_tolerance_mm=0.0)


def test_grbl_junction_speed():
    # GRBL planner.c: v² = a·δ·s/(1 − s), s = cos(turn/2); straight on is unlimited,
    # a 90° corner gives √(a·δ·(√2/2)/(1 − √2/2)) = √(2.414·a·δ), a reversal stops
    v = grbl_junction_speed_mm_s([0.0, math.pi / 2, math.pi], acceleration_mm_s2=100)
    assert math.isinf(v[0]) and v[2] == 0.0
    assert float(v[1]) == pytest.approx(math.sqrt((1 + math.sqrt(2)) * 100 * 0.010))


@pytest.mark.parametrize("radius", [0.001, 0.00099999999999989, 0.0004])
def test_grbl_segment_count_is_refused_where_mc_arc_divides_by_nothing(radius: float) -> None:
    # analytic: √(tol·(2r − tol)) is 0 at r = tol/2 and the root of a negative number below
    # it; GRBL's uint16 cast of the quotient (inf or NaN) is undefined C: no prediction
    with pytest.raises(InputError, match=r"not over half of grbl's arc tolerance \$12"):
        grbl_arc_segments(radius, math.pi, 0.002)
    # just over half: a finite count (analytic, the formula)
    r = 0.0010001
    assert grbl_arc_segments(r, math.pi, 0.002) == math.floor(
        0.5 * math.pi * r / math.sqrt(0.002 * (2 * r - 0.002))
    )
