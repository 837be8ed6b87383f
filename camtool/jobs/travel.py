"""A job refused before planning: too large for the travel, or too small for any tool.

Too small: a drawing whose unit is set wrong (a part in mm that says µm).

Design notes: docs/internals.md, ``camtool/jobs/travel.py``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import TYPE_CHECKING

from camtool.geometry.chain import joint_distance
from camtool.jobs.job import Job, Operation
from camtool.jobs.selection import Chaining, Selected
from camtool.model.errors import InputError
from camtool.model.shapes import BBox, Contour, bbox_union
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


SMALLEST_TOLERANCES = 10.0
"""A drawing's cuts must span more than this many ``--tolerance`` on their longer side."""
SMALLEST_JOINTS = 2.0
"""... and more than this many chaining distances (ends closer than one are joined)."""


def refuse_too_small(
    selections: Sequence[tuple[Selected, Selected]],
    setup: PlanOptions,
    source: str,
) -> None:
    """Refuse, before planning, a job whose cuts span next to nothing: a unit set wrong.

    The contours the operations select, as scaled, must span more
    than :data:`SMALLEST_TOLERANCES` curve tolerances and :data:`SMALLEST_JOINTS`
    chaining distances on their longer side; a smaller drawing (a part in mm whose DXF
    says µm, ``$INSUNITS`` 13) has its lines joined, merged and fitted away within those
    tolerances, and its program would cut a dot where a part was drawn. The drawing's
    points (``marks``, drilled) are left out: one hole spans nothing. So is a job scaled
    into a box (``fit``).

    Args:
        selections: each operation's selection, as drawn and as scaled (``scale``).
        setup: the job's shared options (``fit``, ``tolerance``, ``chain_tolerance``).
        source: the drawing's name, for the message.

    Raises:
        InputError: naming the span, the limit and the remedies (units, scale, tolerances).
    """
    if setup.fit is not None:
        return
    contours = (c for _, scaled in selections for c in scaled.drawing.contours)
    refuse_small_box(contours, setup.tolerance, setup.chain_tolerance, source)


def refuse_small_box(
    contours: Iterable[Contour], tolerance: float, chain_tolerance: float, source: str
) -> None:
    """:func:`refuse_too_small` of ``contours`` (mm) at those tolerances (mm).

    Their boxes are joined until they span the limit: a drawing of any size reads a few.

    Raises:
        InputError: as :func:`refuse_too_small`.
    """
    joint = joint_distance(chain_tolerance)
    limit = max(SMALLEST_TOLERANCES * tolerance, SMALLEST_JOINTS * joint)
    box: BBox | None = None
    for contour in contours:
        c = contour.bbox()
        box = c if box is None else bbox_union([box, c])
        if max(box[2] - box[0], box[3] - box[1]) >= limit:
            return
    if box is None:
        return
    x0, y0, x1, y1 = box
    raise InputError(
        f"{source or 'the drawing'}: its cuts span only {x1 - x0:.4g} × {y1 - y0:.4g} mm, "
        f"under {limit:g} mm ({SMALLEST_TOLERANCES:g} times the {tolerance:g} mm "
        f"tolerance, {SMALLEST_JOINTS:g} times the {joint:g} mm within which ends are "
        "joined): its lines would be joined and merged, and the tool would cut next to "
        "nothing of it. Check the drawing's units (a DXF's $INSUNITS, an SVG's width and "
        "height) and scale it (--scale, --fit W H; a job's scale or fit), or for a part "
        "this small give a finer --tolerance and --chain-tolerance"
    )
