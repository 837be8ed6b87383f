"""Step-rate time models: seed-000 ``pic-mmh``, seed-001 ``flashcut``, seed-004 ``valcnc``.

Controllers whose block time is a count of steps (or interpolator iterations)
times a period that does not change inside the block: no acceleration ramp.
Re-exported by :mod:`camtool.verify.timing`, which documents the interface.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.verify.timing_blocks import (
    BlockKinematics,
    FloatArray,
    counts,
    flags,
    floats,
    per_block,
    positive,
    same_length,
    seconds,
)

# ------------------------------------------------------------------ pic-mmh, seed-000

PIC_MMH_STEPS_PER_MM = 1e6 / 140.0
"""Steps per mm of the GMM MMH-1: 140 nm/step (seed-000 S000-12)."""
PIC_MMH_MAX_STEP_RATE_HZ = 166.0
"""Serial-link-limited step rate of the PIC controller, Hz (seed-000 §2.4, L3198)."""


def _feed_moves_have_feed(feed: FloatArray, rapid: npt.NDArray[np.bool_], work: FloatArray) -> None:
    """Raise if a feed move with something to do has no feed.

    Raises:
        UsageError: Naming the first such block.
    """
    bad = ~rapid & (work > 0) & (feed <= 0)
    if np.any(bad):
        i = int(np.flatnonzero(bad)[0])
        raise UsageError(f"block {i} is a feed move with F = 0 mm/min; program a feed > 0")


def pic_mmh_step_rate_hz(
    feed_mm_min: npt.ArrayLike,
    is_rapid: npt.ArrayLike,
    *,
    steps_per_mm: float = PIC_MMH_STEPS_PER_MM,
    max_step_rate_hz: float = PIC_MMH_MAX_STEP_RATE_HZ,
) -> FloatArray:
    """Interpolator iteration frequency of the seed-000 PIC controller, Hz.

    seed-000 §4.9 (Eq. 3.1 reconstructed, S000-17): ``f = d·F/60`` with ``d``
    the steps/mm the controller assumes and ``F`` in mm/min, capped at the
    serial-limited 166 Hz; rapids (G00, G28) run at the cap. F08 (0.8 mm/min
    under the 0.1 mm/min feed unit) at 140 nm/step gives 95.2 Hz.

    Args:
        feed_mm_min: ``(B,)`` feeds, mm/min, ``>= 0`` (ignored for rapids).
        is_rapid: ``(B,)`` True for rapids.
        steps_per_mm: ``d``, steps/mm, ``> 0``.
        max_step_rate_hz: Cap, Hz, ``> 0``.

    Returns:
        ``(B,) float64`` Hz, read-only (0 for a feed move with F = 0).

    Raises:
        UsageError: On mismatched lengths, negative feeds or bad parameters.
    """
    feed = floats("feed_mm_min", feed_mm_min)
    rapid = flags("is_rapid", is_rapid)
    same_length(feed_mm_min=feed, is_rapid=rapid)
    d = positive("steps_per_mm", steps_per_mm)
    cap = positive("max_step_rate_hz", max_step_rate_hz)
    return seconds(np.where(rapid, cap, np.minimum(d * feed / 60.0, cap)))


def pic_mmh_block_time_s(
    iterations: npt.ArrayLike,
    compensation_steps: npt.ArrayLike,
    feed_mm_min: npt.ArrayLike,
    is_rapid: npt.ArrayLike,
    *,
    steps_per_mm: float = PIC_MMH_STEPS_PER_MM,
    max_step_rate_hz: float = PIC_MMH_MAX_STEP_RATE_HZ,
) -> FloatArray:
    """Seconds per block of the seed-000 PIC controller: (iterations + compensation)/f.

    One interpolator iteration (DDA or DSM, with or without a pulse) per period
    of :func:`pic_mmh_step_rate_hz`; backlash compensation steps run at the
    block's rate before its move (seed-000 §5.1: "at the current step rate",
    the natural reading). One X take-up of 204 µm (1457 steps) at 166 Hz takes
    8.8 s (§5.1). G04 dwells are not blocks here; the simulator adds them.

    Args:
        iterations: ``(B,)`` interpolator iterations.
        compensation_steps: ``(B,)`` backlash compensation steps.
        feed_mm_min: ``(B,)`` feeds, mm/min (ignored for rapids).
        is_rapid: ``(B,)`` True for rapids.
        steps_per_mm: Steps/mm the controller assumes, ``> 0``.
        max_step_rate_hz: Step-rate cap, Hz, ``> 0``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: On mismatched lengths, negative or fractional counts, bad
            parameters, or a feed move with F = 0 that has steps to make.
    """
    it = counts("iterations", iterations)
    comp = counts("compensation_steps", compensation_steps)
    rate = pic_mmh_step_rate_hz(
        feed_mm_min, is_rapid, steps_per_mm=steps_per_mm, max_step_rate_hz=max_step_rate_hz
    )
    same_length(iterations=it, compensation_steps=comp, rate=rate)
    work = (it + comp).astype(np.float64)
    _feed_moves_have_feed(rate, flags("is_rapid", is_rapid), work)
    return seconds(np.divide(work, rate, out=np.zeros_like(work), where=work > 0))


@dataclass(frozen=True, kw_only=True)
class PicMmhTiming:
    """Parameters of the seed-000 ``pic-mmh`` time model (:func:`pic_mmh_block_time_s`).

    Attributes:
        steps_per_mm: Steps/mm the controller assumes in Eq. 3.1.
        max_step_rate_hz: Serial-limited step-rate cap, also the rapid rate, Hz.

    Raises:
        UsageError: If a value is not a finite number > 0.
    """

    model: ClassVar[str] = "pic-mmh"
    steps_per_mm: float = PIC_MMH_STEPS_PER_MM
    max_step_rate_hz: float = PIC_MMH_MAX_STEP_RATE_HZ

    def __post_init__(self) -> None:
        positive("steps_per_mm", self.steps_per_mm)
        positive("max_step_rate_hz", self.max_step_rate_hz)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        return pic_mmh_block_time_s(
            blocks.iterations,
            blocks.compensation_steps,
            blocks.feed_mm_min,
            blocks.is_rapid,
            steps_per_mm=self.steps_per_mm,
            max_step_rate_hz=self.max_step_rate_hz,
        )


# ----------------------------------------------------------------- flashcut, seed-001

FLASHCUT_MIN_HALF_PERIOD_MS = 3.0
"""Smallest "Período medio de la señal", ms: the maximum speed (seed-001 §2.6, R21)."""


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
    """Seconds per block of the seed-001 VB6 application: (N_dom + N_comp)·k·(P + δ).

    seed-001 §4.7 and R15 (fitted to Tables 4.1/4.2): each dominant-axis step
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
    """Parameters of the seed-001 ``flashcut`` time model (:func:`flashcut_block_time_s`).

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

        Z moves are blocks of their own in seed-001 (``funcionZH``, §4.3), so
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


# ------------------------------------------------------------------- valcnc, seed-004

VALCNC_STEP_DELAY_US = 166.667
"""The ValCNC firmware's "reposo motor" delay after each step pulse, µs (seed-004 L1336)."""


