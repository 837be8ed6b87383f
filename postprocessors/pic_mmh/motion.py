"""Motion model of the UNAM-GMM GMM PIC controller (``pic-mmh``) for the verifier.

Design notes: docs/internals.md, ``postprocessors/pic_mmh/motion.py``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np
import numpy.typing as npt

from camtool.model.errors import UsageError
from camtool.model.machine import Machine
from camtool.verify.motion import MotionHooks
from camtool.verify.timing import (
    BlockKinematics,
    FloatArray,
    IntArray,
    blocks_by_value,
    counts,
    flags,
    floats,
    positive,
    same_length,
    seconds,
    timing_from_table,
)

PIC_MMH_STEPS_PER_MM = 1e6 / 140.0
"""Steps per mm of the GMM MMH-1: 140 nm/step (UNAM-GMM S000-12)."""
PIC_MMH_MAX_STEP_RATE_HZ = 166.0
"""Serial-link-limited step rate of the PIC controller, Hz (UNAM-GMM §2.4, L3198)."""


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
    """Interpolator iteration frequency of the UNAM-GMM PIC controller, Hz.

    UNAM-GMM §4.9 (Eq. 3.1 reconstructed, S000-17): ``f = d·F/60`` with ``d``
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
    """Seconds per block of the UNAM-GMM PIC controller: (iterations + compensation)/f.

    One interpolator iteration (DDA or DSM, with or without a pulse) per period
    of :func:`pic_mmh_step_rate_hz`; backlash compensation steps run at the
    block's rate before its move (UNAM-GMM §5.1: "at the current step rate",
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
    """Parameters of the UNAM-GMM ``pic-mmh`` time model (:func:`pic_mmh_block_time_s`).

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

    def capped_blocks(self, blocks: BlockKinematics) -> list[tuple[IntArray, str]]:
        """Feed moves whose step rate ``d·F/60`` is over the cap (F14 and up at 140 nm/step).

        UNAM-GMM §2.4 (L3198): the serial link limits the PIC to 166 Hz, so such
        a move runs (and is timed) at the cap, slower than programmed.
        """
        rate = self.steps_per_mm * blocks.feed_mm_min / 60.0
        over = ~blocks.is_rapid & (rate > self.max_step_rate_hz)
        slowest = self.max_step_rate_hz * 60.0 / self.steps_per_mm
        return [
            (
                group,
                f"feed {feed:g} mm/min asks {rate[group[0]]:.1f} Hz, over the "
                f"{self.max_step_rate_hz:g} Hz step-rate cap of the pic-mmh controller (serial "
                f"link, UNAM-GMM §2.4): it runs and is timed at {slowest:.4g} mm/min",
            )
            for group, feed in blocks_by_value(over, blocks.feed_mm_min)
        ]

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


def _timing(table: Mapping[str, Any], machine: Machine | None, where: str) -> PicMmhTiming:
    """The ``pic-mmh`` model from its table, completed from the profile.

    The profile's steps/mm (the larger of X and Y) and step-rate cap go in where
    the table does not say (UNAM-GMM Eq. 3.1).

    Raises:
        InputError: an unknown key or a bad value, naming ``where``.
    """
    completed = dict(table)
    if machine is not None:
        completed.setdefault("steps_per_mm", max(machine.steps_per_mm[:2]))
        if machine.max_step_rate_hz > 0:
            completed.setdefault("max_step_rate_hz", machine.max_step_rate_hz)
    model: PicMmhTiming = timing_from_table(PicMmhTiming, completed, where=where)
    return model


MOTION = MotionHooks(timing={"pic-mmh": _timing})
"""What ``pic-mmh`` adds to the verifier: its timing model."""
