"""Timer-driven step models of controllers without a coordinated interpolator.

seed-001 §4.7 (R11): the VB6 application of the LMM machine steps each axis from
a millisecond timer (``timeGetTime``); an axis fires when ``now − last > period``.
With a 1 ms timer an axis of period T ms therefore fires every ``floor(T) + 1``
ms. The dominant axis has the configured half-period P (so P + 1 ms); the other
axis is scheduled at ``P·N_dom/N_other`` and is **not** count-limited: it keeps
firing until the dominant axis has done its steps, which over-steps it.
"""

from __future__ import annotations

import math

from camtool.errors import UsageError


def timer_period_ms(period_ms: float, timer_ms: int = 1) -> int:
    """Effective firing period of ``now − last > period`` on a ``timer_ms`` clock, ms.

    Args:
        period_ms: Scheduled period, ms, ``> 0``.
        timer_ms: Timer resolution, ms (seed-001 §2.6: ``timeBeginPeriod 1``).

    Returns:
        The smallest multiple of ``timer_ms`` strictly greater than ``period_ms``.

    Raises:
        UsageError: If ``period_ms`` or ``timer_ms`` is not positive.
    """
    if not (period_ms > 0 and timer_ms > 0):
        raise UsageError(f"periods must be > 0 ms, got {period_ms!r} and {timer_ms!r}")
    return (math.floor(period_ms / timer_ms) + 1) * timer_ms


def flashcut_line_steps(
    n_dominant: int, n_other: int, half_period_ms: int, *, timer_ms: int = 1
) -> int:
    """Steps the non-dominant axis really makes in one seed-001 ``funcionXYH`` line.

    The move lasts ``n_dominant·(P + 1)`` ms (dominant period ``P + 1``); the other
    axis fires every ``floor(P·n_dominant/n_other) + 1`` ms until then.
    seed-001 §4.7 Table 3.8: a 10 × 5 mm line (5263 × 2632 steps) gives 2763,
    2719 and 2697 Y steps at P = 20, 30 and 40 ms.

    Args:
        n_dominant: Steps of the axis with more steps (exact, count-limited).
        n_other: Programmed steps of the other axis, ``<= n_dominant``.
        half_period_ms: Configured "Período medio de la señal" P, ms.
        timer_ms: Timer resolution, ms.

    Returns:
        Steps the other axis makes (``0`` if it has none programmed).

    Raises:
        UsageError: If the counts are negative or ``n_other > n_dominant``, or a
            period is not positive.
    """
    if not 0 <= n_other <= n_dominant:
        raise UsageError(f"need 0 <= other <= dominant steps, got {n_other!r}, {n_dominant!r}")
    if n_other == 0:
        return 0
    duration = n_dominant * timer_period_ms(half_period_ms, timer_ms)
    return duration // timer_period_ms(half_period_ms * n_dominant / n_other, timer_ms)
