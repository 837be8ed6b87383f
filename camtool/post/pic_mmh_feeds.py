"""The F word of the pic-mmh dialect: two-digit feed codes and the feed each one means.

Source: seed-000 §4.1 and §4.9, S000-05. The firmware reads F with its
"obtención de 2 dígitos" routine into the variable ``Avance`` (L1839–L1845) and
*computes* the interpolator period from it, it does not look it up in a table:
``FCIAALGORITMO = (PPR * AVANCE) / 60``, ``PDOALGORITMO = 1000000 / FCIAALGORITMO``
with ``PPR = 1000 / RESOL`` steps/mm (annex A.5, L3662–L3664; Eq. 3.1
reconstructed as ``f = d·F·0.1/60``). So the default table is linear: code
``n`` means ``n × 0.1`` mm/min, F01–F99 = 0.1–9.9 mm/min (F08 = 0.8 mm/min, the
thesis example, L1731). A firmware that maps F codes to a table of step delays
instead is described by an explicit ``feed_codes`` table.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

DEFAULT_FEED_UNIT_MM_MIN = 0.1
"""mm/min per unit of F under the default, linear table (seed-000 §4.9, S000-05)."""

MAX_CODE = 99
"""F has two digits (seed-000 Tabla 21, L3297–L3358); F00 would divide by zero
in the firmware's period ``1000000 / FCIAALGORITMO`` (L3664), so codes are 1–99."""


@dataclass(frozen=True)
class FeedTable:
    """The feed codes a pic-mmh controller knows, each with its feed in mm/min.

    Attributes:
        codes: ``(code, feed_mm_min)`` pairs sorted by code; codes are 1–99 and
            the feeds strictly increase with the code (a faster code is never
            slower), each > 0 mm/min.
    """

    codes: tuple[tuple[int, float], ...]

    def __post_init__(self) -> None:
        if not self.codes:
            raise ValueError("feed_codes is empty; give at least one code = mm/min pair")
        previous: tuple[int, float] | None = None
        for code, feed in self.codes:
            if not 1 <= code <= MAX_CODE:
                raise ValueError(f"feed code {code} is not F01–F{MAX_CODE} (two digits, not F00)")
            if not (math.isfinite(feed) and feed > 0):
                raise ValueError(f"feed code {code}: {feed!r} mm/min must be a number > 0")
            if previous is not None and (code <= previous[0] or feed <= previous[1]):
                raise ValueError(
                    f"feed codes must be sorted with feeds strictly increasing: "
                    f"F{previous[0]:02d} = {previous[1]:g} then F{code:02d} = {feed:g} mm/min"
                )
            previous = (code, feed)

    @classmethod
    def linear(cls, unit_mm_min: float = DEFAULT_FEED_UNIT_MM_MIN) -> FeedTable:
        """Codes 1–99 meaning ``code × unit_mm_min`` mm/min (the firmware's formula).

        Raises:
            ValueError: ``unit_mm_min`` is not a finite number > 0.
        """
        unit = _positive("feed_unit_mm_min", unit_mm_min)
        return cls(tuple((n, n * unit) for n in range(1, MAX_CODE + 1)))

    @classmethod
    def from_option(cls, table: Mapping[Any, Any]) -> FeedTable:
        """The table of a ``[dialect_options] feed_codes`` TOML table.

        Keys are the codes as written (``"8"`` or ``"08"``; ints from Python),
        values the feed each code runs, mm/min.

        Raises:
            ValueError: ``table`` is not a table, a key is not a code 1–99 written
                with at most two digits, a value is not a number > 0, two keys
                name one code, or the feeds do not increase with the code.
        """
        if not isinstance(table, Mapping):
            raise ValueError(f"feed_codes must be a table of code = mm/min, not {table!r}")
        pairs: dict[int, float] = {}
        for key, value in table.items():
            code = _code(key)
            if code in pairs:
                raise ValueError(f"feed_codes names code {code} twice")
            pairs[code] = _positive(f"feed_codes[{key!r}]", value)
        return cls(tuple(sorted(pairs.items())))

    @property
    def lowest(self) -> tuple[int, float]:
        """The slowest ``(code, feed_mm_min)``."""
        return self.codes[0]

    @property
    def highest(self) -> tuple[int, float]:
        """The fastest ``(code, feed_mm_min)``."""
        return self.codes[-1]

    def feed_of(self, code: int) -> float | None:
        """The feed of ``code``, mm/min, or ``None`` when the table has no such code."""
        i = bisect.bisect_left(self.codes, (code, -math.inf))
        return self.codes[i][1] if i < len(self.codes) and self.codes[i][0] == code else None

    def nearest(self, feed_mm_min: float) -> tuple[int, float] | None:
        """The code whose feed is nearest ``feed_mm_min`` (ties go to the faster code).

        Returns ``None`` when the feed is not finite or lies beyond either end of
        the table by more than half the gap to its neighbour (for the linear
        table: outside 0.05–9.95 mm/min, i.e. what would round to F00 or F100).
        """
        if not math.isfinite(feed_mm_min):
            return None
        feeds = [f for _, f in self.codes]
        i = bisect.bisect_left(feeds, feed_mm_min)
        candidates = [j for j in (i - 1, i) if 0 <= j < len(feeds)]
        best = min(candidates, key=lambda j: (abs(feeds[j] - feed_mm_min), -j))
        tol = 1e-9 * max(1.0, abs(feed_mm_min))
        lo_gap = (feeds[1] - feeds[0]) / 2 if len(feeds) > 1 else 0.0
        hi_gap = (feeds[-1] - feeds[-2]) / 2 if len(feeds) > 1 else 0.0
        if feed_mm_min < feeds[0] - lo_gap - tol or feed_mm_min > feeds[-1] + hi_gap + tol:
            return None
        return self.codes[best]


def _code(key: Any) -> int:
    """A feed code from a table key: an int, or a string of one or two digits."""
    if isinstance(key, bool):
        raise ValueError(f"feed code {key!r} is not a number")
    if isinstance(key, int):
        return key
    if isinstance(key, str) and key.isascii() and key.isdigit() and 1 <= len(key) <= 2:
        return int(key)
    raise ValueError(f"feed code {key!r} is not a code of one or two digits (1–{MAX_CODE})")


def _positive(name: str, value: Any) -> float:
    """``value`` as a finite float > 0 (bools refused)."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ValueError(f"{name} must be a number of mm/min > 0, not {value!r}")
    number = float(value)
    if not (math.isfinite(number) and number > 0):
        raise ValueError(f"{name} must be a number of mm/min > 0, not {value!r}")
    return number
