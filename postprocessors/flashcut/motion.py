"""Motion model of the Yanez-07 LMM VB6 application (``flashcut``) for the verifier.

Three pieces the generic library does not have:

Design notes: docs/internals.md, ``postprocessors/flashcut/motion.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.model.machine import Machine, Motion
from camtool.model.program import ArcMove
from camtool.model.shapes import Point
from camtool.verify.interpolators import arc_offsets, freeze_points
from camtool.verify.motion import (
    LineInterpolator,
    MotionHooks,
    timing_class,
    timing_model_from_table,
)
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import STEP_DTYPE, StepArray, freeze
from camtool.verify.timing import (
    BlockKinematics,
    FloatArray,
    counts,
    flags,
    per_block,
    positive,
    same_length,
    seconds,
)

# ------------------------------------------------------------------ timing model

FLASHCUT_MIN_HALF_PERIOD_MS = 3.0
"""Smallest "Período medio de la señal", ms: the maximum speed (Yanez-07 §2.6, R21)."""


def flashcut_block_time_s(
    dominant_steps: npt.ArrayLike,
    compensation_steps: npt.ArrayLike,
    is_rapid: npt.ArrayLike,
    *,
    half_period_ms: float | npt.ArrayLike = FLASHCUT_MIN_HALF_PERIOD_MS,
    periods_per_step: float = 2.0,
    timer_overshoot_ms: float = 1.0,
    rapid_half_period_ms: float = FLASHCUT_MIN_HALF_PERIOD_MS,
) -> FloatArray:
    """Seconds per block of the Yanez-07 VB6 application: (N_dom + N_comp)·k·(P + δ).

    Yanez-07 §4.7 and R15 (fitted to Tables 4.1/4.2): each dominant-axis step
    costs ``k·(P + δ)`` ms with k = 2 and δ = 1 ms (for whole-ms P, δ is the
    ``floor(P) + 1`` firing rule of :func:`timer_period_ms`), P the configured
    half-period; backlash compensation steps (``backlashXY``, same stepping
    logic) cost the same. The feed word is ignored by the application (§3.2).
    G00 runs "at the maximum rate" (R3), i.e. at the minimum half-period 3 ms
    (R21). Z-only blocks (``funcionZH``): pass the Z steps as dominant steps.
    A 10×10 mm square at P = 3 ms (21052 + 509 steps) takes 172.5 s, measured
    173 s (Table 4.1).

    Args:
        dominant_steps: ``(B,)`` steps of the axis with more steps.
        compensation_steps: ``(B,)`` backlash compensation steps.
        is_rapid: ``(B,)`` True for G00.
        half_period_ms: P, ms, ``>= 3``, scalar or ``(B,)`` (the thesis changed
            it between moves, e.g. 3 ms edges and 40 ms diagonals, §6.2).
        periods_per_step: k, half-periods per counted step.
        timer_overshoot_ms: δ, ms, ``>= 0``.
        rapid_half_period_ms: P used for G00, ms, ``>= 3``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: On mismatched lengths, negative or fractional counts, a
            half-period below 3 ms (R21), or other bad parameters.
    """
    dom = counts("dominant_steps", dominant_steps)
    comp = counts("compensation_steps", compensation_steps)
    rapid = flags("is_rapid", is_rapid)
    b = same_length(dominant_steps=dom, compensation_steps=comp, is_rapid=rapid)
    p = per_block("half_period_ms", half_period_ms, b, minimum=FLASHCUT_MIN_HALF_PERIOD_MS)
    p_rapid = per_block(
        "rapid_half_period_ms", rapid_half_period_ms, 1, minimum=FLASHCUT_MIN_HALF_PERIOD_MS
    )[0]
    k = positive("periods_per_step", periods_per_step)
    delta = float(per_block("timer_overshoot_ms", timer_overshoot_ms, 1, minimum=0.0)[0])
    step_ms = k * (np.where(rapid, p_rapid, p) + delta)
    return seconds((dom + comp) * step_ms / 1000.0)


@dataclass(frozen=True, kw_only=True)
class FlashcutTiming:
    """Parameters of the Yanez-07 ``flashcut`` time model (:func:`flashcut_block_time_s`).

    Attributes:
        half_period_ms: P, the "Período medio de la señal", ms (default 3, L1404).
        periods_per_step: k (fitted, 2).
        timer_overshoot_ms: δ (fitted, 1 ms).
        rapid_half_period_ms: P of G00 moves, ms (the minimum, 3).

    Raises:
        UsageError: If a half-period is below 3 ms or a value is out of range.
    """

    model: ClassVar[str] = "flashcut"
    half_period_ms: float = FLASHCUT_MIN_HALF_PERIOD_MS
    periods_per_step: float = 2.0
    timer_overshoot_ms: float = 1.0
    rapid_half_period_ms: float = FLASHCUT_MIN_HALF_PERIOD_MS

    def __post_init__(self) -> None:
        # one empty block through the model validates every parameter in one place
        flashcut_block_time_s(
            [0],
            [0],
            [False],
            half_period_ms=self.half_period_ms,
            periods_per_step=self.periods_per_step,
            timer_overshoot_ms=self.timer_overshoot_ms,
            rapid_half_period_ms=self.rapid_half_period_ms,
        )

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only.

        Z moves are blocks of their own in Yanez-07 (``funcionZH``, §4.3), so
        the counted steps are ``max(dominant_steps, |z steps|)``.
        """
        return flashcut_block_time_s(
            np.maximum(blocks.dominant_steps, np.abs(blocks.steps[:, 2])),
            blocks.compensation_steps,
            blocks.is_rapid,
            half_period_ms=self.half_period_ms,
            periods_per_step=self.periods_per_step,
            timer_overshoot_ms=self.timer_overshoot_ms,
            rapid_half_period_ms=self.rapid_half_period_ms,
        )


