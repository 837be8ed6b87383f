"""One DXF entity (or a transformed copy of one from a block) as contours, in drawing units.

LINE, ARC, CIRCLE, LWPOLYLINE and 2D POLYLINE are exact (bulges become arcs; bulge > 0 is
counter-clockwise in the entity's OCS). HATCH boundary paths become closed contours.
Entities with an extrusion of (0, 0, −1) are mirrored into the WCS, which flips their arcs'
direction; entities tilted out of the XY plane are refused.

Design notes: docs/internals.md, ``camtool/importers/dxf_entities.py``.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from camtool.geometry.arcfit import FIT_KERNELS, FloatArray, PointsFn
from camtool.geometry.chain import closes_alone, with_end, with_start
from camtool.geometry.curves import corner_knots, ellipse, ellipse_extent, fit_pieces, joined_run
from camtool.geometry.fitpool import fit_key
from camtool.importers.dxf_damage import implied_degree
from camtool.importers.dxf_hatch import boundary_entities
from camtool.importers.dxf_prefit import take
from camtool.importers.options import check_curve_size
from camtool.model.errors import GeometryError, UsageError
from camtool.model.shapes import TAU, Arc, Contour, Line, Point, Segment, distance

_RELATIVE = 1e-9  # times the size: a z spread that is still planar, ends that coincide
_CIRCULAR = 1e-3  # an ellipse whose axes differ by < this share of the tolerance is a circle


class Unsupported(Exception):
    """An entity that cannot become a contour; ``reason`` is the user-facing why."""

    def __init__(self, reason: str, detail: str = "") -> None:
        super().__init__(reason)
        self.reason = reason
        self.detail = detail


class BadEntity(ValueError):
    """An entity holds a number camtool refuses; the message names the entity and value.

    Raised by :func:`camtool.importers.dxf_entities.check_numbers`; the DXF importer
    turns it into an :class:`~camtool.model.errors.InputError` naming the file.
    """


CONVERTED = ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE", "ELLIPSE", "SPLINE", "HATCH")
"""Entity types that become contours (HATCH only with ``hatch_boundaries``)."""

ZERO_LENGTH = 1e-9
"""Drawing units: segments shorter than this are dropped as zero-length."""

# Entities whose centre or insertion point is stored in their OCS (DXF reference).
_OCS_POINTS = frozenset({"ARC", "CIRCLE", "TEXT", "ATTRIB", "INSERT", "SHAPE"})
_WCS_PATHS = frozenset({"LINE", "SPLINE", "POINT"})
"""Entities whose path is in world coordinates: their extrusion (a SPLINE's normal, a
LINE's thickness direction) does not place them, so a null one is no damage. AutoCAD 2007
writes SPLINEs with the normal (0, 0, 0) (bjnortier/dxf's splines.dxf)."""
THREE_D = "3D entity; camtool cuts 2D contours"
"""Why an entity whose points are not at one Z is skipped."""
_MAX_RATIO = 1.0 + 1e-9  # ELLIPSE minor/major axis ratio, (0, 1] in the DXF reference


def line_inside(entity: Any, limit: float) -> bool:
    """True when both ends of a LINE are finite and within ``limit`` (drawing units).

    Not ``max()``: ``max()`` drops a NaN that is not its first argument; every
    comparison with NaN is false, so a NaN end is never inside.
    """
    s, e = entity.dxf.start, entity.dxf.end
    return (
        abs(s.x) <= limit
        and abs(s.y) <= limit
        and abs(s.z) <= limit
        and abs(e.x) <= limit
        and abs(e.y) <= limit
        and abs(e.z) <= limit
    )


def check_numbers(entity: Any, label: str, layer: str, limit: float) -> None:
    """Refuse an entity with a number that is NaN, infinite or beyond ``±limit``.

    Every float attribute (points, radius, angles, scales, bulges, ratio, extrusion ...)
    and the vertex, control point, fit point, knot and weight arrays are checked, so the
    converters downstream can trust them. Also refused: a zero extrusion vector (no
    plane) on an entity placed by it (not a LINE, SPLINE or POINT: :data:`_WCS_PATHS`).

    Args:
        entity: an ezdxf entity (model space, block content, or a virtual one).
        label: how messages name it, e.g. ``"LINE #2A"``.
        layer: its effective layer, for the message.
        limit: largest magnitude accepted, drawing units (the importer passes
            :data:`~camtool.importers.options.MAX_COORDINATE_MM` converted to drawing units).

    Raises:
        BadEntity: the message names the entity, its layer, the attribute and the value.
    """
    what = _bad_number(entity, limit)
    if what is not None:
        text, finite = what
        if finite:  # a drawing in map coordinates (UTM northings are thousands of km)
            raise BadEntity(
                f"{label} on layer {layer!r}: {text}, beyond ±{_short(limit)} drawing units "
                "from 0, as far as camtool plans with sub-micrometre precision; move the "
                "drawing near 0 in the CAD program (a plan in map coordinates) or fix the "
                "entity, and export again"
            )
        raise BadEntity(
            f"{label} on layer {layer!r}: {text}, not a finite number within ±{_short(limit)} "
            "(drawing units); the file is damaged: fix or delete the entity in the CAD "
            "program and export again"
        )
    shape = _bad_shape(entity)
    if shape is not None:
        raise BadEntity(
            f"{label} on layer {layer!r}: {shape}; the file is damaged: fix or delete the "
            "entity in the CAD program and export again"
        )


def _bad_number(entity: Any, limit: float) -> tuple[str, bool] | None:
    """The first number out of range, else None.

    Returns ``("<attribute> <value>", finite)``: ``finite`` when its numbers are all finite
    (then only too large: a drawing far from 0), not when one is NaN or infinite.
    """
    from ezdxf.math import Vec2, Vec3

    kind = entity.dxftype()
    if kind == "LINE":  # the bulk of large drawings: four numbers, checked directly
        inside = line_inside(entity, limit)
        if inside and not entity.dxf.hasattr("extrusion"):
            return None
    for name, value in entity.dxf.all_existing_dxf_attribs().items():
        if isinstance(value, float):
            if not abs(value) <= limit:
                return f"{name} {value:g}", math.isfinite(value)
        elif (
            isinstance(value, tuple | Vec2 | Vec3)
            and all(isinstance(v, float) for v in value)
            and not all(abs(v) <= limit for v in value)
        ):
            return f"{name} ({', '.join(f'{v:g}' for v in value)})", all(
                math.isfinite(v) for v in value
            )
    for name, rows in _arrays(entity):
        values = np.asarray(rows, dtype=float)
        if values.size and not bool((np.abs(values) <= limit).all()):
            values = values.reshape(len(values), -1)
            k = int(np.flatnonzero(~(np.abs(values) <= limit).all(axis=1))[0])
            shown = ", ".join(f"{v:g}" for v in values[k])
            return f"{name} {k + 1} ({shown})", bool(np.isfinite(values[k]).all())
    if kind == "POLYLINE":
        for k, vertex in enumerate(entity.vertices, start=1):
            what = _bad_number(vertex, limit)
            if what is not None:
                return f"vertex {k} {what[0]}", what[1]
    return None


def _short(value: float) -> str:
    """``1e9`` rather than ``1e+09``."""
    return f"{value:g}".replace("e+0", "e").replace("e+", "e")


def _arrays(entity: Any) -> list[tuple[str, Any]]:
    """Name and rows of the number arrays an entity keeps outside its DXF attributes."""
    kind = entity.dxftype()
    if kind == "LWPOLYLINE":
        return [("vertex (x, y, start width, end width, bulge)", entity.lwpoints.values)]
    if kind == "SPLINE":
        return [
            ("control point", entity.control_points.values),
            ("fit point", entity.fit_points.values),
            ("knot", entity.knots),
            ("weight", entity.weights),
        ]
    return []


def _bad_shape(entity: Any) -> str | None:
    """What makes the entity's numbers meaningless though finite, else None."""
    extrusion = entity.dxf.get("extrusion", None)
    if (
        extrusion is not None
        and not math.hypot(*extrusion) > 1e-12
        and entity.dxftype() not in _WCS_PATHS
    ):
        return f"extrusion {tuple(float(v) for v in extrusion)} is not a direction"
    if entity.dxftype() == "INSERT":  # MINSERT too: ezdxf reads both as Insert
        for axis in ("xscale", "yscale"):
            if entity.dxf.get(axis, 1.0) == 0.0:
                # The DXF reference asks a non-zero scale: an X or Y scale 0 folds the block
                # onto a line (ezdxf cannot transform it either). A Z scale 0 only flattens
                # what is already flat, so it is read.
                return f"{axis} 0: a block inserted at scale 0 has no size"
    if entity.dxftype() == "POLYLINE":
        for k, vertex in enumerate(entity.vertices, start=1):
            if vertex.dxf.get("location", None) is None:
                return f"vertex {k} has no location (group codes 10 and 20)"
    return None


def swapped_axes(entity: Any) -> bool:
    """Whether ``entity`` is an ELLIPSE whose axis ratio is above 1 (the DXF range is (0, 1]).

    Its numbers still describe one curve, ``c + M cos t + ratio · (Z × M) sin t``: the
    minor axis is the longer. It is read as that curve, as ezdxf's auditor repairs it
    (swapping the axes) and as viewers draw it; the importer warns.
    """
    return entity.dxftype() == "ELLIPSE" and abs(entity.dxf.get("ratio", 1.0)) > _MAX_RATIO


def check_centres(contours: Sequence[Contour], layer: str, limit: float) -> None:
    """Refuse arcs whose centre lies beyond ``±limit`` (a huge radius from a bulge).

    The ends of every segment come from numbers :func:`check_numbers` bounded; a centre
    is derived and can still be far away (a bulge of 1e-8 on a long chord).

    Raises:
        BadEntity: naming the contour's entity and the centre.
    """
    for contour in contours:
        for seg in contour.segments:
            if isinstance(seg, Arc) and not (
                abs(seg.centre[0]) <= limit and abs(seg.centre[1]) <= limit
            ):
                x, y = seg.centre
                raise BadEntity(
                    f"{contour.source} on layer {layer!r}: an arc of it has its centre at "
                    f"({x:g}, {y:g}), beyond ±{_short(limit)} (drawing units): a radius or bulge "
                    "too large to cut; fix the entity in the CAD program"
                )


@dataclass(frozen=True)
class Item:
    """An entity ready to convert: the (possibly virtual, transformed) entity and its names.

    Attributes:
        entity: the ezdxf entity, already in WCS drawing units.
        label: how messages name it, e.g. ``"LINE #1A in INSERT #3B (block 'BOLT')"``.
        layer: its effective layer (block content on layer ``0`` takes the INSERT's).
        parts: for an entity exploded to be transformed (a polyline with bulges under a
            non-uniform scale), its pieces placed, in order (:func:`join_pieces` joins them).
        at: for block content not transformed (counted, or a HATCH): where it is, WCS units.
        place: for a HATCH in a block (``entity`` as drawn there), places a boundary piece.
    """

    entity: Any
    label: str
    layer: str
    parts: tuple[Any, ...] = field(default=())
    at: Point | None = None
    place: Callable[[Any], tuple[Any, ...]] | None = None


def convert(item: Item, tolerance: float, limit: float = math.inf) -> list[Contour]:
    """The contours of one entity, in drawing units, Y up.

    Args:
        item: the entity and its names; its type must be one of :data:`CONVERTED`;
            its numbers already checked (:func:`check_numbers`).
        tolerance: fitting and joining tolerance, drawing units (> 0).
        limit: largest number accepted in a HATCH's boundary edges, drawing units.

    Returns:
        One contour, or for a HATCH one per boundary path.

    Raises:
        Unsupported: the entity is tilted out of XY, 3D, empty or has zero length.
        BadEntity: a HATCH boundary edge holds a number beyond ``limit``.
    """
    entity = item.entity
    kind = entity.dxftype()
    if item.parts:
        pieces = [_piece(part, tolerance) for part in item.parts]
        return [
            Contour(tuple(segs), shut, item.layer, item.label)
            for segs, shut in join_pieces(pieces, tolerance)
        ]
    if kind == "HATCH":
        return _hatch(item, tolerance, limit)
    segs, closed = _segments(entity, tolerance)
    return [Contour(tuple(segs), closed, item.layer, item.label)]


def layer_of(entity: Any) -> str:
    """The entity's own layer name (:func:`layer_name`); ``"0"`` when it has none.

    An entity may leave out group code 8 (R12 files do), and an entity of a type ezdxf
    does not know has no ``layer`` attribute at all (asking raises DXFAttributeError).
    """
    if not entity.dxf.is_supported("layer"):
        return "0"
    return layer_name(str(entity.dxf.get("layer", "0")))


def layer_name(raw: str) -> str:
    r"""A layer name as the CAD program shows it: ``\U+039B`` written as ``Λ``.

    A DXF file of R12 or older (a single-byte code page) writes a character its code page
    lacks as ``\U+xxxx``; ezdxf decodes that notation in what it recovers
    (``ezdxf.recover``), not in what it reads (``ezdxf.decode_dxf_unicode``). Decoded
    here, a layer is selected (``--layers``, a job's ``layers``) and named by the name the
    user sees in the CAD program.
    """
    if "\\U+" not in raw:
        return raw
    import ezdxf

    return str(ezdxf.decode_dxf_unicode(raw))


def invisible(entity: Any) -> bool:
    """Whether ``entity``'s invisible flag (group code 60) is set: the CAD program hides it."""
    try:
        return bool(entity.dxf.get("invisible", 0))
    except (AttributeError, TypeError, ValueError):
        return False


def location(entity: Any) -> Point | None:
    """A representative WCS point of an entity (start, centre or first vertex), or None."""
    for name in ("start", "center", "insert", "location"):
        if entity.dxf.hasattr(name):
            p = entity.dxf.get(name)
            if entity.dxftype() in _OCS_POINTS:
                p = entity.ocs().to_wcs(p)
            return (float(p[0]), float(p[1]))
    kind = entity.dxftype()
    if kind == "SPLINE":
        pts = entity.control_points if entity.control_point_count() else entity.fit_points
        return _xy(pts[0]) if len(pts) else None
    if kind == "LWPOLYLINE" and len(entity):
        return _xy(entity.ocs().to_wcs((*entity[0][:2], 0.0)))
    if kind == "POLYLINE" and len(entity.vertices):
        return _xy(entity.ocs().to_wcs(entity.vertices[0].dxf.location))
    return None


def join_pieces(
    pieces: Sequence[Sequence[Segment]], tolerance: float
) -> list[tuple[list[Segment], bool]]:
    """Join pieces given in path order into runs, reversing a piece drawn the other way.

    Hatch edges and exploded polylines come in order but not always in direction (an
    ARC always runs counter-clockwise). A piece joins the run when one of its ends is
    within ``tolerance`` of the run's end (a run of one piece may be turned round for
    that); the joint is snapped. A run whose ends meet within ``tolerance`` is closed.

    Returns:
        ``[(segments, closed), ...]``, one per run, in order.
    """
    runs: list[list[Segment]] = []
    single = False  # the last run is one piece so far and may still be turned round
    for piece in pieces:
        segs = [s for s in piece if s.length > ZERO_LENGTH]
        if not segs:
            continue
        if runs:
            run = runs[-1]
            ends = (segs[0].start, segs[-1].end)
            if (
                single
                and _near(run[0].start, tolerance, *ends)
                and not _near(run[-1].end, tolerance, *ends)
            ):
                run[:] = _reverse(run)
            if (
                distance(run[-1].end, segs[0].start)
                > tolerance
                >= distance(run[-1].end, segs[-1].end)
            ):
                segs = _reverse(segs)
            if distance(run[-1].end, segs[0].start) <= tolerance:
                run.extend([with_start(segs[0], run[-1].end), *segs[1:]])
                single = False
                continue
        runs.append(list(segs))
        single = True
    out: list[tuple[list[Segment], bool]] = []
    for run in runs:
        closed = distance(run[-1].end, run[0].start) <= tolerance and (
            len(run) > 1 or closes_alone(run[0])
        )
        if closed:
            run[-1] = with_end(run[-1], run[0].start)
        out.append((run, closed))
    return out


def _near(p: Point, tolerance: float, *others: Point) -> bool:
    return any(distance(p, q) <= tolerance for q in others)


def _reverse(segs: Sequence[Segment]) -> list[Segment]:
    return [s.reversed() for s in reversed(segs)]


def _segments(entity: Any, tolerance: float) -> tuple[list[Segment], bool]:
    """Segments (zero-length ones dropped) and the closed flag of one curve entity."""
    kind = entity.dxftype()
    if kind == "ELLIPSE":
        segs, closed = ellipse_segments(entity, tolerance)
    elif kind == "SPLINE":
        segs, closed = take(entity) or spline_segments(entity, tolerance)
    else:
        _check_flat(entity)
        if kind == "LINE":
            segs, closed = [Line(_xy(entity.dxf.start), _xy(entity.dxf.end))], False
        elif kind in ("ARC", "CIRCLE"):
            segs, closed = [_arc(entity)], kind == "CIRCLE"
        elif kind == "LWPOLYLINE":
            vertices = [(x, y, b) for x, y, b in entity.get_points("xyb")]
            segs, closed = _polyline(entity, vertices, entity.closed), bool(entity.closed)
        elif kind == "POLYLINE":
            segs, closed = _polyline2d(entity), bool(entity.is_closed)
        else:  # pragma: no cover - callers pass CONVERTED types only
            raise Unsupported("not a 2D contour camtool cuts")
    segs = [s for s in segs if s.length > ZERO_LENGTH]
    if not segs:
        raise Unsupported("zero length")
    return segs, closed


def _piece(entity: Any, tolerance: float) -> list[Segment]:
    """Segments of one piece of a joined path; a zero-length piece is no segment."""
    try:
        return _segments(entity, tolerance)[0]
    except Unsupported as exc:
        if exc.reason != "zero length":
            raise
        return []


def not_flat(zs: Sequence[float]) -> bool:
    """Whether Z values (drawing units) of one entity's points differ: a 3D entity.

    Differences within 10⁻⁹ of the largest magnitude (at least 1) are rounding.
    """
    return bool(zs) and max(zs) - min(zs) > 1e-9 * max(1.0, *(abs(z) for z in zs))


def _check_flat(entity: Any) -> None:
    if entity.dxftype() == "LINE":
        if not_flat((entity.dxf.start.z, entity.dxf.end.z)):
            raise Unsupported(THREE_D)
        return
    ex, ey, _ = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if abs(ex) > 1e-9 or abs(ey) > 1e-9:
        raise Unsupported("not parallel to XY")


def _polyline2d(entity: Any) -> list[Segment]:
    """A 2D POLYLINE, or a 3D one that lies flat (all vertices at one Z) as lines.

    Spline-fit frame vertices (flag 16) are not on the curve and are left out.
    """
    vertices = [v.dxf.location for v in entity.vertices if not v.dxf.flags & 16]
    if not entity.is_2d_polyline:
        if not_flat([float(v[2]) for v in vertices]):
            raise Unsupported(THREE_D)
        segs: list[Segment] = [Line(_xy(a), _xy(b)) for a, b in itertools.pairwise(vertices)]
        if entity.is_closed and len(vertices) > 2:
            segs.append(Line(_xy(vertices[-1]), _xy(vertices[0])))
        return [s for s in segs if s.length > ZERO_LENGTH]
    bulges = [v.dxf.bulge for v in entity.vertices if not v.dxf.flags & 16]
    points = [(v[0], v[1], b) for v, b in zip(vertices, bulges, strict=True)]
    return _polyline(entity, points, entity.is_closed)


def _hatch(item: Item, tolerance: float, limit: float) -> list[Contour]:
    """Each boundary path of a HATCH as contours (normally one closed contour per path)."""
    hatch = item.entity
    _check_flat(hatch)
    contours: list[Contour] = []
    try:
        paths = boundary_entities(hatch)
    except (ValueError, ArithmeticError) as exc:  # e.g. an infinite ellipse edge angle
        raise BadEntity(
            f"{item.label} on layer {item.layer!r}: its boundary path data cannot be read "
            f"({exc}); the file is damaged: fix or delete the hatch in the CAD program"
        ) from None
    if item.place is not None:
        paths = [[q for piece in path for q in item.place(piece)] for path in paths]
    for number, path in enumerate(paths, start=1):
        label = f"{item.label} path {number}"
        for edge in path:
            check_numbers(edge, label, item.layer, limit)
        pieces = [_piece(edge, tolerance) for edge in path]
        for segs, closed in join_pieces(pieces, tolerance):
            contours.append(Contour(tuple(segs), closed, item.layer, label))
    if not contours:
        raise Unsupported("no boundary path")
    return contours


def _xy(p: Any) -> Point:
    return (float(p[0]), float(p[1]))


def _arc(entity: Any) -> Arc:
    """ARC or CIRCLE in WCS; OCS arcs run counter-clockwise, mirrored ones clockwise.

    An ARC whose start and end angles are equal is a point, not a whole circle (ezdxf's
    ``arc_angle_span_deg``; BricsCAD and TrueView draw a point, ezdxf issue 330).

    Raises:
        Unsupported: ``"zero length"`` for such an ARC.
    """
    from ezdxf.math import arc_angle_span_deg

    if (
        entity.dxftype() == "ARC"
        and arc_angle_span_deg(float(entity.dxf.start_angle), float(entity.dxf.end_angle)) == 0.0
    ):
        raise Unsupported("zero length", "its start and end angles are equal")
    ocs = entity.ocs()
    flipped = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))[2] < 0
    centre = _xy(ocs.to_wcs(entity.dxf.center))
    r = abs(float(entity.dxf.radius))  # AutoCAD ignores the sign (ezdxf's Circle.vertices)
    if entity.dxftype() == "CIRCLE":
        start = (centre[0] + r, centre[1])
        return Arc(start, start, centre, flipped)
    a0, a1 = math.radians(entity.dxf.start_angle), math.radians(entity.dxf.end_angle)
    c = entity.dxf.center
    p0 = ocs.to_wcs((c[0] + r * math.cos(a0), c[1] + r * math.sin(a0), c[2]))
    p1 = ocs.to_wcs((c[0] + r * math.cos(a1), c[1] + r * math.sin(a1), c[2]))
    return Arc(_xy(p0), _xy(p1), centre, flipped)


