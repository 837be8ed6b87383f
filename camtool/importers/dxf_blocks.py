"""INSERT and MINSERT: block content transformed into the WCS, nested blocks included.

Each entity of a block is copied and transformed once, by the product of the matrices of
the block references that lead to it (:meth:`ezdxf.entities.Insert.matrix44`: insertion
point, scale including negative (mirror) scales, rotation, OCS extrusion and the block's
base point). ezdxf's own ``transform`` is exact for lines, uniformly scaled arcs,
polylines, ellipses, splines and hatches; under a non-uniform scale an ARC or CIRCLE
becomes an ELLIPSE (:meth:`ezdxf.entities.Ellipse.from_arc`, as ezdxf's
``Insert.virtual_entities`` does) and a polyline with bulges is exploded into lines and
such ellipses. A mirror (negative scale) turns the extrusion to (0, 0, −1), which the
converter reads as clockwise. MINSERT grids are expanded row by column, the grid rotated
with the insert and not scaled (DXF reference, INSERT group codes 70/71/44/45).

An entity on layer ``0`` inside a block takes the layer of the INSERT that places it
(DXF rule), through every level of nesting.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

from camtool.geometry import Point
from camtool.importers.dxf_curves import Unsupported
from camtool.importers.dxf_entities import CONVERTED, Item, location

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


def expand_insert(insert: Any, layer: str) -> Iterator[Item | Skip]:
    """Every leaf entity a model-space INSERT (or MINSERT) places, in WCS drawing units.

    Args:
        insert: an ezdxf ``Insert`` from model space.
        layer: the INSERT's effective layer (its own layer in model space).

    Yields:
        :class:`~camtool.importers.dxf_entities.Item` for each placed entity (types in
        :data:`~camtool.importers.dxf_entities.CONVERTED` transformed, others as they
        are, for counting) and :class:`Skip` for content that cannot be placed: a
        missing block, a block that contains itself, an entity the transform refuses.
        ATTRIBs of the INSERTs are yielded as items too (text, to be counted and
        skipped); ATTDEFs (attribute templates) are not.
    """
    yield from _expand(insert, layer, None, "", ())


def _expand(
    insert: Any, layer: str, parent: Any, within: str, names: tuple[str, ...]
) -> Iterator[Item | Skip]:
    """``names``: the blocks around this INSERT, outermost first (to catch cycles)."""
    name = insert.dxf.name
    label = f"INSERT #{insert.dxf.handle}{within}"
    for attrib in insert.attribs:
        at = _moved(location(attrib), parent)
        yield Item(attrib, f"ATTRIB #{attrib.dxf.handle} of {label}", layer, at=at)
    block = insert.block()
    reason = ""
    if block is None:
        reason = f"block {name!r} is missing"
    elif name in names:
        reason = f"block {name!r} contains itself"
    elif len(names) >= MAX_NESTING:
        reason = f"blocks nested deeper than {MAX_NESTING} levels"
    if reason:
        yield Skip("INSERT", reason, label, layer, _moved(location(insert), parent))
        return
    for matrix, cell in _grid(insert):
        if parent is not None:
            from ezdxf.math import Matrix44

            matrix = Matrix44.chain(matrix, parent)
        chain = f" in INSERT #{insert.dxf.handle} (block {name!r}{cell}){within}"
        for entity in block:
            yield from _place(entity, matrix, layer, chain, (*names, name))


def _place(
    entity: Any, matrix: Any, layer: str, chain: str, names: tuple[str, ...]
) -> Iterator[Item | Skip]:
    """One entity of a block under ``matrix``; ``chain`` names the INSERTs around it."""
    kind = entity.dxftype()
    if kind == "ATTDEF":
        return
    own = entity.dxf.get("layer", "0")
    eff = layer if own == "0" else own
    if kind == "INSERT":
        yield from _expand(entity, eff, matrix, chain, names)
        return
    label = f"{kind} #{entity.dxf.handle}{chain}"
    if kind not in CONVERTED:
        yield Item(entity, label, eff, at=_moved(location(entity), matrix))
        return
    try:
        placed, parts = _transformed(entity, matrix)
    except Unsupported as exc:
        yield Skip(kind, exc.reason, label, eff, _moved(location(entity), matrix))
        return
    yield Item(placed, label, eff, parts)


def _moved(p: Point | None, matrix: Any) -> Point | None:
    """A block-coordinate point through ``matrix`` (None: the point is already WCS)."""
    if p is None or matrix is None:
        return p
    x, y, _ = matrix.transform((p[0], p[1], 0.0))
    return (float(x), float(y))


def _transformed(entity: Any, matrix: Any) -> tuple[Any, tuple[Any, ...]]:
    """A transformed copy of ``entity``, or the entity and its transformed pieces."""
    from ezdxf.entities import Ellipse
    from ezdxf.math.transformtools import NonUniformScalingError, TransformError

    try:
        return entity.copy().transform(matrix), ()
    except NonUniformScalingError:
        kind = entity.dxftype()
        if kind in ("ARC", "CIRCLE"):
            if entity.dxf.radius <= 0:
                raise Unsupported("zero length") from None
            return Ellipse.from_arc(entity).transform(matrix), ()
        if kind in ("LWPOLYLINE", "POLYLINE"):
            parts = tuple(_transformed(part, matrix)[0] for part in entity.virtual_entities())
            return entity, parts
        raise Unsupported("cannot be scaled non-uniformly") from None
    except (TransformError, NotImplementedError) as exc:
        raise Unsupported(f"cannot be transformed ({exc})") from exc


def _grid(insert: Any) -> Iterator[tuple[Any, str]]:
    """``(matrix, label)`` per MINSERT cell (one cell for a plain INSERT).

    The cell offset ``(column · column_spacing, row · row_spacing)`` is rotated with the
    insert in its OCS and added to the insertion point; a zero spacing gives one row
    (or column) only, as ezdxf's ``multi_insert`` does.
    """
    from ezdxf.math import Matrix44, Vec3

    base = insert.matrix44()
    rows = int(insert.dxf.get("row_count", 1))
    cols = int(insert.dxf.get("column_count", 1))
    if rows * cols <= 1:
        yield base, ""
        return
    row_step = float(insert.dxf.get("row_spacing", 0.0))
    col_step = float(insert.dxf.get("column_spacing", 0.0))
    rows = rows if row_step else 1
    cols = cols if col_step else 1
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
