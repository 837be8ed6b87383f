"""What an operation cuts: its selection of the drawing, without what is not the part.

A :class:`~camtool.jobs.job.Selection` keeps the contours (and points) whose layer,
colour, closedness, circle diameter and linetype it names. Construction geometry — a
non-continuous linetype (centre, hidden, dashed lines) or a construction, dimension or
centre-line layer (:mod:`camtool.model.construction`) — is kept only when the selection
names its layer or its linetype: a selection of "everything" never cuts it.
"""

from __future__ import annotations

import dataclasses
import shlex
from collections import Counter
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TypeAlias

from camtool.jobs.job import Operation, Selection
from camtool.model.construction import construction_layer, is_construction, line_kind
from camtool.model.shapes import Contour, Drawing, Mark, Point, circle_of


@dataclass(frozen=True)
class Selected:
    """An operation's share of the drawing.

    Attributes:
        drawing: the contours and marks it cuts (the drawing's source and warnings kept).
        construction: the construction contours its selection held but leaves uncut.
        chains: for each of ``drawing.contours``, the closed chain it is a piece of as the
            selection chained it (:attr:`Shape.chain`), or ``None``; empty when the
            selection chained nothing. :func:`as_chained` cuts those chains.
    """

    drawing: Drawing
    construction: tuple[Contour, ...] = ()
    chains: tuple[Contour | None, ...] = ()


def construction_reason(contour: Contour, selection: Selection) -> str | None:
    """Why ``contour`` is construction that ``selection`` does not name, or ``None``.

    Never a reason for a contour that is not construction at all
    (:func:`~camtool.model.construction.is_construction`, which ``--fit`` also follows).
    """
    if not is_construction(contour):
        return None
    named_layer = selection.layers is not None and contour.layer.casefold() in {
        n.casefold() for n in selection.layers
    }
    if contour.linetype:
        named = selection.linetypes is not None and contour.linetype in selection.linetypes
        if not (named or named_layer):
            return line_kind(contour.linetype)
    if construction_layer(contour.layer) and not named_layer:
        return f"construction layer {contour.layer!r}"
    return None


Circle: TypeAlias = tuple[Point, float]
"""A circle's centre and diameter, mm (:func:`~camtool.model.shapes.circle_of`)."""


@dataclass(frozen=True)
class Shape:
    """What a contour is once chained with its neighbours, as the planner chains them.

    ``closed``: the chain is closed (a square of four LINEs is); ``circle``: the chain is
    a whole circle (two ARCs of one centre and radius are), its centre and diameter in the
    drawing's own mm, else ``None``; ``chain``: the closed chain itself, as the drawing is
    placed (after ``scale``/``fit``, mm), its gaps not yet closed, else ``None``.
    """

    closed: bool
    circle: Circle | None
    chain: Contour | None = None


def matches(contour: Contour, selection: Selection, shape: Shape | None = None) -> bool:
    """Whether ``contour`` meets every condition of ``selection`` (construction aside).

    ``shape``: what the contour is once chained (:class:`Shape`), for ``selection.closed``,
    ``diameter`` and ``except_diameter``; ``None``: the contour's own.
    """
    if not selection.contours or (
        selection.layers is not None
        and contour.layer.casefold() not in {n.casefold() for n in selection.layers}
    ):
        return False
    if selection.colours is not None and contour.colour not in selection.colours:
        return False
    is_closed = contour.closed if shape is None else shape.closed
    if selection.closed is not None and is_closed != selection.closed:
        return False
    if selection.linetypes is not None and contour.linetype not in selection.linetypes:
        return False
    if selection.diameter is None and selection.except_diameter is None:
        return True
    circle = circle_of(contour) if shape is None else shape.circle
    d = None if circle is None else circle[1]
    if selection.diameter is not None and (d is None or not _within(d, selection.diameter)):
        return False
    span = selection.except_diameter
    return span is None or d is None or not _within(d, span)


def _within(d: float, span: tuple[float, float]) -> bool:
    """Whether the diameter ``d`` lies in ``span`` (mm, to 1e-6 of it: printed values)."""
    lo, hi = span
    slack = 1e-6 * max(hi, 1.0)
    return lo - slack <= d <= hi + slack


def mark_matches(mark: Mark, selection: Selection) -> bool:
    """Whether the point ``mark`` is selected (``points`` on, layer and colour matching)."""
    if not selection.points:
        return False
    if selection.layers is not None and mark.layer.casefold() not in {
        n.casefold() for n in selection.layers
    }:
        return False
    return selection.colours is None or mark.colour in selection.colours


def with_drilled_marks(drawing: Drawing, selections: Sequence[Selection]) -> Drawing:
    """``drawing`` with only the marks one of ``selections`` selects: what ``--fit`` sizes.

    A point no drill drills is not cut, so it takes no part in the size (a far POINT would
    make the part of a plain ``post --fit`` smaller than asked).
    """
    kept = tuple(m for m in drawing.marks if any(mark_matches(m, s) for s in selections))
    return drawing if len(kept) == len(drawing.marks) else dataclasses.replace(drawing, marks=kept)


