"""Progress of a long ``camtool post`` on stderr: quiet for short jobs, a line per stage after.

A stage that begins before the threshold and then runs on without another step (one
GEOS buffer of a huge pocket, one long fit) is shown by a timer at the threshold, so a
job never runs past it silently.

Design notes: docs/internals.md, ``camtool/cli/progress.py``.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from types import TracebackType
from typing import TextIO

from camtool.model.progress import Step

AFTER_S = 2.0
"""Seconds a job runs before its progress is shown (shorter jobs print nothing new)."""

_TIMER_SLACK_S = 0.01  # the timer wakes this late, so that its tick finds the time up

REDRAW_S = 0.25
"""Least time between two redraws of a terminal's progress line, s."""


_TEXTS = {
    "fitting": "fitting arcs to {total} curves",
    "contours": "making contours of {total} shapes",
    "planning": "planning {total} contours",
    "offsetting": "offsetting {total} contours for the tool",
    "pocketing": "clearing {total} pocket regions",
    "writing": "writing {total} moves for {name}",
    "verifying": "verifying {total} blocks on {name}",
    "simulating": "simulating {total} interpolator iterations",
    "comparing": "comparing {total} cutting rows with the drawing",
    "budget": "error budget: re-simulating once per error source ({total})",
    "drawing": "drawing {total} moves",
}
"""What each stage after ``reading`` says (``total`` and ``name`` of its :class:`Step`)."""


def stage_text(step: Step) -> str:
    """What the stage of ``step`` is doing and how big it is, without the count done.

    >>> stage_text(Step("fitting", 10, 30576))
    'fitting arcs to 2027 curves'
    """
    if step.stage == "reading":
        shapes = f": {step.total} shapes" if step.total else ""
        return f"reading {step.name}{shapes}"
    if step.stage == "verifying" and not step.total:
        return f"verifying the program on {step.name}"
    template = _TEXTS.get(step.stage)
    return step.stage if template is None else template.format(total=step.total, name=step.name)


class StageReporter:
    """A :data:`~camtool.model.progress.Progress` callback that writes to stderr (see module).

    Args:
        after_s: seconds from its creation before anything is shown (tests pass 0).
        stream: where to write (default: ``sys.stderr`` at each write, so that a
            redirected stderr is honoured).
        live: redraw the current stage's line with its count (default: whether the
            stream is a terminal).
        clock: seconds, monotonic (tests pass a fake one).
        timer: start a thread that calls :meth:`tick` at the threshold (tests call
            it themselves).

    Use it as a context manager (``with StageReporter() as progress:``): leaving
    ends the last line and stops the timer, so nothing is written after the command.
    """

    def __init__(
        self,
        *,
        after_s: float | None = None,
        stream: TextIO | None = None,
        live: bool | None = None,
        clock: Callable[[], float] = time.monotonic,
        timer: bool = True,
    ) -> None:
        self._clock = clock
        self._start = clock()
        self._after = AFTER_S if after_s is None else after_s
        self._stream = stream
        self._live = live
        self._shown: tuple[str, int] | None = None  # the stage line last written
        self._drawn = 0.0  # when the live line was last drawn
        self._latest = ""  # the live line as the last step would draw it
        self._on_screen = ""  # the live line as drawn
        self._open = False  # a live line without its newline
        self._broken = False  # writing failed once (closed stderr): stay silent
        self._pending: Step | None = None  # the step running, told before the threshold
        self._lock = threading.RLock()  # the timer's thread and the job's
        self._use_timer = timer
        self._timer: threading.Timer | None = None

    def __enter__(self) -> StageReporter:
        return self

    def __exit__(
        self,
        kind: type[BaseException] | None,
        exc: BaseException | None,
        tb: TracebackType | None,
    ) -> None:
        self.close()
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def __call__(self, step: Step) -> None:
        """Show ``step`` if the job has run long enough (see the module)."""
        with self._lock:
            self._report(step)

    def tick(self) -> None:
        """Show the step still running if the threshold has passed and it is not shown.

        The timer calls this at the threshold; it does nothing after :meth:`close`.
        """
        with self._lock:
            if self._pending is not None and self._clock() - self._start >= self._after:
                self._report(self._pending)

    def _report(self, step: Step) -> None:
        if self._broken:
            return
        now = self._clock()
        if now - self._start < self._after:
            self._pending = step
            if self._use_timer and self._timer is None:
                wait = self._start + self._after - now + _TIMER_SLACK_S
                self._timer = threading.Timer(wait, self.tick)
                self._timer.daemon = True
                self._timer.start()
            return
        self._pending = None
        if self._shown != (step.stage, step.total):
            self._end_line()
            self._shown = (step.stage, step.total)
            if self._is_live():
                self._draw(_line(step), now)
            else:
                self._write(f"camtool: {stage_text(step)}…\n")
        elif self._open:
            self._latest = _line(step)
            if now - self._drawn >= REDRAW_S:
                self._draw(self._latest, now)

    def close(self) -> None:
        """End a redrawn line, with its last count, (call before writing anything else).

        The step told last is over: the timer will not show it.
        """
        with self._lock:
            self._pending = None
            self._end_line()

    def _end_line(self) -> None:
        if self._open:
            if self._latest != self._on_screen:
                self._draw(self._latest, self._clock())
            self._open = False
            self._write("\n")

    def _draw(self, line: str, now: float) -> None:
        self._write(f"\r{line}\x1b[K")  # back to the start, the line, erase what was left
        self._open = True
        self._drawn = now
        self._latest = self._on_screen = line

    def _is_live(self) -> bool:
        if self._live is None:
            try:
                self._live = bool(self._out().isatty())
            except (AttributeError, ValueError, OSError):
                self._live = False
        return self._live

    def _out(self) -> TextIO:
        return self._stream if self._stream is not None else sys.stderr

    def _write(self, text: str) -> None:
        try:
            out = self._out()
            out.write(text)
            out.flush()
        except (OSError, ValueError):  # stderr closed or gone: progress is not worth a failure
            self._broken = True
            self._open = False


def _line(step: Step) -> str:
    """The terminal's line for ``step``: what the stage does, and its count once it has one."""
    return f"camtool: {stage_text(step)}…{_count(step)}"


def _count(step: Step) -> str:
    """`` 1200 of 30576 (3%)`` once the stage has counted some of its work, else ``""``."""
    if step.total <= 0 or step.done <= 0:
        return ""
    return f" {step.done} of {step.total} ({100 * step.done // step.total}%)"
