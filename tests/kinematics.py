"""Shared fixtures of the timing-model tests (tests/verify/test_timing.py and
tests/postprocessors/test_<name>_motion.py): per-block kinematics and the shape of a result."""

from __future__ import annotations

import numpy as np

from camtool.verify.timing import BlockKinematics

FALSE = np.array([False])
TRUE = np.array([True])


def assert_seconds(t: np.ndarray, b: int) -> None:
    """``t`` is what every timing model returns: ``(b,) float64``, read-only."""
    assert t.dtype == np.float64 and t.shape == (b,)
    assert not t.flags.writeable


def blocks() -> BlockKinematics:
    """Three blocks: a feed move with backlash compensation, a rapid, a Z-only move."""
    return BlockKinematics.build(
        dominant_steps=[100, 2000, 0],
        is_rapid=[False, True, False],
        feed_mm_min=[0.8, 0.0, 0.0],
        length_mm=[0.5, 3.0, 0.0],
        iterations=[120, 2000, 0],
        steps=[[100, -40, 0], [-2000, 300, 0], [0, 0, -250]],
        compensation_steps=[1457, 0, 0],
    )
