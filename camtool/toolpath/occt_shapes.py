"""Segments and contours as OpenCASCADE wires and edges, and back."""

from __future__ import annotations

from typing import Any

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment, distance

_JOIN_MM = 1e-6
"""Ends of an offset's edges this close are one point, mm."""


def _to_wire(contour: Contour) -> Any:
    """The contour as a ``TopoDS_Wire`` (``BRepBuilderAPI_MakeWire`` of its edges)."""
    import warnings

    from OCP.BRepBuilderAPI import (
        BRepBuilderAPI_DisconnectedWire,
        BRepBuilderAPI_EmptyWire,
        BRepBuilderAPI_MakeWire,
        BRepBuilderAPI_NonManifoldWire,
    )
    from OCP.collections import List_TopoDS_Shape

    segs: list[Segment] = list(contour.segments)
    if len(segs) == 1 and isinstance(segs[0], Arc):
        segs = list(segs[0].split(2))  # one-edge wires offset badly (see build123d offset_2d)
    edges = List_TopoDS_Shape()
    for seg in segs:
        edges.Append(_to_edge(seg))
    builder = BRepBuilderAPI_MakeWire()
    builder.Add(edges)
    builder.Build()
    if not builder.IsDone():  # what build123d's Wire says
        error = builder.Error()
        if error == BRepBuilderAPI_NonManifoldWire:
            warnings.warn("Wire is non manifold (e.g. branching, self intersecting)", stacklevel=2)
        elif error == BRepBuilderAPI_EmptyWire:
            raise RuntimeError("Wire is empty")
        elif error == BRepBuilderAPI_DisconnectedWire:
            raise ValueError("Edges are disconnected")
    return builder.Wire()


def _to_edge(seg: Segment) -> Any:
    """A ``TopoDS_Edge`` of a line or an arc (a full circle: a ``gp_Circ``)."""
    from OCP.BRepBuilderAPI import BRepBuilderAPI_MakeEdge
    from OCP.GC import GC_MakeArcOfCircle
    from OCP.gp import gp_Ax2, gp_Circ, gp_Dir, gp_Pnt

    if isinstance(seg, Line):
        return BRepBuilderAPI_MakeEdge(_pnt(seg.start), _pnt(seg.end)).Edge()
    if seg.is_full_circle:
        centre = gp_Pnt(float(seg.centre[0]), float(seg.centre[1]), 0.0)
        axes = gp_Ax2(centre, gp_Dir(0.0, 0.0, 1.0), gp_Dir(1.0, 0.0, 0.0))  # Plane.XY moved
        return BRepBuilderAPI_MakeEdge(gp_Circ(axes, seg.radius)).Edge()
    mid = seg.point_at(0.5)
    arc = GC_MakeArcOfCircle(_pnt(seg.start), _pnt(mid), _pnt(seg.end)).Value()
    return BRepBuilderAPI_MakeEdge(arc).Edge()


def _pnt(p: Point) -> Any:
    from OCP.gp import gp_Pnt

    return gp_Pnt(float(p[0]), float(p[1]), 0.0)


_CURVE_NAMES = {
    "GeomAbs_Line": "LINE",
    "GeomAbs_Circle": "CIRCLE",
    "GeomAbs_Ellipse": "ELLIPSE",
    "GeomAbs_Hyperbola": "HYPERBOLA",
    "GeomAbs_Parabola": "PARABOLA",
    "GeomAbs_BezierCurve": "BEZIER",
    "GeomAbs_BSplineCurve": "BSPLINE",
    "GeomAbs_OffsetCurve": "OFFSET",
    "GeomAbs_OtherCurve": "OTHER",
}
"""OCCT curve types by the names build123d's ``GeomType`` gives them."""


def _where(contour: Contour) -> str:
    x, y = contour.start
    src = f"{contour.source} " if contour.source else ""
    return f"contour {src}starting at ({x:.4f}, {y:.4f}) mm"


def _wire_edges(wire: Any) -> list[Any]:
    """The edges of a ``TopoDS_Wire`` in connection order (``BRepTools_WireExplorer``)."""
    from OCP.BRepTools import BRepTools_WireExplorer

    explorer = BRepTools_WireExplorer(wire)
    edges = []
    while explorer.More():
        edges.append(explorer.Current())
        explorer.Next()
    return edges


def _from_edge(edge: Any, contour: Contour) -> Segment:
    from OCP.BRepAdaptor import BRepAdaptor_Curve

    curve = BRepAdaptor_Curve(edge)
    kind = _CURVE_NAMES.get(curve.GetType().name, "OTHER")
    start = _position_at(edge, curve, 0.0)
    end = _position_at(edge, curve, 1.0)
    if kind == "LINE":
        return Line(start, end)
    if kind == "CIRCLE":
        c = curve.Circle().Position().Location()
        centre = (float(c.X()), float(c.Y()))
        a, b = _position_at(edge, curve, 0.25), _position_at(edge, curve, 0.5)
        turn = (a[0] - start[0]) * (b[1] - a[1]) - (a[1] - start[1]) * (b[0] - a[0])
        if distance(start, end) < _JOIN_MM:
            end = start
        return Arc(start, end, centre, turn < 0)
    raise ToolpathError(
        f"{_where(contour)}: the offset holds a {kind.lower()} curve; camtool emits only "
        "lines and arcs"
    )


def _position_at(edge: Any, curve: Any, position: float) -> Point:
    """build123d's ``Edge.position_at(position)``: a fraction of the length, orientation-wise."""
    from OCP.GCPnts import GCPnts_AbscissaPoint
    from OCP.TopAbs import TopAbs_Orientation

    length = GCPnts_AbscissaPoint.Length_s(curve)
    if edge.Orientation() != TopAbs_Orientation.TopAbs_FORWARD:
        position = 1 - position
    param = GCPnts_AbscissaPoint(curve, length * position, curve.FirstParameter()).Parameter()
    p = curve.Value(param)
    return (float(p.X()), float(p.Y()))
