"""The warnings of the ``matlab-router`` writer: one per kind of conversion.

Gathered in a :class:`WriterNotes` while :class:`~camtool.post.matlab_router.MatlabRouterPost`
writes, then worded here (seed-002 §2.8, §3, §4.2 for the reasons given).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from camtool.model.shapes import Point
from camtool.post.matlab_router_read import major_axis_feed_mm_min

if TYPE_CHECKING:
    from camtool.post.matlab_router import RouterJob

FIRST_POINT_SPEED = 500
"""Speed of the move from home to a job's first point, counts per 5 ms (L4796)."""

COMMAND_REASONS = {
    "Spindle": "the Z slave switches the Dremel on at the first segment and off at the end "
    "of every job by itself (seed-002 §2.8, L6556–L6560)",
    "Dwell": "the GUI has no pause; the master stops at every vertex anyway",
    "ToolChange": "the router has one tool, changed by hand",
    "Home": "every job homes Z, X and Y before it starts (seed-002 §2.8 st=0)",
}
"""Why each kind of :data:`~camtool.model.program.Command` is not written."""


@dataclass
class WriterNotes:
    """What the writer has to tell the user, gathered while writing (one warning per kind).

    Attributes:
        warnings: warnings already worded (strokes that round to one point).
        commands: commands not written, by kind (``Spindle``, ``Dwell``...).
        arcs: arcs turned into chords.
        chords: chords written for them.
        sagitta_mm: largest chord sagitta measured, mm (before rounding to 0.1 mm).
        merged: where vertices that rounded onto the previous one were dropped.
        feeds: programmed feeds other than the router's, mm/min.
        trailing_rapid: end of a rapid after the last cut (not written), mm.
    """

    warnings: list[str] = field(default_factory=list)
    commands: Counter[str] = field(default_factory=Counter)
    arcs: int = 0
    chords: int = 0
    sagitta_mm: float = 0.0
    merged: list[str] = field(default_factory=list)
    feeds: set[float] = field(default_factory=set)
    trailing_rapid: Point | None = None


def notes_warnings(notes: WriterNotes, speed: int, tolerance: float) -> list[str]:
    """One warning per kind of conversion the writer made (commands, feeds, arcs, merges)."""
    w = [
        f"{count} {kind} command(s) not written: {COMMAND_REASONS.get(kind, 'no word for it')}"
        for kind, count in sorted(notes.commands.items())
    ]
    if notes.feeds:
        feeds = ", ".join(f"{f:g}" for f in sorted(notes.feeds))
        w.append(
            f"feeds ignored ({feeds} mm/min): the router runs the longer axis of every segment "
            f"at {speed} counts per 5 ms = {major_axis_feed_mm_min(speed):g} mm/min and scales "
            "the other (seed-002 §3, R7)"
        )
    if notes.arcs:
        w.append(
            f"{notes.arcs} arc(s) written as {notes.chords} chords within {tolerance:g} mm "
            f"(largest sagitta {notes.sagitta_mm:.4f} mm), then rounded to 0.1 mm: the router "
            "has straight segments only (seed-002 §4.1)"
        )
    if notes.merged:
        w.append(
            f"{len(notes.merged)} vertex(es) rounded onto the previous one at 0.1 mm and dropped "
            f"(first: {notes.merged[0]})"
        )
    if notes.trailing_rapid is not None:
        x, y = notes.trailing_rapid
        w.append(
            f"the final rapid to ({x:g}, {y:g}) mm is not written: after a job the master "
            "idles with the tool where the job ended (seed-002 §2.8 st=3)"
        )
    return w


def jobs_warnings(jobs: list[RouterJob], max_segments: int) -> list[str]:
    """Warnings about the jobs themselves: splits, several jobs, firmware hazards."""
    w = []
    split = [j for j in jobs if j.part == 2]
    if split:
        joints = "; ".join(
            f"stroke {j.stroke} at ({j.arrays.xy[0, 0] / 10:g}, {j.arrays.xy[1, 0] / 10:g}) mm"
            for j in split[:3]
        )
        w.append(
            f"{len(split)} stroke(s) longer than {max_segments} segments split into jobs that "
            f"continue from the same vertex ({joints}): the master holds {max_segments} per job "
            "(L4625); the tool lifts, homes and re-plunges at each joint"
        )
    if len(jobs) > 1:
        w.append(
            f"{len(jobs)} jobs: the router has no travel inside a job; each job homes Z, X, Y, "
            f"goes to its first point X then Y at speed {FIRST_POINT_SPEED} and lowers the tool, "
            "and the master idles after it (seed-002 §2.8, §6 L3938–L3966): send the jobs "
            "one at a time, resetting the master in between"
        )
    ones = [
        f"{j.where(int(c))} {'XY'[a]}"
        for j in jobs
        for a, c in zip(*np.nonzero(j.arrays.lxy == 1), strict=True)
    ]
    if ones:
        w.append(
            f"{len(ones)} segment(s) move an axis by 0.1 mm (first: {ones[0]}): the thesis "
            "slave's chunk counter underflows on a distance of 1 (factor - 1 = 65535, "
            "seed-002 §4.2) and that axis runs away; check the slave firmware or snap the "
            "drawing to 0.2 mm"
        )
    return w
