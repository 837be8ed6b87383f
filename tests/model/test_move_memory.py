"""A move is a slotted object: no per-instance ``__dict__``, one pointer a field.

A re-post holds every move of the program at once (2.6 M of them for a 50 MB program),
so the object's own size is most of its memory: the object header (16 bytes), the GC
header (16) and 8 bytes per field; a ``__dict__`` would add ~100 bytes more.
"""

from __future__ import annotations

import copy
import pickle
import sys

import pytest

from camtool.model.program import ArcMove, Linear, Rapid

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
