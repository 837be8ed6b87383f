"""The Angel-11 DC-servo wood router's firmware moves, simulated, and their error measures.

Design notes: docs/internals.md, ``postprocessors/matlab_router/servo.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
import numpy.typing as npt

from camtool.model.errors import ToolpathError, UsageError
from camtool.model.units import TENTH_MM
from camtool_postprocessors.matlab_router.arrays import RouterArrays, router_arrays
from camtool_postprocessors.matlab_router.plant import (
    FIRMWARE_GAINS,
    LAWS,
    TABLE_4_1,
    THESIS_PLANT,
    TS_S,
    FirmwareIP,
    IdealIP,
    IPGains,
    Law,
    Plant,
    make_controller,
)

Chunking = Literal["faithful", "fixed"]
CHUNKINGS: tuple[str, ...] = ("faithful", "fixed")
"""``faithful``: floor(d/2) chunks of 0.2 mm as the firmware (R12); ``fixed``: exact d·0.1 mm."""
Stop = Literal["count", "coast"]
STOPS: tuple[str, ...] = ("count", "coast")
"""``count``: an axis stops at its count; ``coast``: the plant coasts on after the drive is cut."""
Qei = Literal["ideal", "firmware"]
QEI_MODELS: tuple[str, ...] = ("ideal", "firmware")
"""``firmware``: chunk counting from the encoder angle with ``1023*k`` and the speed
measurement held on counter wrap (§4.2 (D)3–4, §4.4); ``ideal``: exact counting."""
Decel = Literal["capped", "listing"]
DECELS: tuple[str, ...] = ("capped", "listing")
"""``capped``: Ref = min(|speed|, Tabla[q]); ``listing``: Ref = Tabla[q] at any speed (L5703)."""

QEI_COUNTS = 1024
"""Counter states per motor revolution: 256 slots × 4 (Angel-11 §2.2)."""
UNITS_PER_MM = round(1 / TENTH_MM)
"""GUI units (0.1 mm) per mm."""
MAX_TICKS = 200_000
"""Safety limit of one simulated move, samples (1 000 s at 5 ms)."""


def _check_choice(name: str, value: str, valid: tuple[str, ...]) -> None:
    if value not in valid:
        raise UsageError(f"unknown {name} {value!r}; valid: {', '.join(valid)}")


@dataclass(frozen=True, kw_only=True)
class RouterMachine:
    """The Angel-11 router: R8 constants, the speed loops and the model switches.

    Attributes:
        counts_per_mm: Encoder counts per mm on X and Y: 1024 × 75 / 3 mm (R8).
        z_counts_per_chunk: Z counts per 0.2 mm chunk, 5 954 (L6723; Z is not simulated).
        ts_s: Servo sample period, s.
        chunk_counts: Counts per firmware chunk (``RefP``), 5 120 = 0.2 mm.
        cruise_speed: Major-axis speed the GUI writes, counts/Ts (R7).
        first_point_speed: Speed of the move to the first point, counts/Ts (L4796).
        decel_start_counts: Remaining counts at which ``Tabla`` takes over (L5673).
        decel_beta: β of ``Tabla[q] = floor(√(2βq))``, counts/Ts², ``>= 0.5`` (a
            zero entry before the count would hang the firmware). Default
            115.2 = 480²/(2·1000), i.e. 180 mm/s²: ``Tabla[1000] = 480``.
        decel: One of :data:`DECELS`.
        plants: X, Y, Z plants (default: the thesis plant on all; see
            :func:`~camtool.verify.servo_plant.per_axis_plants`).
        controller: One of :data:`~camtool.verify.servo_plant.LAWS`.
        firmware_gains: ``(kid, kpd)`` × 1000 of the firmware law.
        ideal_gains: X, Y, Z digital gains of the ideal law (Table 4.1).
        handshake_s: Time between segments, s (150 ms, R14e; the master's
            segment loop itself has no delay, so a bare I²C exchange is ≈ 6 ms).
        start_skew_s: Y starts this long after X, s, ``0 <= skew < ts_s`` (R13).
        chunking: One of :data:`CHUNKINGS`.
        stop: One of :data:`STOPS`.
        qei: One of :data:`QEI_MODELS`.
        qei_start_angle: X, Y encoder counter value (0–1023) at the first vertex.
        homing_speeds: X, Y, Z homing references, counts/Ts (R8; not simulated).
        work_area_mm: Side of the square work area, mm (R8).
    """

    counts_per_mm: int = 25_600
    z_counts_per_chunk: int = 5_954
    ts_s: float = TS_S
    chunk_counts: int = 5_120
    cruise_speed: int = 480
    first_point_speed: int = 500
    decel_start_counts: int = 1_000
    decel_beta: float = 115.2
    decel: Decel = "capped"
    plants: tuple[Plant, Plant, Plant] = (THESIS_PLANT, THESIS_PLANT, THESIS_PLANT)
    controller: Law = "firmware"
    firmware_gains: tuple[int, int] = FIRMWARE_GAINS
    ideal_gains: tuple[IPGains, IPGains, IPGains] = TABLE_4_1
    handshake_s: float = 0.150
    start_skew_s: float = 0.0004
    chunking: Chunking = "faithful"
    stop: Stop = "count"
    qei: Qei = "ideal"
    qei_start_angle: tuple[int, int] = (0, 0)
    homing_speeds: tuple[int, int, int] = (-700, -550, -500)
    work_area_mm: float = 300.0

    def __post_init__(self) -> None:
        _check_choice("chunking", self.chunking, CHUNKINGS)
        _check_choice("stop", self.stop, STOPS)
        _check_choice("qei model", self.qei, QEI_MODELS)
        _check_choice("decel", self.decel, DECELS)
        _check_choice("controller", self.controller, LAWS)
        if min(self.counts_per_mm, self.chunk_counts, self.cruise_speed, self.ts_s) <= 0:
            raise UsageError("counts_per_mm, chunk_counts, cruise_speed and ts_s must be > 0")
        if self.counts_per_mm % 10:
            raise UsageError(f"counts_per_mm must be a multiple of 10, got {self.counts_per_mm!r}")
        if self.decel_beta < 0.5 or self.decel_start_counts < 0:
            raise UsageError(
                f"decel_beta must be >= 0.5 counts/Ts² (got {self.decel_beta!r}) and "
                f"decel_start_counts >= 0 (got {self.decel_start_counts!r})"
            )
        if not (0.0 <= self.start_skew_s < self.ts_s and self.handshake_s >= 0.0):
            raise UsageError(
                f"need 0 <= start_skew_s < ts_s and handshake_s >= 0, got "
                f"{self.start_skew_s!r}, {self.handshake_s!r}"
            )
        if not all(0 <= a < QEI_COUNTS for a in self.qei_start_angle):
            raise UsageError(f"qei_start_angle must be in 0..1023, got {self.qei_start_angle!r}")

    @property
    def counts_per_01mm(self) -> int:
        """Counts per GUI unit (0.1 mm): 2 560."""
        return self.counts_per_mm // 10

    def tabla(self, remaining: int) -> int:
        """Deceleration table ``Tabla[q] = floor(√(2βq))``, counts/Ts (eq. 4.14; 0 for q <= 0)."""
        return math.isqrt(int(2 * self.decel_beta * remaining)) if remaining > 0 else 0

    def move_counts(self, d_01mm: int) -> int:
        """Counts an axis travels for a commanded distance, by the chunk rule (R12).

        ``faithful``: ``floor(d/2)·chunk_counts``; ``fixed``: ``d·counts_per_01mm``.
        ``faithful`` with ``d = 1`` (firmware underflow) gives 0 here; the
        simulator warns about it.
        """
        if self.chunking == "fixed":
            return d_01mm * self.counts_per_01mm
        return (d_01mm // 2) * self.chunk_counts


def chunked_increments(arrays: RouterArrays, machine: RouterMachine) -> npt.NDArray[np.int64]:
    """Signed counts each axis travels per segment under the chunk rule (R12, R14 test).

    Pure arithmetic (no dynamics): ``sign(velxy)·move_counts(lxy)``.

    Returns:
        Read-only ``(n, 2) int64`` array, encoder counts.
    """
    d = arrays.lxy.T
    counts = np.vectorize(machine.move_counts, otypes=[np.int64])(d) if d.size else d
    out = (np.sign(arrays.velxy.T) * counts).astype(np.int64)
    out.flags.writeable = False
    return out


def chunk_closure_mm(xy_01mm: npt.ArrayLike, machine: RouterMachine | None = None) -> np.ndarray:
    """End of a job minus its first point by the chunk rule alone, mm: ``(2,) float64``.

    Angel-11 §4.2 (D)1 and R14: the star of §3 gives (+0.4, −0.2) mm under the
    floor(d/2) rule (the GUI commands (+0.2, 0) mm).
    """
    m = machine or RouterMachine()
    inc = chunked_increments(router_arrays(xy_01mm, speed=m.cruise_speed), m)
    return inc.sum(axis=0) / m.counts_per_mm


@dataclass(frozen=True)
class ServoTrace:
    """Result of :func:`simulate_job`. Sample ``k`` is at ``t = k·ts_s``.

    Attributes:
        positions_mm: ``(M, 2) float64``, read-only: tool position, mm (first
            point + simulated travel); row 0 is the first point, row ``k`` the
            position after ``k`` samples.
        segment_start_sample: ``(n,) int64``: sample at which segment ``i``'s
            motion starts (after its handshake).
        segment_end_sample: ``(n,) int64``: sample by which both axes are done.
        axis_done_sample: ``(n, 2) int64``: sample by which X, Y are done.
        commanded_end_mm: ``(n, 2) float64``: vertex ``i + 1`` as written, mm.
        executed_end_mm: ``(n, 2) float64``: position when segment ``i + 1``
            starts (for the last segment: at the end of the trace), mm.
        speeds: ``(n, 2) int64``: signed X, Y speeds written, counts/Ts.
        first_point_mm: ``(2,) float64``: first vertex, mm.
        time_s: Simulated time, handshakes included, s.
        cruise_time_s: ``Σ max(|Δx|, |Δy|)·2560/480·Ts`` (R14e), s.
        ts_s: Sample period, s.
        warnings: Firmware hazards found (underflow, zero speed), one per line.
    """

    positions_mm: npt.NDArray[np.float64]
    segment_start_sample: npt.NDArray[np.int64]
    segment_end_sample: npt.NDArray[np.int64]
    axis_done_sample: npt.NDArray[np.int64]
    commanded_end_mm: npt.NDArray[np.float64]
    executed_end_mm: npt.NDArray[np.float64]
    speeds: npt.NDArray[np.int64]
    first_point_mm: npt.NDArray[np.float64]
    time_s: float
    cruise_time_s: float
    ts_s: float
    warnings: tuple[str, ...] = ()


def _first_s(threshold: int) -> int:
    """Smallest counter advance S with ``S − S//1024 >= threshold`` (``Posi = conv + 1023*k``)."""
    s = threshold
    while s - s // QEI_COUNTS < threshold:
        s += 1
    return s


