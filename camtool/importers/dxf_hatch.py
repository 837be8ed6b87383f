"""A HATCH's boundary paths as the virtual ezdxf entities they are drawn with, in WCS.

Design notes: docs/internals.md, ``camtool/importers/dxf_hatch.py``.
"""

from __future__ import annotations

from typing import Any


def boundary_entities(hatch: Any) -> list[list[Any]]:
    """Per boundary path, its pieces as virtual ezdxf entities in WCS drawing units.

    Args:
        hatch: an ezdxf ``Hatch`` (or ``MPolygon``), possibly a virtual one from a block.

    Returns:
        One list per path, the pieces in path order.
    """
    from ezdxf.entities import LWPolyline
    from ezdxf.entities.boundary_paths import EdgePath, PolylinePath

    ocs = hatch.ocs()
    elevation = float(hatch.dxf.elevation[2])
    extrusion = hatch.dxf.get("extrusion", (0.0, 0.0, 1.0))
    paths: list[list[Any]] = []
    for path in hatch.paths:
        if isinstance(path, PolylinePath):
            poly = LWPolyline.new(dxfattribs={"extrusion": extrusion, "elevation": elevation})
            poly.set_points([tuple(v) for v in path.vertices], format="xyb")
            poly.closed = path.is_closed
            paths.append([poly])
        elif isinstance(path, EdgePath):
            paths.append([_edge(edge, ocs, elevation, extrusion) for edge in path.edges])
    return paths


def _edge(edge: Any, ocs: Any, elevation: float, extrusion: Any) -> Any:
    from ezdxf.entities import Arc, Ellipse, Line, Spline
    from ezdxf.entities.boundary_paths import ArcEdge, EllipseEdge, LineEdge
    from ezdxf.math import Vec3

    def wcs(v: Any) -> Any:
        return ocs.to_wcs(Vec3(v).replace(z=elevation))

    if isinstance(edge, LineEdge):
        return Line.new(dxfattribs={"start": wcs(edge.start), "end": wcs(edge.end)})
    if isinstance(edge, ArcEdge):
        return Arc.new(
            dxfattribs={
                "center": Vec3(edge.center).replace(z=elevation),
                "radius": edge.radius,
                "start_angle": edge.start_angle,
                "end_angle": edge.end_angle,
                "extrusion": extrusion,
            }
        )
    if isinstance(edge, EllipseEdge):
        return Ellipse.new(
            dxfattribs={
                "center": wcs(edge.center),
                "major_axis": ocs.to_wcs(Vec3(edge.major_axis)),
                "ratio": edge.ratio,
                "start_param": edge.start_param,
                "end_param": edge.end_param,
                "extrusion": extrusion,
            }
        )
    spline = Spline.new(dxfattribs={"degree": edge.degree})
    spline.control_points = [wcs(v) for v in edge.control_points]
    if edge.knot_values:
        spline.knots = edge.knot_values
    if edge.weights:
        spline.weights = edge.weights
    if edge.fit_points:
        spline.fit_points = [wcs(v) for v in edge.fit_points]
    if edge.start_tangent is not None and edge.end_tangent is not None:
        spline.dxf.start_tangent = ocs.to_wcs(Vec3(edge.start_tangent))
        spline.dxf.end_tangent = ocs.to_wcs(Vec3(edge.end_tangent))
    return spline
