"""``camtool job init``: a first job for a drawing, with the guesses a machinist would make.

One operation per layer (per colour when the drawing has one layer drawn in several
colours), each with a comment saying why:

- circles no larger than :data:`DRILL_MAX_MM` → a drill operation, a drill per diameter;
- closed contours → a profile: ``outside`` for a layer holding an outermost contour (its
  holes, on the same layer, are cut on their inside by the same operation), ``inside``
  for a layer of holes only; a layer whose name says pocket → a pocket;
- open contours → left out, with a commented engrave operation to uncomment;
- construction (centre lines, construction and dimension layers,
  :mod:`camtool.model.construction`) → left out, said in a comment.

Operations come in the order :meth:`camtool.jobs.job.Job.sequenced` gives ``auto``: drill,
engrave, pocket, inside profiles, outside profiles last, grouped by tool. The depth is the
stock's thickness (``--thickness``) plus a little, in passes of at most the tool's
diameter; every guess is a line the user can change.
"""

from __future__ import annotations

import dataclasses
from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass, field

from camtool.jobs.job import Selection
from camtool.jobs.selection import circle_of, construction_reason
from camtool.model.errors import InputError
from camtool.model.shapes import Contour, Drawing

DRILL_MAX_MM = 6.5
"""Largest circle drilled (ø6.5 mm: an M6 clearance hole); larger ones are profiled."""

BREAKTHROUGH_MM = 0.5
"""How far a through cut goes below the stock (into the spoil board)."""


@dataclass
class _Group:
    """The contours of one layer (or colour) and what they are."""

    key: str
    by: str  # "layers" or "colours"
    contours: list[Contour] = field(default_factory=list)


@dataclass(frozen=True)
class _Op:
    kind: str
    tool: float  # diameter, mm; a drill's is its hole's
    lines: tuple[str, ...]
    commented: bool = False


def initial_job(
    drawing: Drawing,
    *,
    thickness_mm: float = 3.0,
    tool_diameter: float = 3.0,
    source: str = "",
) -> str:
    """A job file (TOML text, comments included) for ``drawing``.

    Args:
        drawing: the imported drawing, mm.
        thickness_mm: the stock's thickness: profiles cut through it (plus
            :data:`BREAKTHROUGH_MM`), pockets go half way.
        tool_diameter: the end mill's diameter, mm.
        source: the drawing's name for the header comment.
    """
    groups = _groups(drawing)
    outer = _outermost(drawing.contours)
    ops: list[_Op] = []
    left: Counter[str] = Counter()
    for group in groups:
        ops.extend(_ops_of(group, outer, thickness_mm, tool_diameter, left))
    if all(op.kind == "engrave" for op in ops):
        # lines only, no part outline: a drawing to engrave (a sign, a symbol)
        ops = [dataclasses.replace(op, commented=False, lines=_engraved(op)) for op in ops]
    ops.extend(_marks(drawing, thickness_mm))
    if not any(not op.commented for op in ops):
        raise InputError(
            f"{drawing.source or 'the drawing'}: nothing to cut: every contour is construction "
            f"({'; '.join(f'{w}: {n}' for w, n in sorted(left.items()))}); name its layer in "
            "an operation of a job written by hand to cut it"
        )
    return _render(ops, left, thickness_mm, tool_diameter, source or drawing.source)


def _engraved(op: _Op) -> tuple[str, ...]:
    """An engrave operation's lines for a drawing that has nothing but open lines."""
    first = op.lines[0].split("  # ")[0]
    return (first + _why("the drawing is lines only: engraved on their paths"), *op.lines[1:])


def _groups(drawing: Drawing) -> list[_Group]:
    layers = sorted({c.layer for c in drawing.contours}, key=str.casefold)
    colours = sorted({c.colour for c in drawing.contours if c.colour})
    if len(layers) == 1 and len(colours) > 1:
        groups = {c: _Group(c, "colours") for c in colours}
        for contour in drawing.contours:
            groups.setdefault(contour.colour, _Group(contour.colour, "colours"))
            groups[contour.colour].contours.append(contour)
        return list(groups.values())
    by_layer = {name: _Group(name, "layers") for name in layers}
    for contour in drawing.contours:
        by_layer[contour.layer].contours.append(contour)
    return list(by_layer.values())


def _outermost(contours: Sequence[Contour]) -> set[int]:
    """The ids of the closed contours that lie inside no other closed contour."""
    from camtool.toolpath.order import nesting

    closed = [c for c in contours if c.closed and not c.linetype]
    if not closed:
        return set()
    nest = nesting(closed)
    return {id(c) for i, c in enumerate(closed) if not nest.parents[i]}


def _ops_of(
    group: _Group, outer: set[int], thickness: float, tool: float, left: Counter[str]
) -> list[_Op]:
    select = f"{group.by} = [{_quote(group.key)}]"
    what = f"layer {group.key!r}" if group.by == "layers" else f"colour {group.key}"
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
    circles: dict[float, int] = {}
    profiled: list[Contour] = []
    opened: list[Contour] = []
    for contour in kept:
        circle = circle_of(contour)
        if circle is not None and circle[1] <= DRILL_MAX_MM:
            d = round(circle[1], 3)
            circles[d] = circles.get(d, 0) + 1
        elif contour.closed:
            profiled.append(contour)
        else:
            opened.append(contour)
    for d, count in sorted(circles.items()):
        out.append(_drill_op(select, what, d, count, thickness))
    if profiled:
        out.append(_profile_op(select, what, profiled, outer, thickness, tool, group.key))
    if opened:
        out.append(_engrave_op(select, what, len(opened)))
    return out


