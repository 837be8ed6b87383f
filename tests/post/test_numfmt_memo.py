"""NumberFormat's memo returns what its Decimal paths compute (issue 17)."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import DialectError
from camtool.post.numfmt import NumberFormat

FORMATS = [
    NumberFormat(),
    NumberFormat(scale=1000.0, decimals=0, int_digits=6),
    NumberFormat(decimals=3, min_decimals=1, sign="always"),
    NumberFormat(scale=10.0, decimals=2, grid_mm=0.0125),
]


@settings(max_examples=300, deadline=None)
@given(st.floats(-1e5, 1e5, allow_nan=False), st.sampled_from(range(len(FORMATS))))
def test_memo_equals_uncached(value: float, which: int) -> None:
    fmt = FORMATS[which]
    try:
        slow = fmt._format_slow(value)
    except DialectError:
        with pytest.raises(DialectError):
            fmt.format(value)
        return
    for _ in range(2):  # computed, then remembered
        assert fmt.format(value) == slow
        assert fmt.parse(slow) == fmt._parse_slow(slow)


def test_signed_zero_and_errors_are_not_remembered_wrongly() -> None:
    fmt = NumberFormat()
    assert fmt.format(-0.0) == fmt._format_slow(-0.0) == fmt.format(0.0) == "0.000"
    for bad in (math.nan, math.inf):
        for _ in range(2):
            with pytest.raises(DialectError):
                fmt.format(bad)
    with pytest.raises(DialectError):
        fmt.parse("x1")


def test_memo_is_not_part_of_equality() -> None:
    a, b = NumberFormat(), NumberFormat()
    a.format(1.5)
    assert a == b and hash(a) == hash(b) and repr(a) == repr(b)
