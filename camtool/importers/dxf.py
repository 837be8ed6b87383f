"""DXF importer (ezdxf): LINE, ARC, CIRCLE, LWPOLYLINE and 2D POLYLINE, arcs kept exact.

Model space only. Each entity becomes one contour (polylines keep their own
closed flag); chaining entities whose ends meet is the planner's job
(:mod:`camtool.toolpath.chain`). Bulges become exact arcs (bulge > 0 is
counter-clockwise in the entity's OCS). Entities with an extrusion of
(0, 0, −1) are mirrored into the WCS, which flips their arcs' direction.
``$INSUNITS`` is converted to mm; a unitless drawing is taken as mm with a
warning. Other entity types are skipped with one warning per type and count.
"""

from __future__ import annotations

import itertools
from collections import Counter
from pathlib import Path
from typing import Any

from camtool.errors import InputError
from camtool.geometry import Arc, Contour, Drawing, Line, Point, Segment, distance
from camtool.units import INCH

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
_SUPPORTED = ("LINE", "ARC", "CIRCLE", "LWPOLYLINE", "POLYLINE")
_ZERO_LENGTH_MM = 1e-9


def read_dxf(path: str | Path) -> Drawing:
    """Read the model space of a DXF file into a drawing in mm.

    Args:
        path: the DXF file.

    Returns:
        A :class:`Drawing` with one contour per usable entity, in mm, Y up, and
        the warnings a user should see (assumed units, skipped entity types).

    Raises:
        InputError: the file is missing, is not a DXF file, is damaged beyond
            reading, uses an unknown ``$INSUNITS`` code, or holds no LINE, ARC,
            CIRCLE, LWPOLYLINE or 2D POLYLINE in model space.
    """
    path = Path(path)
    doc = _open(path)
    warnings: list[str] = []
    scale = _units_scale(path, doc.header.get("$INSUNITS", 0), warnings)
    contours: list[Contour] = []
    skipped: Counter[str] = Counter()
    for entity in doc.modelspace():
        kind = entity.dxftype()
        contour = _read_entity(entity, skipped) if kind in _SUPPORTED else None
        if kind not in _SUPPORTED:
            skipped[kind] += 1
        if contour is not None:
            contours.append(contour.transformed(scale, 0.0, 0.0) if scale != 1.0 else contour)
    for kind, count in sorted(skipped.items()):
        plural = "entity" if count == 1 else "entities"
        warnings.append(f"{path}: skipped {count} {kind} {plural} (not a 2D contour camtool cuts)")
    if not contours:
        raise InputError(
            f"{path}: no usable entity in model space; camtool cuts LINE, ARC, CIRCLE, "
            "LWPOLYLINE and 2D POLYLINE entities"
        )
    return Drawing(tuple(contours), str(path), tuple(warnings))


def _open(path: Path) -> Any:
    import ezdxf

    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        return ezdxf.readfile(str(path))
    except ezdxf.DXFStructureError as exc:
        raise InputError(
            f"{path}: damaged DXF file ({exc}); re-save it from the CAD program"
        ) from exc
    except (OSError, UnicodeDecodeError, ValueError) as exc:
        raise InputError(f"{path}: not a readable DXF file ({exc})") from exc


def _units_scale(path: Path, code: int, warnings: list[str]) -> float:
    if code == 0:
        warnings.append(f"{path}: drawing has no units ($INSUNITS = 0); assuming mm")
        return 1.0
    if code not in _INSUNITS_MM:
        known = ", ".join(f"{c} ({n})" for c, (n, _) in sorted(_INSUNITS_MM.items()))
        raise InputError(f"{path}: unsupported $INSUNITS {code}; camtool knows {known}")
    return _INSUNITS_MM[code][1]


def _label(entity: Any) -> str:
    return f"{entity.dxftype()} #{entity.dxf.handle}"


def _read_entity(entity: Any, skipped: Counter[str]) -> Contour | None:
    """One supported entity as a contour, or None (counted in ``skipped``)."""
    kind = entity.dxftype()
    extrusion = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))
    if kind != "LINE" and (abs(extrusion[0]) > 1e-9 or abs(extrusion[1]) > 1e-9):
        skipped[f"{kind} (not parallel to XY)"] += 1
        return None
    layer = entity.dxf.get("layer", "0")
    if kind == "LINE":
        segs: list[Segment] = [Line(_xy(entity.dxf.start), _xy(entity.dxf.end))]
        closed = False
    elif kind in ("ARC", "CIRCLE"):
        segs, closed = [_arc(entity)], kind == "CIRCLE"
    elif kind == "LWPOLYLINE":
        vertices = [(x, y, b) for x, y, b in entity.get_points("xyb")]
        segs, closed = _polyline(entity, vertices, entity.closed), entity.closed
    else:
        if not entity.is_2d_polyline:
            skipped["POLYLINE (3D or mesh)"] += 1
            return None
        vertices = [(v.dxf.location[0], v.dxf.location[1], v.dxf.bulge) for v in entity.vertices]
        segs, closed = _polyline(entity, vertices, entity.is_closed), entity.is_closed
    segs = [s for s in segs if s.length > _ZERO_LENGTH_MM]
    if not segs:
        skipped[f"{kind} (zero length)"] += 1
        return None
    return Contour(tuple(segs), closed, layer, _label(entity))


def _xy(p: Any) -> Point:
    return (float(p[0]), float(p[1]))


def _arc(entity: Any) -> Arc:
    """ARC or CIRCLE in WCS; OCS arcs run counter-clockwise, mirrored ones clockwise."""
    import math

    ocs = entity.ocs()
    flipped = entity.dxf.get("extrusion", (0.0, 0.0, 1.0))[2] < 0
    centre = _xy(ocs.to_wcs(entity.dxf.center))
    r = float(entity.dxf.radius)
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
    # The extrusion is ±Z here (tilted ones are skipped), so the elevation never
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
        if distance(p0, p1) <= _ZERO_LENGTH_MM:
            continue
        if abs(bulge) < 1e-12:
            segs.append(Line(p0, p1))
            continue
        c = bulge_center((x0, y0), (x1, y1), bulge)
        centre = _xy(ocs.to_wcs((c[0], c[1], z)))
        segs.append(Arc(p0, p1, centre, (bulge < 0) != flipped))
    return segs
