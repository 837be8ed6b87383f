"""Machining-time models of the targets' controllers: seconds per block.

The verifier simulates emitted code block by block; these pure, vectorised
functions turn what it knows per block (:class:`BlockKinematics`: iterations,
dominant steps, compensation steps, length, feed, rapid flag) into ``(B,)``
float64 seconds, read-only. One function and one frozen parameter dataclass per
controller; every dataclass has ``block_time_s(blocks)`` and a ``model`` name,
and :func:`timing_model_from_table` builds one from a TOML ``[timing]`` table.

- ``pic-mmh``: :func:`pic_mmh_block_time_s`, :class:`PicMmhTiming`; seed-000
  §4.9, §5.1, S000-17 (module ``timing_rate``).
- ``flashcut``: :func:`flashcut_block_time_s`, :class:`FlashcutTiming`; seed-001
  §2.6, §4.7, R15, R21 (``timing_rate``).
- ``i8751``: :func:`i8751_block_time_s`, :class:`I8751Timing`; seed-003
  §4.3–4.4, R11–R12 (``timing_ramp``).
- ``valcnc``: :func:`valcnc_block_time_s`, :class:`ValcncTiming`; seed-004 §2.8,
  §4.1, §4.3, S004-R13 (``timing_rate``).
- ``grbl`` / ``linuxcnc``: :func:`grbl_block_time_s`, :class:`TrapezoidTiming`;
  rest-to-rest trapezoids, conservative (``timing_accel``).

Everything is re-exported here; import from this module.

The seed-002 router's time comes from its servo simulation, not from here.

This module also keeps the seed-001 timer-firing helpers (§4.7, R11): the VB6
application of the LMM machine steps each axis from a millisecond timer
(``timeGetTime``); an axis fires when ``now − last > period``. With a 1 ms
timer an axis of period T ms therefore fires every ``floor(T) + 1`` ms. The
dominant axis has the configured half-period P (so P + 1 ms); the other axis is
scheduled at ``P·N_dom/N_other`` and is **not** count-limited: it keeps firing
until the dominant axis has done its steps, which over-steps it.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import fields
from types import MappingProxyType
from typing import Any

from camtool.model.errors import InputError, UsageError
from camtool.verify.timing_accel import (
    GRBL_DEFAULT_ACCELERATION_MM_S2,
    GRBL_DEFAULT_JUNCTION_DEVIATION_MM,
    GRBL_DEFAULT_MAX_RATE_MM_MIN,
    TrapezoidTiming,
    grbl_block_time_s,
    grbl_junction_speed_mm_s,
    trapezoid_time_s,
)
from camtool.verify.timing_blocks import BlockKinematics
from camtool.verify.timing_ramp import (
    CRUISES,
    I8751Timing,
    i8751_block_time_s,
    i8751_cruise_x,
    i8751_delay_s,
    i8751_move_time_s,
    i8751_step_delays_s,
)
from camtool.verify.timing_rate import (
    FLASHCUT_MIN_HALF_PERIOD_MS,
    PIC_MMH_MAX_STEP_RATE_HZ,
    PIC_MMH_STEPS_PER_MM,
    VALCNC_STEP_DELAY_US,
    FlashcutTiming,
    PicMmhTiming,
    ValcncTiming,
    flashcut_block_time_s,
    pic_mmh_block_time_s,
    pic_mmh_step_rate_hz,
    serial_time_s,
    valcnc_block_time_s,
)

__all__ = [
    "CRUISES",
    "FLASHCUT_MIN_HALF_PERIOD_MS",
    "GRBL_DEFAULT_ACCELERATION_MM_S2",
    "GRBL_DEFAULT_JUNCTION_DEVIATION_MM",
    "GRBL_DEFAULT_MAX_RATE_MM_MIN",
    "MODELS",
    "PIC_MMH_MAX_STEP_RATE_HZ",
    "PIC_MMH_STEPS_PER_MM",
    "VALCNC_STEP_DELAY_US",
    "BlockKinematics",
    "FlashcutTiming",
    "I8751Timing",
    "PicMmhTiming",
    "TimingModel",
    "TrapezoidTiming",
    "ValcncTiming",
    "flashcut_block_time_s",
    "flashcut_line_steps",
    "grbl_block_time_s",
    "grbl_junction_speed_mm_s",
    "i8751_block_time_s",
    "i8751_cruise_x",
    "i8751_delay_s",
    "i8751_move_time_s",
    "i8751_step_delays_s",
    "pic_mmh_block_time_s",
    "pic_mmh_step_rate_hz",
    "serial_time_s",
    "timer_period_ms",
    "timing_model_from_table",
    "trapezoid_time_s",
    "valcnc_block_time_s",
]


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


# --------------------------------------------------------------------- TOML profiles

TimingModel = PicMmhTiming | FlashcutTiming | I8751Timing | ValcncTiming | TrapezoidTiming
"""Any of the time-model parameter dataclasses."""

MODELS: Mapping[str, type[TimingModel]] = MappingProxyType(
    {
        "pic-mmh": PicMmhTiming,
        "flashcut": FlashcutTiming,
        "i8751": I8751Timing,
        "valcnc": ValcncTiming,
        "grbl": TrapezoidTiming,
        "linuxcnc": TrapezoidTiming,
    }
)
"""Model names accepted in a ``[timing]`` table and their parameter classes (read-only)."""


def timing_model_from_table(table: Mapping[str, Any], *, where: str) -> TimingModel:
    """Build a time model from a TOML ``[timing]`` table.

    The table holds ``model`` (one of :data:`MODELS`) and any of that model's
    dataclass fields, e.g. ``model = "flashcut"`` and ``half_period_ms = 20``.

    Args:
        table: The parsed table.
        where: What to name in messages, e.g. ``"flashcut.toml [timing]"``.

    Returns:
        The parameter dataclass of the model.

    Raises:
        InputError: An unknown model or key, or a value of the wrong type or
            out of range, naming ``where`` and the valid choices.
    """
    name = table.get("model")
    if not isinstance(name, str) or name not in MODELS:
        raise InputError(f"{where}: unknown timing model {name!r}; valid: {', '.join(MODELS)}")
    cls = MODELS[name]
    known = {f.name for f in fields(cls)}
    unknown = sorted(set(table) - known - {"model"})
    if unknown:
        raise InputError(f"{where}: unknown {name} timing key(s) {unknown}; known: {sorted(known)}")
    kwargs: dict[str, Any] = {}
    for key, value in table.items():
        if key in ("model", "cruise"):
            continue
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise InputError(f"{where}: {key} must be a number, got {value!r}")
        kwargs[key] = float(value)
    if "cruise" in table:
        kwargs["cruise"] = table["cruise"]
    try:
        return cls(**kwargs)
    except UsageError as exc:
        raise InputError(f"{where}: {exc}") from exc
