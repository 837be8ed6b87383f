"""Time model of GRBL 1.1 and LinuxCNC: trapezoidal speed profiles per block.

Each block runs at its programmed feed ``F`` (capped at the machine's maximum
rate; rapids at the maximum rate) with constant acceleration ``a`` up to and
down from that speed. For a block of length ``L`` entered at ``v0`` and left at
``v1`` with nominal speed ``v`` (all mm/s)::

    d_acc = (v² − v0²)/(2a),   d_dec = (v² − v1²)/(2a)
    trapezoid (d_acc + d_dec ≤ L):  t = (v − v0)/a + (v − v1)/a + (L − d_acc − d_dec)/v
    triangle  (otherwise):          v_p = √((2aL + v0² + v1²)/2),  t = (v_p − v0)/a + (v_p − v1)/a

camtool's estimate is **conservative**: every block starts and ends at rest
(``v0 = v1 = 0``, so ``t = L/v + v/a`` or ``t = 2√(L/a)``). That is exact for
LinuxCNC in exact-stop mode (G61.1) but longer than the real time otherwise:

- GRBL's planner (``planner.c``) looks ahead over its block buffer and only
  slows down at junctions to the *junction deviation* speed
  ``v_j = √(a·δ·s/(1 − s))`` with ``s = sin(θ/2)``, θ the angle between the
  reversed incoming and the outgoing direction (θ = π − turn angle, so
  ``s = cos(turn/2)``), δ = ``$11`` (0.010 mm by default), capped by both
  blocks' nominal speeds: a straight continuation has no slow-down, a 90° corner
  ``v_j = √(2.414·a·δ)``, a reversal stops. See :func:`grbl_junction_speed_mm_s`;
  with those entry/exit speeds :func:`trapezoid_time_s` gives the blended time.
- LinuxCNC blends in G64 (path-tolerance) mode with its own trajectory planner.

Per-axis limits: GRBL and LinuxCNC limit a block's acceleration and maximum
rate by every moving axis (GRBL: ``min_i a_i/|u_i|`` over the unit vector
``u``); pass such a per-block value as a ``(B,)`` array if axes differ.
Defaults are GRBL 1.1's generic ``defaults.h``: ``$110`` = 500 mm/min and
``$120`` = 10 mm/s² (LinuxCNC has no defaults: the INI file sets them).
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
    flags,
    floats,
    per_block,
    positive,
    same_length,
    seconds,
)

GRBL_DEFAULT_MAX_RATE_MM_MIN = 500.0
"""GRBL 1.1 generic default ``$110``/``$111``, mm/min (``defaults.h``)."""
GRBL_DEFAULT_ACCELERATION_MM_S2 = 10.0
"""GRBL 1.1 generic default ``$120``/``$121``, mm/s² (``defaults.h``)."""
GRBL_DEFAULT_JUNCTION_DEVIATION_MM = 0.010
"""GRBL 1.1 default ``$11``, mm."""


def trapezoid_time_s(
    length_mm: npt.ArrayLike,
    speed_mm_s: npt.ArrayLike,
    acceleration_mm_s2: float | npt.ArrayLike,
    *,
    entry_mm_s: float | npt.ArrayLike = 0.0,
    exit_mm_s: float | npt.ArrayLike = 0.0,
) -> FloatArray:
    """Duration of trapezoidal (or triangular) speed profiles, s (module docstring formula).

    Entry and exit speeds above the nominal speed are lowered to it.

    Args:
        length_mm: ``(B,)`` path lengths, mm, ``>= 0``.
        speed_mm_s: ``(B,)`` nominal (cruise) speeds, mm/s, ``> 0`` where the
            length is not 0.
        acceleration_mm_s2: Acceleration, mm/s², scalar or ``(B,)``, ``> 0``.
        entry_mm_s: Speed at the block start, mm/s, scalar or ``(B,)``.
        exit_mm_s: Speed at the block end, mm/s, scalar or ``(B,)``.

    Returns:
        ``(B,) float64`` seconds, read-only; 0 for a zero length.

    Raises:
        UsageError: If lengths differ, a value is negative, a moving block has
            no speed, or the exit speed cannot be reached from the entry speed
            within the length (``|v1² − v0²| > 2aL``).
    """
    length = floats("length_mm", length_mm)
    v = floats("speed_mm_s", speed_mm_s)
    b = same_length(length_mm=length, speed_mm_s=v)
    a = per_block("acceleration_mm_s2", acceleration_mm_s2, b, minimum=0.0)
    if np.any(a <= 0):
        raise UsageError("acceleration_mm_s2 must be > 0")
    moving = length > 0
    if np.any(moving & (v <= 0)):
        i = int(np.flatnonzero(moving & (v <= 0))[0])
        raise UsageError(f"block {i} moves {length[i]!r} mm at speed 0; give a feed > 0")
    v0 = np.minimum(per_block("entry_mm_s", entry_mm_s, b, minimum=0.0), v)
    v1 = np.minimum(per_block("exit_mm_s", exit_mm_s, b, minimum=0.0), v)
    unreachable = np.abs(v1**2 - v0**2) > 2.0 * a * length * (1 + 1e-12) + 1e-18
    if np.any(unreachable):
        i = int(np.flatnonzero(unreachable)[0])
        raise UsageError(
            f"block {i}: cannot go from {v0[i]!r} to {v1[i]!r} mm/s in {length[i]!r} mm"
        )
    d_acc = (v**2 - v0**2) / (2.0 * a)
    d_dec = (v**2 - v1**2) / (2.0 * a)
    cruise = length - d_acc - d_dec
    v_safe = np.where(v > 0, v, 1.0)
    t_trap = (2.0 * v - v0 - v1) / a + np.maximum(cruise, 0.0) / v_safe
    vp = np.sqrt(np.maximum((2.0 * a * length + v0**2 + v1**2) / 2.0, 0.0))
    t_tri = (2.0 * vp - v0 - v1) / a
    t = np.where(cruise >= 0, t_trap, t_tri)
    return seconds(np.where(moving, t, 0.0))


def grbl_junction_speed_mm_s(
    turn_angle_rad: npt.ArrayLike,
    *,
    acceleration_mm_s2: float = GRBL_DEFAULT_ACCELERATION_MM_S2,
    junction_deviation_mm: float = GRBL_DEFAULT_JUNCTION_DEVIATION_MM,
) -> FloatArray:
    """GRBL 1.1 junction-deviation speed limit at a corner, mm/s (``planner.c``).

    ``v_j = √(a·δ·c/(1 − c))`` with ``c = cos(turn/2)`` (GRBL's ``sin(θ/2)``,
    θ = π − turn). The planner further caps it by both blocks' nominal speeds;
    that cap is the caller's.

    Args:
        turn_angle_rad: Angle between the incoming and outgoing directions, rad,
            any shape: 0 = straight on (returns ``inf``), π = reversal (0).
        acceleration_mm_s2: Junction acceleration, mm/s², ``> 0``.
        junction_deviation_mm: GRBL ``$11``, mm, ``> 0``.

    Returns:
        Speeds, mm/s, float64, same shape, read-only.

    Raises:
        UsageError: If a parameter is not positive.
    """
    a = positive("acceleration_mm_s2", acceleration_mm_s2)
    d = positive("junction_deviation_mm", junction_deviation_mm)
    c = np.abs(np.cos(np.asarray(turn_angle_rad, dtype=np.float64) / 2.0))
    c = np.where(c < 1e-12, 0.0, c)  # a reversal stops exactly
    with np.errstate(divide="ignore"):
        v2 = np.where(c >= 1.0 - 1e-12, np.inf, a * d * c / np.maximum(1.0 - c, 1e-300))
    return seconds(np.sqrt(v2))


def grbl_block_time_s(
    length_mm: npt.ArrayLike,
    feed_mm_min: npt.ArrayLike,
    is_rapid: npt.ArrayLike,
    *,
    acceleration_mm_s2: float | npt.ArrayLike = GRBL_DEFAULT_ACCELERATION_MM_S2,
    max_rate_mm_min: float | npt.ArrayLike = GRBL_DEFAULT_MAX_RATE_MM_MIN,
) -> FloatArray:
    """Conservative GRBL/LinuxCNC block time: rest-to-rest trapezoid at min(F, max rate), s.

    Rapids run at ``max_rate_mm_min``; feed moves at the programmed feed capped
    by it. No junction look-ahead, so the sum over blocks is an upper bound of
    GRBL's real time (module docstring).

    Args:
        length_mm: ``(B,)`` path lengths, mm (arc length for arcs).
        feed_mm_min: ``(B,)`` programmed feeds, mm/min (ignored for rapids).
        is_rapid: ``(B,)`` True for G00.
        acceleration_mm_s2: Acceleration along the path, mm/s², scalar or ``(B,)``.
        max_rate_mm_min: Maximum rate, mm/min, scalar or ``(B,)``.

    Returns:
        ``(B,) float64`` seconds, read-only.

    Raises:
        UsageError: If lengths differ, a value is negative or not finite, a
            feed move of non-zero length has feed 0, or a limit is not positive.
    """
    length = floats("length_mm", length_mm)
    feed = floats("feed_mm_min", feed_mm_min)
    rapid = flags("is_rapid", is_rapid)
    b = same_length(length_mm=length, feed_mm_min=feed, is_rapid=rapid)
    cap = per_block("max_rate_mm_min", max_rate_mm_min, b, minimum=0.0)
    if np.any(cap <= 0):
        raise UsageError("max_rate_mm_min must be > 0")
    speed = np.where(rapid, cap, np.minimum(feed, cap)) / 60.0
    return trapezoid_time_s(length, speed, acceleration_mm_s2)


@dataclass(frozen=True, kw_only=True)
class TrapezoidTiming:
    """Parameters of the GRBL/LinuxCNC time model (see :func:`grbl_block_time_s`).

    Attributes:
        acceleration_mm_s2: Acceleration along the path, mm/s² (GRBL ``$120``).
        max_rate_mm_min: Maximum rate, also the rapid rate, mm/min (GRBL ``$110``).

    Raises:
        UsageError: If a value is not a finite number > 0.
    """

    model: ClassVar[str] = "grbl"
    acceleration_mm_s2: float = GRBL_DEFAULT_ACCELERATION_MM_S2
    max_rate_mm_min: float = GRBL_DEFAULT_MAX_RATE_MM_MIN

    def __post_init__(self) -> None:
        positive("acceleration_mm_s2", self.acceleration_mm_s2)
        positive("max_rate_mm_min", self.max_rate_mm_min)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        return grbl_block_time_s(
            blocks.length_mm,
            blocks.feed_mm_min,
            blocks.is_rapid,
            acceleration_mm_s2=self.acceleration_mm_s2,
            max_rate_mm_min=self.max_rate_mm_min,
        )