def _polyline(
    entity: Any, vertices: list[tuple[float, float, float]], closed: bool
) -> list[Segment]:
    """Segments of an (LW)POLYLINE; a vertex's bulge shapes the segment after it."""
    from ezdxf.math import bulge_center

    ocs = entity.ocs()
    # The extrusion is ±Z here (tilted ones are refused), so the elevation never
    # changes X or Y in the WCS: z = 0 is exact for the 2D result.
    z = 0.0
    flipped = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))[2] < 0
    pairs = list(itertools.pairwise(vertices))
    if closed and len(vertices) > 1:
        pairs.append((vertices[-1], vertices[0]))
    segs: list[Segment] = []
    for (x0, y0, bulge), (x1, y1, _) in pairs:
        p0 = _xy(ocs.to_wcs((x0, y0, z)))
        p1 = _xy(ocs.to_wcs((x1, y1, z)))
        if distance(p0, p1) <= ZERO_LENGTH:
            continue
        if abs(bulge) * distance(p0, p1) <= 2 * ZERO_LENGTH:  # sagitta ≈ bulge · chord / 2
            segs.append(Line(p0, p1))
            continue
        c = bulge_center((x0, y0), (x1, y1), bulge)
        centre = _xy(ocs.to_wcs((c[0], c[1], z)))
        segs.append(Arc(p0, p1, centre, bool(bulge < 0) != bool(flipped)))  # numpy bools out
    return segs


