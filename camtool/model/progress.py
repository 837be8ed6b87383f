"""Where a long job is: the stages a post goes through, told to a callback as it works.

Library code never prints (STYLE.md): an importer or the pipeline calls a
:data:`Progress` callback with a :class:`Step` at each stage and, in a long loop, as it
counts through the work; the caller decides what to do with it. The CLI turns steps into
stderr lines, and only for a job still running after a couple of seconds
(:mod:`camtool.cli.progress`), so short jobs say exactly what they said before.

A callback must be cheap and must not raise: it may be called once per shape or per
chunk of curve fits (thousands of times on a big drawing); it is called in the calling
process only (never from a worker of :mod:`camtool.geometry.fitpool` or
:class:`camtool.accel.cores.ForkedWork`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeAlias

STAGES = (
    "reading",
    "fitting",
    "contours",
    "planning",
    "offsetting",
    "writing",
    "verifying",
    "budget",
    "drawing",
)
"""The stages of ``camtool post``, in the order a job meets them (a job may skip some):
reading the file (``total``: its drawn shapes, once counted), fitting arcs to its curves
(``total``: distinct curves), making the contours of the shapes (``total``: shapes),
planning the toolpath (``total``: contours), within it offsetting the closed contours for
the tool with OpenCASCADE (``total``: contours offset), writing the code (``total``: moves of the
program), verifying it (``total``: blocks of code) and its error budget (``total``: the
error sources re-simulated, in forked workers when there are cores for them; ``name``: the
next source, in order, whose figures are not in yet); ``camtool preview`` reads, then
draws the picture (``total``: the program's moves)."""


@dataclass(frozen=True)
class Step:
    """One report: the stage the job is in and how far through it.

    Attributes:
        stage: one of :data:`STAGES`.
        done: units of the stage finished so far (0 at its start).
        total: units the stage has (0: not known yet).
        name: what the stage works on, for the message: the file's name when
            ``reading``, the target's name when ``writing`` or ``verifying``, the
            source when ``budget``; else ``""``.
    """

    stage: str
    done: int = 0
    total: int = 0
    name: str = ""


Progress: TypeAlias = Callable[[Step], None]
"""``progress(step)``: told where the job is (see :class:`Step`); returns nothing."""


def no_progress(step: Step) -> None:
    """A :data:`Progress` that ignores every step (the default of every library call)."""
