"""Motion model of the Munoz-22 ValCNC controller (``valcnc``) for the verifier.

Its line interpolator is the generic accumulator DDA
(:func:`camtool.verify.interpolators.accumulator_dda_line`, ``accumulator-dda``);
what is ValCNC's own is its arc routine, chords of a fixed angle β (the
``valcnc`` chord rule, Munoz-22 §4.2, S004-R12), and its time model: a fixed
delay per DDA iteration, no acceleration, F not parsed (the ``valcnc`` timing
model, Munoz-22 §2.8, §4.1, §4.3, S004-R13).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.model.machine import Motion
from camtool.model.program import ArcMove
from camtool.model.shapes import Point
from camtool.verify.interpolators import arc_offsets, freeze_points
from camtool.verify.motion import MotionHooks, timing_class
from camtool.verify.timing import (
    BlockKinematics,
    FloatArray,
    counts,
    per_block,
    positive,
    same_length,
    seconds,
)

VALCNC_STEP_DELAY_US = 166.667
"""The ValCNC firmware's "reposo motor" delay after each step pulse, µs (Munoz-22 L1336)."""


def serial_time_s(
    n_bytes: npt.ArrayLike, *, baud: float, bits_per_byte: float = 10.0
) -> FloatArray:
    """Time to send ``n_bytes`` over an asynchronous serial link, s.

    8N1 framing is 10 bits per byte: 9600 baud → 1.04 ms per byte (Munoz-22
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
    """Seconds per block of the Munoz-22 ValCNC firmware: iterations × 166.667 µs.

    Munoz-22 §4.1, §4.3 (S004-R13): one fixed delay per accumulator-DDA
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
    """Parameters of the Munoz-22 ``valcnc`` time model (:func:`valcnc_block_time_s`).

    Attributes:
        step_delay_us: Delay per DDA iteration, µs (166.667, Munoz-22 L1336).
        serial_baud: Serial speed for adding each block's send time, baud
            (9600 in the thesis); 0 leaves it out, the only value accepted for
            now: the verifier does not yet count the bytes of each block, so a
            speed would be silently ignored (:func:`valcnc_block_time_s` takes
            both when a caller has them).

    Raises:
        UsageError: If ``step_delay_us`` is not > 0 or ``serial_baud`` is not 0.
    """

    model: ClassVar[str] = "valcnc"
    step_delay_us: float = VALCNC_STEP_DELAY_US
    serial_baud: float = 0.0

    def __post_init__(self) -> None:
        positive("step_delay_us", self.step_delay_us)
        per_block("serial_baud", self.serial_baud, 1, minimum=0.0)
        if self.serial_baud != 0:
            raise UsageError(
                f"serial_baud = {self.serial_baud:g} is not modelled yet: the verifier does not "
                "count the bytes of each block, so the send time cannot be added; remove it"
            )

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """Seconds per block, ``(B,) float64`` read-only."""
        return valcnc_block_time_s(
            blocks.iterations,
            step_delay_us=self.step_delay_us,
            block_bytes=blocks.block_bytes,
            serial_baud=self.serial_baud,
        )


# ------------------------------------------------------------------------ chords


def valcnc_arc_points(
    start: Point, end: Point, centre: Point, clockwise: bool, *, beta_rad: float
) -> npt.NDArray[np.float64]:
    """Chord points of the ValCNC arc routine (Munoz-22 §4.2, S004-R12).

    α = 2·asin(min(1, C/2R)) from the chord C and R = √(i² + j²); a sweep over π
    in the commanded sense uses 2π − α (the thesis' reflex test is lost with
    Figs. 4.12–4.13; it is decided here geometrically). θ starts at
    atan2(−j, −i) and steps by −β (G02) or +β (G03); points at
    θ0 ∓ kβ for every k with kβ < α, then the programmed end point, so the last
    chord is the shorter remainder (snapping is not stated in the thesis). A
    full circle (start == end) has α = 0 and moves nowhere, as the thesis'
    formula implies (S004-R05 has the post-processor split such arcs).

    Args:
        start: Arc start, mm.
        end: Arc end, mm.
        centre: Arc centre, mm (``start + (i, j)``).
        clockwise: True for G02, False for G03.
        beta_rad: Chord angle β, rad, ``> 0`` (a profile parameter; unknown in
            the thesis; chord error R(1 − cos(β/2)), see
            :func:`camtool.verify.interpolators.chord_sagitta`).

    Returns:
        Read-only ``(N, 2) float64`` chord end points, mm; the last row is ``end``.

    Raises:
        InputError: If the radius is 0.
        UsageError: If ``beta_rad`` is not positive.
    """
    if not beta_rad > 0:
        raise UsageError(f"chord angle beta must be > 0 rad, got {beta_rad!r}")
    u0, v0, u1, v1, r = arc_offsets(start, end, centre)
    chord = math.hypot(end[0] - start[0], end[1] - start[1])
    alpha = 2.0 * math.asin(min(1.0, chord / (2.0 * r)))
    cross = u0 * v1 - v0 * u1
    if (cross > 0) if clockwise else (cross < 0):
        alpha = 2.0 * math.pi - alpha
    theta0 = math.atan2(v0, u0)
    k = np.arange(1, max(0, math.ceil(alpha / beta_rad - 1e-12)), dtype=np.float64)
    ang = theta0 + (-1.0 if clockwise else 1.0) * beta_rad * k
    inner = np.column_stack((centre[0] + r * np.cos(ang), centre[1] + r * np.sin(ang)))
    return freeze_points(np.vstack((inner, [[float(end[0]), float(end[1])]])))


def _chords(start: Point, move: ArcMove, motion: Motion) -> npt.NDArray[np.float64]:
    beta = math.radians(motion.chord_angle_deg)
    end, centre = (move.x, move.y), (move.cx, move.cy)
    return valcnc_arc_points(start, end, centre, move.clockwise, beta_rad=beta)


MOTION = MotionHooks(chords={"valcnc": _chords}, timing={"valcnc": timing_class(ValcncTiming)})
"""What ``valcnc`` adds to the verifier: its β chords and its timing model."""