# ------------------------------------------------------------------ ELLIPSE and SPLINE


def ellipse_segments(entity: Any, tolerance: float) -> tuple[list[Segment], bool]:
    """An ELLIPSE as lines and arcs within ``tolerance``, and whether it is closed.

    The curve is ``c + M cos t + m sin t`` for ``t`` from ``start_param`` to
    ``end_param`` counter-clockwise about the extrusion, with ``M`` the major axis and
    ``m = extrusion × M · ratio`` (DXF reference, ELLIPSE); an extrusion of (0, 0, −1)
    therefore runs clockwise seen from +Z. An ellipse sweeping more than half a turn
    whose two ends meet within the tolerance is closed (full): CAD programs that round
    ``end_param`` to 6.28318 still give a closed contour. Equal parameters give a point, not
    a whole ellipse, as for an ARC (:func:`_arc`; ezdxf's ``ellipse_param_span``).

    Args:
        entity: an ezdxf ``Ellipse`` (WCS), possibly a virtual one from a block.
        tolerance: largest distance between curve and output, drawing units (> 0).

    Returns:
        ``(segments, closed)`` in drawing units, Y up.

    Raises:
        Unsupported: the ellipse is not parallel to XY, has zero size, or ``"zero
            length"`` (equal start and end parameters).
    """
    from ezdxf.math import ellipse_param_span

    if not math.hypot(*entity.dxf.major_axis) > 0.0:
        raise Unsupported("zero size")  # ezdxf's construction tool refuses a null axis
    if ellipse_param_span(float(entity.dxf.start_param), float(entity.dxf.end_param)) == 0.0:
        raise Unsupported("zero length", "its start and end parameters are equal")
    ce = entity.construction_tool()
    ex, ey, ez = ce.extrusion
    if abs(ex) > 1e-9 or abs(ey) > 1e-9 or abs(ce.major_axis[2]) > 1e-9 * ce.major_axis.magnitude:
        raise Unsupported("not parallel to XY")
    (cx, cy), (mx, my), (nx, ny) = _xy(ce.center), _xy(ce.major_axis), _xy(ce.minor_axis)
    a, b = math.hypot(mx, my), math.hypot(nx, ny)
    if a <= 0.0 or b <= 0.0:
        raise Unsupported("zero size")
    t0 = float(ce.start_param)
    t1 = float(ce.end_param)
    if t1 <= t0:
        t1 += TAU * math.ceil((t0 - t1) / TAU + 1e-15)
    t1 = min(t1, t0 + TAU)

    point_at, tangent_at = ellipse((cx, cy), (mx, my), (nx, ny))
    _check_size(ellipse_extent((cx, cy), (mx, my), (nx, ny), t0, t1), tolerance)  # cut part
    closed = t1 - t0 >= TAU or (
        t1 - t0 > math.pi and distance(point_at(t0), point_at(t1)) <= tolerance
    )
    if closed:
        t1 = t0 + TAU
    if abs(a - b) <= _CIRCULAR * tolerance:
        start = point_at(t0)
        end = start if closed else point_at(t1)
        return [Arc(start, end, (cx, cy), ez < 0)], closed
    return _fit(point_at, tangent_at, [t0, t1], tolerance, closed), closed


