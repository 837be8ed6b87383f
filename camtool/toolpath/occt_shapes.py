"""Segments and contours as OpenCASCADE wires and edges, and back."""

from __future__ import annotations

from typing import Any

from camtool.model.shapes import Arc, Contour, Line, Point, Segment


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
