"""Timer-driven line stepping of the LMM VB6 application (seed-001 §4.2, §4.7, R11).

``funcionXYH`` has no coordinated interpolator: each axis is stepped from a
1 ms timer (``timeGetTime``) and fires when ``now − last > period``. The
dominant axis (more steps) has the configured half-period P, so it fires every
``floor(P) + 1`` ms and is count-limited; the other axis is scheduled at
``P·N_dom/N_other`` ms, fires every ``floor(that) + 1`` ms and is **not**
count-limited: it keeps stepping until the dominant axis is done, which
over-steps it (Table 3.8: 5263 × 2632 programmed → 2763 / 2719 / 2697 Y steps at
P = 20 / 30 / 40 ms). The step array returned here is what the motors do; the
application's own position counter still believes the programmed counts.
"""

from __future__ import annotations

import numpy as np

from camtool.model.errors import UsageError
from camtool.verify.steparray import STEP_DTYPE, StepArray, freeze
from camtool.verify.timing import timer_period_ms


def timer_line(dx: int, dy: int, half_period_ms: float, *, timer_ms: int = 1) -> StepArray:
    """Motor steps of one seed-001 line move of ``(dx, dy)`` programmed steps.

    One row per timer event at which at least one axis fires (both fire in the
    same row when their events coincide). Events of the dominant axis fall at
    ``k·(floor(P) + 1)`` ms, k = 1..N_dom; those of the other axis at
    ``j·(floor(P·N_dom/N_other) + 1)`` ms up to the dominant axis' last event.
    Equal counts (|dx| = |dy|) fire together every ``floor(P) + 1`` ms.

    Args:
        dx: Programmed X steps (signed).
        dy: Programmed Y steps (signed).
        half_period_ms: The application's "periodo medio" P, ms (> 0).
        timer_ms: Timer resolution, ms.

    Returns:
        Step array ``(N, 2) int8``; its X (or Y) sum equals ``dx`` (or ``dy``) on
        the dominant axis and may exceed the other axis' programmed count.

    Raises:
        UsageError: If ``half_period_ms`` is not positive.
    """
    if not half_period_ms > 0:
        raise UsageError(f"half period must be > 0 ms, got {half_period_ms!r}")
    ax, ay = abs(int(dx)), abs(int(dy))
    n_dom, n_other = max(ax, ay), min(ax, ay)
    if n_dom == 0:
        return freeze(np.zeros((0, 2), dtype=STEP_DTYPE))
    t_dom = timer_period_ms(half_period_ms, timer_ms)
    dom_times = np.arange(1, n_dom + 1, dtype=np.int64) * t_dom
    if n_other == 0:
        other_times = np.zeros(0, dtype=np.int64)
    elif n_other == n_dom:
        other_times = dom_times
    else:
        t_other = timer_period_ms(half_period_ms * n_dom / n_other, timer_ms)
        count = int(dom_times[-1] // t_other)
        other_times = np.arange(1, count + 1, dtype=np.int64) * t_other
    events = np.union1d(dom_times, other_times)
    rows = np.zeros((events.size, 2), dtype=STEP_DTYPE)
    dom_axis = 0 if ax >= ay else 1
    sign = (1 if dx >= 0 else -1, 1 if dy >= 0 else -1)
    rows[np.searchsorted(events, dom_times), dom_axis] = sign[dom_axis]
    rows[np.searchsorted(events, other_times), 1 - dom_axis] = sign[1 - dom_axis]
    return freeze(rows)