def spline_segments(entity: Any, tolerance: float) -> tuple[list[Segment], bool]:
    """A SPLINE (any degree, rational or not, control or fit points) as lines and arcs.

    The curve is the B-spline over its valid domain ``[u_p, u_n]`` (p the degree,
    n the control point count; the same as ``[0, max_t]`` for clamped splines, the
    periodic part for closed unclamped ones). It is fitted piecewise between knots
    of multiplicity ≥ p, where the curve may have a corner; a clamped non-rational
    quadratic or cubic one between every two knots, as the Bézier curves it is there
    (:func:`_bezier_fits`). Splines given by fit points only are rebuilt as AutoCAD does
    (:func:`ezdxf.math.fit_points_to_cad_cv`, with the stored end tangents); a closed one
    is closed through its first fit point. The contour is closed when the spline's ends
    coincide, or when it is flagged closed and its ends meet within the tolerance.

    Args:
        entity: an ezdxf ``Spline`` (WCS), possibly a virtual one from a block.
        tolerance: largest distance between curve and output, drawing units (> 0).

    Returns:
        ``(segments, closed)`` in drawing units, Y up.

    Raises:
        Unsupported: invalid spline data (knots that decrease or that ezdxf cannot
            evaluate among them), a spline not parallel to XY, or one whose
            curve is a single point.
    """
    spline = spline_tool(entity)
    pts = spline.control_points
    zs = [p[2] for p in pts]
    size = max(1.0, *(max(abs(p[0]), abs(p[1])) for p in pts))
    if max(zs) - min(zs) > _RELATIVE * size:
        raise Unsupported("not parallel to XY")
    p, n = spline.degree, spline.count
    knots = spline.knots()
    t0, t1 = float(knots[p]), float(knots[n])
    if not t1 > t0:
        raise Unsupported("invalid spline data", "empty parameter range")
    if any(b < a for a, b in itertools.pairwise(knots)):
        raise Unsupported("invalid spline data", "its knots decrease")
    breaks = [t0, *corner_knots(knots, p, t0, t1), t1]
    xs, ys = [q[0] for q in pts], [q[1] for q in pts]
    _check_size(max(max(xs) - min(xs), max(ys) - min(ys)), tolerance)

    # one evaluator for every point: ezdxf's BSpline.point(t) builds one from the control
    # points at each call (what BSpline.point does, without the rebuilding)
    evaluator = spline.evaluator

    def point_at(t: float) -> Point:
        return _xy(evaluator.point(t))

    def tangent_at(t: float) -> Point:
        return _xy(evaluator.derivative(t, 1)[1])

    def points_at(ts: FloatArray) -> FloatArray:
        # the (x, y, z) of each Vec3 in a row, without a tuple per point
        xyz = itertools.chain.from_iterable(evaluator.points(ts))
        return np.fromiter(xyz, np.float64, count=3 * len(ts)).reshape(-1, 3)[:, :2]

    try:
        gap = distance(point_at(t0), point_at(t1))
        closed = gap <= _RELATIVE * size or (bool(entity.closed) and gap <= tolerance)
        pieces = _bezier_fits(spline, tolerance, closed)
        if pieces is not None:
            return pieces, closed
        return _fit(point_at, tangent_at, breaks, tolerance, closed, points_at), closed
    except ZeroDivisionError as exc:  # ezdxf's basis functions on knots a hair apart
        raise Unsupported("invalid spline data", f"ezdxf cannot evaluate it ({exc})") from exc


