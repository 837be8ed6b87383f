"""All number formatting of every dialect, in one place.

A :class:`NumberFormat` says how one word's value is written: scale from mm,
decimals, zero padding of the integer part, sign policy. Rounding is half away
from zero on the decimal value (``Decimal`` of the float's shortest repr), so
``2.969 mm`` at 1000 units/mm is exactly ``2969.00``. ``-0`` never appears: a
value that rounds to zero is written without a sign.

Every value is checked: NaN and infinity are a :class:`DialectError` naming the
value, and a finite value of any size is written exactly (the decimal context
is as wide as the number), so no float reaches the code unchecked.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal, InvalidOperation, localcontext

from camtool.model.errors import DialectError

_MEMO_SIZE = 1 << 12
"""Most values one format remembers (then it starts afresh): the gain is in the values just
written (the word, its read-back, the arc check); a larger memo only costs memory (65 536
entries per format took about 70 MB more on a 93 000-block program)."""

SIGN_POLICIES = ("negative", "always")
"""``negative``: ``-`` only before negatives (seed-000 L1731); ``always``: ``+`` too."""


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
            ``X2.969`` with ``decimals=3, min_decimals=1``, seed-001 R7; with 0
            a whole number is written without a point).
        pad: ``False`` makes ``int_digits`` a limit only (no zero padding).
        grid_mm: round the value to a multiple of this many mm before scaling
            (a machine's step grid, seed-004 S004-R10); ``None``: no grid.
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
        # Memos of format() and parse() (not fields: equality, hashing and asdict ignore
        # them). A program writes the same coordinates many times (the word, its read-back,
        # the arc check); a result depends only on the value and the format's fields.
        object.__setattr__(self, "_formatted", {})
        object.__setattr__(self, "_parsed", {})

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

    def resolution_mm(self) -> float:
        """The smallest step this format can write, mm (the grid when coarser)."""
        step = 10.0 ** (-self.decimals) / self.scale
        return max(step, self.grid_mm) if self.grid_mm is not None else step

    def format(self, value_mm: float) -> str:
        """Write ``value_mm`` (mm) in this format.

        Results are remembered per value (the same text every time: see
        :meth:`format_uncached`, which computes it).

        Raises:
            DialectError: ``value_mm`` is NaN or infinite, or the integer part
                needs more than ``int_digits`` digits.
        """
        memo: dict[float, str] = self._formatted  # type: ignore[attr-defined]
        text = memo.get(value_mm)
        if text is None:
            text = self.format_uncached(value_mm)
            if len(memo) >= _MEMO_SIZE:
                memo.clear()
            memo[value_mm] = text
        return text

    def format_uncached(self, value_mm: float) -> str:
        """:meth:`format` computed afresh (no memo)."""
        q = self.quantize(value_mm)
        magnitude = abs(q)
        text = f"{magnitude:.{self.decimals}f}"
        if self.min_decimals is not None and self.decimals > self.min_decimals:
            whole, frac = text.split(".")
            frac = frac.rstrip("0").ljust(self.min_decimals, "0")
            text = f"{whole}.{frac}" if frac else whole
        int_part = text.split(".")[0]
        if self.int_digits is not None:
            if len(int_part) > self.int_digits:
                raise DialectError(f"{_short(q)} does not fit {self.int_digits} integer digits")
            if self.pad:
                text = text.rjust(len(text) - len(int_part) + self.int_digits, "0")
        if q < 0:
            return "-" + text
        return ("+" + text) if self.sign == "always" else text

    def parse(self, text: str) -> float:
        """Read a value written in this format back to mm (signs optional).

        Results are remembered per text (:meth:`parse_uncached` computes them).

        Raises:
            DialectError: ``text`` is not a finite decimal number, or is too
                large for a float once in mm.
        """
        memo: dict[str, float] = self._parsed  # type: ignore[attr-defined]
        value = memo.get(text)
        if value is None:
            value = self.parse_uncached(text)
            if len(memo) >= _MEMO_SIZE:
                memo.clear()
            memo[text] = value
        return value

    def parse_uncached(self, text: str) -> float:
        """:meth:`parse` computed afresh (no memo)."""
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
