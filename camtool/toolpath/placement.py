"""Work coordinates and placement: where a program's X0 Y0 lies and whether it fits a machine.

Design notes: docs/internals.md, ``camtool/toolpath/placement.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from camtool.model.errors import DialectError, TooLargeError
from camtool.model.plain import slot_setters
from camtool.model.program import (
    ArcMove,
    Command,
    DrillCycle,
    Linear,
    Move,
    Program,
    Rapid,
    segment_of,
)
from camtool.model.shapes import BBox, Point, bbox_union
from camtool.model.units import fmt_num
from camtool.toolpath.options import PLACEMENTS

if TYPE_CHECKING:
    from camtool.model.machine import Machine

EPS_MM = 1e-6
"""Positions closer than this to a limit or to the work zero count as on it, mm (1 nm:
below every machine's step, above the rounding noise of the offset stages)."""


def toolpath_extent(program: Program) -> BBox | None:
    """XY extent of the toolpath: the cuts and the travel between and after them, mm.

    The travel before the first cut (the rapids from :attr:`Program.origin`, where the
    machine stands before the program, and the Z moves there) is left out: it says
    where the machine starts, not where the part is. The first cut's start is in.
    Arcs count by their extremes. A program without cuts: the ends of its rapids
    but those that stay at the start position.

    Returns:
        ``(xmin, ymin, xmax, ymax)``, mm; ``None`` for a program with nothing to place.
    """
    return _extent(program)


def _extent(program: Program) -> BBox | None:
    """:func:`toolpath_extent` computed afresh."""
    moves = program.moves
    first = next((i for i, m in enumerate(moves) if not isinstance(m, Rapid)), None)
    if first is None:
        ends = [(m.x, m.y) for m in moves[_at_start(program) :]]
        return bbox_union([(x, y, x, y) for x, y in ends]) if ends else None
    start = program.origin if first == 0 else (moves[first - 1].x, moves[first - 1].y)
    tail = moves[first:]
    box = _extent_of_ends(start, tail, zero_sides=True)
    return box if box is not None else _union_of_boxes(start, tail)


def _union_of_boxes(start: Point, moves: Sequence[Move]) -> BBox:
    """The union of every move's :meth:`~camtool.model.shapes.Arc.bbox` (or Line's), in order."""
    boxes = []
    for move in moves:
        boxes.append(segment_of(start, move).bbox())
        start = (move.x, move.y)
    return bbox_union(boxes)


def _extent_of_ends(
    start: Point, moves: Sequence[Move], *, zero_sides: bool = False
) -> BBox | None:
    """:func:`_union_of_boxes`'s box, skipping the arcs that cannot widen it; ``None``: not sure.

    The box of the end points comes first. An arc whose four circle extremes (the very floats
    :meth:`Arc.bbox` would add: ``c + r·cos(kπ/2)``, ``c + r·sin(kπ/2)``) all lie strictly
    inside it adds no value that could be a minimum or a maximum, so its box is not needed;
    the others' boxes are computed as before. The union of a set of floats is the same in any
    order but for the sign of a zero and NaN (``min`` keeps the first of equals), so a box
    with a non-finite side is left to the union (``None``), and so is one with a zero
    side unless ``zero_sides``.

    ``zero_sides`` (what :func:`toolpath_extent` uses: ``--origin lower-left`` puts the
    lower-left corner at exactly 0): a zero side is kept when no value that could be it is
    ``-0.0``. The union's values are the end points (all in the end-point box's lists),
    the boxes of the arcs kept here (the same boxes) and extremes of the skipped arcs, which
    lie strictly inside and so are no side. When none of the first two is ``-0.0``, every
    zero among them is ``+0.0`` and both unions give ``+0.0`` in any order.
    """
    xs = [start[0], *(m.x for m in moves)]
    ys = [start[1], *(m.y for m in moves)]
    if not all(map(math.isfinite, xs)) or not all(map(math.isfinite, ys)):
        return None
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    boxes = [(x0, y0, x1, y1)]
    hx, hy = start
    for move in moves:
        if type(move) is ArcMove:
            cx, cy = move.cx, move.cy
            r = math.hypot(hx - cx, hy - cy)  # Arc.radius
            # The four extremes strictly inside, each the float Arc.bbox computes: c + r·q
            # for its quadrants' cosines (sines for y) 1, 6e-17, -1, -2e-16 lie within the
            # floats c - r and c + r (rounding keeps order; r ≥ 0), and those two are
            # among them: they decide.
            if not (x0 < cx - r and cx + r < x1 and y0 < cy - r and cy + r < y1):
                boxes.append(segment_of((hx, hy), move).bbox())
        hx, hy = move.x, move.y
    box = bbox_union(boxes)
    if not all(map(math.isfinite, box)):
        return None
    if 0.0 in box:
        if not zero_sides:
            return None
        values = (*xs, *ys, *(v for b in boxes[1:] for v in b))
        if any(v == 0.0 and math.copysign(1.0, v) < 0.0 for v in values):
            return None  # a -0.0 takes part: its place in the order decides
    return box


def placement_shift(program: Program, placement: str, translate: Point) -> Point:
    """The shift ``(dx, dy)`` (mm) that ``--origin placement`` then ``--translate`` ask for.

    ``drawing`` keeps the coordinates; ``lower-left``/``center`` put X0 Y0 at the
    lower-left corner / the centre of :func:`toolpath_extent` (tool radius, lead-ins
    and tabs included). ``translate`` is added after.

    Raises:
        ValueError: ``placement`` is not one of
            :data:`~camtool.toolpath.options.PLACEMENTS`.
    """
    if placement not in PLACEMENTS:
        raise ValueError(f"unknown placement {placement!r}")
    box = None if placement == "drawing" else toolpath_extent(program)  # drawing: not needed
    if box is None:
        ref = (0.0, 0.0)
    elif placement == "lower-left":
        ref = (box[0], box[1])
    else:  # center
        ref = ((box[0] + box[2]) / 2.0, (box[1] + box[3]) / 2.0)
    return (translate[0] - ref[0], translate[1] - ref[1])


def shift_program(program: Program, dx: float, dy: float) -> Program:
    """``program`` moved by ``(dx, dy)`` mm: move ends and arc centres.

    The start position (:attr:`Program.origin`) stays where the machine stands, and so
    do the leading rapids that do not leave it (a lift to clearance height before any
    travel): moving them would drag the tool sideways from wherever it stands. When
    the path itself began at the start position (a cut from there), one rapid to its
    new start is put before it, at the height the tool is at. Commands keep their
    place (those before the first shifted move stay before that rapid); a drilling
    cycle's hole moves with its moves.
    """
    if dx == 0.0 and dy == 0.0:
        return program
    moves = list(program.moves)
    commands, lines = shift_moves(moves, program.origin, program.commands, program.lines, dx, dy)
    return dataclasses.replace(program, moves=tuple(moves), commands=commands, lines=lines)


def shift_moves(
    moves: list[Move],
    origin: Point,
    commands: tuple[tuple[int, Command], ...],
    lines: Sequence[int],
    dx: float,
    dy: float,
) -> tuple[tuple[tuple[int, Command], ...], Sequence[int]]:
    """:func:`shift_program` of a program's ``moves``, in the list itself; its commands and lines.

    Each move is replaced by its shifted copy in turn, so a caller that holds the moves
    in this list alone lets each old one go as its copy is made: the moves are never
    there twice.

    Args:
        moves: the program's moves, shifted in place (a rapid may be inserted).
        origin: :attr:`Program.origin`, mm.
        commands: :attr:`Program.commands`.
        lines: :attr:`Program.lines` (source lines, one per move, or empty).
        dx: shift along X, mm.
        dy: shift along Y, mm.

    Returns:
        The commands and lines that go with the shifted moves.
    """
    if dx == 0.0 and dy == 0.0:
        return commands, lines
    k = _lifts_at(moves, origin)
    for i in range(k, len(moves)):
        moves[i] = _shifted(moves[i], dx, dy)
    commands = tuple(
        (i, dataclasses.replace(c, x=c.x + dx, y=c.y + dy) if isinstance(c, DrillCycle) else c)
        for i, c in commands
    )
    if k < len(moves) and not isinstance(moves[k], Rapid):
        x, y = origin
        moves.insert(k, Rapid(x + dx, y + dy, contour=moves[k].contour))
        commands = tuple((i + (i > k), c) for i, c in commands)
        if lines:
            lines = (*lines[:k], lines[k], *lines[k:])
    return commands, lines


def _at_start(program: Program) -> int:
    """How many leading moves are Z-only rapids at the start position (lifts).

    An XY rapid (``z`` None) to the start position is positioning, not a lift: it moves
    with the program.
    """
    return _lifts_at(program.moves, program.origin)


def _lifts_at(moves: Sequence[Move], origin: Point) -> int:
    """:func:`_at_start` of the moves ``moves`` from ``origin``."""
    ox, oy = origin
    k = 0
    for move in moves:
        lift = isinstance(move, Rapid) and move.z is not None
        if not (lift and move.x == ox and move.y == oy):
            break
        k += 1
    return k


_SLOTTED = {
    cls: tuple(zip(cls.__dataclass_fields__, setters, strict=True))
    for cls in (Rapid, Linear, ArcMove)
    if (setters := slot_setters(cls))
}
"""Move classes :func:`_shifted` may build field by field: each field's name and setter."""
_new = object.__new__


def _shifted(move: Move, dx: float, dy: float) -> Move:
    """``move`` moved by ``(dx, dy)``: :func:`_shifted_replaced`'s object, field by field.

    A plain slotted move (:func:`~camtool.model.plain.slot_setters`) is copied field by
    field, with ``x``, ``y`` (and an arc's ``cx``, ``cy``) shifted: the fields
    ``dataclasses.replace`` gives, so equal, with the same hash, ``repr`` and pickle.
    Anything else goes through :func:`_shifted_replaced`.
    """
    spec = _SLOTTED.get(type(move))
    if spec is None:
        return _shifted_replaced(move, dx, dy)
    new = _new(type(move))
    for name, put in spec:
        value = getattr(move, name)
        if name == "x" or name == "cx":
            value += dx
        elif name == "y" or name == "cy":
            value += dy
        put(new, value)
    return new


def _shifted_replaced(move: Move, dx: float, dy: float) -> Move:
    """``move`` moved by ``(dx, dy)`` through ``dataclasses.replace`` (any move)."""
    if isinstance(move, Rapid):
        return dataclasses.replace(move, x=move.x + dx, y=move.y + dy)
    if isinstance(move, ArcMove):
        return dataclasses.replace(
            move, x=move.x + dx, y=move.y + dy, cx=move.cx + dx, cy=move.cy + dy
        )
    return dataclasses.replace(move, x=move.x + dx, y=move.y + dy)


@dataclass(frozen=True)
class Placing:
    """How the program was placed, so that a remedy can be printed that works as written.

    Attributes:
        placement: the ``--origin`` used.
        translate: the ``--translate`` used, mm.
        margin_mm: ``(w, h)`` by which the toolpath's extent is larger than the
            drawing's (twice the tool radius plus the lead arcs for an outside
            profile; negative inside), mm: ``--fit`` scales the drawing, so the
            travel less this margin is what the drawing may measure.
    """

    placement: str = "drawing"
    translate: Point = (0.0, 0.0)
    margin_mm: Point = (0.0, 0.0)


def check_travel(
    program: Program,
    machine: Machine,
    placing: Placing | None = None,
    *,
    planned: bool | None = None,
) -> tuple[str, ...]:
    """Refuse a program ``machine`` cannot run; warn where its work zero needs care.

    Work coordinates (``machine.coordinates == "work"``): the toolpath
    (:func:`toolpath_extent`) must be no larger than the travel; where it lies is the
    operator's choice of work zero. A warning when it lies on both sides of the work
    zero on an axis (the tool goes below X0 or Y0: zero must be set that far inside
    the travel) unless ``--origin``/``--translate`` placed it there or the code came
    from elsewhere (``placing`` None), or when the work zero and the far side of the
    toolpath are further apart than the travel (a zero set by touching the work cannot
    be used).

    Machine coordinates: every position must lie inside ``work_area_mm``.

    Args:
        program: the program, mm.
        machine: the machine profile.
        placing: how the program was placed (``None``: not planned here, a program
            read from code); the remedy names options that work as written.
        planned: whether ``--origin`` can move the program (it was planned from a
            drawing), for a warning's remedy; ``None``: when ``placing`` is given. A
            writer passes it, holding a planned program without its placing.

    Returns:
        Warnings for the user (empty when nothing needs care).

    Raises:
        DialectError: the toolpath is larger than the travel, or (machine
            coordinates) reaches outside the work area; the message gives both sizes
            and a remedy.
    """
    return check_extent(toolpath_extent(program), machine, placing, planned=planned)


def check_z_travel(program: Program, machine: Machine, *, reposted: bool = False) -> None:
    """Refuse a program whose Z spans more than the machine's Z travel (when it is known).

    The span is from the highest Z a move goes to (the clearance height) to the lowest
    (the deepest cut), mm: wherever the operator sets Z0, the machine must reach both.
    A profile without ``z_travel_mm`` (0) is not checked. ``reposted``: the program is
    G-code another program wrote (its heights are changed there, not by options).

    Raises:
        DialectError: naming the span, both heights, the Z travel and what to change.
    """
    travel = machine.z_travel_mm
    if travel <= 0 or not machine.has_z:
        return
    zs = [m.z for m in program.moves if m.z is not None]
    if not zs:
        return
    top, bottom = max(zs), min(zs)
    if top - bottom <= travel + EPS_MM:
        return
    where = (
        "in the program that wrote it"
        if reposted
        else "(--depth, --clearance-z, or the job file's)"
    )
    raise DialectError(
        f"the program's Z spans {_mm(top - bottom)} mm (from Z{_num(top)} to Z{_num(bottom)} "
        f"mm), more than the {_mm(travel)} mm Z travel of {machine.name}: no work zero lets "
        f"the machine reach both; check the depth and the clearance height {where}, or give "
        "the machine's own z_travel_mm (--machine FILE.toml)"
    )


def check_extent(
    box: BBox | None, machine: Machine, placing: Placing | None, *, planned: bool | None = None
) -> tuple[str, ...]:
    """:func:`check_travel` of a program whose :func:`toolpath_extent` is ``box``.

    For a caller that has the box already (one walk of the moves, not one per check).

    Raises:
        DialectError: as :func:`check_travel`.
    """
    if box is None:
        return ()
    too_large(box, machine, placing)
    if machine.coordinates == "machine":
        if machine.outside_work_area(box, EPS_MM):
            raise DialectError(
                f"the toolpath spans {_span(box)} mm, {outside_text(machine)}; "
                f"{place_remedy(box, machine, placing)}"
            )
        return ()
    # work zero as drawn is worth a word; one the user placed (--origin, --translate) or
    # one another program chose (code read back, placing None) is what was asked for
    chosen = placing is None or placing.placement != "drawing" or placing.translate != (0.0, 0.0)
    planned = placing is not None if planned is None else planned
    return _zero_warnings(box, machine, chosen=chosen, planned=planned)


def larger_than_travel(box: BBox, machine: Machine) -> bool:
    """Whether a toolpath extent ``box`` is larger than the travel of ``machine`` (mm).

    The test of :func:`too_large`; only then is :attr:`Placing.margin_mm` read.
    """
    tw, th = machine.travel_mm
    return not (box[2] - box[0] <= tw + EPS_MM and box[3] - box[1] <= th + EPS_MM)


def too_large(box: BBox, machine: Machine, placing: Placing | None) -> None:
    """Refuse a toolpath extent ``box`` larger than the travel of ``machine``.

    Raises:
        TooLargeError: naming both sizes, ``--fit W H`` that makes it fit (when the
            program was planned here) and a larger machine.
    """
    if not larger_than_travel(box, machine):
        return
    w, h = box[2] - box[0], box[3] - box[1]
    tw, th = machine.travel_mm
    fit = _fit_remedy(machine, placing, w, h)
    raise TooLargeError(
        f"the toolpath is {_mm(w)} × {_mm(h)} mm, larger than the {_mm(tw)} × {_mm(th)} mm "
        f"travel of {machine.name}; {fit}use a larger machine (--machine FILE.toml "
        "with its work_area_mm)"
    )


def too_large_drawing(
    box: BBox, machine: Machine, placing: Placing, *, scale: float = 1.0, slack_mm: float = 0.0
) -> None:
    """Refuse, before planning, a drawing whose toolpath would be larger than the travel.

    For a caller that knows the toolpath will pass within ``slack_mm`` of every point of
    the drawing as planning scales it (every contour cut on its line or enclosed by a cut
    outside it; ``slack_mm`` covers the chaining and arc-fitting tolerances): then a
    drawing more than ``2 · slack_mm`` larger than the travel on an axis gives a toolpath
    :func:`too_large` refuses after planning, and it is refused here instead, before
    the curves are fitted and the contours planned (Inkscape's ``filters.svg`` without
    ``--fit``: 65 s to the same refusal).

    Args:
        box: a box within the drawing's extent, mm as drawn (before ``scale``).
        machine: the machine profile.
        placing: how the program will be placed, for the ``--fit`` remedy (its margin:
            what the toolpath adds to the drawing, tool and lead arcs).
        scale: the scale planning applies (``--scale``).
        slack_mm: how far inside the drawing's points the toolpath may pass, mm.

    Raises:
        TooLargeError: naming the drawing's size (at least), the travel, ``--fit W H``
            that makes it fit and a larger machine.
    """
    w, h = (box[2] - box[0]) * scale, (box[3] - box[1]) * scale
    inner = (0.0, 0.0, max(w - 2.0 * slack_mm, 0.0), max(h - 2.0 * slack_mm, 0.0))
    if not larger_than_travel(inner, machine):
        return
    tw, th = machine.travel_mm
    fit = _fit_remedy(machine, placing, w, h)
    scaled = f" at --scale {_num(scale)}" if scale != 1.0 else ""
    raise TooLargeError(
        f"the drawing is at least {_mm(w)} × {_mm(h)} mm{scaled}, so its toolpath is larger "
        f"than the {_mm(tw)} × {_mm(th)} mm travel of {machine.name} (refused before "
        f"planning); {fit}use a larger machine (--machine FILE.toml with its work_area_mm)"
    )


def outside_text(machine: Machine) -> str:
    """``outside the work area X a…b, Y c…d mm of NAME, which …`` for messages."""
    x0, y0, x1, y1 = machine.work_area_mm
    return (
        f"outside the work area X {_mm(x0)}…{_mm(x1)}, Y {_mm(y0)}…{_mm(y1)} mm of "
        f"{machine.name}, which runs programs in machine coordinates (from its home)"
    )


def place_remedy(box: BBox, machine: Machine, placing: Placing | None) -> str:
    """How to bring a toolpath of extent ``box`` (no larger than the travel) inside the area.

    ``--origin lower-left`` (with ``--translate`` to the area's corner when it is not
    at 0, 0 or a translation was given) and ``--translate DX DY`` with the numbers (the
    one given plus the shift), both complete option values that replace those given.
    For code read back (``placing`` is ``None``) the shift is said as such.
    """
    x0, y0, _, _ = machine.work_area_mm
    lower_left = "--origin lower-left"
    used = placing.translate if placing is not None else (0.0, 0.0)
    if (x0, y0) != (0.0, 0.0) or used != (0.0, 0.0):
        lower_left += f" --translate {_num(x0)} {_num(y0)}"
    move = _inside_shift(box, machine)
    if placing is None:  # read from code: the options it was posted with are not known
        text = f"post it again with {lower_left}"
        if move is not None:
            text += f", or with its --translate moved by {_num(move[0])} {_num(move[1])} mm"
        return text
    text = f"place it with {lower_left}"
    if move is not None:
        tx, ty = used[0] + move[0], used[1] + move[1]
        text += f", or move it with --translate {_num(tx)} {_num(ty)}"
    return text


def moved_remedy(box: BBox, machine: Machine) -> str:
    """How to bring a re-posted program of extent ``box`` inside the area.

    camtool does not move one (``--origin`` and ``--translate`` are for drawings): the
    program that wrote it does, by the shift :func:`place_remedy` would give.
    """
    move = _inside_shift(box, machine)
    by = f" by X{_num(move[0])} Y{_num(move[1])} mm" if move is not None else ""
    return (
        f"move the program{by} in the program that wrote it (its work zero), then post it "
        "again: camtool re-posts a program where it is"
    )


def _inside_shift(box: BBox, machine: Machine) -> Point | None:
    """A shift that brings ``box`` inside the work area, or ``None`` if none prints exactly.

    Each axis moves by the least whole µm that brings it inside (within
    :data:`EPS_MM`), so that the printed number still does.
    """
    shift = []
    for lo, hi, a0, a1 in (
        (box[0], box[2], machine.work_area_mm[0], machine.work_area_mm[2]),
        (box[1], box[3], machine.work_area_mm[1], machine.work_area_mm[3]),
    ):
        if lo < a0:
            d = math.ceil((a0 - lo - EPS_MM / 2) * 1000.0) / 1000.0
        elif hi > a1:
            d = -math.ceil((hi - a1 - EPS_MM / 2) * 1000.0) / 1000.0
        else:
            d = 0.0
        if lo + d < a0 - EPS_MM or hi + d > a1 + EPS_MM:
            return None
        shift.append(d)
    return (shift[0], shift[1])


def _fit_remedy(machine: Machine, placing: Placing | None, w: float, h: float) -> str:
    """``scale it with --fit W H …, or `` when a planned drawing can be scaled to fit."""
    if placing is None:
        return ""
    tw, th = machine.travel_mm
    mx, my = placing.margin_mm
    fw, fh = (math.floor((t - m) * 100.0 - 1.0) / 100.0 for t, m in ((tw, mx), (th, my)))
    if fw <= 0 or fh <= 0:
        return ""
    text = f"scale it with --fit {_num(fw)} {_num(fh)}"
    if machine.coordinates == "machine":
        x0, y0, _, _ = machine.work_area_mm
        text += f" --origin lower-left --translate {_num(x0)} {_num(y0)}"
    elif placing.placement == "drawing":  # --fit keeps the lower-left corner where it was
        text += " --origin lower-left"
    return text + " or "


def _zero_warnings(
    box: BBox, machine: Machine, *, chosen: bool, planned: bool = True
) -> tuple[str, ...]:
    """The work-coordinate warnings of :func:`check_travel` (one message).

    ``chosen``: the user placed work zero (``--origin center``, ``--translate``), so a
    toolpath on both sides of it is what was asked for: no warning for that.
    ``planned``: the program was planned here, so ``--origin`` can move it (code read
    back, another program's G-code above all, is moved where it was written).
    """
    across = [
        (axis, lo, hi)
        for axis, lo, hi in (("X", box[0], box[2]), ("Y", box[1], box[3]))
        if lo < -EPS_MM and hi > EPS_MM
    ]
    far = [
        (axis, lo, hi, t)
        for (axis, lo, hi), t in zip(
            (("X", box[0], box[2]), ("Y", box[1], box[3])), machine.travel_mm, strict=True
        )
        if max(hi, 0.0) - min(lo, 0.0) > t + EPS_MM
    ]
    tw, th = machine.travel_mm
    if far:
        axis, lo, hi, t = far[0]
        return (
            f"the toolpath spans {axis} {_mm(lo)}…{_mm(hi)} mm, so work zero (X0 Y0) lies "
            f"{_mm(max(hi, 0.0) - min(lo, 0.0))} mm from its far side, more than the "
            f"{_mm(t)} mm {axis} travel of {machine.name}: work zero cannot be a point the "
            "tool reaches; "
            + (
                "use --origin lower-left or set it with an offset"
                if planned
                else "set it with an offset from a point the tool reaches, or move the "
                "program in the program that wrote it"
            ),
        )
    if across and not chosen:
        spans = ", ".join(f"{axis} {_mm(lo)}…{_mm(hi)}" for axis, lo, hi in across)
        return (
            f"the toolpath spans {spans} mm, on both sides of work zero (X0 Y0): set work "
            f"zero so that this fits the {_mm(tw)} × {_mm(th)} mm travel of {machine.name}, "
            "or use --origin lower-left",
        )
    return ()


def _span(box: BBox) -> str:
    return f"X {_mm(box[0])}…{_mm(box[2])}, Y {_mm(box[1])}…{_mm(box[3])}"


def _mm(value: float, decimals: int = 3) -> str:
    """A length for messages: at most ``decimals`` decimals, no trailing zeros, never ``-0``."""
    text = fmt_num(value, decimals)
    return text.rstrip("0").rstrip(".") if "." in text else text


def _num(value: float) -> str:
    """An option value for a remedy: within 1 nm of ``value`` (6 decimals, no ``-0``)."""
    return _mm(value, 6)
