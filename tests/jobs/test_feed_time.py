"""``feed_time_s``: the header's time estimate, by analysis of a few moves."""

from __future__ import annotations

import math

import pytest

from camtool.jobs.run import feed_time_s
from camtool.model.program import ArcMove, Linear, Rapid
from camtool.post.registry import load_target


def test_lines_arcs_and_plunges_at_their_feeds() -> None:
    target = load_target("linuxcnc")
    moves = [
        Linear(0.0, 0.0, 300.0, z=-1.0),  # 1 mm plunge at 300 mm/min: 0.2 s
        Linear(30.0, 40.0, 600.0),  # 50 mm at 600 mm/min: 5 s
        ArcMove(10.0, 40.0, 20.0, 40.0, False, 600.0),  # half of R 10 CCW: 10π mm, π s
        ArcMove(10.0, 40.0, 20.0, 40.0, True, 600.0, z=-2.0),  # a whole helix turn, 1 mm down
        ArcMove(30.0, 40.0, 20.0, 40.0, True, 0.0),  # no feed: not counted
    ]
    helix = math.hypot(20.0 * math.pi, 1.0) / 600.0 * 60.0
    expected = 0.2 + 5.0 + math.pi + helix
    rate = target.machine.timing.get("max_rate_mm_min")
    got = feed_time_s(moves, target, start=(0.0, 0.0, 0.0))
    assert got == pytest.approx(expected, rel=1e-12)
    with_rapid = feed_time_s([*moves, Rapid(30.0, 40.0, 3.0)], target, start=(0.0, 0.0, 0.0))
    # a 5 mm retract at the profile's rapid rate (not counted without one)
    assert with_rapid - got == pytest.approx(5.0 / float(rate) * 60.0 if rate else 0.0, abs=1e-9)
