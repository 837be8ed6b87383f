"""Table tests of the one number-formatting module (STYLE 8)."""

from __future__ import annotations

import math

import pytest

from camtool.model.errors import DialectError
from camtool.post.numfmt import NumberFormat, format_int

UM52 = NumberFormat(scale=1000.0, decimals=2, int_digits=5)


@pytest.mark.parametrize(
    ("value_mm", "fmt", "text"),
    [
        (2.969, UM52, "02969.00"),  # UNAM-GMM L1731
        (3.4, UM52, "03400.00"),
        (-0.15, UM52, "-00150.00"),  # S000-03 example X-00150.00
        (0.0, UM52, "00000.00"),
        (-0.000001, UM52, "00000.00"),  # rounds to zero: never "-0"
        (0.000005, UM52, "00000.01"),  # half away from zero
        (-0.000005, UM52, "-00000.01"),
        (99.99999, UM52, "99999.99"),
        (2.969, NumberFormat(scale=1000.0, decimals=2, int_digits=5, sign="always"), "+02969.00"),
        (0.0, NumberFormat(scale=1000.0, decimals=2, int_digits=5, sign="always"), "+00000.00"),
        (1.0, NumberFormat(decimals=1), "1.0"),
        (-1.25, NumberFormat(decimals=3), "-1.250"),
        (12.5, NumberFormat(scale=10.0, decimals=0), "125"),
    ],
)
def test_format_table(value_mm: float, fmt: NumberFormat, text: str) -> None:
    assert fmt.format(value_mm) == text


def test_overflow_is_a_dialect_error() -> None:
    with pytest.raises(DialectError, match="5 integer digits"):
        UM52.format(100.0)  # 100000 µm needs 6 digits


@pytest.mark.parametrize("text", ["02969.00", "-00150.00", "+00001.50"])
def test_parse_inverts_format(text: str) -> None:
    assert UM52.format(UM52.parse(text)).lstrip("+") == text.lstrip("+")


def test_format_int() -> None:
    assert format_int(8, 2, what="feed code") == "08"
    with pytest.raises(DialectError):
        format_int(100, 2, what="feed code")


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan])
@pytest.mark.parametrize("fmt", [UM52, NumberFormat(), NumberFormat(decimals=2, grid_mm=0.04)])
def test_non_finite_values_are_a_dialect_error_naming_the_value(
    value: float, fmt: NumberFormat
) -> None:
    # was: decimal.InvalidOperation, an "internal error" at the CLI
    with pytest.raises(DialectError, match=f"cannot write {value!r}: the value is not a finite"):
        fmt.format(value)


@pytest.mark.parametrize(
    ("value_mm", "fmt", "text"),
    [
        # wider than the default 28-digit decimal context: written exactly, not refused
        (1e30, NumberFormat(decimals=3), "1" + "0" * 30 + ".000"),
        (-1e30, NumberFormat(decimals=2, grid_mm=0.04, min_decimals=0), "-1" + "0" * 30),
        (1e300, NumberFormat(scale=10.0, decimals=0), "1" + "0" * 301),
    ],
)
def test_huge_finite_values_are_written_exactly(
    value_mm: float, fmt: NumberFormat, text: str
) -> None:
    # 1e30 is exactly 10**30 in the float's shortest repr, so the text is analytic
    assert fmt.format(value_mm) == text


def test_huge_value_over_its_digits_names_it_briefly() -> None:
    with pytest.raises(DialectError, match=r"^1\.00000e\+311 does not fit 5 integer digits$"):
        UM52.format(1e308)


@pytest.mark.parametrize(
    ("kwargs", "bad"),
    [({"scale": 0.0}, "scale"), ({"scale": math.inf}, "scale"), ({"grid_mm": math.nan}, "grid_mm")],
)
def test_format_refuses_a_scale_that_would_divide_by_zero(
    kwargs: dict[str, float], bad: str
) -> None:
    with pytest.raises(ValueError, match=f"{bad} must be a finite number > 0"):
        NumberFormat(**kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("Infinity", "is not a finite number"),
        ("NaN", "is not a finite number"),
        ("x", "is not a number"),
        ("1" + "0" * 400, r"1\.00000e\+400 is too large"),
    ],
)
def test_parse_refuses_what_is_not_a_finite_number(text: str, message: str) -> None:
    with pytest.raises(DialectError, match=message):
        NumberFormat().parse(text)
