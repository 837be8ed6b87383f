"""A bound on the CPU time a block of a test may use: a hang guard, not a speed test.

``ITIMER_PROF`` counts the CPU time of this process only, so a heavily loaded machine does
not trip it; a bound far above what the block needs catches a hang or a cost that grows
with the square of the input (a hostile file that would keep camtool busy for hours).
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator
from typing import Any


class CpuTimeExceeded(AssertionError):
    """The block used more CPU time than its bound."""


@contextlib.contextmanager
def cpu_bound(seconds: float) -> Iterator[None]:
    """Raise :class:`CpuTimeExceeded` once the block has used ``seconds`` of CPU time."""

    def _on_alarm(signum: int, frame: Any) -> None:
        raise CpuTimeExceeded(f"still running after {seconds:g} s of CPU time")

    previous = signal.signal(signal.SIGPROF, _on_alarm)
    signal.setitimer(signal.ITIMER_PROF, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_PROF, 0)
        signal.signal(signal.SIGPROF, previous)
