"""The last answers of a function, given again for the very same arguments.

The error budget re-measures a verification once per error source with the same drawing,
the same programmed path and the same samples: a :class:`LastAnswers` keeps the last few
answers of such a measure by its arguments' identity (numbers by value), and keeps the
arguments too, so that their ``id`` cannot be reused by another object while kept. Only
the time depends on it: a caller keeps only answers that cannot change (read-only arrays,
tuples). ``CAMTOOL_ACCEL=0`` keeps nothing, and every call computes its answer.
"""

from __future__ import annotations

from typing import Generic, TypeVar

from camtool.accel import enabled

V = TypeVar("V")


class LastAnswers(Generic[V]):
    """The last ``size`` answers, each with the arguments it was computed for.

    Args:
        size: answers kept (the oldest goes first).
    """

    def __init__(self, size: int = 1) -> None:
        self.size = size
        self._kept: list[tuple[tuple[object, ...], V]] = []

    def get(self, *args: object) -> V | None:
        """The answer kept for ``args`` (the same objects; numbers equal), else ``None``."""
        if not enabled():
            return None
        for seen, answer in self._kept:
            if len(seen) == len(args) and all(map(_same, seen, args)):
                return answer
        return None

    def keep(self, answer: V, *args: object) -> V:
        """Keep ``answer`` for ``args`` (nothing with ``CAMTOOL_ACCEL=0``); returns it."""
        if enabled():
            self._kept = [*self._kept[max(0, len(self._kept) + 1 - self.size) :], (args, answer)]
        return answer


def _same(a: object, b: object) -> bool:
    """The same object, or equal numbers (a spacing in mm)."""
    if a is b:
        return True
    return isinstance(a, int | float) and isinstance(b, int | float) and a == b
