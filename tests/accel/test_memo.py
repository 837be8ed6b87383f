"""Answers kept by the identity of their arguments (numbers by value), and none when off."""

from __future__ import annotations

import pytest

from camtool.accel.memo import LastAnswers


@pytest.mark.usefixtures("accel_on")
def test_the_same_objects_get_the_kept_answer_and_equal_ones_do_not() -> None:
    memo: LastAnswers[str] = LastAnswers(2)
    a, b, c = [1], [1], [2]  # a and b equal, not the same
    memo.keep("A", a, 0.5)
    assert memo.get(a, 0.5) == "A"
    assert memo.get(b, 0.5) is None  # equal is not enough for an object
    assert memo.get(a, 0.25) is None  # a number must be equal
    memo.keep("B", b, 0.5)
    memo.keep("C", c, 0.5)  # two kept: the oldest (a's) goes
    assert memo.get(a, 0.5) is None
    assert (memo.get(b, 0.5), memo.get(c, 0.5)) == ("B", "C")


def test_switched_off_nothing_is_kept(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    memo: LastAnswers[str] = LastAnswers()
    key = object()
    assert memo.keep("A", key) == "A"
    assert memo.get(key) is None
