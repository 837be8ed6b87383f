"""A test plugin target's motion model: a machine that steps X, then Y, 1 s per block.

Shows that a target outside camtool brings its own line interpolator and timing
model through its own ``MOTION`` (:class:`camtool.verify.motion.MotionHooks`)
with no edit in ``camtool/``; its target is ``xy-then.toml`` beside this file.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from camtool.verify.motion import MotionHooks, fixed_line, timing_class
from camtool.verify.steparray import STEP_DTYPE, StepArray, freeze
from camtool.verify.timing import BlockKinematics, FloatArray, positive, seconds


def x_then_y(dx: int, dy: int) -> StepArray:
    """Every X step, then every Y step: one axis per row, ``|dx| + |dy|`` rows."""
    rows = np.zeros((abs(dx) + abs(dy), 2), dtype=STEP_DTYPE)
    rows[: abs(dx), 0] = np.sign(dx)
    rows[abs(dx) :, 1] = np.sign(dy)
    return freeze(rows)


@dataclass(frozen=True, kw_only=True)
class FixedBlockTiming:
    """Every block takes ``seconds_per_block`` seconds, whatever it does."""

    model: ClassVar[str] = "fixed-block"
    seconds_per_block: float = 1.0

    def __post_init__(self) -> None:
        positive("seconds_per_block", self.seconds_per_block)

    def block_time_s(self, blocks: BlockKinematics) -> FloatArray:
        """``(B,)`` seconds, all ``seconds_per_block``."""
        return seconds(np.full(len(blocks), self.seconds_per_block))


MOTION = MotionHooks(
    lines={"x-then-y": fixed_line(x_then_y)},
    timing={"fixed-block": timing_class(FixedBlockTiming)},
)
