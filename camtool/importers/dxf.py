"""DXF importer (ezdxf): model space as contours in mm, arcs kept exact, curves fitted.

Read: LINE, ARC, CIRCLE, LWPOLYLINE and 2D POLYLINE exactly (bulges become arcs; bulge > 0
is counter-clockwise); ELLIPSE and SPLINE as biarcs within the tolerance
(:mod:`camtool.importers.dxf_curves`); INSERT/MINSERT expanded with their full transform,
nested blocks included (:mod:`camtool.importers.dxf_blocks`); HATCH boundary paths when
asked (``hatch_boundaries``). Entities with an extrusion of (0, 0, −1) are mirrored into
the WCS, which flips their arcs' direction. Each entity becomes one contour; chaining
entities whose ends meet is the planner's job (:mod:`camtool.toolpath.chain`).

``$INSUNITS`` is converted to mm exactly; a unitless drawing is taken as mm with a
warning. Everything else (text, dimensions, images, points, 3D entities, HATCH without
the option) is skipped with one warning per type and reason, giving the count. A file
ezdxf cannot read is tried again with :func:`ezdxf.recover.readfile`, with a warning
saying what was repaired. Model space only: paper space is ignored.
"""

from __future__ import annotations

import logging
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camtool.errors import InputError, UsageError
from camtool.geometry import Contour, Drawing, Point
from camtool.units import INCH

if TYPE_CHECKING:
    from camtool.importers import ImportOptions

# Exact mm per unit for the $INSUNITS codes a shop meets (ezdxf's own factors
# carry rounding noise, e.g. 25.400000000101603 for inches).
_INSUNITS_MM: dict[int, tuple[str, float]] = {
    1: ("in", INCH),
    2: ("ft", 12 * INCH),
    4: ("mm", 1.0),
    5: ("cm", 10.0),
    6: ("m", 1000.0),
    8: ("microinch", INCH * 1e-6),
    9: ("mil", INCH * 1e-3),
    10: ("yd", 36 * INCH),
    13: ("µm", 1e-3),
    14: ("dm", 100.0),
}

_TEXT = "text is not cut; explode it to curves in the CAD program"
_THREE_D = "3D entity; camtool cuts 2D contours"
_SKIP_REASONS: dict[str, str] = {
    **dict.fromkeys(("TEXT", "MTEXT", "ATTRIB", "ATTDEF", "RTEXT"), _TEXT),
    **dict.fromkeys(
        ("DIMENSION", "ARC_DIMENSION", "LEADER", "MULTILEADER", "MLEADER", "TOLERANCE"),
        "annotation, not a contour",
    ),
    **dict.fromkeys(
        ("IMAGE", "WIPEOUT", "PDFUNDERLAY", "DWFUNDERLAY", "DGNUNDERLAY", "OLE2FRAME"),
        "picture or underlay, not a contour",
    ),
    "POINT": "a point has no path to cut",
    **dict.fromkeys(
        ("3DFACE", "3DSOLID", "MESH", "BODY", "REGION", "SURFACE", "POLYFACE", "POLYMESH"),
        _THREE_D,
    ),
    **dict.fromkeys(("SOLID", "TRACE"), "filled area; draw its outline to cut it"),
    "HATCH": "a fill; use --hatch-boundaries to cut its boundary paths",
}


@dataclass(frozen=True)
class DxfNote:
    """One entity the reader dropped, and where it is (for ``camtool inspect``).

    Attributes:
        source: the entity, e.g. ``"LINE #2A"`` or ``"LINE #1A in INSERT #3B (block 'B')"``.
        layer: its effective layer.
        reason: why it was dropped (``"zero length"``, ``"text is not cut; ..."``).
        location: a point of it in mm (WCS, Y up), or None when it has none.
    """

    source: str
    layer: str
    reason: str
    location: Point | None = None


@dataclass(frozen=True)
class DxfImport:
    """What :func:`import_dxf` read: the drawing plus what ``camtool inspect`` reports.

    Attributes:
        drawing: the contours in mm and the user warnings.
        units: the drawing unit, e.g. ``"in"``; ``"mm (assumed)"`` without $INSUNITS.
        mm_per_unit: scale applied to the drawing's coordinates.
        entity_counts: ``(type, layer, count)`` of the model-space entities, all layers,
            sorted; INSERTs count once each.
        block_entity_counts: ``(type, layer, count)`` of the entities the INSERTs place,
            by effective layer, sorted.
        notes: the entities that were dropped, each with its location.
        recovered: the file was damaged and read by ezdxf's recover mode.
    """

    drawing: Drawing
    units: str
    mm_per_unit: float
    entity_counts: tuple[tuple[str, str, int], ...] = field(default=())
    block_entity_counts: tuple[tuple[str, str, int], ...] = field(default=())
    notes: tuple[DxfNote, ...] = field(default=())
    recovered: bool = False


