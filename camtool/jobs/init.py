"""``camtool job init``: a first job for a drawing, with the guesses a machinist would make.

One operation per layer (per colour when the drawing has one layer drawn in several
colours), each with a comment saying why:

Design notes: docs/internals.md, ``camtool/jobs/init.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

from camtool.geometry.chain import chain_members, joint_distance
from camtool.jobs.init_holes import around_note, around_smaller, hole_sizes, smallest_at
from camtool.jobs.init_mills import END_MILLS_MM, Parts, mill_between, mill_that_fits
from camtool.jobs.init_mills import why as _why
from camtool.jobs.job import MAX_TOOLS, Selection
from camtool.jobs.selection import circle_of, construction_reason
from camtool.jobs.travel import refuse_small_box
from camtool.model.construction import fit_extent, is_construction
from camtool.model.errors import InputError
from camtool.model.shapes import Contour, Drawing, distance, fit_factor
from camtool.model.units import fmt_num
from camtool.toolpath.chain import GAP_SHARE, as_cut
from camtool.toolpath.cuts import where
from camtool.toolpath.gaps import option_value
from camtool.toolpath.options import DEFAULT_CHAIN_TOLERANCE, DEFAULT_CLOSE_GAP, PlanOptions
from camtool.toolpath.placement import EPS_MM

DRILL_MAX_MM = 6.5
"""Largest circle drilled (ø6.5 mm: an M6 clearance hole); larger ones are profiled."""

BREAKTHROUGH_MM = 0.5
"""How far a through cut goes below the stock (into the spoil board)."""

NEAR_CLOSED_MM = 0.5
"""An open outline whose own ends lie at most this far apart (mm), and under
:data:`NEAR_CLOSED_SHARE` of its length, is one the drawing meant closed: ``job init``
sets ``close_gap`` to close it (boxes.py leaves a part's last corner, 0.14 mm, undrawn)."""

NEAR_CLOSED_SHARE = 0.01
"""See :data:`NEAR_CLOSED_MM`: a larger gap for its length is drawn open on purpose."""


@dataclass
class _Group:
    """The contours of one layer (or colour) and what they are."""

    key: str
    by: str  # "layers" or "colours"
    contours: list[Contour] = field(default_factory=list)
    close_gap: float = DEFAULT_CLOSE_GAP  # mm: the job's ``close_gap``
    joined: list[Contour] | None = None  # :func:`_joined`
    chained: list[Contour] | None = None  # :func:`_chains`


@dataclass(frozen=True)
class _Op:
    kind: str
    tool: float  # diameter, mm; a drill's is its hole's
    lines: tuple[str, ...]
    commented: bool = False
    unfit: str = ""  # why no common end mill fits its contours (it stays commented out)


def initial_job(
    drawing: Drawing,
    *,
    thickness_mm: float = 3.0,
    tool_diameter: float = 3.0,
    source: str = "",
    travel_mm: tuple[float, float] | None = None,
    no_z: str = "",
) -> str:
    """A job file (TOML text, comments included) for ``drawing``.

    Args:
        drawing: the imported drawing, mm.
        thickness_mm: the stock's thickness: profiles cut through it (plus
            :data:`BREAKTHROUGH_MM`), pockets go half way.
        tool_diameter: the end mill's diameter, mm.
        source: the drawing's name for the header comment.
        travel_mm: the target machine's travel ``(x, y)``; a drawing (with the tool
            around it) larger than it gets a ``fit`` that scales it down, said in a
            comment (``None``: no machine in view).
        no_z: the target machine's name when it has no programmable Z (its depth is set
            by hand): then no heights, depths, passes or tabs, and no drilling (a hole
            is profiled on its inside).

    Raises:
        InputError: nothing to cut, cuts too small for any tool (a unit set wrong:
            :func:`~camtool.jobs.travel.refuse_small_box`), or the tool is as wide as the
            machine's travel.
    """
    defaults = PlanOptions()  # a unit set wrong: the job's post would refuse it
    refuse_small_box(drawing.contours, defaults.tolerance, defaults.chain_tolerance, drawing.source)
    fit, k = _fit(drawing, tool_diameter, travel_mm)
    if fit:  # sizes as cut (drills, tabs), selections in the drawing's own mm
        drawing = drawing.transformed(k)
    groups = _groups(drawing)
    close_gap, gap = _close_gap(groups)
    for group in groups:
        group.close_gap = close_gap
    outer = _outermost([(group, c) for group in groups for c in _chains(group)])
    parts = Parts([c for group in groups for c in _chains(group) if id(c) in outer[0]])
    circles = (circle_of(c) for group in groups for c in _chains(group))
    smallest = smallest_at(c for c in circles if c is not None)
    ops: list[_Op] = []
    left: Counter[str] = Counter()
    cut: list[tuple[_Group, list[_Op]]] = []
    for group in groups:
        made = _ops_of(
            group, (*outer, parts), thickness_mm, tool_diameter, left, k, smallest, drill=not no_z
        )
        ops.extend(_repeated(group, made, cut))
        cut.append((group, made))
    if all(op.kind == "engrave" for op in ops):
        # lines only, no part outline: a drawing to engrave (a sign, a symbol)
        ops = [dataclasses.replace(op, commented=False, lines=_engraved(op)) for op in ops]
    if no_z:
        ops = [dataclasses.replace(op, lines=_flat(op.lines)) for op in ops]
    else:
        ops.extend(_marks(drawing, thickness_mm))
    if not any(not op.commented for op in ops):
        raise InputError(_nothing_to_cut(drawing, left, ops))
    return _render(
        ops, left, thickness_mm, tool_diameter, source or drawing.source, (*fit, *gap), no_z
    )


def _nothing_to_cut(drawing: Drawing, left: Counter[str], ops: Sequence[_Op]) -> str:
    """Why ``job init`` writes no job: no tool fits, every contour is construction, or none is."""
    about = f"{drawing.source or 'the drawing'}: nothing to cut"
    unfit = [f"{op.lines[3]}: {op.unfit}" for op in ops if op.unfit]  # by its selection line
    if unfit:
        return (
            f"{about} with a common end mill (the smallest {min(END_MILLS_MM):g} mm): "
            f"{'; '.join(unfit)}; write a job naming a tool that fits (docs/jobs.md)"
        )
    if left:
        return (
            f"{about}: every contour is construction "
            f"({'; '.join(f'{w}: {n}' for w, n in sorted(left.items()))}); name its layer in "
            "an operation of a job written by hand to cut it"
        )
    n = len(drawing.marks)
    if not n:
        return f"{about}: the drawing has no contour"
    layers = sorted({m.layer for m in drawing.marks}, key=str.casefold)
    on = f"layer{'s' if len(layers) > 1 else ''} {', '.join(repr(x) for x in layers)}"
    return (
        f"{about}: the drawing has no contour, only {n} point{'s' if n > 1 else ''} (on {on}); "
        "a drill operation of a job written by hand drills points (docs/jobs.md)"
    )


_Z_KEYS = ("depth =", "step_down =", "tabs =", "tab_height =", "# no tabs:")
"""The lines of an operation a machine without programmable Z has no use for."""


def _flat(lines: tuple[str, ...]) -> tuple[str, ...]:
    """An operation's lines without heights, depths, passes and tabs (no programmable Z)."""
    return tuple(line for line in lines if not line.startswith(_Z_KEYS))


def _fit(
    drawing: Drawing, tool: float, travel: tuple[float, float] | None
) -> tuple[tuple[str, ...], float]:
    """The ``fit = [w, h]`` lines and the scale they give (``()`` and 1: no fit needed).

    A fit when the drawing's outside profile (the tool's radius around it) is larger than
    the machine's travel; construction (a sheet's border drawn as a guide, centre lines)
    is not cut, so it does not count, as ``post``'s travel check does not count it.
    """
    cut = any(not is_construction(c) for c in drawing.contours)
    if travel is None or not (cut or drawing.marks):
        return (), 1.0
    # as post fits it: construction aside, and the points (their drill is commented out)
    x0, y0, x1, y1 = box = fit_extent(drawing, marks=False)
    w, h = travel
    if x1 - x0 + tool <= w + EPS_MM and y1 - y0 + tool <= h + EPS_MM:
        return (), 1.0  # its outside profile's toolpath fits the travel as it is (as post checks)
    fw, fh = _fit_box(tool, travel)
    k = fit_factor(box, (fw, fh))
    return (
        f"fit = [{fw:g}, {fh:g}]"
        + _why(
            f"the drawing is {x1 - x0:.4g} × {y1 - y0:.4g} mm; with the {tool:g} mm tool "
            f"around it, larger than the {w:g} × {h:g} mm travel: SCALED DOWN to {k:.3g}×; "
            "remove this line on a larger machine"
        ),
    ), k


def _fit_box(tool: float, travel: tuple[float, float]) -> tuple[float, float]:
    """The box a drawing must fit for its outside profile to fit ``travel`` (mm).

    The profile's tool centre runs a tool radius outside the drawing on each side, so
    the drawing may take the travel less the tool's diameter, less 0.01 mm (as ``post``
    proposes for a toolpath larger than the travel).

    Raises:
        InputError: the tool is as wide as the travel: nothing fits.
    """
    fw, fh = (math.floor((t - tool) * 100.0 - 1.0) / 100.0 for t in travel)
    if fw <= 0 or fh <= 0:
        raise InputError(
            f"the {tool:g} mm tool is as wide as the machine's {travel[0]:g} × {travel[1]:g} mm "
            "travel: give the end mill you will use with --tool-diameter"
        )
    return fw, fh


def _engraved(op: _Op) -> tuple[str, ...]:
    """An engrave operation's lines for a drawing that has nothing but open lines."""
    first = op.lines[0].split("  # ")[0]
    return (first + _why("the drawing is lines only: engraved on their paths"), *op.lines[1:])


def _groups(drawing: Drawing) -> list[_Group]:
    layers = sorted({c.layer for c in drawing.contours}, key=str.casefold)
    colours = sorted({c.colour for c in drawing.contours if c.colour})
    # by colour only when every contour has one: a job selects no contour by "no colour"
    coloured = all(c.colour for c in drawing.contours)
    if len(layers) == 1 and len(colours) > 1 and coloured:
        groups = {c: _Group(c, "colours") for c in colours}
        for contour in drawing.contours:
            groups.setdefault(contour.colour, _Group(contour.colour, "colours"))
            groups[contour.colour].contours.append(contour)
        return list(groups.values())
    by_layer = {name: _Group(name, "layers") for name in layers}
    for contour in drawing.contours:
        by_layer[contour.layer].contours.append(contour)
    return list(by_layer.values())


def _joined(group: _Group) -> list[Contour]:
    """The group's contours but construction, chained end to end (made once per group).

    At the job's default chain tolerance, as a job's selection chains them
    (:func:`camtool.jobs.selection.select`): an outline drawn as LINEs is one closed contour.
    """
    if group.joined is None:
        kept = [c for c in group.contours if not is_construction(c)]
        group.joined = chain_members(kept, joint_distance(DEFAULT_CHAIN_TOLERANCE))[0]
    return group.joined


def _chains(group: _Group) -> list[Contour]:
    """:func:`_joined`'s chains as the job cuts them (made once per group).

    As a job's selection judges them for ``closed``
    (:func:`~camtool.toolpath.chain.as_cut`): gaps up to the job's ``close_gap`` closed, a
    line drawn twice one open line.
    """
    if group.chained is None:
        joint = joint_distance(DEFAULT_CHAIN_TOLERANCE)
        group.chained = as_cut(_joined(group), group.close_gap, joint)[0]
    return group.chained


def _close_gap(groups: Sequence[_Group]) -> tuple[float, tuple[str, ...]]:
    """The job's ``close_gap`` (mm) and its ``[job]`` line (none for the default).

    An open chain whose own ends lie within :data:`NEAR_CLOSED_MM` and
    :data:`NEAR_CLOSED_SHARE` of its length was meant closed. ``close_gap`` closes every
    open chain whose gap is within it and under :data:`~camtool.toolpath.chain.GAP_SHARE`
    of its length, so it is set just above the largest such gap only while no chain
    drawn open on purpose (a larger gap for its length) is within it; a value the default
    (:data:`~camtool.toolpath.options.DEFAULT_CLOSE_GAP`) covers needs no line.
    """
    joint = joint_distance(DEFAULT_CHAIN_TOLERANCE)
    meant: list[tuple[float, Contour]] = []
    limit = math.inf  # the least gap of a chain drawn open that close_gaps would close
    for group in groups:
        for chain in _joined(group):
            gap = distance(chain.end, chain.start)
            if chain.closed or gap <= joint or gap >= GAP_SHARE * chain.length:
                continue  # closed, or left open by close_gaps whatever the value
            if gap <= NEAR_CLOSED_MM and gap < NEAR_CLOSED_SHARE * chain.length:
                meant.append((gap, chain))
            else:
                limit = min(limit, gap)
    meant.sort(key=lambda t: t[0])
    value, taken = "", 0
    for gap, _ in meant:
        if float(option_value(gap)) >= limit:
            break
        value, taken = option_value(gap), taken + 1
    if not value or float(value) <= DEFAULT_CLOSE_GAP:
        return DEFAULT_CLOSE_GAP, ()
    shut = meant[:taken]
    first = min((c for _, c in shut), key=lambda c: (c.start[1], c.start[0]))
    return float(value), (
        f"close_gap = {value}"
        + _why(
            f"{taken} outline(s) end up to {fmt_num(shut[-1][0], 4)} mm from their start "
            f"(first {where(first)}): closed with a straight line; 0 leaves them open, not cut"
        ),
    )


def _outermost(chains: Sequence[tuple[_Group, Contour]]) -> tuple[set[int], dict[int, str]]:
    """Which closed contours are parts, and which are holes of another group's parts.

    Returns the ids of the closed contours that lie inside no other closed contour, and,
    by id, the closed contours whose surrounding contours are all of other groups (holes on
    a layer of their own), each with the name (:func:`_what`) of the group around it.

    Inside as the planner nests them (:func:`~camtool.toolpath.order.nesting`), or across
    the edge: a contour that crosses a larger one's outline with more than
    :data:`CUTOUT_SHARE` of its area within it is a cutout of that part drawn across its
    edge (boxes.py's slots open at a part's edge poke 0.1 mm out of its outline, a notch
    in ``OttoBody.svg`` lies 63 % outside), not a part (shapely's intersection of the
    areas, :func:`~camtool.geometry.area.enclosed`).
    """
    from camtool.toolpath.order import nesting

    closed = [(g, c) for g, c in chains if c.closed and not c.linetype]
    if not closed:
        return set(), {}
    nest = nesting([c for _, c in closed])
    top = [i for i in range(len(closed)) if not nest.parents[i]]
    across = _across_an_edge([closed[i][1] for i in top])
    around = {i: tuple(nest.parents[i]) for i in range(len(closed))}
    around.update({top[k]: (top[j],) for k, j in across.items()})
    foreign = {
        id(c): _what(closed[parents[0]][0])
        for i, (g, c) in enumerate(closed)
        if (parents := around[i]) and all(closed[j][0] is not g for j in parents)
    }
    cutouts = {top[k] for k in across}
    return {id(closed[i][1]) for i in top if i not in cutouts}, foreign


CUTOUT_SHARE = 0.01
"""Share of a contour's area within a larger closed contour whose outline it crosses that
makes it a cutout of it (a slot or notch at the part's edge); less is a touch."""


def _across_an_edge(contours: Sequence[Contour]) -> dict[int, int]:
    """For each of ``contours`` (closed) that is a cutout of a larger one, its index, by index."""
    if len(contours) < 2:
        return {}
    import shapely

    from camtool.geometry.area import enclosed

    boxes = shapely.box(*zip(*(c.bbox() for c in contours), strict=True))
    a, b = shapely.STRtree(boxes).query(boxes, predicate="intersects")
    pairs = [(i, j) for i, j in zip(a.tolist(), b.tolist(), strict=True) if i != j]
    areas: dict[int, Any] = {}  # only of the contours whose boxes meet another's
    for k in sorted({k for pair in pairs for k in pair}):
        areas[k] = enclosed(contours[k].points(_AREA_TOLERANCE_MM))
    out: dict[int, int] = {}
    for i, j in pairs:
        small, large = areas[i], areas[j]
        inside = large.area > small.area > 0 and small.intersects(large)
        if inside and small.intersection(large).area > CUTOUT_SHARE * small.area:
            out.setdefault(i, j)
    return out


_AREA_TOLERANCE_MM = 0.01
"""Chord tolerance of the areas :func:`_across_an_edge` compares (mm)."""


def _ops_of(
    group: _Group,
    outer: tuple[set[int], dict[int, str], Parts],
    thickness: float,
    tool: float,
    left: Counter[str],
    k: float,
    smallest: dict[tuple[float, float], float],
    *,
    drill: bool = True,
) -> list[_Op]:
    """The operations of one layer (or colour); ``k``: the scale the job fits it by.

    ``outer``: the ids of the outermost closed contours, the holes of other groups' parts
    (:func:`_outermost`), and every group's parts (the outermost contours themselves).
    ``smallest``: the smallest circle about each centre of the drawing
    (:func:`.init_holes.smallest_at`).

    ``drill``: small circles are drilled (else profiled with the rest: no Z to drill by).
    """
    select = f"{group.by} = [{_quote(group.key)}]"
    what = _what(group)
    kept: list[Contour] = []
    for contour in group.contours:
        reason = construction_reason(contour, Selection())
        if reason is not None:
            left[f"{what}: {reason}"] += 1
            continue
        kept.append(contour)
    if not kept:
        return []
    out: list[_Op] = []
    drilled: list[tuple[float, bool]] = []  # each circle drilled: diameter, drawn around a smaller
    around: Counter[float] = Counter()  # profiled circles drawn around a smaller circle (0.0)
    profiled: list[Contour] = []
    opened: list[Contour] = []
    shaper = _shaper_cut(group.key)
    online = (
        shaper is not None and shaper[0] == "online"
    )  # cut on the line: engraved, closed or not
    # as chained, as the selection's closed and diameter read them: a circle drawn as two
    # ARCs is a circle, a square of four LINEs closed
    for contour in _chains(group):
        circle = circle_of(contour)
        if online:
            opened.append(contour)
        elif drill and circle is not None and 0.0 < round(circle[1], 3) <= DRILL_MAX_MM:
            drilled.append((circle[1], around_smaller(*circle, smallest)))
        elif contour.closed:
            profiled.append(contour)
            around[0.0] += circle is not None and around_smaller(*circle, smallest)
        else:
            opened.append(contour)
    sizes = hole_sizes(drilled)
    circles = {d: [diameter for diameter, _ in holes] for d, holes in sizes.items()}
    for d, exact in sorted(circles.items()):
        span = (_drawn(min(exact), k), _drawn(max(exact), k))
        inside = sum(drawn_around for _, drawn_around in sizes[d])
        out.append(_drill_op(select, what, d, span, thickness, len(exact), inside))
    if profiled:
        op = _profile_op(select, what, profiled, outer, thickness, tool, group.key)
        if around[0.0]:
            note = _why(around_note(around[0.0], "cut", "of its circles")).lstrip()
            op = dataclasses.replace(op, lines=(*op.lines, note))
        if circles:
            lo = _drawn(min(min(v) for v in circles.values()), k)
            hi = _drawn(max(max(v) for v in circles.values()), k)
            lo, hi = round(lo, 6), round(hi, 6)
            skip = f"except_diameter = [{lo!r}, {hi!r}]" + _why("not the drilled holes")
            op = dataclasses.replace(op, lines=(*op.lines[:4], skip, *op.lines[4:]))
        out.append(op)
    if opened:
        depth = shaper[1] if shaper else None
        out.append(_engrave_op(select, what, len(opened), closed_too=online, depth=depth))
    return out


def _repeated(group: _Group, made: list[_Op], cut: list[tuple[_Group, list[_Op]]]) -> list[_Op]:
    """``made``, commented out when each contour of ``group`` lies on an earlier group's path.

    A filled and outlined shape exported as a fill path and a stroke path (LibreOffice
    Draw and Impress) is one shape in two colours: the earlier group's operation of the
    same kind cuts it, and ``post`` would cut this one's copy once only
    (:func:`~camtool.toolpath.copies.drop_copies`).
    """
    from camtool.toolpath.copies import drop_copies

    kinds = {op.kind for op in made if not op.commented}
    earlier = [
        (_what(g), _chains(g))
        for g, ops in cut
        if kinds and kinds <= {op.kind for op in ops if not op.commented}
    ]
    chains = _chains(group)
    if not earlier or not chains or drop_copies(chains, cut_before=earlier)[0]:
        return made
    others = " and ".join(
        w
        for w, theirs in earlier
        if len(drop_copies(chains, cut_before=[(w, theirs)])[0]) < len(chains)
    )
    why = _why(
        f"each contour of {_what(group)} lies on one of {others} (a fill and its outline): "
        "cut there; not cut twice unless you uncomment this"
    )
    return [
        dataclasses.replace(
            op, commented=True, lines=(op.lines[0].split("  # ")[0] + why, *op.lines[1:])
        )
        for op in made
    ]


def _what(group: _Group) -> str:
    """How comments name a group: ``"layer 'OUTLINE'"``, ``"colour #ff0000"``."""
    return f"layer {group.key!r}" if group.by == "layers" else f"colour {group.key}"


def _drawn(d: float, k: float) -> float:
    """A diameter as cut (scaled by ``k``) back in the drawing's mm, as selections give it."""
    return d if k == 1.0 else round(d / k, 9)


def _drill_op(
    select: str,
    what: str,
    d: float,
    span: tuple[float, float],
    thickness: float,
    count: int,
    around: int = 0,
) -> _Op:
    """A drill per hole size: the circles whose diameter rounds to ``d`` (to 1 µm).

    ``around``: how many of them are drawn around a smaller circle (said in the comment).
    """
    depth = thickness + BREAKTHROUGH_MM
    lo, hi = round(span[0], 6), round(span[1], 6)  # selections match to 1e-6 of the value
    size = f"diameter = {lo!r}" if lo == hi else f"diameter = [{lo!r}, {hi!r}]"
    why = f"{count} circle(s) of ø{d:g} mm on {what}: small, drilled"
    if around:
        why += "; " + around_note(around, "drilled")
    lines = (
        f"name = {_quote(f'holes {d:g}')}",
        'type = "drill"' + _why(why),
        f"tool = {{drill {d:g}}}",
        select,
        size + _why("only the circles of this size"),
        f"depth = {depth:g}" + _why(f"through the {thickness:g} mm stock"),
        f"step_down = {max(d, 1.0):g}"
        + _why("peck about a diameter deep (G83)" if d >= 1.0 else "peck 1 mm at a time (G83)"),
    )
    return _Op("drill", d, lines)


def _profile_op(
    select: str,
    what: str,
    contours: list[Contour],
    nested: tuple[set[int], dict[int, str], Parts],
    thickness: float,
    tool: float,
    key: str,
) -> _Op:
    pocket = "pocket" in key.casefold()
    shaper = _shaper_cut(key)
    cut, given = shaper if shaper else (None, None)
    depth = given or thickness + BREAKTHROUGH_MM
    if pocket:
        return _pocket_op(select, what, contours, thickness, tool, key, given)
    outer, foreign, parts = nested
    tops = sum(1 for c in contours if id(c) in outer)
    holes = [foreign[id(c)] for c in contours if id(c) in foreign]
    # one side per operation: that of most of the contours whose side is known (boxes.py's
    # Lamp.svg: 605 blue holes in black parts, 2 blue squares in parts drawn open)
    has_outer = cut == "outside" if cut else tops > 0 and tops >= len(holes)
    side = "outside" if has_outer else "inside"
    if cut:
        why = f"Shaper's cut type of {what}"
    elif has_outer:
        why = f"{what} holds an outermost contour: cut outside it (its holes inside)"
        why += _foreign_holes(holes)
    elif tops:
        why = (
            f"{what} holds {len(holes)} holes of {holes[0]}'s parts: cut on their inside; but "
            f"{tops} of its contours lie inside no part and are cut inside too: if those are "
            "parts, give them a layer or colour of their own, cut outside"
        )
    else:
        why = f"{what} holds holes of a part only: cut on their inside"
    mill: float | None
    unfit = ""
    if has_outer:
        mill, tool_line = mill_between([c for c in contours if id(c) in outer], parts, tool)
    else:
        mill, tool_line, unfit = mill_that_fits(contours, tool)
    lines = [
        f"name = {_quote(key)}",
        'type = "profile"',
        tool_line,
        select,
        "closed = true" + _why("open contours have no side"),
        f'side = "{side}"' + _why(why),
        f"depth = {depth:g}"
        + _why("Shaper's cut depth" if given else f"through the {thickness:g} mm stock"),
        f"step_down = {min(mill or tool, depth):g}" + _why("passes of at most the tool's diameter"),
    ]
    if has_outer:
        shortest = min(c.length for c in _parts(contours))
        tabs = _tabs_that_fit(shortest, mill or tool)
        if tabs:
            lines.append(f"tabs = {tabs}" + _why("hold the part to the stock on the last pass"))
            lines.append(
                f"tab_height = {min(1.0, depth / 2):g}" + _why("mm of material left in each tab")
            )
        else:
            lines.append(
                _why(
                    f"no tabs: a {shortest:.3g} mm outline has no room for them; hold the "
                    "part another way"
                ).lstrip()
            )
    if mill is None:  # no end mill fits: a guess the user must finish
        return _Op(f"profile {side}", tool, tuple(lines), commented=True, unfit=unfit)
    return _Op(f"profile {side}", mill, tuple(lines))


def _foreign_holes(holes: Sequence[str]) -> str:
    """What an outside profile does to its contours that are holes of other groups' parts.

    ``holes``: per such contour, the name (:func:`_what`) of the group around it.
    """
    if not holes:
        return ""
    return (
        f"; but {len(holes)} of its contours lie inside {holes[0]}'s parts and are cut "
        "outside too, into them: give those a layer or colour of their own, cut inside"
    )


def _pocket_op(
    select: str,
    what: str,
    contours: list[Contour],
    thickness: float,
    tool: float,
    key: str,
    given: float | None = None,
) -> _Op:
    """A pocket with an end mill that fits its narrowest pocket.

    At half the stock, or ``given``: Shaper's depth, mm.
    """
    mill, tool_line, unfit = mill_that_fits(contours, tool, "pocket")
    depth = given or thickness / 2
    lines = (
        f"name = {_quote(key)}",
        'type = "pocket"' + _why(f"{what}: the layer's name says pocket"),
        tool_line,
        select,
        f"depth = {depth:g}"
        + _why("Shaper's cut depth" if given else "half the stock: set the pocket's depth"),
        f"step_down = {min(mill or tool, depth):g}" + _why("at most a tool diameter"),
    )
    return _Op("pocket", mill or tool, lines, commented=mill is None, unfit=unfit)


TAB_WIDTH_MM = 2.0
"""The tab width a job leaves as ``post``'s ``--tab-width`` default."""


def _parts(contours: Sequence[Contour]) -> list[Contour]:
    """The closed contours an outside profile of ``contours`` cuts on their outside.

    Those inside an even number of the others (the even-odd rule the planner cuts by:
    a part, a part in a hole of another...), each of which gets the operation's tabs.
    """
    from camtool.toolpath.order import nesting

    closed = [c for c in contours if c.closed]
    nest = nesting(closed)
    return [c for i, c in enumerate(closed) if nest.depth(i) % 2 == 0]


def _tabs_that_fit(length: float, tool: float) -> int:
    """Up to 3 tabs, as many as fit a path of ``length`` mm (with room between them).

    Each tab needs its width plus the tool's diameter of path
    (:func:`camtool.toolpath.passes.tab_spans`), within the middle 90 % of the path; a
    tab's own length again between two keeps them apart.
    """
    need = 2.0 * (TAB_WIDTH_MM + tool)
    return max(0, min(3, int(0.9 * length // need)))


def _engrave_op(
    select: str, what: str, count: int, *, closed_too: bool = False, depth: float | None = None
) -> _Op:
    """A shallow line on the paths of the open contours, left commented out.

    ``closed_too``: of every contour (Shaper's "online" cut type); ``depth``: Shaper's.
    """
    kind = "" if closed_too else "open "
    lines = (
        'type = "engrave"'
        + _why(f"{count} {kind}contour(s) on {what}: not cut unless you uncomment this"),
        "tool = {end-mill}",
        select,
        *(() if closed_too else ("closed = false",)),
        f"depth = {depth:g}" + _why("Shaper's cut depth")
        if depth
        else "depth = 0.2" + _why("a shallow line on its path"),
    )
    return _Op("engrave", 0.0, lines, commented=True)


def _shaper_cut(key: str) -> tuple[str, float | None] | None:
    """The cut type and depth (mm) of a layer ``key`` named for Shaper's format.

    (:func:`camtool.importers.svgstyle.shaper_layer`); ``None`` for any other layer.
    """
    from camtool.importers.svgstyle import shaper_cut_of

    return shaper_cut_of(key)


def _marks(drawing: Drawing, thickness: float) -> list[_Op]:
    if not drawing.marks:
        return []
    layers = sorted({m.layer for m in drawing.marks}, key=str.casefold)
    lines = (
        'type = "drill"' + _why(f"{len(drawing.marks)} point(s): drilled if you uncomment this"),
        "tool = {drill 3}",
        f"layers = [{', '.join(_quote(n) for n in layers)}]",
        'points = "only"' + _why("not the contours of these layers"),
        f"depth = {thickness + BREAKTHROUGH_MM:g}",
    )
    return [_Op("drill", 3.0, lines, commented=True)]


_ORDER = {"drill": 0, "engrave": 1, "pocket": 2, "profile inside": 3, "profile outside": 4}


def _render(
    ops: list[_Op],
    left: Counter[str],
    thickness: float,
    tool: float,
    source: str,
    fit: tuple[str, ...] = (),
    no_z: str = "",
) -> str:
    tools: dict[tuple[str, float], int] = {}
    ordered = sorted(ops, key=lambda op: (_ORDER[op.kind], op.tool))
    for op in ordered:
        key = _tool_key(op, tool)
        if not op.commented or key in tools:
            tools.setdefault(key, len(tools) + 1)
    if not tools:
        tools[("end-mill", tool)] = 1
    if len(tools) > MAX_TOOLS:
        raise InputError(
            f"{source}: its first job would need {len(tools)} tools (a drill for each hole "
            f"diameter, an end mill for each size of part), more than the {MAX_TOOLS} a job "
            "may hold; round the holes' diameters to the drills you have in the drawing"
        )
    out = [
        f"# camtool job for {source}: a first guess; read each line and change what is not so.",
        "# Post it with: camtool post DRAWING -t TARGET --job THIS.toml",
        "",
        "[job]",
        'origin = "lower-left"' + _why("work zero at the toolpath's lower-left corner"),
        *(
            (
                f"# {no_z} has no programmable Z: no heights, depths or tabs here; set each "
                "operation's depth by hand on the machine",
            )
            if no_z
            else (
                "clearance_z = 10.0" + _why("mm above the top: start, end and tool changes"),
                "safe_z = 2.0" + _why("mm above the top: rapids within an operation"),
            )
        ),
        'sequence = "auto"'
        + _why("drill, engrave, pocket, inside, outside profiles last, by tool"),
        *fit,
        "",
    ]
    for (kind, d), number in tools.items():
        out += [
            "[[tools]]",
            f"id = {number}",
            f'type = "{kind}"',
            f"diameter = {d:g}" + _why("mm; set it to the tool you load"),
            "",
        ]
    first = next(iter(tools))
    for op in ordered:
        number = tools.get(_tool_key(op, tool), 1)
        prefix = "# " if op.commented else ""
        out.append(f"{prefix}[[operations]]")
        for line in op.lines:
            line = line.replace("{end-mill}", str(number))
            line = line.replace(f"{{end-mill {op.tool:g}}}", str(number))
            if f"{{drill {op.tool:g}}}" in line and first[0] != "drill":  # no drill listed
                line += _why(f"the {first[1]:g} mm {first[0]}: add a [[tools]] drill, give its id")
            line = line.replace(f"{{drill {op.tool:g}}}", str(number))
            out.append(prefix + line)
        out.append("")
    if left:
        out.append("# left out (construction, never cut unless an operation names its layer):")
        out.extend(f"#   {what}: {n} contour(s)" for what, n in sorted(left.items()))
    return "\n".join(out).rstrip() + "\n"


def _tool_key(op: _Op, tool: float) -> tuple[str, float]:
    """The tool an operation uses: its drill, its own end mill, or the job's (``tool``)."""
    if op.kind == "drill":
        return ("drill", op.tool)
    own = op.kind.startswith("profile") or op.kind == "pocket"
    return ("end-mill", op.tool if own else tool)


def _quote(text: str) -> str:
    """``text`` as a TOML basic string."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'
