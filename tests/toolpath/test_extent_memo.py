"""toolpath_extent's kept last result is the box computed afresh, for that program only."""

from __future__ import annotations

import random

from camtool.model.program import Linear, Program, Rapid
from camtool.toolpath import placement
from camtool.toolpath.placement import toolpath_extent


def _program(rng: random.Random) -> Program:
    moves = [Rapid(rng.uniform(-9, 9), rng.uniform(-9, 9), 5.0)]
    moves += [Linear(rng.uniform(-9, 9), rng.uniform(-9, 9), 100.0) for _ in range(5)]
    return Program(tuple(moves), origin=(rng.uniform(-1, 1), 0.0))


def test_memo_equals_fresh_and_follows_the_program() -> None:
    rng = random.Random(4)
    programs = [_program(rng) for _ in range(30)]
    for p in programs + programs[::-1]:
        assert toolpath_extent(p) == placement._extent(p)
        assert toolpath_extent(p) == placement._extent(p)  # the kept one


def test_equal_but_new_moves_are_computed_again() -> None:
    p = _program(random.Random(1))
    toolpath_extent(p)
    other = Program(tuple(Linear(m.x + 1.0, m.y, 100.0) for m in p.moves), origin=p.origin)
    assert toolpath_extent(other) == placement._extent(other) != placement._extent(p)
    moved = Program(p.moves, origin=(p.origin[0] + 50.0, 1.0))  # same moves, new origin
    assert toolpath_extent(moved) == placement._extent(moved)