def read_dxf(path: str | Path, options: ImportOptions | None = None) -> Drawing:
    """Read the model space of a DXF file into a drawing in mm.

    Args:
        path: the DXF file.
        options: layers to keep, curve fitting tolerance (mm), HATCH boundaries;
            ``None`` takes the defaults.

    Returns:
        A :class:`Drawing` with one contour per usable entity (per boundary path for a
        HATCH), in mm, Y up, and the warnings a user should see (assumed units, skipped
        entity types, a repaired file).

    Raises:
        InputError: the file is missing, empty, not a DXF file or damaged beyond
            recovery; it uses an unknown ``$INSUNITS`` code; ``options.layers`` names a
            layer the drawing does not have; or model space (on the selected layers)
            holds nothing camtool can cut. The message names the file.
        UsageError: ``options.tolerance`` is not > 0.
    """
    return import_dxf(path, options).drawing


def import_dxf(path: str | Path, options: ImportOptions | None = None) -> DxfImport:
    """Read a DXF file like :func:`read_dxf` and also count its entities by type and layer.

    Raises:
        InputError: as :func:`read_dxf`.
        UsageError: ``options.tolerance`` is not > 0.
    """
    from camtool.importers import ImportOptions

    path = Path(path)
    options = options or ImportOptions()
    if not options.tolerance > 0:
        raise UsageError(f"the tolerance must be > 0 mm, got {options.tolerance!r}")
    doc, warnings = _open(path)
    recovered = bool(warnings)
    units, scale = _units(path, doc.header.get("$INSUNITS", 0), warnings)
    msp = doc.modelspace()
    if len(msp) == 0:
        _refuse_empty(path, doc, warnings)
    keep = _layer_filter(path, doc, options.layers)
    reader = _Reader(options.tolerance / scale, options.hatch_boundaries, keep)
    for entity in msp:
        reader.read(entity)
    for (kind, reason), count in sorted(reader.skipped.items()):
        plural = "entity" if count == 1 else "entities"
        warnings.append(f"{path}: skipped {count} {kind} {plural} ({reason})")
    if not reader.contours:
        on = f" on layers {', '.join(options.layers)}" if options.layers else ""
        raise InputError(
            f"{path}: no usable entity in model space{on}; camtool cuts LINE, ARC, CIRCLE, "
            "ELLIPSE, SPLINE, LWPOLYLINE and 2D POLYLINE entities (also inside blocks)"
            + "".join(f"\n  {w}" for w in warnings)
        )
    contours = tuple(c.transformed(scale, 0.0, 0.0) if scale != 1.0 else c for c in reader.contours)
    notes = tuple(
        DxfNote(n.source, n.layer, n.reason, _scaled(n.location, scale)) for n in reader.notes
    )
    return DxfImport(
        drawing=Drawing(contours, str(path), tuple(warnings)),
        units=units,
        mm_per_unit=scale,
        entity_counts=_rows(reader.counts),
        block_entity_counts=_rows(reader.block_counts),
        notes=notes,
        recovered=recovered,
    )


class _Reader:
    """Walks model space once; collects contours, skip counts, notes and entity counts."""

    def __init__(self, tolerance: float, hatch: bool, keep: Any) -> None:
        self.tolerance = tolerance  # drawing units
        self.hatch = hatch
        self.keep = keep
        self.contours: list[Contour] = []
        self.skipped: Counter[tuple[str, str]] = Counter()
        self.notes: list[DxfNote] = []
        self.counts: Counter[tuple[str, str]] = Counter()
        self.block_counts: Counter[tuple[str, str]] = Counter()

    def read(self, entity: Any) -> None:
        from camtool.importers.dxf_blocks import Skip, expand_insert
        from camtool.importers.dxf_entities import Item

        kind = entity.dxftype()
        layer = entity.dxf.get("layer", "0")
        self.counts[(kind, layer)] += 1
        if kind != "INSERT":
            self._item(Item(entity, f"{kind} #{entity.dxf.handle}", layer))
            return
        for placed in expand_insert(entity, layer):
            if isinstance(placed, Skip):
                self.block_counts[(placed.kind, placed.layer)] += 1
                if self.keep(placed.layer):
                    self._skip(
                        placed.kind, placed.reason, placed.label, placed.layer, placed.location
                    )
            else:
                self.block_counts[(placed.entity.dxftype(), placed.layer)] += 1
                self._item(placed)

    def _item(self, item: Any) -> None:
        from camtool.importers.dxf_curves import Unsupported
        from camtool.importers.dxf_entities import CONVERTED, convert, location

        if not self.keep(item.layer):
            return
        kind = _kind(item.entity)
        where = item.at if item.at is not None else location(item.entity)
        if kind not in CONVERTED or (kind == "HATCH" and not self.hatch):
            reason = _SKIP_REASONS.get(kind, "not a 2D contour camtool cuts")
            self._skip(kind, reason, item.label, item.layer, where)
            return
        try:
            self.contours.extend(convert(item, self.tolerance))
        except Unsupported as exc:
            detail = exc.reason + (f": {exc.detail}" if exc.detail else "")
            self._skip(kind, exc.reason, item.label, item.layer, where, detail)

    def _skip(
        self,
        kind: str,
        reason: str,
        label: str,
        layer: str,
        where: Point | None,
        detail: str | None = None,
    ) -> None:
        self.skipped[(kind, reason)] += 1
        self.notes.append(DxfNote(label, layer, detail or reason, where))