def _bezier_fits(spline: Any, tolerance: float, closed: bool) -> list[Segment] | None:
    """A clamped, non-rational quadratic or cubic B-spline fitted as its Bézier spans.

    Between two knots such a spline is one Bézier curve: ezdxf's
    ``BSpline.bezier_decomposition`` (The NURBS Book, algorithm A5.6) gives their control
    points, and each is fitted as an SVG path's curves are
    (:func:`~camtool.geometry.fitpool.fit_key`: compiled once a drawing has enough curves,
    the same fits either way). A span whose control points all coincide is a point and
    left out. ``None`` for any other spline, or when a span's fit fails: the caller
    fits the curve through ezdxf's evaluator, which says why.
    """
    if spline.degree not in (2, 3) or spline.is_rational or not spline.is_clamped:
        return None
    kind = "cubic" if spline.degree == 3 else "quadratic"
    segs: list[Segment] = []
    try:
        FIT_KERNELS.get(len(set(spline.knots())))  # a long one asks for the compiled fitter
        for controls in spline.bezier_decomposition():  # one span at a time
            points = tuple((float(v.x), float(v.y)) for v in controls)
            if any(q != points[0] for q in points):  # all in one place: a point, no curve
                segs.extend(fit_key((kind, points), tolerance))
    except (GeometryError, UsageError, TypeError, ValueError, ZeroDivisionError):
        return None
    return joined_run(segs, closed) or None


