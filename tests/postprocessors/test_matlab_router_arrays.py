"""Tests of the Angel-11 Matlab GUI arrays (camtool_postprocessors.matlab_router.arrays).

Golden numbers: reference/Angel-11.md §3 (the star worked example, thesis L3183–L3235)
and §8 R1–R2, R7. Other expectations are analytic (the algorithm's definition).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from camtool.model.errors import DialectError, UsageError
from camtool_postprocessors.matlab_router.arrays import (
    DEFAULT_SPEED,
    matlab_round,
    points_01mm,
    router_arrays,
)
from tests.shapes import STAR_LXY, STAR_VELXY, STAR_XY_01MM

STAR_XY = np.array(STAR_XY_01MM)  # Angel-11 §3, L3196–L3200


def test_star_reproduces_the_thesis_arrays_exactly() -> None:
    # Angel-11 §3 (L3212–L3228) and R2 golden test.
    arrays = router_arrays(STAR_XY.T)
    assert arrays.lxy.tolist() == STAR_LXY
    assert arrays.velxy.tolist() == STAR_VELXY
    assert arrays.xy.tolist() == STAR_XY.tolist()


def test_star_header_values() -> None:
    # Angel-11 §3, L3233–L3235: "n=10 y el primer punto ... x=151 e y=86"; default speed 480 (R7).
    arrays = router_arrays(STAR_XY.T)
    assert arrays.n == 10
    assert arrays.first_point == (151, 86)
    assert arrays.speed == DEFAULT_SPEED == 480


def test_arrays_are_read_only_int64() -> None:
    arrays = router_arrays(STAR_XY.T)
    for arr in (arrays.xy, arrays.lxy, arrays.velxy, arrays.increments):
        assert arr.dtype == np.int64
        assert not arr.flags.writeable


@pytest.mark.parametrize(
    ("value", "expected"),
    [(2.5, 3), (-2.5, -3), (0.5, 1), (-0.5, -1), (1.4999999999999998, 1),
     (0.49999999999999994, 0), (-0.2, 0), (76.52, 77), (-77.5, -78)],
)  # fmt: skip
def test_matlab_round_is_half_away_from_zero(value: float, expected: int) -> None:
    # Angel-11 §3: Matlab round rounds halves away from zero (Python's round(2.5) == 2).
    assert matlab_round(value) == expected
    assert isinstance(matlab_round(value), int)


def test_matlab_round_array() -> None:
    out = matlab_round(np.array([[0.5, -1.5], [2.49, -2.51]]))
    assert out.tolist() == [[1, -2], [2, -3]]
    assert out.dtype == np.int64


def test_matlab_round_rejects_nan() -> None:
    with pytest.raises(UsageError):
        matlab_round(float("nan"))


def test_points_01mm_rounds_like_the_gui() -> None:
    # R1: round(x_mm*10) half away from zero, as the GUI's round(x_cm*100).
    out = points_01mm([[15.15, 0.25], [-0.25, 199.99]])
    assert out.tolist() == [[152, 3], [-3, 2000]]
    assert not out.flags.writeable


def test_equal_deltas_keep_both_axes_at_full_speed() -> None:
    # Angel-11 §3 observations: |lx| = |ly| leaves both speeds at ±480.
    arrays = router_arrays([(0, 0), (100, -100), (100, -100)])
    assert arrays.velxy.tolist() == [[480, 480], [-480, 480]]
    assert arrays.lxy.tolist() == [[100, 0], [100, 0]]


def test_zero_minor_delta_gives_zero_speed() -> None:
    # Angel-11 §3 observations: factor = Inf, so the minor speed is 480/Inf = 0.
    arrays = router_arrays([(0, 0), (0, -50), (70, -50)])
    assert arrays.velxy.tolist() == [[0, 480], [-480, 0]]


def test_speed_parameter_scales_the_major_axis() -> None:
    # R7: the major-axis speed is configurable; minor = round(300·120/200) = 180.
    arrays = router_arrays([(0, 0), (-200, 120)], speed=300)
    assert arrays.velxy.tolist() == [[-300], [180]]


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((1, 2)),
        np.zeros((3, 3)),
        np.zeros(4),
        [[0.0, 0.0], [1.5, 2.0]],
        [[0, 0], [np.nan, 1]],
    ],
)
def test_bad_vertices_raise_dialect_error(bad: object) -> None:
    with pytest.raises(DialectError):
        router_arrays(bad)  # type: ignore[arg-type]


@pytest.mark.parametrize("speed", [0, -480, 480.0, True])
def test_bad_speed_raises_usage_error(speed: object) -> None:
    with pytest.raises(UsageError, match="speed"):
        router_arrays([(0, 0), (1, 1)], speed=speed)  # type: ignore[arg-type]


coord = st.integers(min_value=0, max_value=2000)


@given(st.lists(st.tuples(coord, coord), min_size=2, max_size=12), st.integers(1, 1000))
def test_speed_rules_hold_for_any_polyline(points: list[tuple[int, int]], speed: int) -> None:
    # R2 (analytic): major axis ±speed, minor ±round(speed·|minor|/|major|), sign of the delta.
    arrays = router_arrays(points, speed=speed)
    d = np.diff(np.array(points), axis=0).T
    assert arrays.lxy.tolist() == np.abs(d).tolist()
    for (dx, dy), (vx, vy) in zip(d.T, arrays.velxy.T, strict=True):
        big, small = max(abs(dx), abs(dy)), min(abs(dx), abs(dy))
        v_big, v_small = (vx, vy) if abs(dx) >= abs(dy) else (vy, vx)
        if big == 0:
            assert (vx, vy) == (speed, speed)
            continue
        assert abs(v_big) == speed
        assert abs(abs(v_small) - speed * small / big) <= 0.5 + 1e-9
        for delta, v in ((dx, vx), (dy, vy)):
            assert np.sign(v) == np.sign(delta) or v == 0
