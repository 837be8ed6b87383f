"""`camtool.model.units.fmt_num`: fixed decimals, never a negative zero (STYLE.md §8)."""

from __future__ import annotations

import pytest

from camtool.model.units import fmt_num


@pytest.mark.parametrize(
    ("value", "decimals", "text"),
    [
        (-0.0, 4, "0.0000"),
        (-0.00001, 4, "0.0000"),
        (-0.0004, 3, "0.000"),
        (-0.4, 0, "0"),
        (-0.6, 0, "-1"),
        (-0.0005001, 3, "-0.001"),
        (3.14159, 2, "3.14"),
        (12.0, 1, "12.0"),
        (0.0, 4, "0.0000"),
    ],
)
def test_fmt_num(value: float, decimals: int, text: str) -> None:
    assert fmt_num(value, decimals) == text


def test_default_is_four_decimals() -> None:
    assert fmt_num(1.5) == "1.5000"
