"""Programs the step simulator's tests share (tests/verify/test_stream.py and others)."""

from __future__ import annotations

import numpy as np

from camtool.model.program import ArcMove, Linear, Program, Rapid

TARGETS = ("pic-mmh", "flashcut", "valcnc", "i8751", "grbl")
"""Targets whose profile runs the step simulator (the one that streams)."""


def mixed_program(seed: int) -> Program:
    """Contours with reversals (backlash), a full circle, zero-length moves, rapids between.

    Inside 0.5 … 6 mm (pic-mmh's work area is 10 × 7 mm).
    """
    rng = np.random.default_rng(seed)
    moves: list[Linear | ArcMove | Rapid] = [Rapid(1.0, 1.0, contour=1)]
    x, y = 1.0, 1.0
    for _ in range(int(rng.integers(3, 8))):  # a zig-zag with reversals on both axes
        x = round(float(rng.uniform(0.5, 6.0)), 3)
        y = round(float(rng.uniform(0.5, 6.0)), 3)
        moves.append(Linear(x, y, 300.0, contour=1))
    moves.append(Linear(x, y, 300.0, contour=1))  # no XY length
    moves.append(Rapid(4.5, 3.0, contour=2))  # a full circle: the fitted diameter
    moves.append(ArcMove(4.5, 3.0, 3.5, 3.0, bool(seed % 2), 300.0, contour=2))
    moves.append(Rapid(1.0, 1.0, contour=3))  # a closed square with an arc corner
    moves += [
        Linear(2.0, 1.0, 300.0, contour=3),
        ArcMove(2.5, 1.5, 2.0, 1.5, False, 300.0, contour=3),
        Linear(2.5, 2.5, 300.0, contour=3),
        Linear(1.0, 2.5, 300.0, contour=3),
        Linear(1.0, 1.0, 300.0, contour=3),
    ]
    moves.append(Rapid(0.5, 0.5))
    return Program(tuple(moves), origin=(0.0, 0.0))