def _kind(entity: Any) -> str:
    """DXF type, with polyface and polygon mesh POLYLINEs told apart from 2D/3D ones."""
    kind = entity.dxftype()
    if kind == "POLYLINE" and entity.is_poly_face_mesh:
        return "POLYFACE"
    if kind == "POLYLINE" and entity.is_polygon_mesh:
        return "POLYMESH"
    return kind


def _open(path: Path) -> tuple[Any, list[str]]:
    """The document, and a warning when it had to be recovered."""
    import ezdxf
    from ezdxf import recover

    if not path.is_file():
        raise InputError(f"{path}: no such file")
    if path.stat().st_size == 0:
        raise InputError(f"{path}: empty file; export the drawing again from the CAD program")
    try:
        return ezdxf.readfile(str(path)), []
    except OSError as exc:
        if exc.errno is not None:  # a system error; ezdxf's "is not a DXF file" has none
            raise InputError(f"{path}: cannot read the file ({exc.strerror})") from exc
        first: Exception = exc
    except (ezdxf.DXFError, UnicodeDecodeError, ValueError) as exc:
        first = exc
    with _captured_log("ezdxf") as messages:
        try:
            doc, auditor = recover.readfile(str(path))
        except (ezdxf.DXFError, UnicodeDecodeError, ValueError, OSError) as exc:
            raise InputError(
                f"{path}: not a readable DXF file ({first}); even ezdxf's recover mode "
                f"failed ({exc}); re-save or export it as DXF from the CAD program"
            ) from exc
    fixes = [f.message for f in auditor.fixes]
    repaired = messages + fixes
    shown = "; ".join(repaired[:5]) + (
        f"; and {len(repaired) - 5} more" if len(repaired) > 5 else ""
    )
    warning = (
        f"{path}: damaged DXF file ({first}); read in recover mode with "
        f"{len(fixes)} fixes and {len(auditor.errors)} unfixed errors"
        + (f": {shown}" if shown else "")
        + "; check the result, or re-save the file from the CAD program"
    )
    return doc, [warning]


class _captured_log:
    """Collect a logger's warnings (ezdxf logs what recover mode repaired) while active."""

    def __init__(self, name: str) -> None:
        self.logger = logging.getLogger(name)
        self.messages: list[str] = []
        self.handler = logging.Handler(logging.WARNING)
        self.handler.emit = lambda record: self.messages.append(record.getMessage())  # type: ignore[method-assign]

    def __enter__(self) -> list[str]:
        self.logger.addHandler(self.handler)
        self.propagate, self.logger.propagate = self.logger.propagate, False
        return self.messages

    def __exit__(self, *exc: object) -> None:
        self.logger.removeHandler(self.handler)
        self.logger.propagate = self.propagate


def _units(path: Path, code: int, warnings: list[str]) -> tuple[str, float]:
    if code == 0:
        warnings.append(f"{path}: drawing has no units ($INSUNITS = 0); assuming mm")
        return "mm (assumed)", 1.0
    if code not in _INSUNITS_MM:
        known = ", ".join(f"{c} ({n})" for c, (n, _) in sorted(_INSUNITS_MM.items()))
        raise InputError(f"{path}: unsupported $INSUNITS {code}; camtool knows {known}")
    return _INSUNITS_MM[code]


def _refuse_empty(path: Path, doc: Any, warnings: list[str]) -> None:
    """Model space is empty: say whether the drawing is in paper space instead."""
    layouts = [lay for lay in doc.layouts if not lay.is_modelspace and len(lay)]
    if layouts:
        names = ", ".join(repr(lay.name) for lay in layouts)
        raise InputError(
            f"{path}: model space is empty; the drawing is in paper space (layout {names}), "
            "which camtool does not read; move it to model space in the CAD program"
        )
    raise InputError(
        f"{path}: the drawing is empty (no entity in model space)"
        + "".join(f"\n  {w}" for w in warnings)
    )


def _layer_filter(path: Path, doc: Any, layers: tuple[str, ...] | None) -> Any:
    """A predicate on effective layer names; unknown names are an error listing the layers."""
    if layers is None:
        return lambda layer: True
    present = {layer.dxf.name for layer in doc.layers} | {
        e.dxf.get("layer", "0") for e in doc.modelspace()
    }
    by_key = {name.casefold(): name for name in present}
    unknown = [name for name in layers if name.casefold() not in by_key]
    if unknown:
        listed = ", ".join(repr(n) for n in unknown)
        raise InputError(
            f"{path}: no layer {listed} in the drawing; its layers are "
            + ", ".join(sorted(present, key=str.casefold))
        )
    wanted = {name.casefold() for name in layers}
    return lambda layer: layer.casefold() in wanted


def _rows(counts: Counter[tuple[str, str]]) -> tuple[tuple[str, str, int], ...]:
    return tuple((kind, layer, n) for (kind, layer), n in sorted(counts.items()))


def _scaled(p: Point | None, scale: float) -> Point | None:
    return None if p is None else (p[0] * scale, p[1] * scale)
