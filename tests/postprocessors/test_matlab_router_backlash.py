"""matlab-router: reversals counted from the servo trace; a backlash applied or refused."""

from __future__ import annotations

import dataclasses

import pytest

from camtool.model.errors import InputError
from camtool.model.machine import Backlash, BacklashRegion
from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.verify.verifier import verify_program
from camtool_postprocessors.matlab_router.motion import count_reversals

F = 225.0


def _square() -> Program:
    """A 20 mm square from (10, 10), CCW: X goes + then −, Y + then −."""
    corners = [(30, 10), (30, 30), (10, 30), (10, 10)]
    return Program((Rapid(10, 10, contour=1), *(Linear(x, y, F, contour=1) for x, y in corners)))


def _zigzag() -> Program:
    """X 10 → 30 → 10 → 30 stepping 5 mm in Y: 2 X reversals, Y always +: 0."""
    path = [(30, 10), (30, 15), (10, 15), (10, 20), (30, 20)]
    return Program((Rapid(10, 10, contour=1), *(Linear(x, y, F, contour=1) for x, y in path)))


def test_reversals_are_counted_from_the_trace() -> None:
    machine = load_target("matlab-router").machine
    assert verify_program(_square(), machine, name="r").trace.reversals == (1, 1)
    assert verify_program(_zigzag(), machine, name="r").trace.reversals == (2, 0)


def test_count_reversals_ignores_a_wobble_under_the_dead_band() -> None:
    assert count_reversals([0.0, 1.0, 0.9995, 1.0, 2.0]) == 0
    assert count_reversals([0.0, 1.0, 0.5, 1.0, 0.0]) == 3
    assert count_reversals([3.0]) == 0


def test_backlash_overlay_is_applied_as_a_dead_band() -> None:
    """Angel-11 R15: the band starts taken up in +; after the square's − legs the table
    lags by the band, so the closure is (+100, +50) µm for bands of 100 and 50 µm."""
    base = load_target("matlab-router").machine
    machine = dataclasses.replace(base, backlash=Backlash(true_um=(100.0, 50.0, 0.0)))
    plain = verify_program(_square(), base, name="r")
    v = verify_program(_square(), machine, name="r")
    assert plain.contours[0].closure_um is not None and v.contours[0].closure_um is not None
    dx = v.contours[0].closure_um[0] - plain.contours[0].closure_um[0]
    dy = v.contours[0].closure_um[1] - plain.contours[0].closure_um[1]
    assert (dx, dy) == pytest.approx((100.0, 50.0), abs=1e-6)
    budget = v.error_budget
    assert budget.dominant("contour 1 closure gap") == "backlash"
    assert {s.name for s in budget.sources if s.status == "modelled"} == {"backlash"}


@pytest.mark.parametrize(
    ("backlash", "named"),
    [
        (Backlash(true_um=(100.0, 0.0, 0.0), compensation_um=(100.0, 0.0, 0.0)), "compensation_um"),
        (
            Backlash(regions=(BacklashRegion(axis="x", x_mm=(0, 10), y_mm=(0, 10), true_um=50.0),)),
            "regions",
        ),
    ],
)
def test_what_the_router_cannot_model_is_refused(backlash: Backlash, named: str) -> None:
    machine = dataclasses.replace(load_target("matlab-router").machine, backlash=backlash)
    with pytest.raises(InputError, match=rf"\[machine.backlash\] {named}.*--machine file"):
        verify_program(_square(), machine, name="r")