def serial_time_s(
    n_bytes: npt.ArrayLike, *, baud: float, bits_per_byte: float = 10.0
) -> FloatArray:
    """Time to send ``n_bytes`` over an asynchronous serial link, s.

    8N1 framing is 10 bits per byte: 9600 baud → 1.04 ms per byte (seed-004
    S004-R13).

    Args:
        n_bytes: ``(B,)`` byte counts.
        baud: Bits per second, ``> 0``.
        bits_per_byte: Start + data + parity + stop bits, ``> 0``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: On negative counts or non-positive parameters.
    """
    n = counts("n_bytes", n_bytes)
    return seconds(n * positive("bits_per_byte", bits_per_byte) / positive("baud", baud))


def valcnc_block_time_s(
    iterations: npt.ArrayLike,
    *,
    step_delay_us: float = VALCNC_STEP_DELAY_US,
    block_bytes: npt.ArrayLike | None = None,
    serial_baud: float = 0.0,
) -> FloatArray:
    """Seconds per block of the seed-004 ValCNC firmware: iterations × 166.667 µs.

    seed-004 §4.1, §4.3 (S004-R13): one fixed delay per accumulator-DDA
    iteration (one iteration per master-axis step), no acceleration, F not
    parsed. 10 mm at 25 steps/mm = 250 steps = 41.7 ms, and so does a
    10 × 10 mm diagonal. Optionally adds the time to send each block over the
    serial link (the GUI sends one block at a time), when ``serial_baud > 0``.

    Args:
        iterations: ``(B,)`` DDA iterations (master-axis steps).
        step_delay_us: Delay per iteration, µs, ``> 0``.
        block_bytes: ``(B,)`` bytes per block including the terminator, or None.
        serial_baud: Link speed for the serial term, baud (8N1); 0 = not counted.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: On negative or fractional counts, mismatched lengths or
            bad parameters.
    """
    it = counts("iterations", iterations)
    t = it * positive("step_delay_us", step_delay_us) * 1e-6
    if block_bytes is not None and serial_baud > 0:
        serial = serial_time_s(block_bytes, baud=serial_baud)
        same_length(iterations=it, block_bytes=serial)
        t = t + serial
    return seconds(t)


@dataclass(frozen=True, kw_only=True)
class ValcncTiming:
    """Parameters of the seed-004 ``valcnc`` time model (:func:`valcnc_block_time_s`).

    Attributes:
        step_delay_us: Delay per DDA iteration, µs (166.667, seed-004 L1336).
        serial_baud: Serial speed for adding each block's send time, baud
            (9600 in the thesis); 0 leaves it out (the default).

    Raises:
        UsageError: If ``step_delay_us`` is not > 0 or ``serial_baud`` < 0.
    """

    model: ClassVar[str] = "valcnc"
    step_delay_us: float = VALCNC_STEP_DELAY_US
    serial_baud: float = 0.0

    def __post_init__(self) -> None:
        positive("step_delay_us", self.step_delay_us)
        per_block("serial_baud", self.serial_baud, 1, minimum=0.0)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        return valcnc_block_time_s(
            blocks.iterations,
            step_delay_us=self.step_delay_us,
            block_bytes=blocks.block_bytes,
            serial_baud=self.serial_baud,
        )
