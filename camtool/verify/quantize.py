"""mm → motor steps, rounded the way a controller's software rounds.

Inside camtool lengths are mm; the verifier works in integer steps. Where a
thesis shows how its software rounds, the rounding rule is a profile choice.
"""

from __future__ import annotations

import math
from decimal import ROUND_FLOOR, ROUND_HALF_EVEN, ROUND_HALF_UP, Decimal
from typing import Literal

from camtool.model.errors import UsageError

Rounding = Literal["half_even", "half_up", "floor", "trunc"]
ROUNDINGS: tuple[str, ...] = ("half_even", "half_up", "floor", "trunc")
"""Valid ``rounding`` names of :func:`steps_from_mm`."""


def steps_from_mm(value_mm: float, step_mm: float, rounding: Rounding = "half_even") -> int:
    """Convert a length in mm to a whole number of steps, the way a controller rounds.

    The quotient is formed in decimal from the shortest repr of both floats, so
    10/0.0019 and 0.0057/0.0019 (= 3 exactly) are not spoiled by binary
    rounding. ``half_even`` is the banker's rounding of VB6 ``CLng``/``CInt``,
    which the Yanez-07 application (VB6) would use; ``half_up`` rounds halves
    away from zero; ``floor`` (towards −∞) and ``trunc`` (towards 0) cut.
    Yanez-07 §4.5 (R8): 10 mm → 5263 and 5 mm → 2632 steps at 1.9 µm/step, which
    both nearest-rounding rules give and truncation (2631) does not.

    Args:
        value_mm: Length, mm, signed.
        step_mm: Travel of one step, mm, ``> 0``.
        rounding: One of ``half_even``, ``half_up``, ``floor``, ``trunc``.

    Returns:
        Signed step count.

    Raises:
        UsageError: If ``step_mm`` is not positive and finite, ``value_mm`` is
            not finite, or ``rounding`` is not one of the valid names.
    """
    if rounding not in ROUNDINGS:
        raise UsageError(f"unknown rounding {rounding!r}; valid: {', '.join(ROUNDINGS)}")
    if not (math.isfinite(step_mm) and step_mm > 0):
        raise UsageError(f"step size must be a positive number of mm, got {step_mm!r}")
    if not math.isfinite(value_mm):
        raise UsageError(f"length must be a finite number of mm, got {value_mm!r}")
    fast = _far_from_a_tie(float(value_mm) / float(step_mm), rounding)
    if fast is not None:
        return fast
    q = Decimal(repr(float(value_mm))) / Decimal(repr(float(step_mm)))
    if rounding == "trunc":
        return int(q)
    mode = {"half_even": ROUND_HALF_EVEN, "half_up": ROUND_HALF_UP, "floor": ROUND_FLOOR}
    return int(q.to_integral_value(rounding=mode[rounding]))


TIE_MARGIN = 1e-9
"""Relative distance from a rounding boundary beyond which :func:`_far_from_a_tie` answers."""


def _far_from_a_tie(q: float, rounding: Rounding) -> int | None:
    """:func:`steps_from_mm`'s answer from the binary quotient ``q``, or ``None``: ask Decimal.

    The binary quotient of two floats and the decimal one of their shortest reprs differ
    by a few parts in 10¹⁶ of it; one farther than :data:`TIE_MARGIN` (relative) from
    every boundary of ``rounding`` (the halves for ``half_even`` and ``half_up``, the
    integers for ``floor`` and ``trunc``) rounds as the decimal one does, where the rules
    can differ only on a boundary. Nearer (0.3 mm / 0.1 mm is 2.9999999999999996 in
    binary, 3 in decimal) or beyond 2⁵² (no fraction left), ``None``.
    """
    if not abs(q) < 2.0**52:
        return None
    low = math.floor(q)
    frac = q - low  # within an ulp of q: far below the margin
    margin = TIE_MARGIN * (1.0 + abs(q))
    if rounding in ("half_even", "half_up"):
        if abs(frac - 0.5) <= margin:
            return None
        return int(low) + (1 if frac > 0.5 else 0)
    if frac <= margin or frac >= 1.0 - margin:
        return None
    return int(low) if rounding == "floor" or q >= 0 else int(low) + 1
