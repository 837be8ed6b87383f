"""A job refused before planning when its toolpath cannot fit the machine's travel.

Design notes: docs/internals.md, ``camtool/jobs/travel.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from camtool.geometry.chain import joint_distance
from camtool.jobs.job import Job, Operation
from camtool.jobs.selection import Chaining, Selected
from camtool.model.shapes import bbox_union
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.placement import Placing, too_large_drawing

if TYPE_CHECKING:
    from camtool.post.base import Target


def refuse_too_large(
    job: Job,
    sequence: Sequence[Operation],
    selections: Sequence[tuple[Selected, Selected]],
    chaining: Chaining,
    setup: PlanOptions,
    target: Target,
) -> None:
    """Refuse, before planning, a job whose toolpath would be larger than the travel.

    Args:
        job: the job (its tools).
        sequence: its operations, in cutting order.
        selections: each operation's selection, as drawn and as scaled (``scale``/``fit``).
        chaining: how the planner chains the drawing's contours (closed or not).
        setup: the job's shared options (``fit``, ``placement``, tolerances).
        target: the machine whose travel it must fit.

    A profile cut on the line and an engraving cut every contour they select, a profile
    outside every one that is closed once chained (the planner leaves an open chain out);
    each such cut passes within the chaining and fitting tolerances of the contour, so the
    box of them all is within the program's extent:
    :func:`~camtool.toolpath.placement.too_large_drawing` refuses it as a single
    operation's drawing is refused as soon as it is read
    (:func:`camtool.jobs.pipeline.travel_check`). Pockets, inside profiles (whose cuts can
    vanish) and drills (at the holes' centres) are checked after planning only, as every
    program is; so is a job scaled into a box (``fit``).

    Raises:
        TooLargeError: as :func:`~camtool.toolpath.placement.too_large_drawing`.
    """
    if setup.fit is not None:
        return
    boxes, margin = [], 0.0
    for op, (drawn, scaled) in zip(sequence, selections, strict=True):
        offset = op.plan.offset
        if op.type == "drill" or offset not in ("on", "outside") or not scaled.drawing.contours:
            continue
        cut = list(scaled.drawing.contours)
        if offset == "outside":  # an open chain is left out
            shapes = chaining(drawn.drawing.contours)
            cut = [c for c, shape in zip(cut, shapes, strict=True) if shape.closed]
        if not cut:
            continue
        boxes.append(bbox_union([c.bbox() for c in cut]))
        radius = job.tool(op.tool).diameter / 2.0 if offset == "outside" else 0.0
        margin = max(margin, 2.0 * (radius + op.plan.lead_in))
    if not boxes:
        return
    slack = joint_distance(setup.chain_tolerance) + setup.tolerance
    placing = Placing(setup.placement, setup.translate, (margin, margin))
    too_large_drawing(bbox_union(boxes), target.machine, placing, slack_mm=slack)
