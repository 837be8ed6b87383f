"""A job refused before planning when its toolpath cannot fit the machine's travel.

Design notes: docs/internals.md, ``camtool/jobs/travel.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

from camtool.geometry.chain import joint_distance
from camtool.jobs.job import Job, Operation
from camtool.jobs.selection import Selected
from camtool.model.shapes import bbox_union
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.placement import Placing, too_large_drawing

if TYPE_CHECKING:
    from camtool.post.base import Target


def refuse_too_large(
    job: Job,
    sequence: Sequence[Operation],
    chosen: Sequence[Selected],
    setup: PlanOptions,
    target: Target,
) -> None:
    """Refuse, before planning, a job whose toolpath would be larger than the travel.

    The contours of the profiles cut on their line or outside them (and engravings) lie
    within the chaining and fitting tolerances of their toolpath, so the box of them all
    is within the program's extent: :func:`~camtool.toolpath.placement.too_large_drawing`
    refuses it as a single operation's drawing is refused as soon as it is read
    (:func:`camtool.jobs.pipeline.travel_check`). Pockets, inside profiles (whose cuts can
    vanish) and drills (at the holes' centres) are checked after planning only, as every
    program is; so is a job scaled into a box (``fit``).

    Raises:
        TooLargeError: as :func:`~camtool.toolpath.placement.too_large_drawing`.
    """
    boxes, margin = [], 0.0
    for op, selected in zip(sequence, chosen, strict=True):
        plan = op.plan
        if (
            op.type == "drill"
            or plan.offset not in ("on", "outside")
            or not selected.drawing.contours
        ):
            continue
        boxes.append(bbox_union([c.bbox() for c in selected.drawing.contours]))
        radius = job.tool(op.tool).diameter / 2.0 if plan.offset == "outside" else 0.0
        margin = max(margin, 2.0 * (radius + plan.lead_in))
    if setup.fit is not None or not boxes:
        return
    slack = joint_distance(setup.chain_tolerance) + setup.tolerance
    placing = Placing(setup.placement, setup.translate, (margin, margin))
    too_large_drawing(bbox_union(boxes), target.machine, placing, slack_mm=slack)