def _check_size(extent: float, tolerance: float) -> None:
    try:
        check_curve_size(extent, tolerance)
    except ValueError as exc:
        raise BadEntity(f"{exc} (drawing units)") from None


def spline_tool(entity: Any) -> Any:
    """The entity's BSpline, with AutoCAD-style periodic knot vectors unwrapped."""
    from ezdxf.math import BSpline, fit_points_to_cad_cv

    try:
        if entity.control_point_count() == 0 and entity.fit_point_count() > 0 and entity.closed:
            fit = [tuple(v) for v in entity.fit_points]
            if distance(_xy(fit[0]), _xy(fit[-1])) > 0.0:
                fit.append(fit[0])
            tangents = None
            if entity.dxf.hasattr("start_tangent") and entity.dxf.hasattr("end_tangent"):
                tangents = [entity.dxf.start_tangent, entity.dxf.end_tangent]
            return fit_points_to_cad_cv(fit, tangents=tangents)
        count = entity.control_point_count()
        if entity.closed and count and len(entity.knots) == count + 1:
            cps, knots, weights = _unwrap_periodic(
                [tuple(v) for v in entity.control_points],
                list(entity.knots),
                list(entity.weights),
                int(entity.dxf.degree),
            )
            return BSpline(cps, int(entity.dxf.degree) + 1, knots, weights or None)
        implied = implied_degree(entity)  # an exporter's quadratic written as degree 3
        if implied is not None:
            return BSpline(
                [tuple(v) for v in entity.control_points],
                implied + 1,
                list(entity.knots),
                list(entity.weights) or None,
            )
        return entity.construction_tool()
    except (ValueError, IndexError, ZeroDivisionError) as exc:  # ezdxf's DXFValueError too
        raise Unsupported("invalid spline data", str(exc)) from exc