@dataclass(frozen=True)
class _MovePlan:
    """What one ``MOVIMIENTO_X`` call does, in counts of progress along its direction."""

    sign: int
    speed: int
    target: int  # progress at which the firmware's last loop ends
    rem_base: int  # remaining = rem_base − Posi(progress)
    p_final: int  # progress at which the last chunk starts (firmware QEI)
    c_final: int  # Posi offset of the last chunk (encoder angle; firmware QEI)
    qei_fw: bool

    def remaining(self, progress: int) -> int:
        """Counts the firmware believes remain (``RefP1 − Posi`` in the last chunk)."""
        if not self.qei_fw:
            return self.rem_base - progress
        s = self.c_final + progress - self.p_final
        return self.rem_base - (s - s // QEI_COUNTS)


def _plan(m: RouterMachine, d: int, speed: int, angle: int) -> _MovePlan:
    """Plan one axis move of ``d`` 0.1 mm at ``speed``, from encoder counter value ``angle``."""
    sign = 1 if speed > 0 else -1
    target = m.move_counts(d)
    if not (m.qei == "firmware" and m.chunking == "faithful"):
        return _MovePlan(sign, speed, target, target, 0, 0, False)
    chunk = m.chunk_counts
    s_next, s_end = _first_s(chunk + 1), _first_s(chunk)  # `Posi<=RefP1` / `Posi<RefP1` loops

    def offset(progress: int) -> int:
        a = (angle + sign * progress) % QEI_COUNTS
        return a if sign > 0 else QEI_COUNTS - 1 - a

    p = 0
    for _ in range(d // 2 - 1):
        p += s_next - offset(p)
    c = offset(p)
    return _MovePlan(sign, speed, p + s_end - c, chunk, p, c, True)


class _Axis:
    """One slave and its motor during a job (mutable; local to one simulation)."""

    __slots__ = ("angle0", "b", "ctrl", "enc", "hold", "out", "p", "pos", "qei_fw", "vel", "w")

    def __init__(
        self, plant: Plant, ctrl: FirmwareIP | IdealIP, angle0: int, *, qei_fw: bool, hold: bool
    ) -> None:
        self.p, self.b, self.ctrl = plant.pole, plant.gain, ctrl
        self.angle0, self.qei_fw, self.hold = angle0, qei_fw, hold
        self.pos = self.w = 0.0
        self.enc = self.vel = 0
        self.out = [0.0]

    @property
    def angle(self) -> int:
        return (self.angle0 + self.enc) % QEI_COUNTS

    def _measure(self) -> None:
        """``velAc`` of the Timer5 ISR (L5494–L5518): a magnitude, held on counter wrap."""
        enc = math.floor(self.pos)
        if self.qei_fw:
            prev, now = self.angle, (self.angle0 + enc) % QEI_COUNTS
            if self.w >= 0:
                if now >= prev:
                    self.vel = now - prev
            elif prev >= now:
                self.vel = prev - now
        else:
            self.vel = abs(enc - self.enc)
        self.enc = enc

    def _drive(self, ref: int) -> None:
        u = self.ctrl.step(ref, self.vel, self.w)
        self.w = self.p * self.w + self.b * u
        self.pos += self.w

    def idle(self, n: int) -> None:
        """``n`` samples with ``Ref = 0`` (motor off; the ISR keeps integrating)."""
        for _ in range(n):
            self._drive(0)
            self._measure()
            self.out.append(self.pos)

    def move(self, plan: _MovePlan, m: RouterMachine) -> int:
        """Run ``MOVIMIENTO_X`` until the firmware's count is reached; return the samples used."""
        start, sg, zone = self.pos, plan.sign, m.decel_start_counts
        cap = abs(plan.speed) if m.decel == "capped" else 1 << 30
        for ticks in range(1, MAX_TICKS + 1):
            rem = plan.remaining(math.floor(sg * (self.pos - start)))
            ref = plan.speed if rem > zone else sg * min(cap, m.tabla(rem))
            self._drive(ref)
            done = sg * (self.pos - start) >= plan.target
            if done and self.hold:
                self.pos, self.w = start + sg * plan.target, 0.0
            self._measure()
            self.out.append(self.pos)
            if done:
                return ticks
        raise ToolpathError(f"a router axis move did not finish in {MAX_TICKS} samples")


def _segment_plans(
    m: RouterMachine, arrays: RouterArrays, i: int, axes: list[_Axis], warnings: list[str]
) -> list[_MovePlan | None]:
    """Per-axis plans of segment ``i``; ``None`` where the axis does not move."""
    plans: list[_MovePlan | None] = []
    for a, ax in enumerate(axes):
        d, v = int(arrays.lxy[a, i]), int(arrays.velxy[a, i])
        where = f"segment {i + 1}, axis {'XY'[a]}"
        if d == 1 and m.chunking == "faithful":
            warnings.append(
                f"{where}: distance 1 (0.1 mm) makes the firmware's chunk counter "
                "underflow (factor - 1 = 65535): the axis would run away; simulated as no move"
            )
        elif d > 0 and v == 0:
            warnings.append(
                f"{where}: distance {d} at speed 0 (rounded): the firmware never "
                "reaches its count and the job hangs; simulated as no move"
            )
        plans.append(_plan(m, d, v, ax.angle) if d > 0 and v != 0 and m.move_counts(d) else None)
    return plans


def simulate_job(xy_01mm: npt.ArrayLike, machine: RouterMachine | None = None) -> ServoTrace:
    """Simulate one stroke (one job, R6) of the Angel-11 router, sample by sample.

    Segment ``i``: a handshake (both axes idle), then X and Y (``start_skew_s``
    later) each run ``MOVIMIENTO_X`` with their own speed loop; the next
    segment starts when both are done (barrier, stop at every vertex). Homing
    and the move to the first point are not simulated: the trace starts at rest
    on the first vertex. With ``stop="coast"`` the trace runs on until both axes
    are still (< 0.01 counts/Ts, at most 2 s).

    Args:
        xy_01mm: ``(N, 2)`` vertices, whole 0.1 mm units, ``N >= 2``.
        machine: The machine (default :class:`RouterMachine`).

    Returns:
        The trace; see :class:`ServoTrace`.

    Raises:
        DialectError: If the vertices are not an ``(N, 2)`` whole-number array.
        ToolpathError: If a move does not finish within ``MAX_TICKS`` samples.
    """
    m = machine or RouterMachine()
    arrays = router_arrays(xy_01mm, speed=m.cruise_speed)
    axes = [
        _Axis(
            m.plants[a],
            make_controller(m.controller, gains=m.ideal_gains[a], firmware_gains=m.firmware_gains),
            m.qei_start_angle[a],
            qei_fw=m.qei == "firmware",
            hold=m.stop == "count",
        )
        for a in (0, 1)
    ]
    n_hs, frac = round(m.handshake_s / m.ts_s), m.start_skew_s / m.ts_s
    warnings: list[str] = []
    marks: list[tuple[int, int, int]] = []  # (start, done X, done Y)
    for i in range(arrays.n):
        for ax in axes:
            ax.idle(n_hs)
        s = len(axes[0].out) - 1
        plans = _segment_plans(m, arrays, i, axes, warnings)
        ticks = [0 if pl is None else ax.move(pl, m) for ax, pl in zip(axes, plans, strict=True)]
        done = (s + ticks[0], s + ticks[1] + (1 if frac > 0 and ticks[1] else 0))
        for ax in axes:
            ax.idle(max(done) - (len(ax.out) - 1))
        marks.append((s, *done))
    if m.stop == "coast":
        for _ in range(round(2.0 / m.ts_s)):
            if max(abs(ax.w) for ax in axes) < 0.01:
                break
            for ax in axes:
                ax.idle(1)
    return _trace(m, arrays, axes, marks, frac, warnings)


def _trace(
    m: RouterMachine,
    arrays: RouterArrays,
    axes: list[_Axis],
    marks: list[tuple[int, int, int]],
    frac: float,
    warnings: list[str],
) -> ServoTrace:
    """Assemble the read-only arrays of a :class:`ServoTrace`."""
    x, y = np.array(axes[0].out), np.array(axes[1].out)
    if frac > 0:  # Y runs start_skew_s late: its position at t is its own at t − skew
        y[1:] = frac * y[:-1] + (1.0 - frac) * y[1:]
    first = arrays.xy[:, 0] / UNITS_PER_MM  # division keeps 151 -> 15.1 exact
    pos = np.column_stack([x, y]) / m.counts_per_mm + first
    mk = np.array(marks, dtype=np.int64).reshape(-1, 3)
    done = mk[:, 1:]
    ends = done.max(axis=1)
    nxt = np.append(mk[1:, 0], len(pos) - 1)
    longest = arrays.lxy.max(axis=0).sum() if arrays.n else 0
    cruise = float(longest * m.counts_per_01mm / m.cruise_speed * m.ts_s)
    fields = {
        "positions_mm": pos,
        "segment_start_sample": mk[:, 0].copy(),
        "segment_end_sample": ends,
        "axis_done_sample": done.copy(),
        "commanded_end_mm": arrays.xy[:, 1:].T / UNITS_PER_MM,
        "executed_end_mm": pos[nxt],
        "speeds": arrays.velxy.T.copy(),
        "first_point_mm": first.astype(np.float64),
    }
    for arr in fields.values():
        arr.flags.writeable = False
    return ServoTrace(
        **fields,
        time_s=(len(pos) - 1) * m.ts_s,
        cruise_time_s=cruise,
        ts_s=m.ts_s,
        warnings=tuple(warnings),
    )


# ------------------------------------------------------------------ error measures


FloatArray = npt.NDArray[np.float64]


def apply_backlash(positions_mm: npt.ArrayLike, backlash_mm: tuple[float, float]) -> FloatArray:
    """Table positions behind a per-axis dead band (play operator), mm (R15).

    The table follows the motor side only while the motor pushes it; after a
    reversal the motor travels the dead band before the table moves again. The
    band starts taken up in the + direction (the approach to the first point
    is +X then +Y, Angel-11 §2.8 st=1), so the table equals the motor position
    while an axis moves +, and lags by the band (is ``+band`` from it) while it
    moves −.

    Args:
        positions_mm: ``(M, 2)`` motor-side positions, mm.
        backlash_mm: ``(x, y)`` dead bands, mm, ``>= 0`` (default 0: the thesis
            gives no value).

    Returns:
        Read-only ``(M, 2) float64`` table positions, mm.

    Raises:
        UsageError: If a band is negative or the positions are not ``(M, 2)``.
    """
    pos = np.asarray(positions_mm, dtype=np.float64)
    if pos.ndim != 2 or pos.shape[1] != 2:
        raise UsageError(f"positions must be (M, 2), got shape {pos.shape}")
    if min(backlash_mm) < 0:
        raise UsageError(f"backlash must be >= 0 mm per axis, got {backlash_mm!r}")
    out = pos.copy()
    for a, band in enumerate(backlash_mm):
        if band == 0 or len(pos) == 0:
            continue
        col = pos[:, a].tolist()
        table = col[0]
        res = []
        for motor in col:
            table = min(max(table, motor), motor + band)
            res.append(table)
        out[:, a] = res
    out.flags.writeable = False
    return out


def closure_mm(trace: ServoTrace, *, backlash_mm: tuple[float, float] = (0.0, 0.0)) -> FloatArray:
    """End of the job minus its first point, mm: ``(2,) float64`` (R14c).

    Args:
        trace: A simulated job.
        backlash_mm: Per-axis dead band applied to the executed positions (R15).
    """
    table = apply_backlash(trace.positions_mm, backlash_mm)
    return np.asarray(table[-1] - trace.first_point_mm, dtype=np.float64)


def backlash_effect_mm(trace: ServoTrace, backlash_mm: tuple[float, float]) -> FloatArray:
    """What a per-axis backlash adds to the closure, mm: ``(2,) float64`` (R15)."""
    return closure_mm(trace, backlash_mm=backlash_mm) - closure_mm(trace)


def _max_distance(points: FloatArray, origin: FloatArray, direction: FloatArray) -> float:
    """Max distance of ``(K, 2)`` points from the line through ``origin`` along ``direction``."""
    rel = points - origin
    norm = float(np.hypot(*direction))
    if norm == 0.0:
        return float(np.hypot(rel[:, 0], rel[:, 1]).max(initial=0.0))
    cross = rel[:, 0] * direction[1] - rel[:, 1] * direction[0]
    return float(np.abs(cross).max(initial=0.0) / norm)


def segment_deviation_mm(trace: ServoTrace) -> FloatArray:
    """Per segment, the largest distance of the path from its start–stop chord, mm (R14b).

    Covers the samples from the segment's start to the barrier; includes the
    servo mismatch, the start skew and the axes finishing at different times.

    Returns:
        Read-only ``(n,) float64``, mm.
    """
    pos = trace.positions_mm
    out = np.array(
        [
            _max_distance(pos[s : e + 1], pos[s], pos[e] - pos[s])
            for s, e in zip(trace.segment_start_sample, trace.segment_end_sample, strict=True)
        ]
    )
    out.flags.writeable = False
    return out


def tracking_deviation_mm(trace: ServoTrace) -> FloatArray:
    """Per segment, the largest distance from the line along the written speeds, mm.

    Only samples at least one sample before the one in which the first axis
    finishes count (the margin covers the skewed Y, whose finish straddles two
    samples), so the measure isolates the speed loops' mismatch (and the start skew) from
    the axes finishing apart. Includes the lurch of an axis that starts with
    the integrator wound up by the previous segment (``INTE`` is never reset,
    Angel-11 §4.5).
    Angel-11 §5.2 (D): ≈ 0.03 mm on star segment 1 with the back-solved per-axis
    plants, ≈ 0.0003 mm with identical plants.

    Returns:
        Read-only ``(n,) float64``, mm.
    """
    pos = trace.positions_mm
    rows = zip(trace.segment_start_sample, trace.axis_done_sample, trace.speeds, strict=True)
    out = np.array(
        [
            _max_distance(pos[s : max(s, min(done) - 1)], pos[s], speeds.astype(np.float64))
            for s, done, speeds in rows
        ]
    )
    out.flags.writeable = False
    return out
