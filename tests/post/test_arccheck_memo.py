"""Grid.value keeps the floats it made (issue 17): the same float as made afresh."""

from __future__ import annotations

import numpy as np
import pytest

from camtool.post import arcconform
from camtool.post.arcconform import Grid


def test_value_memo_gives_the_fresh_float(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(arcconform, "_MEMO_SIZE", 50)  # overflow: the memo starts again
    rng = np.random.default_rng(17)
    for quantum in (0.001, 0.01, 0.0001, 0.005):
        grid = Grid.of(quantum)
        ks = [int(k) for k in rng.integers(-(10**12), 10**12, 300)] + [0, 1, -1, 10**21]
        for k in ks + ks[::-1]:
            got = grid.value(k)
            assert repr(got) == repr(grid._value_slow(k)), (quantum, k)
        assert len(grid._values) <= 50
