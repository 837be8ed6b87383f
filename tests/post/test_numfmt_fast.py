"""NumberFormat's mm fast paths equal its Decimal paths exactly (camtool.post.numfmt, issue 17).

``format`` rounds the float's shortest repr half away from zero without
``Decimal`` at scale 1 without a grid, ``parse`` reads a plain decimal with
``float``; ``_format_slow`` and ``_parse_slow`` are the ``Decimal`` code as it
was. Random values of every kind (uniform, exact halves at each number of
decimals, a few digits, huge and tiny, signed zeros, NaN and infinity) and every
format option: the texts, or the errors, are identical.
"""

from __future__ import annotations

import contextlib
import math

import numpy as np
import pytest

from camtool.model.errors import DialectError
from camtool.post.numfmt import NumberFormat

FORMATS = [
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
    try:
        return repr(call(arg))  # type: ignore[operator]
    except DialectError as exc:
        return f"DialectError: {exc}"


@pytest.mark.parametrize("k", range(0, len(FORMATS), 1))
def test_format_fast_equals_decimal(k: int) -> None:
    fmt = FORMATS[k]
    rng = np.random.default_rng(k)
    for v in _values(rng, 1500):
        assert _outcome(fmt.format, v) == _outcome(fmt._format_slow, v), (fmt, v)


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
        for f in FORMATS[::7]:
            with contextlib.suppress(DialectError):
                texts.append(f.format(v))
        texts.append(repr(v))
    for t in texts:
        assert _outcome(fmt.parse, t) == _outcome(fmt._parse_slow, t), t


def test_half_up_equals_decimal() -> None:
    """``half_up``'s shortcut (a repr that rounds down keeps its digits) is Decimal's rounding."""
    from decimal import ROUND_HALF_UP, Decimal

    from camtool.post.numfmt import half_up

    rng = np.random.default_rng(1717)
    for v in _values(rng, 4000):
        for d in range(8):
            got = half_up.__wrapped__(v, d)
            if got is None:
                assert "e" in repr(v) or not math.isfinite(v)
                continue
            q = Decimal(repr(v)).quantize(Decimal(1).scaleb(-d), rounding=ROUND_HALF_UP)
            assert got == (f"{abs(q):.{d}f}", q < 0), (v, d)
