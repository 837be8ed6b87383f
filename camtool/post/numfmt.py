"""All number formatting of every dialect, in one place.

Design notes: docs/internals.md, ``camtool/post/numfmt.py``.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal, InvalidOperation, localcontext
from functools import lru_cache

from camtool.model.errors import DialectError

SIGN_POLICIES = ("negative", "always")
"""``negative``: ``-`` only before negatives (UNAM-GMM L1731); ``always``: ``+`` too."""


@dataclass(frozen=True, kw_only=True)
class NumberFormat:
    """How a word's value is written.

    Attributes:
        scale: units written per mm (1000 for µm, 10 for 0.1 mm, 1 for mm).
        decimals: digits after the decimal point (0 writes no point).
        int_digits: zero-pad the integer part to this many digits; values whose
            integer part needs more digits do not fit. ``None`` pads nothing and
            has no limit.
        sign: one of :data:`SIGN_POLICIES`.
        min_decimals: ``None`` writes all ``decimals`` digits; a number trims
            trailing zeros down to that many decimals (FlashCut's ``X1.0`` and
            ``X2.969`` with ``decimals=3, min_decimals=1``, Yanez-07 R7; with 0
            a whole number is written without a point).
        pad: ``False`` makes ``int_digits`` a limit only (no zero padding).
        grid_mm: round the value to a multiple of this many mm before scaling
            (a machine's step grid, Munoz-22 S004-R10); ``None``: no grid.
    """

    scale: float = 1.0
    decimals: int = 3
    int_digits: int | None = None
    sign: str = "negative"
    min_decimals: int | None = None
    pad: bool = True
    grid_mm: float | None = None

    def __post_init__(self) -> None:
        if not (math.isfinite(self.scale) and self.scale > 0):
            raise ValueError(f"scale must be a finite number > 0, got {self.scale!r}")
        if self.sign not in SIGN_POLICIES:
            raise ValueError(f"unknown sign policy {self.sign!r}; choose {SIGN_POLICIES}")
        if self.decimals < 0 or (self.int_digits is not None and self.int_digits < 1):
            raise ValueError("decimals must be ≥ 0 and int_digits ≥ 1")
        if self.min_decimals is not None and not 0 <= self.min_decimals <= self.decimals:
            raise ValueError("min_decimals must lie between 0 and decimals")
        if self.grid_mm is not None and not (math.isfinite(self.grid_mm) and self.grid_mm > 0):
            raise ValueError(f"grid_mm must be a finite number > 0, got {self.grid_mm!r}")
        # texts already written and read, by value (not fields: no part of eq, hash or repr)
        object.__setattr__(self, "_texts", {})
        object.__setattr__(self, "_values", {})

    def quantize(self, value_mm: float) -> Decimal:
        """The value in written units, rounded to ``decimals`` (half away from zero).

        With ``grid_mm`` the value is first rounded (half away from zero) to the
        nearest multiple of ``grid_mm``.

        Raises:
            DialectError: ``value_mm`` is NaN or infinite.
        """
        value_mm = float(value_mm)
        if not math.isfinite(value_mm):
            raise DialectError(f"cannot write {value_mm!r}: the value is not a finite number")
        exp = Decimal(1).scaleb(-self.decimals)
        value = Decimal(repr(value_mm))
        scale = Decimal(repr(float(self.scale)))
        with localcontext() as ctx:
            # Wide enough for every digit of the result: 1e308 mm in µm with 2
            # decimals has 313 digits, which the default 28-digit context refuses.
            ctx.prec = max(28, value.adjusted() + scale.adjusted() + self.decimals + 8)
            if self.grid_mm is not None:
                grid = Decimal(repr(float(self.grid_mm)))
                value = (value / grid).quantize(Decimal(1), rounding=ROUND_HALF_UP) * grid
            q = (value * scale).quantize(exp, rounding=ROUND_HALF_UP)
        return q if q != 0 else Decimal(0).quantize(exp)

    def reach_mm(self) -> float | None:
        """About the largest magnitude this format can write, mm (``None``: no limit).

        For advice only (how far from work zero a toolpath may lie): :meth:`format` decides.
        """
        if self.int_digits is None:
            return None
        return (10.0**self.int_digits - 10.0 ** (-self.decimals)) / self.scale

    def resolution_mm(self) -> float:
        """The smallest step this format can write, mm (the grid when coarser)."""
        step = 10.0 ** (-self.decimals) / self.scale
        return max(step, self.grid_mm) if self.grid_mm is not None else step

    def format(self, value_mm: float) -> str:
        """Write ``value_mm`` (mm) in this format.

        In mm (``scale`` 1, no ``grid_mm``) the digits are rounded on the
        float's shortest repr directly (:func:`half_up`), which is what
        :meth:`quantize` does with ``Decimal``, without it (tests/post/test_numfmt.py
        holds the two equal).

        A program writes the same numbers again and again: the texts are kept by
        value (up to :data:`_CACHED` of them; ``0.0`` and ``-0.0`` share one, both
        are written without a sign, and errors are not kept).

        Raises:
            DialectError: ``value_mm`` is NaN or infinite, or the integer part
                needs more than ``int_digits`` digits.
        """
        value = float(value_mm)
        texts: dict[float, str] = self._texts  # type: ignore[attr-defined]
        text = texts.get(value)
        if text is None:
            text = self._format(value)
            if len(texts) >= _CACHED:
                texts.clear()
            texts[value] = text
        return text

    def _format(self, value_mm: float) -> str:
        """:meth:`format` without its cache."""
        plain = None
        if self.scale == 1.0 and self.grid_mm is None:
            plain = half_up(float(value_mm), self.decimals)
        if plain is None:
            q = self.quantize(value_mm)
            text, negative = f"{abs(q):.{self.decimals}f}", q < 0
        else:
            text, negative = plain
        if self.min_decimals is not None and self.decimals > self.min_decimals:
            whole, frac = text.split(".")
            frac = frac.rstrip("0").ljust(self.min_decimals, "0")
            text = f"{whole}.{frac}" if frac else whole
        int_part = text.split(".")[0]
        if self.int_digits is not None:
            if len(int_part) > self.int_digits:
                q = self.quantize(value_mm)
                raise DialectError(f"{_short(q)} does not fit {self.int_digits} integer digits")
            if self.pad:
                text = text.rjust(len(text) - len(int_part) + self.int_digits, "0")
        if negative:
            return "-" + text
        return ("+" + text) if self.sign == "always" else text

    def parse(self, text: str) -> float:
        """Read a value written in this format back to mm (signs optional).

        In mm (``scale`` 1) a plain decimal (``[+-]digits[.digits]``, up to
        :data:`_PLAIN_DIGITS` characters) is read by ``float``: ``Decimal`` divided
        by 1 is the same decimal, and both convert it correctly rounded.

        Raises:
            DialectError: ``text`` is not a finite decimal number, or is too
                large for a float once in mm.
        """
        values: dict[str, float] = self._values  # type: ignore[attr-defined]
        value = values.get(text)
        if value is None:
            if self.scale == 1.0 and len(text) <= _PLAIN_DIGITS and _PLAIN.fullmatch(text):
                value = float(text)
            else:
                value = self._parse_decimal(text)
            if len(values) >= _CACHED:
                values.clear()
            values[text] = value
        return value

    def _parse_decimal(self, text: str) -> float:
        """:meth:`parse` of any text, through ``Decimal`` (exponents, long digits, a scale)."""
        try:
            number = Decimal(text)
        except InvalidOperation:
            raise DialectError(f"{text[:20]!r} is not a number") from None
        if not number.is_finite():
            raise DialectError(f"{text[:20]!r} is not a finite number")
        with localcontext() as ctx:
            ctx.prec = max(28, len(number.as_tuple().digits) + 8)
            value = float(number / Decimal(repr(float(self.scale))))
        if not math.isfinite(value):
            raise DialectError(f"{_short(number)} is too large")
        return value


_CACHED = 1 << 13
"""Most texts a :class:`NumberFormat` keeps (written or read), each way."""
_PLAIN = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)")
"""A decimal without exponent, as the writers print them."""
_PLAIN_DIGITS = 24
"""Longest such text :meth:`NumberFormat.parse` reads with ``float`` (mm)."""


@lru_cache(maxsize=1 << 13)
def half_up(value: float, decimals: int) -> tuple[str, bool] | None:
    """``|value|`` to ``decimals`` places, halves away from zero, and its sign (or ``None``).

    The same digits as ``Decimal(repr(value)).quantize(10**-decimals, ROUND_HALF_UP)``
    (:meth:`NumberFormat.quantize` at scale 1 without a grid): ``repr`` is the
    shortest decimal that reads back as ``value``, and rounding a decimal half up
    looks at the first dropped digit only (≥ 5 rounds the magnitude up). Cached:
    a program writes the same numbers again and again (``0.0`` and ``-0.0`` share
    an entry and give the same text). Only
    reprs without an exponent (``1e-05``, ``1e+16``, ``nan``, ``inf`` go to
    ``Decimal``); a result of zero has no sign, as ``quantize`` gives it.

    Returns:
        ``(text, negative)``: the magnitude written with ``decimals`` places (no
        point when 0) and whether a ``-`` goes before it.
    """
    r = repr(value)
    if "e" in r or "n" in r:
        return None
    negative = r[0] == "-"
    if negative:
        r = r[1:]
    cut = r.find(".") + 1 + decimals  # r has a point: a float's repr without exponent
    # The digits of r are the text's when none is dropped (zeros added) or the first dropped
    # is below 5 (r has no leading zeros but the one of "0."); else a carry may ripple.
    if cut >= len(r):
        text = r + "0" * (cut - len(r))  # decimals > 0: r has a digit after its point
    elif r[cut] < "5":
        text = r[: cut - 1] if decimals == 0 else r[:cut]
    else:
        return _half_up_digits(r, decimals, negative)
    return text, negative and text.strip("0.") != ""


def _half_up_digits(r: str, decimals: int, negative: bool) -> tuple[str, bool]:
    """:func:`half_up` of the repr ``r`` (no sign, no exponent) by integer arithmetic."""
    whole, _, frac = r.partition(".")
    if len(frac) <= decimals:
        digits = int(whole + frac.ljust(decimals, "0"))
    else:
        digits = int(whole + frac[:decimals]) + (frac[decimals] >= "5")
    if decimals:
        text = str(digits).rjust(decimals + 1, "0")
        text = text[:-decimals] + "." + text[-decimals:]
    else:
        text = str(digits)
    return text, negative and digits != 0


def _short(number: Decimal) -> str:
    """``number`` for a message: as written up to 20 characters, else ``1.00000e+308``."""
    text = str(number)
    return text if len(text) <= 20 else f"{number:.5e}"


def format_int(value: int, digits: int, *, what: str) -> str:
    """Zero-pad a non-negative integer code (feed code, tool number) to ``digits``.

    Raises:
        DialectError: ``value`` is negative or needs more digits.
    """
    if value < 0 or len(str(value)) > digits:
        raise DialectError(f"{what} {value} does not fit {digits} digits")
    return str(value).zfill(digits)
