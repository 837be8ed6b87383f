"""Table tests of the one number-formatting module (STYLE 8), and its shortcuts against
``Decimal``: the texts it keeps, ``half_up`` on the float's repr and ``float`` for a plain
decimal give what ``Decimal`` gives, on random values of every kind and every format
option (the texts, or the refusals, identical)."""

from __future__ import annotations

import contextlib
import math
from decimal import ROUND_HALF_UP, Decimal, InvalidOperation, localcontext

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtool.model.errors import DialectError
from camtool.post.numfmt import NumberFormat, format_int, half_up

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
    # not: decimal.InvalidOperation, an "internal error" at the CLI
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


# ---------------------------------------------------------------- against Decimal
# The judge of the shortcuts (``half_up`` on the float's repr, ``float`` for a plain
# decimal, the kept texts): the writer and reader written out with ``Decimal`` here.


def decimal_format(fmt: NumberFormat, value_mm: float) -> str:
    """What :meth:`NumberFormat.format` must write: its ``Decimal`` quantization, laid out."""
    q = fmt.quantize(value_mm)
    text = f"{abs(q):.{fmt.decimals}f}"
    if fmt.min_decimals is not None and fmt.decimals > fmt.min_decimals:
        whole, frac = text.split(".")
        frac = frac.rstrip("0").ljust(fmt.min_decimals, "0")
        text = f"{whole}.{frac}" if frac else whole
    int_part = text.split(".")[0]
    if fmt.int_digits is not None:
        if len(int_part) > fmt.int_digits:
            raise DialectError(f"does not fit {fmt.int_digits} integer digits")
        if fmt.pad:
            text = text.rjust(len(text) - len(int_part) + fmt.int_digits, "0")
    if q < 0:
        return "-" + text
    return ("+" + text) if fmt.sign == "always" else text


def decimal_parse(fmt: NumberFormat, text: str) -> float:
    """What :meth:`NumberFormat.parse` must read: the decimal over the scale, correctly rounded."""
    try:
        number = Decimal(text)
    except InvalidOperation:
        raise DialectError("not a number") from None
    if not number.is_finite():
        raise DialectError("not a finite number")
    with localcontext() as ctx:
        ctx.prec = max(28, len(number.as_tuple().digits) + 8)
        value = float(number / Decimal(repr(float(fmt.scale))))
    if not math.isfinite(value):
        raise DialectError("too large")
    return value


ALL_FORMATS = [
    NumberFormat(decimals=d, min_decimals=m, int_digits=i, pad=p, sign=sg)
    for d in (0, 1, 3, 4, 6)
    for m in (None, 0, min(1, d))
    if m is None or m <= d
    for i, p in ((None, True), (4, True), (4, False))
    for sg in ("negative", "always")
]


def _values(rng: np.random.Generator, n: int) -> list[float]:
    out = [0.0, -0.0, 0.5, -0.5, 0.0005, -0.0005, 2.0005, 1e-5, -1e-7, 1e15, 1e16, -1e22]
    out += [math.nan, math.inf, -math.inf, 5e-324, 1.7976931348623157e308]
    for _ in range(n):
        kind = rng.integers(0, 6)
        if kind == 0:
            v = float(rng.uniform(-1000, 1000))
        elif kind == 1:  # an exact half at some number of decimals
            d = int(rng.integers(0, 8))
            v = (int(rng.integers(-(10**6), 10**6)) + 0.5) / 10**d
        elif kind == 2:  # a few digits, as G-code is written
            v = round(float(rng.uniform(-500, 500)), int(rng.integers(0, 7)))
        elif kind == 3:
            v = float(10 ** rng.uniform(-9, 18)) * float(rng.choice([-1, 1]))
        elif kind == 4:  # repr with a digit 4 or 5 just past the 3rd decimal
            tail = rng.choice([4, 5, 49, 50, 51])
            v = float(f"{rng.integers(-9999, 9999)}.{rng.integers(0, 1000):03d}{tail}")
        else:
            v = float(rng.normal(0, 50)) * 10 ** -int(rng.integers(0, 5))
        out.append(v)
    return out