Chaining: TypeAlias = Callable[[Sequence[Contour]], Sequence[Shape]]
"""What each of some contours is once they are chained end to end, as the planner chains
what an operation selects (:func:`camtool.toolpath.plan.chained`)."""


def select(drawing: Drawing, selection: Selection, chaining: Chaining | None = None) -> Selected:
    """The contours and marks of ``drawing`` that ``selection`` cuts (see the module).

    ``closed``, ``diameter`` and ``except_diameter`` ask what a contour is as it will be
    cut: a closed shape drawn as several entities (four LINEs, LINEs and ARCs) is one
    closed contour once chained, a circle drawn as two ARCs one circle. ``chaining`` tells
    that of the contours the other conditions keep (chained together, as the planner
    chains them); ``None``: each contour's own.
    """
    kept: list[Contour] = []
    construction: list[Contour] = []
    shapes: dict[int, Shape] = {}
    asks = (selection.closed, selection.diameter, selection.except_diameter)
    if chaining is not None and any(a is not None for a in asks):
        loose = dataclasses.replace(selection, closed=None, diameter=None, except_diameter=None)
        candidates = [  # what the planner gets: construction is not cut
            c
            for c in drawing.contours
            if matches(c, loose) and construction_reason(c, selection) is None
        ]
        shapes = {id(c): k for c, k in zip(candidates, chaining(candidates), strict=True)}
    for contour in drawing.contours:
        if not matches(contour, selection, shapes.get(id(contour))):
            continue
        if construction_reason(contour, selection) is None:
            kept.append(contour)
        else:
            construction.append(contour)
    marks = tuple(m for m in drawing.marks if mark_matches(m, selection))
    chosen = Drawing(tuple(kept), drawing.source, drawing.warnings, marks)
    chains = tuple(shapes[id(c)].chain for c in kept) if shapes else ()
    return Selected(chosen, tuple(construction), chains)


def as_chained(selected: Selected) -> Selected:
    """``selected`` with each closed chain the selection found in place of its pieces.

    Where more than two ends meet, chaining depends on what else is there: the layer's
    open lines that end at a vertex two loops share steer which way each loop goes on.
    The selection chained the operation's whole layer (as ``job init`` does, to tell a
    part from its holes); the planner, given only the pieces of closed chains, could join
    them otherwise (two loops that touch into one figure, a hole into its part). Given
    the chains themselves, closed, it cuts them as they were selected. Each chain takes
    the place of its first piece; contours in no closed chain stay as they are.
    """
    if not any(selected.chains):
        return selected
    contours: list[Contour] = []
    seen: set[int] = set()
    for contour, chain in zip(selected.drawing.contours, selected.chains, strict=True):
        if chain is None:
            contours.append(contour)
        elif id(chain) not in seen:
            seen.add(id(chain))
            contours.append(chain)
    drawing = dataclasses.replace(selected.drawing, contours=tuple(contours))
    return Selected(drawing, selected.construction)


def nothing_selected(drawing: Drawing, op: Operation, where: str) -> str:
    """Why an operation selects nothing, naming what the drawing does have."""
    s = op.select
    selects = "select" if where.endswith("options") else "selects"  # "the options select"
    if not drawing.contours and drawing.marks and not s.points:
        n = len(drawing.marks)
        return (
            f"{where} {selects} nothing: the drawing has no contour, only {n} point"
            f"{'s' if n > 1 else ''} (DXF POINT entities, SVG dots); a drill operation drills "
            "points (a job file, docs/jobs.md), or draw the contours to cut"
        )
    layers = sorted({c.layer for c in drawing.contours} | {m.layer for m in drawing.marks})
    if s.layers is not None:
        present = {name.casefold() for name in layers}
        missing = [n for n in s.layers if n.casefold() not in present]
        if missing:
            return (
                f"{where} {selects} layer {', '.join(repr(n) for n in missing)}; the drawing has "
                f"{', '.join(layers)}"
            )
    colours = sorted({c.colour for c in drawing.contours if c.colour})
    return (
        f"{where} {selects} nothing ({s.describe()}): the drawing has layers "
        f"{', '.join(layers)}" + (f" and colours {', '.join(colours)}" if colours else "")
    )


def construction_notes(contours: Sequence[Contour]) -> list[str]:
    """One line per kind of construction left uncut, with counts and a first place."""
    groups: Counter[tuple[str, str]] = Counter()
    first: dict[tuple[str, str], Contour] = {}
    for c in contours:
        key = (c.layer, c.linetype)
        groups[key] += 1
        first.setdefault(key, c)
    out = []
    for (layer, linetype), count in sorted(groups.items()):
        c = first[(layer, linetype)]
        what = line_kind(linetype)
        where = f"{c.source} at ({c.start[0]:.4f}, {c.start[1]:.4f}) mm"
        out.append(
            f"not cut: {count} contour(s) on layer {layer!r} ({what}: construction, not the "
            f"part; first {where}); an operation that names the layer cuts them "
            f"(post --layers {shlex.quote(layer)}, or a job operation that selects it)"
        )
    return out
