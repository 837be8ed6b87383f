"""Arc-preserving 2D offsets of closed contours (build123d / OpenCASCADE).

The only module that touches OpenCASCADE; build123d is imported lazily so that
``camtool --version`` and ``camtool targets`` never load it. Straight edges stay
lines, arcs stay arcs and convex corners become arcs of the offset radius
(``Kind.ARC``), so the toolpath keeps exact G02/G03 moves.
"""

from __future__ import annotations

from typing import Any

from camtool.errors import ToolpathError
from camtool.geometry import Arc, Contour, Line, Point, Segment, distance
from camtool.toolpath.chain import chain

_JOIN_MM = 1e-6


def offset_contour(contour: Contour, amount: float) -> Contour:
    """Offset a closed contour by ``amount`` mm: > 0 grows it, < 0 shrinks it.

    The result keeps the contour's orientation (clockwise stays clockwise) and
    starts at the vertex nearest the contour's own start.

    Args:
        contour: a closed contour, mm.
        amount: offset distance, mm; positive is away from the enclosed area.

    Returns:
        The offset contour.

    Raises:
        ToolpathError: the contour is open, OpenCASCADE cannot offset it, the
            offset leaves nothing (a region narrower than the tool), or the
            offset holds curves other than lines and arcs.
    """
    if not contour.closed:
        raise ToolpathError(f"{_where(contour)}: only closed contours can be offset")
    if amount == 0:
        return contour
    original_area = contour.signed_area()
    wire = _to_wire(contour)
    try:
        result = wire.offset_2d(amount, kind=_kind_arc())
    except Exception as exc:  # OCCT's StdFail_* types share no base below Exception
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm failed ({exc}); the region may "
            "be narrower than the tool"
        ) from exc
    pieces = [_from_edge(e, contour) for e in result.edges()]
    joined = chain(
        [Contour((p,), False, contour.layer, contour.source) for p in pieces],
        _JOIN_MM,
    )
    if len(joined) != 1 or not joined[0].closed:
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm splits into {len(joined)} pieces; "
            "camtool cuts one piece per contour (use a smaller tool)"
        )
    out = joined[0]
    area = out.signed_area()
    if (amount < 0 and abs(area) >= abs(original_area)) or abs(area) < 1e-12:
        raise ToolpathError(
            f"{_where(contour)}: offset by {amount:+.4g} mm leaves nothing; the region is "
            "narrower than the tool"
        )
    if (area > 0) != (original_area > 0):
        out = out.reversed()
    return _start_near(out, contour.start)


def _where(contour: Contour) -> str:
    x, y = contour.start
    src = f"{contour.source} " if contour.source else ""
    return f"contour {src}starting at ({x:.4f}, {y:.4f}) mm"


def _kind_arc() -> Any:
    from build123d import Kind

    return Kind.ARC


def _to_wire(contour: Contour) -> Any:
    from build123d import Wire

    return Wire([_to_edge(seg) for seg in contour.segments])


def _to_edge(seg: Segment) -> Any:
    from build123d import Edge, Plane, Vector

    if isinstance(seg, Line):
        return Edge.make_line(Vector(*seg.start), Vector(*seg.end))
    if seg.is_full_circle:
        plane = Plane.XY.move(_location(seg.centre))
        return Edge.make_circle(seg.radius, plane)
    mid = seg.point_at(0.5)
    return Edge.make_three_point_arc(Vector(*seg.start), Vector(*mid), Vector(*seg.end))


def _location(p: Point) -> Any:
    from build123d import Location

    return Location((p[0], p[1], 0.0))


def _from_edge(edge: Any, contour: Contour) -> Segment:
    kind = edge.geom_type.name
    start = _xy(edge.position_at(0.0))
    end = _xy(edge.position_at(1.0))
    if kind == "LINE":
        return Line(start, end)
    if kind == "CIRCLE":
        centre = _xy(edge.arc_center)
        a, b = _xy(edge.position_at(0.25)), _xy(edge.position_at(0.5))
        turn = (a[0] - start[0]) * (b[1] - a[1]) - (a[1] - start[1]) * (b[0] - a[0])
        if distance(start, end) < _JOIN_MM:
            end = start
        return Arc(start, end, centre, turn < 0)
    raise ToolpathError(
        f"{_where(contour)}: the offset holds a {kind.lower()} curve; camtool emits only "
        "lines and arcs"
    )


def _xy(v: Any) -> Point:
    return (float(v.X), float(v.Y))


def _start_near(contour: Contour, p: Point) -> Contour:
    """Rotate a closed contour so it starts at the segment start nearest ``p``."""
    segs = contour.segments
    if len(segs) == 1:
        return contour
    k = min(range(len(segs)), key=lambda i: (distance(segs[i].start, p), i))
    rotated = segs[k:] + segs[:k]
    return Contour(rotated, True, contour.layer, contour.source)
