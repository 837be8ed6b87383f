"""Error measures of a seed-002 router trace (seed-002 R14, R15), all in mm.

- :func:`closure_mm`: where a job ends relative to its first point (R14c), with
  an optional per-axis backlash (R15) applied to the executed positions;
- :func:`backlash_effect_mm`: what that backlash alone adds to the closure;
- :func:`segment_deviation_mm`: largest distance of each segment's path from
  the straight line joining where it started and where it stopped (R14b);
- :func:`tracking_deviation_mm`: the same against the line the two speeds aim
  along, while both axes are moving: the servo-mismatch part of R14b, as in
  seed-002 §5.2 "(D) Rough simulation".
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.verify.servo import ServoTrace

FloatArray = npt.NDArray[np.float64]


def apply_backlash(positions_mm: npt.ArrayLike, backlash_mm: tuple[float, float]) -> FloatArray:
    """Table positions behind a per-axis dead band (play operator), mm (R15).

    The table follows the motor side only while the motor pushes it; after a
    reversal the motor travels the dead band before the table moves again. The
    band starts taken up in the + direction (the approach to the first point
    is +X then +Y, seed-002 §2.8 st=1), so the table equals the motor position
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
    seed-002 §4.5).
    seed-002 §5.2 (D): ≈ 0.03 mm on star segment 1 with the back-solved per-axis
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
