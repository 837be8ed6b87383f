"""A move is a slotted object: no per-instance ``__dict__``, one pointer a field.

A re-post holds every move of the program at once (2.6 M of them for a 50 MB program),
so the object's own size is most of its memory: the object header (16 bytes), the GC
header (16) and 8 bytes per field; a ``__dict__`` would add ~100 bytes more.
"""

from __future__ import annotations

import copy
import pickle
import random
import sys
import tracemalloc

import pytest

from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import bbox_union

MOVES = [
    Rapid(1.0, 2.0, 5.0, 3),
    Linear(1.0, 2.0, 300.0, -1.0, 4),
    ArcMove(1.0, 2.0, 0.5, 0.5, True, 300.0, None, 5),
]


@pytest.mark.parametrize("move", MOVES, ids=lambda m: type(m).__name__)
def test_a_move_has_no_dict_and_costs_a_pointer_a_field(move: object) -> None:
    assert not hasattr(move, "__dict__")
    fields = type(move).__dataclass_fields__  # type: ignore[attr-defined]
    assert sys.getsizeof(move) <= 16 + 16 + 8 * len(fields)


@pytest.mark.parametrize("move", MOVES, ids=lambda m: type(m).__name__)
def test_a_move_pickles_copies_and_stays_frozen(move: object) -> None:
    assert pickle.loads(pickle.dumps(move)) == move
    assert copy.copy(move) == move and copy.deepcopy(move) == move
    with pytest.raises(AttributeError):
        move.x = 9.0  # type: ignore[attr-defined]


def _zigzag(n: int) -> Program:
    rng = random.Random(n)
    moves: list[Move] = [Rapid(0.0, 0.0, 2.0)]
    for k in range(n):
        x, y = rng.uniform(-50, 50), rng.uniform(-50, 50)
        z = rng.choice([None, -1.0, -0.5])
        if k % 3 == 0:
            moves.append(ArcMove(x, y, x / 2, y / 2, k % 2 == 0, 400.0, z))
        else:
            moves.append(Linear(x, y, 300.0 + k % 5, z))
    return Program(tuple(moves))


def test_bbox_and_cutting_time_walk_the_moves_once_without_lists() -> None:
    """Equal to the per-move reference, and no per-move list (peak well under one)."""
    program = _zigzag(3_000)
    boxes = [s.bbox() for m, s in program.segments() if not isinstance(m, Rapid)]
    assert program.bbox(cutting_only=True) == bbox_union(boxes)
    assert program.bbox() == bbox_union([s.bbox() for _, s in program.segments()])
    reference = sum(
        length / m.feed_mm_min * 60.0
        for m, length in zip(program.moves, program.path_lengths(), strict=True)
        if not isinstance(m, Rapid)
    )
    assert program.cutting_time_s() == reference
    big = _zigzag(60_000)
    for measure in (big.bbox, big.cutting_time_s):
        tracemalloc.start()
        try:
            measure()
            peak = tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()
        assert peak < 60_000 * 8, f"{measure.__name__}: {peak} bytes"  # a list's pointers alone


def test_source_lines_cost_8_bytes_a_move_and_behave_as_a_tuple() -> None:
    # a program read from a file keeps the source line of every move: a tuple would hold
    # an int object each (28 bytes + an 8-byte pointer)
    n = 200_000
    numbers = list(range(1_000_000, 1_000_000 + n))
    tracemalloc.start()
    try:
        before = tracemalloc.get_traced_memory()[0]
        program = Program((), lines=numbers[:0]), Program(MOVES[:1], lines=(7,))
        lines = Program(tuple(MOVES[:1]) * n, lines=numbers).lines
        held = tracemalloc.get_traced_memory()[0] - before
    finally:
        tracemalloc.stop()
    assert held < 9 * n + 8 * n + 100_000  # the lines (8 a move) and the moves' tuple (8)
    assert lines == tuple(numbers) and tuple(numbers) == lines and lines != numbers[:-1]
    assert lines[5] == numbers[5] and lines[2:4] == (numbers[2], numbers[3])
    assert hash(program[1].lines) == hash((7,)) and not program[0].lines
    assert pickle.loads(pickle.dumps(program[1])) == program[1]