def _outcome(call: object, arg: object) -> str:
    """The value's repr, or that it was refused (the messages are the library's own)."""
    try:
        return repr(call(arg))  # type: ignore[operator]
    except DialectError:
        return "DialectError"


@pytest.mark.parametrize("k", range(0, len(ALL_FORMATS), 1))
def test_format_fast_equals_decimal(k: int) -> None:
    fmt = ALL_FORMATS[k]
    rng = np.random.default_rng(k)
    for v in _values(rng, 1500):
        assert _outcome(fmt.format, v) == _outcome(lambda x: decimal_format(fmt, x), v), (fmt, v)


def test_parse_fast_equals_decimal() -> None:
    rng = np.random.default_rng(99)
    fmt = NumberFormat(decimals=3)
    texts = [
        "0",
        "-0",
        "-0.000",
        "+1.5",
        ".5",
        "5.",
        "-.5",
        "1e3",
        "1_0",
        " 1",
        "",
        "-",
        ".",
        "0x10",
        "nan",
        "inf",
        "1" * 30,
        "9" * 24,
        "0." + "1" * 22,
        "00012.34000",
    ]
    for v in _values(rng, 5000):
        for f in ALL_FORMATS[::7]:
            with contextlib.suppress(DialectError):
                texts.append(f.format(v))
        texts.append(repr(v))
    for t in texts:
        assert _outcome(fmt.parse, t) == _outcome(lambda x: decimal_parse(fmt, x), t), t


def test_half_up_equals_decimal() -> None:
    """``half_up``'s shortcut (a repr that rounds down keeps its digits) is Decimal's rounding."""
    rng = np.random.default_rng(1717)
    for v in _values(rng, 4000):
        for d in range(8):
            got = half_up.__wrapped__(v, d)
            if got is None:
                assert "e" in repr(v) or not math.isfinite(v)
                continue
            q = Decimal(repr(v)).quantize(Decimal(1).scaleb(-d), rounding=ROUND_HALF_UP)
            assert got == (f"{abs(q):.{d}f}", q < 0), (v, d)


MEMO_FORMATS = [
    NumberFormat(),
    NumberFormat(scale=1000.0, decimals=0, int_digits=6),
    NumberFormat(decimals=3, min_decimals=1, sign="always"),
    NumberFormat(scale=10.0, decimals=2, grid_mm=0.0125),
]


@settings(max_examples=300, deadline=None)
@given(st.floats(-1e5, 1e5, allow_nan=False), st.sampled_from(range(len(MEMO_FORMATS))))
def test_memo_equals_uncached(value: float, which: int) -> None:
    fmt = MEMO_FORMATS[which]
    try:
        slow = decimal_format(fmt, value)
    except DialectError:
        with pytest.raises(DialectError):
            fmt.format(value)
        return
    for _ in range(2):  # computed, then remembered
        assert fmt.format(value) == slow
        assert fmt.parse(slow) == decimal_parse(fmt, slow)


def test_signed_zero_and_errors_are_not_remembered_wrongly() -> None:
    fmt = NumberFormat()
    assert fmt.format(-0.0) == decimal_format(fmt, -0.0) == fmt.format(0.0) == "0.000"
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


def test_the_reach_of_a_format_is_its_largest_number_in_mm() -> None:
    """5 integer digits of µm with 2 decimals: 99999.99 µm; 4 digits of inches: 9999.9999 in."""
    microns = NumberFormat(scale=1000.0, decimals=2, int_digits=5)
    assert microns.reach_mm() == pytest.approx(99.99999, abs=1e-12)
    microns.format(microns.reach_mm())  # the largest fits
    with pytest.raises(DialectError):
        microns.format(100.0)
    inches = NumberFormat(scale=1 / 25.4, decimals=4, int_digits=4)
    assert inches.reach_mm() == pytest.approx(9999.9999 * 25.4)
    assert NumberFormat(decimals=3).reach_mm() is None