# ----------------------------------------------------------------- timer stepping


def timer_period_ms(period_ms: float, timer_ms: int = 1) -> int:
    """Effective firing period of ``now − last > period`` on a ``timer_ms`` clock, ms.

    Args:
        period_ms: Scheduled period, ms, ``> 0``.
        timer_ms: Timer resolution, ms (Yanez-07 §2.6: ``timeBeginPeriod 1``).

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
    """Steps the non-dominant axis really makes in one Yanez-07 ``funcionXYH`` line.

    The move lasts ``n_dominant·(P + 1)`` ms (dominant period ``P + 1``); the other
    axis fires every ``floor(P·n_dominant/n_other) + 1`` ms until then.
    Yanez-07 §4.7 Table 3.8: a 10 × 5 mm line (5263 × 2632 steps) gives 2763,
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


def timer_line(dx: int, dy: int, half_period_ms: float, *, timer_ms: int = 1) -> StepArray:
    """Motor steps of one Yanez-07 line move of ``(dx, dy)`` programmed steps.

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
    return _merged_rows(dx, dy, dom_times, other_times)


def exact_timer_line(dx: int, dy: int) -> StepArray:
    """:func:`timer_line` on an exact clock: no firing overshoot, every axis makes its count.

    The ``dynamics`` source of the ``timer`` line switched off: the dominant axis
    fires every P and the other every ``P·N_dom/N_other`` exactly, so (in units
    of ``P/N_other``) the dominant events fall at ``k·N_other`` and the other's at
    ``j·N_dom``, both firing in one row where they coincide; the other axis makes
    exactly ``N_other`` steps, by the dominant's last event.

    Args:
        dx: Programmed X steps (signed).
        dy: Programmed Y steps (signed).

    Returns:
        Step array ``(N, 2) int8`` summing to ``(dx, dy)``.
    """
    ax, ay = abs(int(dx)), abs(int(dy))
    n_dom, n_other = max(ax, ay), min(ax, ay)
    if n_dom == 0:
        return freeze(np.zeros((0, 2), dtype=STEP_DTYPE))
    unit = max(n_other, 1)
    dom_times = np.arange(1, n_dom + 1, dtype=np.int64) * unit
    other_times = np.arange(1, n_other + 1, dtype=np.int64) * n_dom
    return _merged_rows(dx, dy, dom_times, other_times)


# ------------------------------------------------------------------------ chords


def flashcut_arc_points(
    start: Point, end: Point, centre: Point, clockwise: bool, *, segments: int
) -> npt.NDArray[np.float64]:
    """Arc points of the Yanez-07 VB6 application (Yanez-07 §4.4, reconstructed routine).

    Start angle from ``angulo(I, J, "inicio")`` = atan2(−J, −I), end angle from
    the end offset; the sweep is normalised to [−2π, 0) for G02 and (0, 2π] for
    G03, a zero sweep (start == end) being a full circle (an assumption of the
    notes). Points at ``a0 + k·sweep/n``, k = 1..n, on the radius from the start;
    the last one is not snapped to the programmed end (not stated). The thesis
    gives no point count ("un determinado número de puntos"), hence ``segments``
    (see :func:`camtool.model.shapes.chord_count` to derive it
    from a chord tolerance).

    Args:
        start: Arc start, mm.
        end: Arc end, mm.
        centre: Arc centre, mm (``start + (I, J)``).
        clockwise: True for G02, False for G03.
        segments: Number of chords n, ``>= 1``.

    Returns:
        Read-only ``(segments, 2) float64`` chord end points, mm.

    Raises:
        InputError: If the radius is 0.
        UsageError: If ``segments < 1``.
    """
    if segments < 1:
        raise UsageError(f"segments must be >= 1, got {segments!r}")
    u0, v0, u1, v1, r = arc_offsets(start, end, centre)
    a0 = math.atan2(v0, u0)
    sweep = math.atan2(v1, u1) - a0
    if clockwise:
        sweep = sweep % -(2.0 * math.pi) or -2.0 * math.pi
    else:
        sweep = sweep % (2.0 * math.pi) or 2.0 * math.pi
    k = np.arange(1, segments + 1, dtype=np.float64)
    ang = a0 + k * (sweep / segments)
    return freeze_points(
        np.column_stack((centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)))
    )


def _timer(machine: Machine, *, sources: Sources = ALL) -> LineInterpolator:
    """The ``timer`` line for ``machine``: P from its ``flashcut`` timing table.

    With ``sources.dynamics`` off, the exact-clock line (:func:`exact_timer_line`).

    Raises:
        UsageError: the profile's timing model is not ``flashcut``.
        InputError: its timing table is invalid.
    """
    where = f"machine {machine.name!r} [machine.timing]"
    model = timing_model_from_table(machine.timing, where=where, machine=machine)
    if not isinstance(model, FlashcutTiming):
        raise UsageError(
            f"{where}: line = 'timer' steps by the Yanez-07 half period; "
            "it needs model = 'flashcut'"
        )
    period = model.half_period_ms
    if not sources.dynamics:
        return exact_timer_line
    return lambda dx, dy: timer_line(dx, dy, period)


def _chords(start: Point, move: ArcMove, motion: Motion) -> npt.NDArray[np.float64]:
    end, centre = (move.x, move.y), (move.cx, move.cy)
    return flashcut_arc_points(start, end, centre, move.clockwise, segments=motion.chord_segments)


MOTION = MotionHooks(
    lines={"timer": _timer},
    chords={"flashcut": _chords},
    timing={"flashcut": timing_class(FlashcutTiming)},
    honours={"timer": ("dynamics",)},
)
"""What ``flashcut`` adds to the verifier: timer stepping (its overshoot is the ``dynamics``
error source), its chords, its timing model."""


def _merged_rows(dx: int, dy: int, dom_times: np.ndarray, other_times: np.ndarray) -> StepArray:
    """The step rows of two axes firing at the given times (both in one row where they coincide).

    The dominant axis steps at ``dom_times``, the other at ``other_times``; signs from
    ``(dx, dy)``.
    """
    events = np.union1d(dom_times, other_times)
    rows = np.zeros((events.size, 2), dtype=STEP_DTYPE)
    dom_axis = 0 if abs(int(dx)) >= abs(int(dy)) else 1
    sign = (1 if dx >= 0 else -1, 1 if dy >= 0 else -1)
    rows[np.searchsorted(events, dom_times), dom_axis] = sign[dom_axis]
    rows[np.searchsorted(events, other_times), 1 - dom_axis] = sign[1 - dom_axis]
    return freeze(rows)
