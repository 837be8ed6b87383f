"""Motion model of the Intf8751 8751 stepper interface (``i8751``): a delay-loop speed ramp.

Its line is the generic "corte recto" (:func:`camtool.verify.interpolators.corte_recto_line`,
``corte-recto``); what is the 8751's own is its time model, ``i8751`` (:class:`I8751Timing`).

Design notes: docs/internals.md, ``postprocessors/i8751/motion.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar, Literal

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.verify.motion import MotionHooks, timing_class
from camtool.verify.timing import (
    BlockKinematics,
    FloatArray,
    counts,
    per_block,
    same_length,
    seconds,
)

I8751_CLOCK_HZ = 12e6
"""Crystal of the 8751 board, Hz (Intf8751 §4.4, T = 1/12 MHz)."""
I8751_X_MIN_SPEED = 0xF2
"""Delay register value of the minimum speed, 8 Hz (Intf8751 §4.4)."""
I8751_X_CRUISE_FIRMWARE = 0x11
"""Delay register at the end of the firmware ramp: F2H − 45·5 = 11H (≈104 Hz)."""
I8751_RAMP_STEPS = 45
"""Steps of the acceleration and of the deceleration ramp (Intf8751 §4.4)."""
I8751_DESIGN_CRUISE_HZ = 70.0
"""Cruise step rate the design text aims at, Hz (Intf8751 §4.4)."""

Cruise = Literal["firmware", "design"]
CRUISES: tuple[str, ...] = ("firmware", "design")
"""Valid ``cruise`` names: the firmware's ≈104 Hz or the design's 70 Hz."""


def i8751_delay_s(x: npt.ArrayLike) -> FloatArray:
    """Delay of one step for delay register ``x``: (6156·X + 10272)/12e6 s.

    Intf8751 §4.4 (R12): t(F2H) = 125.0 ms, t(EDH) = 122.4 ms, t(11H) = 9.58 ms.

    Args:
        x: Delay register value(s), any shape (non-integer values model the
            design-intent ramp).

    Returns:
        Seconds, same shape as ``x``, float64, read-only.
    """
    return seconds((6156.0 * np.asarray(x, dtype=np.float64) + 10272.0) / I8751_CLOCK_HZ)


def i8751_cruise_x(cruise: Cruise = "firmware") -> float:
    """Delay register value at cruise: 11H (firmware) or the X of 70 Hz (design, ≈26.18).

    Raises:
        UsageError: If ``cruise`` is not one of :data:`CRUISES`.
    """
    if cruise == "firmware":
        return float(I8751_X_CRUISE_FIRMWARE)
    if cruise == "design":
        return (I8751_CLOCK_HZ / I8751_DESIGN_CRUISE_HZ - 10272.0) / 6156.0
    raise UsageError(f"unknown cruise {cruise!r}; valid: {', '.join(CRUISES)}")


def _ramp_x(cruise: Cruise) -> tuple[FloatArray, FloatArray, float]:
    """Delay-register values of the acceleration and deceleration ramps and of cruise."""
    x_cruise = i8751_cruise_x(cruise)
    dx = (I8751_X_MIN_SPEED - x_cruise) / I8751_RAMP_STEPS  # 5 for the firmware
    k = np.arange(I8751_RAMP_STEPS, dtype=np.float64)
    return I8751_X_MIN_SPEED - k * dx, x_cruise + k * dx, x_cruise


def i8751_step_delays_s(n_steps: int, *, cruise: Cruise = "firmware") -> FloatArray:
    """Delay after each step of one 8751 motor routine of ``n_steps`` steps, s.

    Intf8751 §4.4 (R12): fewer than 90 steps all at X = F2H; otherwise 45
    acceleration steps (X = F2H − 5k), ``n − 90`` cruise steps and 45
    deceleration steps (X = 11H + 5k), k = 0…44, with the firmware cruise.
    For plots of speed against step number.

    Args:
        n_steps: Steps of the routine, ``>= 0``.
        cruise: ``"firmware"`` (X → 11H, ≈104 Hz) or ``"design"`` (→ 70 Hz).

    Returns:
        ``(n_steps,) float64`` seconds, read-only.

    Raises:
        UsageError: If ``n_steps`` is negative or ``cruise`` is unknown.
    """
    n = int(counts("n_steps", [n_steps])[0])
    accel, decel, x_cruise = _ramp_x(cruise)
    if n < 2 * I8751_RAMP_STEPS:
        x = np.full(n, float(I8751_X_MIN_SPEED))
    else:
        x = np.concatenate([accel, np.full(n - 2 * I8751_RAMP_STEPS, x_cruise), decel])
    return i8751_delay_s(x)


def i8751_move_time_s(n_steps: npt.ArrayLike, *, cruise: Cruise = "firmware") -> FloatArray:
    """Duration of 8751 motor routines of ``n_steps`` steps each, s (closed form).

    Equals ``i8751_step_delays_s(n).sum()`` for each ``n``: ``n·t(F2H)`` below
    90 steps, else the ramp sums plus ``(n − 90)·t(cruise)`` (Intf8751 §4.4).

    Args:
        n_steps: ``(B,)`` step counts, ``>= 0``.
        cruise: ``"firmware"`` or ``"design"``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: If a count is negative or not whole, or ``cruise`` is unknown.
    """
    n = counts("n_steps", n_steps)
    accel, decel, x_cruise = _ramp_x(cruise)
    ramps = float(i8751_delay_s(accel).sum() + i8751_delay_s(decel).sum())
    t_min = float(i8751_delay_s(I8751_X_MIN_SPEED))
    t_cruise = float(i8751_delay_s(x_cruise))
    ramped = ramps + (n - 2 * I8751_RAMP_STEPS) * t_cruise
    return seconds(np.where(n < 2 * I8751_RAMP_STEPS, n * t_min, ramped))


def i8751_block_time_s(
    dominant_steps: npt.ArrayLike,
    z_steps: npt.ArrayLike | None = None,
    *,
    cruise: Cruise = "firmware",
    wait_t1_s: float | npt.ArrayLike = 0.0,
    wait_t2_s: float | npt.ArrayLike = 0.0,
) -> FloatArray:
    """Time of each 8751 move: X/Y routine, wait T1, Z routine, wait T2, s.

    Intf8751 §4.3–4.4 and R11–R12: the X/Y "corte recto" move runs one ramped
    routine of ``max(|n1|, |n2|)`` steps; Z (motor 3) runs its own routine
    after X/Y; T1 and T2 are the packet's whole-second waits (0–255 s in the
    dialect), here scalars or per-block arrays, default 0. Feed is ignored (the
    dialect has none).

    Args:
        dominant_steps: ``(B,)`` X/Y dominant step counts.
        z_steps: ``(B,)`` Z step counts (sign ignored), or None for no Z.
        cruise: ``"firmware"`` or ``"design"`` (see :func:`i8751_cruise_x`).
        wait_t1_s: Wait before Z, s, scalar or ``(B,)``, ``>= 0``.
        wait_t2_s: Wait after Z, s, scalar or ``(B,)``, ``>= 0``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: On negative or fractional counts, mismatched lengths,
            negative waits or an unknown ``cruise``.
    """
    dom = counts("dominant_steps", dominant_steps)
    z = np.zeros_like(dom) if z_steps is None else np.abs(np.asarray(z_steps))
    z = counts("z_steps", z)
    b = same_length(dominant_steps=dom, z_steps=z)
    t1 = per_block("wait_t1_s", wait_t1_s, b, minimum=0.0)
    t2 = per_block("wait_t2_s", wait_t2_s, b, minimum=0.0)
    xy = i8751_move_time_s(dom, cruise=cruise)
    return seconds(xy + t1 + i8751_move_time_s(z, cruise=cruise) + t2)


@dataclass(frozen=True, kw_only=True)
class I8751Timing:
    """Parameters of the Intf8751 ``i8751`` time model (see :func:`i8751_block_time_s`).

    Attributes:
        cruise: ``"firmware"`` (ramp to 11H, ≈104 Hz) or ``"design"`` (to 70 Hz).
        wait_t1_s: Wait between the X/Y and Z motions of every move, s (R11).
        wait_t2_s: Wait after the Z motion of every move, s (R11).

    Raises:
        UsageError: If ``cruise`` is unknown or a wait is negative.
    """

    model: ClassVar[str] = "i8751"
    cruise: Cruise = "firmware"
    wait_t1_s: float = 0.0
    wait_t2_s: float = 0.0

    def __post_init__(self) -> None:
        i8751_cruise_x(self.cruise)
        per_block("wait_t1_s", self.wait_t1_s, 1, minimum=0.0)
        per_block("wait_t2_s", self.wait_t2_s, 1, minimum=0.0)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only; Z from ``blocks.steps[:, 2]``."""
        return i8751_block_time_s(
            blocks.dominant_steps,
            blocks.steps[:, 2],
            cruise=self.cruise,
            wait_t1_s=self.wait_t1_s,
            wait_t2_s=self.wait_t2_s,
        )


MOTION = MotionHooks(timing={"i8751": timing_class(I8751Timing)})
"""What ``i8751`` adds to the verifier: its ramp timing model."""
