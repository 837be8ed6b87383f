"""INSERT and MINSERT: block content transformed into the WCS, nested blocks included.

Design notes: docs/internals.md, ``camtool/importers/dxf_blocks.py``.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from functools import cache, partial
from typing import Any

from camtool.importers.dxf_entities import (
    CONVERTED,
    BadEntity,
    Item,
    Unsupported,
    check_numbers,
    invisible,
    layer_of,
    location,
    spline_tool,
)
from camtool.importers.options import check_expansion, entity_limit, too_many_entities
from camtool.model.shapes import Point

MAX_NESTING = 32
"""Deepest block nesting followed; deeper is refused (a block that contains itself, too)."""


@dataclass(frozen=True)
class Skip:
    """Block content that could not be placed, with the reason and where it is.

    Attributes:
        kind: DXF type of the entity (``"ARC"``, ``"INSERT"`` ...).
        reason: why, for the user (``"block 'X' is missing"``).
        label: the entity with its chain of INSERTs.
        layer: effective layer.
        location: a WCS point of the entity in drawing units, or None.
    """

    kind: str
    reason: str
    label: str
    layer: str
    location: Point | None = None


HIDDEN = Skip("INSERT", "hidden", "", "")
"""Yielded for a nested block reference ``hides`` hides, in place of all it would place."""

INVISIBLE = Skip("INSERT", "invisible", "", "")
"""Yielded for a nested block reference with its invisible flag (group code 60) set."""


def _hides_nothing(layer: str) -> bool:
    return False


def expand_insert(
    insert: Any,
    layer: str,
    limit: float,
    cyclic: frozenset[str] = frozenset(),
    hides: Callable[[str], bool] = _hides_nothing,
) -> Iterator[Item | Skip]:
    """Every leaf entity a model-space INSERT (or MINSERT) places, in WCS drawing units.

    Each INSERT on the way and each block entity is checked by
    :func:`~camtool.importers.dxf_entities.check_numbers` before it is used, so a NaN
    scale or an infinite coordinate is an error naming the entity, not a skip.

    Args:
        insert: an ezdxf ``Insert`` from model space.
        layer: the INSERT's effective layer (its own layer in model space).
        limit: largest number accepted, drawing units.
        cyclic: blocks on a reference cycle (:attr:`BlockGraph.cyclic`); their INSERTs
            are skipped whole.
        hides: called with the effective layer of each nested INSERT; true when the CAD
            program hides the reference with all it places (AutoCAD: its layer is frozen).
            Such a reference yields :data:`HIDDEN`, one with its invisible flag set
            :data:`INVISIBLE`.

    Yields:
        :class:`~camtool.importers.dxf_entities.Item` for each placed entity (types in
        :data:`~camtool.importers.dxf_entities.CONVERTED` transformed, others as they
        are, for counting) and :class:`Skip` for content that cannot be placed: a
        missing block, a block that contains itself, an external reference (XREF: its
        content is in another file), an entity the transform refuses.
        ATTRIBs of the INSERTs are yielded as items too (text, to be counted and
        skipped); ATTDEFs (attribute templates) are not.

    Raises:
        BadEntity: an INSERT or a block entity holds a NaN, infinite or huge number; an
            INSERT (at any depth) has a clipping boundary switched on (XCLIP).
    """
    yield from _expand(insert, layer, None, "", (), (limit, cyclic, hides))


_Limits = tuple[float, frozenset[str], Callable[[str], bool]]  # number, cyclic blocks, hides


def _expand(
    insert: Any, layer: str, parent: Any, within: str, names: tuple[str, ...], limits: _Limits
) -> Iterator[Item | Skip]:
    """``names``: the blocks around this INSERT, outermost first (to count the depth)."""
    name = insert.dxf.name
    label = f"INSERT #{insert.dxf.handle}{within}"
    check_numbers(insert, label, layer, limits[0])
    for attrib in insert.attribs:
        at = _moved(location(attrib), parent)
        yield Item(attrib, f"ATTRIB #{attrib.dxf.handle} of {label}", layer, at=at)
    block = insert.block()
    reason = ""
    if block is None:
        reason = f"block {name!r} is missing"
    elif name in names or name in limits[1]:
        reason = f"block {name!r} contains itself"
    elif len(names) >= MAX_NESTING:
        reason = f"blocks nested deeper than {MAX_NESTING} levels"
    elif _external(block):
        path = block.block.dxf.get("xref_path", "") or "another file"
        reason = (
            f"block {name!r} is an external reference to {path}, which camtool does not read; "
            "bind it in the CAD program (XREF > Bind) to cut it"
        )
    if reason:
        yield Skip("INSERT", reason, label, layer, _moved(location(insert), parent))
        return
    if _clipped(insert):
        raise BadEntity(
            f"{label} on layer {layer!r} shows only part of block {name!r} (a clipping "
            "boundary, XCLIP), and camtool reads whole blocks: what the clip hides would be "
            "cut; delete the clip (XCLIP > Delete) and trim the geometry, or explode the "
            "block and trim it, in the CAD program"
        )
    for matrix, cell in _grid(insert):
        if parent is not None:
            from ezdxf.math import Matrix44

            matrix = Matrix44.chain(matrix, parent)
        chain = f" in INSERT #{insert.dxf.handle} (block {name!r}{cell}){within}"
        for entity in block:
            yield from _place(entity, matrix, layer, chain, (*names, name), limits)


def _clipped(insert: Any) -> bool:
    """Whether ``insert`` has a clipping boundary switched on (AutoCAD's XCLIP; ezdxf.xclip)."""
    from ezdxf.xclip import XClip

    if not insert.has_extension_dict:  # the clip lives in its ACAD_FILTER dictionary
        return False
    clip = XClip(insert)
    return bool(clip.has_clipping_path and clip.is_clipping_enabled)


def _external(block: Any) -> bool:
    """Whether ``block`` (an ezdxf BlockLayout) is an external reference (XREF or overlay)."""
    try:
        return bool(block.block.is_xref or block.block.is_xref_overlay)
    except AttributeError:
        return False


def _place(
    entity: Any, matrix: Any, layer: str, chain: str, names: tuple[str, ...], limits: _Limits
) -> Iterator[Item | Skip]:
    """One entity of a block under ``matrix``; ``chain`` names the INSERTs around it."""
    kind = entity.dxftype()
    if kind == "ATTDEF":
        return
    own = layer_of(entity)
    eff = layer if own == "0" else own
    if kind == "MLINE":
        lines = mline_parts(entity)
        if isinstance(lines, str):
            at = _moved(location(entity), matrix)
            yield Skip(kind, lines, f"MLINE #{entity.dxf.handle}{chain}", eff, at)
            return
        for part in lines:  # in block coordinates, placed as the block's own entities are
            yield from _place(
                part, matrix, eff, f" of MLINE #{entity.dxf.handle}{chain}", names, limits
            )
        return
    if kind == "INSERT":
        if invisible(entity):
            yield INVISIBLE
        elif limits[2](eff):
            yield HIDDEN
        else:
            yield from _expand(entity, eff, matrix, chain, names, limits)
        return
    handle = entity.dxf.handle  # None for an MLINE's drawn lines
    label = f"{kind} #{handle}{chain}" if handle else f"{kind}{chain}"
    if kind not in CONVERTED:
        yield Item(entity, label, eff, at=_moved(location(entity), matrix))
        return
    check_numbers(entity, label, eff, limits[0])
    if kind == "HATCH":  # its boundary is placed piece by piece when it is read
        at = _moved(location(entity), matrix)
        yield Item(entity, label, eff, at=at, place=partial(_placed, matrix=matrix))
        return
    try:
        placed, parts = _transformed(entity, matrix)
    except Unsupported as exc:
        yield Skip(kind, exc.reason, label, eff, _moved(location(entity), matrix))
        return
    yield Item(placed, label, eff, parts)


def _placed(piece: Any, matrix: Any) -> tuple[Any, ...]:
    """A HATCH's boundary piece, an entity drawn in the block, placed by ``matrix``.

    Each piece is placed as the entity it is (:func:`_transformed`): ezdxf's own HATCH
    transform misplaces an ellipse edge under nested scales and mirrors.

    Raises:
        Unsupported: the piece cannot be placed.
    """
    moved, parts = _transformed(piece, matrix)
    return parts or (moved,)


def mline_parts(mline: Any) -> list[Any] | str:
    """The LINE and ARC entities ezdxf draws for an MLINE (its fill left out).

    Returns:
        The virtual entities, on the MLINE's layer; or, when ezdxf cannot draw it
        (a missing MLINESTYLE, too few vertices), the reason, for a skip.
    """
    from ezdxf.lldxf.const import DXFError

    try:
        parts = [e for e in mline.virtual_entities() if e.dxftype() in ("LINE", "ARC")]
    except (DXFError, ValueError, TypeError, AttributeError, IndexError, ZeroDivisionError) as exc:
        return f"cannot be drawn ({exc})"
    if not parts:
        return "draws no line (fewer than two vertices, or no elements in its style)"
    return parts


def _moved(p: Point | None, matrix: Any) -> Point | None:
    """A block-coordinate point through ``matrix`` (None: the point is already WCS)."""
    if p is None or matrix is None:
        return p
    x, y, _ = matrix.transform((p[0], p[1], 0.0))
    return (float(x), float(y))


def _transformed(entity: Any, matrix: Any) -> tuple[Any, tuple[Any, ...]]:
    """A transformed copy of ``entity``, or the entity and its transformed pieces.

    A SPLINE given by fit points only is first given the control points of its curve in
    block coordinates (:func:`_controlled`).
    """
    from ezdxf.entities import Ellipse
    from ezdxf.math.transformtools import NonUniformScalingError, TransformError

    try:
        if _sheared(entity, matrix):
            raise NonUniformScalingError("not a similarity in the entity's plane")
        return _controlled(entity).transform(matrix), ()
    except NonUniformScalingError:
        kind = entity.dxftype()
        if kind in ("ARC", "CIRCLE"):
            if entity.dxf.radius == 0:
                raise Unsupported("zero length") from None
            circle = geometry_copy(entity)
            circle.dxf.radius = abs(entity.dxf.radius)  # AutoCAD ignores the sign
            return Ellipse.from_arc(circle).transform(matrix), ()
        if kind in ("LWPOLYLINE", "POLYLINE"):
            parts = tuple(_transformed(part, matrix)[0] for part in entity.virtual_entities())
            return entity, parts
        raise Unsupported("cannot be scaled non-uniformly") from None
    except (TransformError, NotImplementedError) as exc:
        raise Unsupported(f"cannot be transformed ({exc})") from exc


_BULGED = frozenset({"ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE"})
"""Entities whose arcs ezdxf keeps circular when it transforms them."""


def _sheared(entity: Any, matrix: Any) -> bool:
    """Whether ``matrix`` maps ``entity``'s plane by more than a similarity (a shear).

    ezdxf transforms a CIRCLE, an ARC or a polyline's bulges as circles when the images of
    the entity's OCS x and y axes are equally long (``transform_extrusion``), without
    asking that they stay perpendicular: a block rotated by 45° inside a block scaled
    non-uniformly (``S(1, 2) · R(45°)``: both axes √2.5 long, not perpendicular) made a
    circle where the placed curve is an ellipse. Such an entity is transformed as the
    non-uniform case is: arcs as ELLIPSEs, whose transform is exact under any affine map.
    """
    if entity.dxftype() not in _BULGED:
        return False
    from ezdxf.math import OCS, X_AXIS, Y_AXIS

    ocs = OCS(entity.dxf.get("extrusion", (0.0, 0.0, 1.0)))
    x, y = matrix.transform_directions((ocs.to_wcs(X_AXIS), ocs.to_wcs(Y_AXIS)))
    size = x.magnitude * y.magnitude
    return size > 0.0 and abs(x.dot(y)) > 1e-9 * size


@cache
def _geometry_only() -> Any:
    from ezdxf.entities.copy import CopySettings, CopyStrategy

    return CopyStrategy(
        CopySettings(
            copy_extension_dict=False,
            copy_xdata=False,
            copy_appdata=False,
            copy_proxy_graphic=False,
            set_source_of_copy=False,
        )
    )


def geometry_copy(entity: Any) -> Any:
    """A copy of ``entity`` with its geometry only (ezdxf ``CopySettings``).

    Its extension dictionary, XDATA and application data stay behind: camtool reads no
    more than the geometry, and ezdxf cannot copy some objects other programs keep there
    (TurboCAD's TCOPTIONALDATA): copying them makes it log a line on stderr.
    """
    return entity.copy(copy_strategy=_geometry_only())


def _controlled(entity: Any) -> Any:
    """A copy of ``entity`` whose fit-point-only splines are given by their control points.

    The curve through placed fit points is not the placed curve under a non-uniform
    scale (chord lengths and end tangents change), while a B-spline's control points
    place it exactly under any affine map (*The NURBS Book*, section 4.2): the curve is
    built where it was drawn, as a CAD program draws a block, then placed (a HATCH's
    spline edges too, as the SPLINEs :func:`_placed` is given).

    Raises:
        Unsupported: fit points no spline can be built through.
    """
    copy = geometry_copy(entity)
    if entity.dxftype() == "SPLINE" and not entity.control_point_count():
        if not entity.fit_point_count():
            return copy
        copy.apply_construction_tool(spline_tool(entity))
        copy.fit_points = []
    return copy


def _grid(insert: Any) -> Iterator[tuple[Any, str]]:
    """``(matrix, label)`` per MINSERT cell (one cell for a plain INSERT).

    The cell offset ``(column · column_spacing, row · row_spacing)`` is rotated with the
    insert in its OCS and added to the insertion point; a zero spacing gives one row
    (or column) only, as ezdxf's ``multi_insert`` does.
    """
    from ezdxf.math import Matrix44, Vec3

    base = insert.matrix44()
    rows, cols = _rows_columns(insert)
    if (rows, cols) == (1, 1):
        yield base, ""
        return
    row_step = float(insert.dxf.get("row_spacing", 0.0))
    col_step = float(insert.dxf.get("column_spacing", 0.0))
    ocs = insert.ocs()
    rotation = float(insert.dxf.get("rotation", 0.0))
    for row in range(rows):
        for col in range(cols):
            offset = Vec3(col * col_step, row * row_step).rotate_deg(rotation)
            shift = Vec3(ocs.to_wcs(offset))
            yield (
                Matrix44.chain(base, Matrix44.translate(*shift)),
                f", row {row + 1} column {col + 1}",
            )


def _rows_columns(insert: Any) -> tuple[int, int]:
    """MINSERT grid size as :func:`_grid` expands it; ``(1, 1)`` for a plain INSERT."""
    rows = int(insert.dxf.get("row_count", 1))
    cols = int(insert.dxf.get("column_count", 1))
    if rows * cols <= 1:
        return 1, 1
    rows = max(rows, 0) if insert.dxf.get("row_spacing", 0.0) else 1
    cols = max(cols, 0) if insert.dxf.get("column_spacing", 0.0) else 1
    return rows, cols


@dataclass(frozen=True)
class BlockGraph:
    """Which blocks model space reaches, which of them lie on a reference cycle, and sizes.

    Attributes:
        cyclic: names of the blocks that contain themselves, directly or through other
            blocks (the strongly connected components of the block reference graph with a
            cycle). An INSERT of such a block is skipped whole, wherever it is: expanding
            "up to the cycle" would give a size that depends on the way in, which the
            entity count below could not bound.
        sizes: per reached block, how many entities one placement of it expands to
            (nested INSERTs, their ATTRIBs and MINSERT cells included), saturated at
            ``limit + 1``.
        held: how many entities the reached blocks hold in the file (each block once;
            INSERTs and their ATTRIBs included, ATTDEFs left out).
    """

    cyclic: frozenset[str]
    sizes: dict[str, int]
    held: int


def checked_block_graph(name: str, msp: Any, max_entities: int | None) -> BlockGraph:
    """The block graph of model space ``msp``; refuse a drawing that expands past the limits.

    Args:
        name: the file, as messages name it.
        msp: the model space (ezdxf).
        max_entities: ``--max-entities`` (``None``: the defaults).

    Raises:
        InputError: too many entities once blocks are expanded
            (:func:`~camtool.importers.options.check_expansion`).
    """
    limit = entity_limit(max_entities)
    if len(msp) > limit:
        raise too_many_entities(name, limit)
    inserts = [e for e in msp if e.dxftype() == "INSERT"]
    graph = block_graph(inserts, limit)
    count = expanded_count(inserts, len(msp) - len(inserts), graph, limit)
    held = len(msp) + sum(len(i.attribs) for i in inserts) + graph.held
    check_expansion(name, count, held, max_entities, "block references")
    return graph


def block_graph(inserts: Iterable[Any], limit: int) -> BlockGraph:
    """Analyse the blocks model space references, without expanding any of them.

    Each block is visited once (a "billion laughs" of blocks, a block placing the
    previous one 10 times 30 levels deep, is 30 visits, not 10³⁰), without recursion (a
    chain of thousands of nested blocks is fine).

    Args:
        inserts: the model-space INSERTs.
        limit: the entity count above which the caller refuses the drawing.
    """
    children: dict[str, list[Any]] = {}  # block name -> its INSERT entities
    contents: dict[str, int] = {}  # block name -> its other entities (ATTDEFs left out)
    todo = list(inserts)
    while todo:
        insert = todo.pop()
        name = insert.dxf.name
        if name in children:
            continue
        block = insert.block()
        inserts = [] if block is None else [e for e in block if e.dxftype() == "INSERT"]
        children[name] = inserts
        contents[name] = (
            0 if block is None else sum(1 for e in block if e.dxftype() not in ("INSERT", "ATTDEF"))
        )
        todo.extend(inserts)
    cyclic = _cyclic({n: [i.dxf.name for i in inserts] for n, inserts in children.items()})
    cap = limit + 1
    sizes: dict[str, int] = {}
    for name in _bottom_up(children, cyclic):
        total = contents[name]
        for insert in children[name]:
            total = min(cap, total + insert_size(insert, sizes, cyclic, cap))
        sizes[name] = total
    held = sum(contents.values()) + sum(1 + len(i.attribs) for c in children.values() for i in c)
    return BlockGraph(frozenset(cyclic), sizes, held)


def insert_size(insert: Any, sizes: dict[str, int], cyclic: Iterable[str], cap: int) -> int:
    """Entities one INSERT stands for: itself, its ATTRIBs and each cell's block content."""
    name = insert.dxf.name
    own = 1 + len(insert.attribs)
    if name in cyclic or name not in sizes:
        return own
    rows, cols = _rows_columns(insert)
    return min(cap, own + min(cap, rows * cols) * sizes[name])


def expanded_count(inserts: Iterable[Any], others: int, graph: BlockGraph, limit: int) -> int:
    """How many entities model space expands to (at most ``limit + 1``).

    Args:
        inserts: the model-space INSERTs.
        others: how many other entities model space holds.
        graph: the block analysis of :func:`block_graph`.
        limit: the entity count above which the caller refuses the drawing.
    """
    cap = limit + 1
    total = min(cap, others)
    for insert in inserts:
        total = min(cap, total + insert_size(insert, graph.sizes, graph.cyclic, cap))
    return total


def _bottom_up(children: dict[str, list[Any]], cyclic: set[str]) -> list[str]:
    """The acyclic block names, each after every block it places (post-order, iterative)."""
    order: list[str] = []
    seen: set[str] = set()
    for root in children:
        if root in seen or root in cyclic:
            continue
        seen.add(root)
        stack = [(root, iter(children[root]))]
        while stack:
            name, it = stack[-1]
            for insert in it:
                child = insert.dxf.name
                if child not in seen and child not in cyclic and child in children:
                    seen.add(child)
                    stack.append((child, iter(children[child])))
                    break
            else:
                stack.pop()
                order.append(name)
    return order


def _cyclic(graph: dict[str, list[str]]) -> set[str]:
    """Nodes on a cycle: members of strongly connected components with a cycle.

    Tarjan's algorithm (1972), iterative.
    """
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    on_stack: set[str] = set()
    stack: list[str] = []
    out: set[str] = set()
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(graph[root]))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, it = work[-1]
            for child in it:
                if child not in graph:
                    continue
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(graph[child])))
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            else:
                work.pop()
                if work:
                    parent = work[-1][0]
                    low[parent] = min(low[parent], low[node])
                if low[node] == index[node]:
                    component = []
                    while True:
                        member = stack.pop()
                        on_stack.discard(member)
                        component.append(member)
                        if member == node:
                            break
                    if len(component) > 1 or node in graph[node]:
                        out.update(component)
    return out
