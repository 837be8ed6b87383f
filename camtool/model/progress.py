"""Where a long job is: the stages a post goes through, told to a callback as it works.

Design notes: docs/internals.md, ``camtool/model/progress.py``.
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
    "pocketing",
    "writing",
    "verifying",
    "simulating",
    "comparing",
    "budget",
    "drawing",
)
"""The stages of ``camtool post``, in the order a job meets them (a job may skip some):
reading the file (``total``: its drawn shapes, once counted), fitting arcs to its curves
(``total``: distinct curve shapes, copies placed apart sharing one fit), making the
contours of the shapes (``total``: shapes),
planning the toolpath (``total``: contours), within it offsetting the closed contours for
the tool with OpenCASCADE (``total``: contours offset), or clearing pockets (``--offset
pocket``; ``total``: the regions to clear), writing the code (``total``: moves of the
program), verifying it (``total``: blocks of code; 0: not counted), within it simulating
the machine (``total``: the interpolator's iterations, ``done`` as they are measured; a
long trace, streamed) and comparing the machined edge with the drawing (``total``: the
cutting rows compared), and its error budget (``total``: the
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