def _unwrap_periodic(
    cps: list[tuple[float, ...]], knots: list[float], weights: list[float], p: int
) -> tuple[list[tuple[float, ...]], list[float], list[float]]:
    """Periodic spline stored with ``n + 1`` knots (ObjectARX style) as an unclamped one.

    The ``n`` knot intervals repeat with the period; the first ``p`` control points (and
    weights) are appended, and ``p`` knots are added on each side, so that the valid
    domain ``[u_p, u_n]`` of the result is the stored ``[k_0, k_n]``.
    """
    n = len(cps)
    d = [knots[i + 1] - knots[i] for i in range(n)]
    left = [knots[0]]
    for i in range(p):
        left.insert(0, left[0] - d[(n - 1 - i) % n])
    right = [knots[n] + (knots[i] - knots[0]) for i in range(1, p + 1)]
    full = left[:-1] + knots + right
    return cps + cps[:p], full, (weights + weights[:p]) if weights else []


def _fit(
    point_at: Callable[[float], Point],
    tangent_at: Callable[[float], Point],
    breaks: Sequence[float],
    tolerance: float,
    closed: bool,
    points_at: PointsFn | None = None,
) -> list[Segment]:
    """:func:`camtool.geometry.curves.fit_pieces`, its failures as :class:`Unsupported`."""
    try:
        segs = fit_pieces(point_at, tangent_at, breaks, tolerance, closed, points_at)
    except GeometryError as exc:
        raise Unsupported("curve could not be fitted", str(exc)) from exc
    if not segs:
        raise Unsupported("zero length")
    return segs
