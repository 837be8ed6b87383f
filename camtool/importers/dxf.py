"""DXF importer (ezdxf): model space as contours in mm, arcs kept exact, curves fitted.

Design notes: docs/internals.md, ``camtool/importers/dxf.py``.
"""

from __future__ import annotations

import dataclasses
import io
import logging
import math
from collections import Counter
from collections.abc import Callable, Iterable
from contextlib import suppress
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from camtool.accel.collector import paused
from camtool.geometry.arcfit import FIT_KERNELS
from camtool.importers.dxf_damage import implied_degree, refuse_guessed_numbers
from camtool.importers.dxf_entities import (
    THREE_D,
    ZERO_LENGTH,
    BadEntity,
    check_numbers,
    invisible,
    layer_of,
    line_inside,
    not_flat,
)
from camtool.importers.dxf_layers import LayerFilter, hidden_warnings, layer_filter
from camtool.importers.dxf_prefit import MIN_SPLINES, fit_ahead, fitted_ahead
from camtool.importers.dxf_style import CONTINUOUS, Style, StyleResolver
from camtool.importers.dxf_subclass import missing_subclass, with_subclass_markers
from camtool.importers.options import MAX_COORDINATE_MM, ImportOptions
from camtool.model.errors import InputError, UsageError, not_a_file
from camtool.model.shapes import BBox, Contour, Drawing, Line, Mark, Point, bbox_union
from camtool.model.units import INCH, LENGTH_UNITS

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
_SKIP_REASONS: dict[str, str] = {
    **dict.fromkeys(("XLINE", "RAY"), "an infinite construction line, not a contour"),
    **dict.fromkeys(("TEXT", "MTEXT", "ATTRIB", "ATTDEF", "RTEXT"), _TEXT),
    **dict.fromkeys(
        (
            "DIMENSION",
            "ARC_DIMENSION",
            "LARGE_RADIAL_DIMENSION",
            "LEADER",
            "MULTILEADER",
            "MLEADER",
            "TOLERANCE",
        ),
        "annotation, not a contour",
    ),
    **dict.fromkeys(
        ("IMAGE", "PDFUNDERLAY", "DWFUNDERLAY", "DGNUNDERLAY", "OLE2FRAME"),
        "picture or underlay, not a contour",
    ),
    "WIPEOUT": (
        "a mask: what it covers on screen is still read and cut; trim those lines in the "
        "CAD program if they are not to be cut"
    ),
    "POINT": "a point has no path to cut; a drill operation of a job drills it",
    **dict.fromkeys(
        ("3DFACE", "3DSOLID", "MESH", "BODY", "REGION", "SURFACE", "POLYFACE", "POLYMESH"),
        THREE_D,
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
        repairs: what recover mode repaired or could not (ezdxf's auditor and log), or what
            ezdxf's reader logged about a file it read without recovering, one
            message each; the user warning only gives their count.
        converted: an entity other than a plain LINE was read, whose contours may
            depend on the tolerance (a fitted curve, a joined boundary); ``False``: the
            drawing is the same at any tolerance.
    """

    drawing: Drawing
    units: str
    mm_per_unit: float
    entity_counts: tuple[tuple[str, str, int], ...] = field(default=())
    block_entity_counts: tuple[tuple[str, str, int], ...] = field(default=())
    notes: tuple[DxfNote, ...] = field(default=())
    recovered: bool = False
    repairs: tuple[str, ...] = field(default=())
    converted: bool = True


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
            recovery (a coordinate that is not a number, such as ``2,5``: see
            :func:`camtool.importers.dxf_damage.refuse_guessed_numbers`); it uses an
            unknown ``$INSUNITS`` code; ``options.layers`` names a layer the drawing
            does not have; or model space (on the selected layers) holds nothing
            camtool can cut. The message names the file.
        UsageError: ``options.tolerance`` is not > 0.
    """
    return import_dxf(path, options).drawing


def import_dxf(
    path: str | Path,
    options: ImportOptions | None = None,
    *,
    check: Callable[[BBox], None] | None = None,
) -> DxfImport:
    """Read a DXF file like :func:`read_dxf` and also count its entities by type and layer.

    Args:
        path: the DXF file.
        options: importer options; ``None`` takes the defaults.
        check: called, as entities are read, with the extent of the contours read so far
            (mm, a box within the drawing's): what it raises stops the reading before the
            other curves are fitted (``camtool post`` refuses there a drawing too large for
            the machine).

    Raises:
        InputError: as :func:`read_dxf`.
        UsageError: ``options.tolerance`` is not > 0.
        Whatever ``check`` raises.
    """
    path = Path(path)
    options = options or ImportOptions()
    if not options.tolerance > 0:
        raise UsageError(f"the tolerance must be > 0 mm, got {options.tolerance!r}")
    with paused():
        return _import(path, options, check)


_CHECK_EVERY = 4096
"""Contours of plain LINEs read between two calls of an import's ``check`` (a curve's
contours are checked as soon as they are read: fitting them is what the check saves)."""


def _import(
    path: Path, options: ImportOptions, check: Callable[[BBox], None] | None = None
) -> DxfImport:
    doc, damage, repairs = _open(path)
    recovered = damage is not None
    warnings = [] if damage is None else [_damaged(path, damage, repairs)]
    if damage is None and repairs:
        warnings.append(
            f"{path}: ezdxf noted {len(repairs)} problem(s) while reading it ({repairs[0]}); "
            "check the result (`camtool inspect` lists them), or re-save the file from the "
            "CAD program"
        )
    units, scale = _units(
        path, _insunits(path, doc, recovered), warnings, options.units, _imperial(doc)
    )
    try:
        msp = doc.modelspace()
    except KeyError:  # a damaged file ezdxf recovered without its Model layout
        raise InputError(
            f"{path}: no model space (its *Model_Space block record or Model layout is "
            "damaged); re-save or export it as DXF from the CAD program"
        ) from None
    if len(msp) == 0:
        _refuse_empty(path, doc, damage)
    keep = layer_filter(path, doc, options.layers, options.shown)
    from camtool.importers.dxf_blocks import checked_block_graph

    graph = checked_block_graph(str(path), msp, options.max_entities)
    limit = MAX_COORDINATE_MM / max(scale, 1.0)
    reader = _Reader(options.tolerance / scale, options.hatch_boundaries, keep, limit, graph)
    reader.styles = StyleResolver(doc)
    try:
        with _captured_log("ezdxf") as logged:  # in camtool's words, not a bare line
            if check is None:
                with fitted_ahead(_splines_ahead(msp, reader)):
                    for entity in msp:
                        reader.read(entity)
            else:  # refused as soon as the drawing is too large: fitted as read
                _read_checked(reader, msp, scale, check)
    except BadEntity as exc:
        raise InputError(f"{path}: {exc}") from None
    if logged:
        warnings.append(
            f"{path}: ezdxf logged {len(logged)} message(s) while reading the entities "
            f"(first: {logged[0]}); check the result in the preview"
        )
    for (kind, reason), count in sorted(reader.skipped.items()):
        plural = "entity" if count == 1 else "entities"
        warnings.append(f"{path}: skipped {count} {kind} {plural} ({reason})")
    warnings += hidden_warnings(path, keep, reader.invisible)
    if reader.swapped:
        label, ratio = reader.swapped[0]
        warnings.append(
            f"{path}: {len(reader.swapped)} ELLIPSE(s) with an axis ratio above 1, the DXF "
            f"range being (0, 1] (first {label}, ratio {ratio:g}): read as the curve their "
            "numbers describe, the longer axis being the minor one (as ezdxf's auditor "
            "repairs it by swapping the axes); check it in the preview"
        )
    if reader.redegreed:
        label, declared, implied = reader.redegreed[0]
        warnings.append(
            f"{path}: {len(reader.redegreed)} SPLINE(s) whose knots and control points make "
            f"another degree than the one they declare (first {label}: declared {declared}, "
            f"its data that of degree {implied}): read at the degree of their data, the one "
            "curve those numbers describe; check it in the preview"
        )
    if reader.wide:
        label, width = reader.wide[0]
        warnings.append(
            f"{path}: {len(reader.wide)} polyline(s) drawn with a width (first {label}, "
            f"{width * scale:.4g} mm wide): camtool cuts a polyline's centre line, not the edges "
            "of the band it draws; to cut the edges, draw them as contours"
        )
    if not reader.contours and not reader.marks:
        on = f" on layers {', '.join(options.layers)}" if options.layers else ""
        raise InputError(
            f"{path}: no usable entity in model space{on}; camtool cuts LINE, ARC, CIRCLE, "
            "ELLIPSE, SPLINE, LWPOLYLINE, 2D POLYLINE and MLINE entities (also inside blocks)"
            + "".join(f"\n  {w}" for w in warnings)
        )
    contours = tuple(c.transformed(scale, 0.0, 0.0) if scale != 1.0 else c for c in reader.contours)
    marks = tuple(m.transformed(scale, 0.0, 0.0) if scale != 1.0 else m for m in reader.marks)
    notes = tuple(
        DxfNote(n.source, n.layer, n.reason, _scaled(n.location, scale)) for n in reader.notes
    )
    return DxfImport(
        drawing=Drawing(contours, str(path), tuple(warnings), marks),
        units=units,
        mm_per_unit=scale,
        entity_counts=_rows(reader.counts),
        block_entity_counts=_rows(reader.block_counts),
        notes=notes,
        recovered=recovered,
        repairs=tuple(repairs),
        converted=reader.converted,
    )


def _splines_ahead(msp: Any, reader: _Reader) -> dict[int, Any]:
    """The model space's SPLINEs on the layers read, fitted on the cores (:mod:`.dxf_prefit`)."""
    from camtool.importers.dxf_entities import check_numbers, layer_of, spline_segments

    splines = [e for e in msp.query("SPLINE") if reader.keep.reads(layer_of(e))]
    if len(splines) < MIN_SPLINES:
        return {}

    def check(entity: Any) -> None:
        check_numbers(entity, "", layer_of(entity), reader.limit)

    if FIT_KERNELS.get(len(splines)) is not None:  # loaded once, for every worker too
        # the reader fits a clamped quadratic or cubic one as its Bézier spans, compiled,
        # faster than a worker's answer comes back: only the others go to the pool
        splines = [e for e in splines if not _bezier_spans(e)]
        if len(splines) < MIN_SPLINES:
            return {}
    return fit_ahead(splines, reader.tolerance, spline_segments, check)


def _bezier_spans(spline: Any) -> bool:
    """Whether a SPLINE looks fitted as its Bézier spans (degree 2 or 3, no weights).

    A look at the entity, not its curve: a wrong answer changes where it is fitted, not
    the fit (:func:`~camtool.importers.dxf_entities.spline_segments` decides).
    """
    return int(spline.dxf.degree) in (2, 3) and len(spline.weights) == 0


def _read_checked(
    reader: _Reader, entities: Iterable[Any], scale: float, check: Callable[[BBox], None]
) -> None:
    """Read ``entities``, calling ``check`` with the extent read so far (mm) as it grows.

    A block reference's content counts as each entity of it is placed (MINSERT cells too).
    """
    box: BBox | None = None
    done = 0

    def checkpoint() -> None:
        nonlocal box, done
        new = len(reader.contours) - done
        if new and (new >= _CHECK_EVERY or not _one_line(reader.contours[-1])):
            boxes = [c.bbox() for c in reader.contours[done:]]
            box = bbox_union(boxes if box is None else [box, *boxes])
            done = len(reader.contours)
            check((box[0] * scale, box[1] * scale, box[2] * scale, box[3] * scale))

    reader.checkpoint = checkpoint
    for entity in entities:
        reader.read(entity)
        checkpoint()


def _one_line(contour: Contour) -> bool:
    return len(contour.segments) == 1 and type(contour.segments[0]) is Line


class _Reader:
    """Walks model space once; collects contours, skip counts, notes and entity counts."""

    def __init__(
        self, tolerance: float, hatch: bool, keep: LayerFilter, limit: float, graph: Any
    ) -> None:
        self.tolerance = tolerance  # drawing units
        self.hatch = hatch
        self.keep = keep
        self.limit = limit  # largest number accepted, drawing units
        self.cyclic = graph.cyclic
        self.contours: list[Contour] = []
        self.marks: list[Mark] = []
        self.styles: StyleResolver | None = None
        self.skipped: Counter[tuple[str, str]] = Counter()
        self.notes: list[DxfNote] = []
        self.counts: Counter[tuple[str, str]] = Counter()
        self.block_counts: Counter[tuple[str, str]] = Counter()
        self.converted = False  # an entity went through the converters (and the tolerance)
        self.invisible = 0  # entities left out for their invisible flag (group code 60)
        self.swapped: list[tuple[str, float]] = []  # ELLIPSEs with a ratio above 1
        self.redegreed: list[tuple[str, int, int]] = []  # SPLINEs read at another degree
        self.wide: list[tuple[str, float]] = []  # polylines drawn with a width (label, widest)
        self.checkpoint: Callable[[], None] = lambda: None  # called as a block places content

    def read(self, entity: Any) -> None:
        from camtool.importers.dxf_blocks import HIDDEN, INVISIBLE, Skip, expand_insert
        from camtool.importers.dxf_entities import Item

        kind = entity.dxftype()
        dxf = entity.dxf
        layer = layer_of(entity)
        self.counts[(kind, layer)] += 1
        if kind == "LINE" and not dxf.hasattr("extrusion"):
            self._line(entity, layer)
            return
        if kind != "INSERT":
            self._item(Item(entity, f"{kind} #{dxf.handle}", layer))
            return
        if invisible(entity):  # a hidden block reference hides its content
            self.invisible += self.keep(layer)
            return
        if self.keep.freezes(layer):
            return
        block = self._style(entity, layer)
        for placed in expand_insert(entity, layer, self.limit, self.cyclic, self.keep.freezes):
            if placed is HIDDEN:  # a nested block reference on a frozen layer (counted)
                continue
            if placed is INVISIBLE:
                self.invisible += 1
                continue
            if isinstance(placed, Skip):
                self.block_counts[(placed.kind, placed.layer)] += 1
                if self.keep(placed.layer):
                    self._skip(
                        placed.kind, placed.reason, placed.label, placed.layer, placed.location
                    )
            else:
                self.block_counts[(placed.entity.dxftype(), placed.layer)] += 1
                self._item(placed, block)
                self.checkpoint()  # a MINSERT of 10⁶ cells too large is refused at once

    def _line(self, entity: Any, layer: str) -> None:
        """A model-space LINE, read as ``_item`` would read it, without its machinery.

        LINEs are the bulk of large drawings; this skips the Item, the generic number
        check and the converter (10⁵ LINEs: 2.3 s of CPU before, 0.6 s after).
        """
        if not self.keep(layer):
            return
        if invisible(entity):
            self.invisible += 1
            return
        dxf = entity.dxf
        s, e = dxf.start, dxf.end
        if not line_inside(entity, self.limit):
            check_numbers(entity, f"LINE #{dxf.handle}", layer, self.limit)  # raises
        start, end = (s.x, s.y), (e.x, e.y)
        label = f"LINE #{dxf.handle}"
        if s.z != e.z and not_flat((s.z, e.z)):
            self._skip("LINE", THREE_D, label, layer, start)
            return
        if math.hypot(end[0] - start[0], end[1] - start[1]) <= ZERO_LENGTH:
            self._skip("LINE", "zero length", label, layer, start)
            return
        colour, linetype = self._style(entity, layer)
        self.contours.append(Contour((Line(start, end),), False, layer, label, colour, linetype))

    def _style(self, entity: Any, layer: str, block: Style = CONTINUOUS) -> Style:
        """How ``entity`` is drawn (:class:`~camtool.importers.dxf_style.StyleResolver`)."""
        if self.styles is None:
            return CONTINUOUS
        return self.styles.style(entity, layer, block)

    def _mark(self, item: Any, block: Style) -> None:
        """A POINT: a mark a drill operation may select (nothing to cut otherwise)."""
        check_numbers(item.entity, item.label, item.layer, self.limit)
        at = self._where(item)
        if at is not None:
            colour = self._style(item.entity, item.layer, block)[0]
            self.marks.append(Mark(at, item.layer, item.label, colour))

    def _item(self, item: Any, block: Style = CONTINUOUS) -> None:
        from camtool.importers.dxf_entities import (
            CONVERTED,
            Unsupported,
            check_centres,
            check_numbers,
            convert,
            swapped_axes,
        )

        if not self.keep(item.layer):
            return
        if invisible(item.entity):
            self.invisible += 1
            return
        kind = _kind(item.entity)
        if kind == "POINT":
            self._mark(item, block)
        if kind == "MLINE":
            self._mline(item, block)
            return
        if kind not in CONVERTED or (kind == "HATCH" and not self.hatch):
            reason = _SKIP_REASONS.get(kind, "not a 2D contour camtool cuts")
            self._skip(kind, reason, item.label, item.layer, self._where(item))
            return
        check_numbers(item.entity, item.label, item.layer, self.limit)
        for part in item.parts:
            check_numbers(part, item.label, item.layer, self.limit)
        if swapped_axes(item.entity):
            self.swapped.append((item.label, float(item.entity.dxf.ratio)))
        width = _width(item.entity, kind)
        if width > 0.0:
            self.wide.append((item.label, width))
        implied = implied_degree(item.entity)
        if implied is not None:
            self.redegreed.append((item.label, int(item.entity.dxf.degree), implied))
        self.converted = True
        try:
            contours = convert(item, self.tolerance, self.limit)
        except BadEntity as exc:  # the converters do not know the entity's name
            if str(exc).startswith(item.label):
                raise
            raise BadEntity(f"{item.label} on layer {item.layer!r}: {exc}") from None
        except Unsupported as exc:
            detail = exc.reason + (f": {exc.detail}" if exc.detail else "")
            self._skip(kind, exc.reason, item.label, item.layer, self._where(item), detail)
            return
        check_centres(contours, item.layer, self.limit)
        style = self._style(item.entity, item.layer, block)
        if style != CONTINUOUS:
            contours = [
                dataclasses.replace(c, colour=style[0], linetype=style[1]) for c in contours
            ]
        self.contours.extend(contours)

    def _mline(self, item: Any, block: Style) -> None:
        """A model-space MLINE: the lines and arcs of its elements and caps, as drawn.

        Its geometry is what ezdxf draws of it (``MLine.virtual_entities``, from the
        vertices' miter directions and the MLINESTYLE's element offsets); a fill is not
        cut. (An MLINE in a block is exploded where the block is placed.)
        """
        from camtool.importers.dxf_blocks import mline_parts
        from camtool.importers.dxf_entities import Item

        parts = mline_parts(item.entity)
        if isinstance(parts, str):
            self._skip("MLINE", parts, item.label, item.layer, self._where(item))
            return
        for n, part in enumerate(parts, start=1):
            self._item(Item(part, f"{part.dxftype()} {n} of {item.label}", item.layer), block)

    @staticmethod
    def _where(item: Any) -> Point | None:
        from camtool.importers.dxf_entities import location

        return item.at if item.at is not None else location(item.entity)

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


def _width(entity: Any, kind: str) -> float:
    """The widest a 2D polyline is drawn (its constant, start and end widths), drawing units.

    0.0 for another entity, or a polyline drawn as a line.
    """
    if kind == "LWPOLYLINE":
        ends = [w for start, end in entity.get_points("se") for w in (start, end)]
        return float(max([entity.dxf.const_width, *ends]))
    if kind == "POLYLINE" and entity.is_2d_polyline:
        dxf = entity.dxf
        ends = [w for v in entity.vertices for w in (v.dxf.start_width, v.dxf.end_width)]
        return float(max([dxf.default_start_width, dxf.default_end_width, *ends]))
    return 0.0


def _kind(entity: Any) -> str:
    """DXF type, with polyface and polygon mesh POLYLINEs told apart from 2D/3D ones."""
    kind = entity.dxftype()
    if kind == "POLYLINE" and entity.is_poly_face_mesh:
        return "POLYFACE"
    if kind == "POLYLINE" and entity.is_polygon_mesh:
        return "POLYMESH"
    return kind


_PARSER_ERRORS = (
    UnicodeDecodeError,
    ValueError,
    ArithmeticError,  # int(float("inf")) of an integer group code: OverflowError
    StopIteration,
    EOFError,
    IndexError,
    KeyError,
    AttributeError,  # dxf-parser's blocks.dxf: a VIEWPORT's missing XDATA (ezdxf 1.4)
    TypeError,
    AssertionError,  # ezdxf's layouts audit asserts each name is text (a damaged LAYOUT)
)
"""What ezdxf's reader raises on damaged files besides DXFError (a DXF cut short in its
HEADER ends ezdxf's ``dxf_info`` scan with a bare StopIteration)."""


def _open(path: Path) -> tuple[Any, str | None, list[str]]:
    """The document, why it had to be recovered (None: it did not), and the repairs."""
    import ezdxf
    from ezdxf import recover

    if not path.is_file():
        raise not_a_file(path)
    if path.stat().st_size == 0:
        raise InputError(f"{path}: empty file; export the drawing again from the CAD program")
    try:
        with _captured_log("ezdxf") as noted:  # on stderr as it was, not camtool's words
            return ezdxf.readfile(str(path)), None, noted
    except OSError as exc:
        if exc.errno is not None:  # a system error; ezdxf's "is not a DXF file" has none
            raise InputError(f"{path}: cannot read the file ({exc.strerror})") from exc
        first: BaseException = exc
    except (ezdxf.DXFError, *_PARSER_ERRORS) as exc:
        first = exc
    marked = None
    with _captured_log("ezdxf") as messages:
        try:
            try:
                doc, auditor = recover.readfile(str(path))
            except (ezdxf.DXFError, *_PARSER_ERRORS) as exc:
                if not missing_subclass(_reason(exc)):
                    raise
                marked = with_subclass_markers(path.read_bytes())
                if not marked.counts:
                    raise
                messages.clear()
                doc, auditor = recover.read(io.BytesIO(marked.data))
        except (ezdxf.DXFError, OSError, *_PARSER_ERRORS) as exc:
            raise InputError(
                f"{path}: not a readable DXF file ({_reason(first)}); even ezdxf's recover "
                f"mode failed ({_reason(exc)}); re-save or export it as DXF from the CAD "
                "program"
            ) from None
    refuse_guessed_numbers(path, messages, marked.original_line if marked else None)
    fixes = [f"fixed: {f.message}" for f in auditor.fixes]
    if marked is not None:  # read with its markers: said first
        kinds = ", ".join(f"{n} {kind}" for kind, n in sorted(marked.counts.items()))
        fixes.insert(
            0,
            f"fixed: {kinds} without subclass markers (as small DXF writers write them) "
            "read by their group codes",
        )
    errors = [f"not fixed: {e.message}" for e in auditor.errors]
    return doc, _reason(first), messages + fixes + errors


def _damaged(path: Path, reason: str, repairs: list[str]) -> str:
    """The one-line warning for a file read in recover mode (details: ``camtool inspect``)."""
    fixed = sum(r.startswith("fixed: ") for r in repairs)
    unfixed = sum(r.startswith("not fixed: ") for r in repairs)
    return (
        f"{path}: damaged DXF file ({reason}); read in recover mode with {fixed} fixes and "
        f"{unfixed} unfixed errors; check the result (`camtool inspect` lists the repairs), "
        "or re-save the file from the CAD program"
    )


def _reason(exc: BaseException) -> str:
    """An exception as a short phrase: its message, else its type's name."""
    if isinstance(exc, EOFError):
        return "the file ends too early"
    if isinstance(exc, StopIteration):  # ezdxf ran out of a table's or block's tags
        return "a table or block ends before it begins: a stray ENDTAB or ENDBLK"
    text = " ".join("".join(c if c.isprintable() else " " for c in str(exc)).split())
    text = text if len(text) <= 120 else text[:117] + "..."
    return text or type(exc).__name__


def _insunits(path: Path, doc: Any, recovered: bool) -> int:
    """``$INSUNITS`` as the file gives it; 0 when the file has no HEADER section.

    ezdxf fills a missing HEADER with its defaults for new drawings, ``$INSUNITS`` 6 (m),
    which would make a headerless R12 file 1000 times too big. Recover mode builds the
    header from the file only, so its value is the file's.
    """
    if recovered or _has_header(path):
        return doc.header.get("$INSUNITS", 0)
    return 0


def _has_header(path: Path) -> bool:
    """Whether the (readable) DXF file has a HEADER section, found by its raw tags.

    The scan stops at the first section when it is the HEADER (where DXF puts it); a
    file whose first section is another one is scanned to its end.
    """
    from ezdxf.lldxf.tagger import ascii_tags_loader, binary_tags_loader
    from ezdxf.lldxf.validator import is_binary_dxf_file

    with path.open("rb") as raw:
        if is_binary_dxf_file(str(path)):
            tags = binary_tags_loader(raw.read())
            return _header_in(tags)
    with path.open(encoding="latin-1") as text:  # section names are ASCII
        return _header_in(ascii_tags_loader(text))


def _header_in(tags: Any) -> bool:
    previous = None
    for tag in tags:
        if previous == (0, "SECTION") and tag.code == 2 and tag.value == "HEADER":
            return True
        previous = tag
    return False


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


def _imperial(doc: Any) -> bool:
    """Whether the header says the drawing was made with imperial settings (``$MEASUREMENT = 0``).

    ``$MEASUREMENT`` chooses the hatch and line-type files, not the unit of the
    coordinates, so it is only a hint for a drawing without ``$INSUNITS``.
    """
    try:
        return "$MEASUREMENT" in doc.header and int(doc.header["$MEASUREMENT"]) == 0
    except (TypeError, ValueError):
        return False


def _units(
    path: Path, code: int, warnings: list[str], given: str | None, imperial: bool = False
) -> tuple[str, float]:
    """The drawing unit and its size in mm: the file's ``$INSUNITS``, else ``--units``.

    ``imperial``: the header's ``$MEASUREMENT`` is 0 (:func:`_imperial`); the warning for
    a drawing without units then says so, as the likeliest unit is the inch.

    Raises:
        InputError: an ``$INSUNITS`` camtool does not know.
        UsageError: ``--units`` for a drawing that declares another unit.
    """
    if code == 0:
        if given is not None:
            return given, LENGTH_UNITS[given]
        hint = (
            "; its $MEASUREMENT = 0 says it was made with imperial settings: give --units in "
            "if it was drawn in inches"
            if imperial
            else " (give --units in, cm ... if it was drawn in another unit)"
        )
        warnings.append(
            f"{path}: drawing has no units ($INSUNITS = 0 or not in the file); assuming mm" + hint
        )
        return "mm (assumed)", 1.0
    if code not in _INSUNITS_MM:
        known = ", ".join(f"{c} ({n})" for c, (n, _) in sorted(_INSUNITS_MM.items()))
        raise InputError(f"{path}: unsupported $INSUNITS {code}; camtool knows {known}")
    declared = _INSUNITS_MM[code]
    if given is not None and not math.isclose(LENGTH_UNITS[given], declared[1]):
        raise UsageError(
            f"--units {given}: {path} declares its unit, {declared[0]} ($INSUNITS = {code}); "
            "--units is for a drawing without units: leave it out, or use --scale to resize"
        )
    return declared


def _refuse_empty(path: Path, doc: Any, damage: str | None) -> None:
    """Model space is empty: say whether the drawing is in paper space instead."""
    layouts = []
    for lay in doc.layouts:
        with suppress(AttributeError, KeyError, TypeError):  # a layout damaged past repair
            if not lay.is_modelspace and len(lay):
                layouts.append(lay.name)
    if layouts:
        names = ", ".join(repr(name) for name in layouts)
        raise InputError(
            f"{path}: model space is empty; the drawing is in paper space (layout {names}), "
            "which camtool does not read; move it to model space in the CAD program"
        )
    if damage is not None:
        raise InputError(
            f"{path}: damaged DXF file ({damage}) with nothing left in model space; "
            "re-save or export it as DXF from the CAD program"
        )
    raise InputError(f"{path}: the drawing is empty (no entity in model space)")


def _rows(counts: Counter[tuple[str, str]]) -> tuple[tuple[str, str, int], ...]:
    return tuple((kind, layer, n) for (kind, layer), n in sorted(counts.items()))


def _scaled(p: Point | None, scale: float) -> Point | None:
    return None if p is None else (p[0] * scale, p[1] * scale)