def _drill_op(select: str, what: str, d: float, count: int, thickness: float) -> _Op:
    depth = thickness + BREAKTHROUGH_MM
    lines = (
        f"name = {_quote(f'holes {d:g}')}",
        'type = "drill"' + _why(f"{count} circle(s) of ø{d:g} mm on {what}: small, drilled"),
        f"tool = {{drill {d:g}}}",
        select,
        f"diameter = {d:g}" + _why("only the circles of this size"),
        f"depth = {depth:g}" + _why(f"through the {thickness:g} mm stock"),
        f"step_down = {max(d, 1.0):g}" + _why("peck about a diameter deep (G83)"),
    )
    return _Op("drill", d, lines)


def _profile_op(
    select: str,
    what: str,
    contours: list[Contour],
    outer: set[int],
    thickness: float,
    tool: float,
    key: str,
) -> _Op:
    pocket = "pocket" in key.casefold()
    depth = thickness + BREAKTHROUGH_MM
    step = tool
    if pocket:
        return _Op(
            "pocket",
            tool,
            (
                f"name = {_quote(key)}",
                'type = "pocket"' + _why(f"{what}: the layer's name says pocket"),
                "tool = {end-mill}",
                select,
                f"depth = {thickness / 2:g}" + _why("half the stock: set the pocket's depth"),
                f"step_down = {min(step, thickness / 2):g}" + _why("at most a tool diameter"),
            ),
        )
    has_outer = any(id(c) in outer for c in contours)
    side = "outside" if has_outer else "inside"
    why = (
        f"{what} holds an outermost contour: cut outside it (its holes inside)"
        if has_outer
        else f"{what} holds holes of a part only: cut on their inside"
    )
    lines = [
        f"name = {_quote(key)}",
        'type = "profile"',
        "tool = {end-mill}",
        select,
        "closed = true" + _why("open contours have no side"),
        f'side = "{side}"' + _why(why),
        f"depth = {depth:g}" + _why(f"through the {thickness:g} mm stock"),
        f"step_down = {min(step, depth):g}" + _why("passes of at most the tool's diameter"),
    ]
    if has_outer:
        lines.append("tabs = 3" + _why("hold the part to the stock on the last pass"))
        lines.append(
            f"tab_height = {min(1.0, depth / 2):g}" + _why("mm of material left in each tab")
        )
    return _Op(f"profile {side}", tool, tuple(lines))


def _engrave_op(select: str, what: str, count: int) -> _Op:
    lines = (
        'type = "engrave"'
        + _why(f"{count} open contour(s) on {what}: not cut unless you uncomment this"),
        "tool = {end-mill}",
        select,
        "closed = false",
        "depth = 0.2" + _why("a shallow line on its path"),
    )
    return _Op("engrave", 0.0, lines, commented=True)


def _marks(drawing: Drawing, thickness: float) -> list[_Op]:
    if not drawing.marks:
        return []
    layers = sorted({m.layer for m in drawing.marks}, key=str.casefold)
    lines = (
        'type = "drill"' + _why(f"{len(drawing.marks)} point(s): drilled if you uncomment this"),
        "tool = {drill 3}",
        f"layers = [{', '.join(_quote(n) for n in layers)}]",
        f"depth = {thickness + BREAKTHROUGH_MM:g}",
    )
    return [_Op("drill", 3.0, lines, commented=True)]


_ORDER = {"drill": 0, "engrave": 1, "pocket": 2, "profile inside": 3, "profile outside": 4}


def _render(ops: list[_Op], left: Counter[str], thickness: float, tool: float, source: str) -> str:
    tools: dict[tuple[str, float], int] = {}
    ordered = sorted(ops, key=lambda op: (_ORDER[op.kind], op.tool))
    for op in ordered:
        key = ("drill", op.tool) if op.kind == "drill" else ("end-mill", tool)
        if not op.commented or key in tools:
            tools.setdefault(key, len(tools) + 1)
    if not tools:
        tools[("end-mill", tool)] = 1
    out = [
        f"# camtool job for {source}: a first guess; read each line and change what is not so.",
        "# Post it with: camtool post DRAWING -t TARGET --job THIS.toml",
        "",
        "[job]",
        'origin = "lower-left"' + _why("work zero at the toolpath's lower-left corner"),
        "clearance_z = 10.0" + _why("mm above the top: start, end and tool changes"),
        "safe_z = 2.0" + _why("mm above the top: rapids within an operation"),
        'sequence = "auto"'
        + _why("drill, engrave, pocket, inside, outside profiles last, by tool"),
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
    for op in ordered:
        key = ("drill", op.tool) if op.kind == "drill" else ("end-mill", tool)
        number = tools.get(key, 1)
        prefix = "# " if op.commented else ""
        out.append(f"{prefix}[[operations]]")
        for line in op.lines:
            line = line.replace("{end-mill}", str(number))
            line = line.replace(f"{{drill {op.tool:g}}}", str(number))
            out.append(prefix + line)
        out.append("")
    if left:
        out.append("# left out (construction, never cut unless an operation names its layer):")
        out.extend(f"#   {what}: {n} contour(s)" for what, n in sorted(left.items()))
    return "\n".join(out).rstrip() + "\n"


def _why(text: str) -> str:
    return f"  # {text}"


def _quote(text: str) -> str:
    """``text`` as a TOML basic string."""
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    return f'"{escaped}"'
