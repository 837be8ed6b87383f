"""Points along a DXF's entities from their DXF definitions, for judging camtool's programs.

Independent of camtool's reader: each primitive is sampled from its group codes (a bulge's
arc by its tangent, an ARC by its angles in its OCS, an ELLIPSE by its parameter in the
plane its extrusion names, a SPLINE by ezdxf's own B-spline evaluator), and a block's
entities in the block's coordinates, then through the INSERT's matrix (ezdxf's
``Insert.matrix44``). ezdxf's ``path.make_path`` is not used: it draws arcs and degree-2
splines as cubic Béziers, up to ~0.02 mm off at the radii used here; nor its virtual
entities of a block, which re-fit a spline's fit points after a non-uniform scale where
AutoCAD maps the curve itself.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Iterator
from typing import Any

import numpy as np
from ezdxf.math import Matrix44, Vec3, bulge_to_arc

STEP_MM = 0.05
"""Largest spacing of the sampled points along an arc or ellipse, mm."""


def primitive_points(e: Any) -> np.ndarray:
    """``(N, 3)`` WCS points along one LINE, ARC, CIRCLE, ELLIPSE, SPLINE or 2D polyline."""
    kind = e.dxftype()
    if kind in ("LWPOLYLINE", "POLYLINE"):
        return _polyline(e)
    if kind == "LINE":
        return np.array([tuple(e.dxf.start), tuple(e.dxf.end)])
    if kind in ("ARC", "CIRCLE"):
        ocs, c, r = e.ocs(), Vec3(e.dxf.center), e.dxf.radius
        a0, a1 = 0.0, math.tau
        if kind == "ARC":
            a0, a1 = math.radians(e.dxf.start_angle), math.radians(e.dxf.end_angle)
            while a1 <= a0:
                a1 += math.tau
        t = np.linspace(a0, a1, max(8, int((a1 - a0) * r / STEP_MM) + 1))
        local = [Vec3(c.x + r * math.cos(a), c.y + r * math.sin(a), c.z) for a in t]
        return np.array([tuple(ocs.to_wcs(p)) for p in local])
    if kind == "ELLIPSE":
        c, major = Vec3(e.dxf.center), Vec3(e.dxf.major_axis)
        minor = Vec3(e.dxf.extrusion).cross(major).normalize(major.magnitude * e.dxf.ratio)
        s, f = e.dxf.start_param, e.dxf.end_param
        if abs(f - s - math.tau) < 1e-9 or abs(f - s) < 1e-12:
            f = s + math.tau  # a whole ellipse, however its parameters are written
        while f < s:
            f += math.tau
        t = np.linspace(s, f, max(16, int((f - s) * major.magnitude / STEP_MM) + 1))
        return np.array([tuple(c + major * math.cos(a) + minor * math.sin(a)) for a in t])
    if kind == "SPLINE":
        curve = e.construction_tool()
        t = np.linspace(0.0, curve.max_t, 4000)
        return np.array([tuple(p) for p in curve.points(t)])
    return np.zeros((0, 3))


def _polyline(e: Any) -> np.ndarray:
    if e.dxftype() == "LWPOLYLINE":
        vertices = [(p[0], p[1], p[2]) for p in e.get_points("xyb")]
        closed, z = e.closed, e.dxf.elevation
    else:
        vertices = [(v.dxf.location.x, v.dxf.location.y, v.dxf.bulge) for v in e.vertices]
        closed, z = e.is_closed, e.dxf.elevation.z
    n = len(vertices)
    out = [vertices[0][:2]]
    for i in range(n if closed else n - 1):
        (x0, y0, bulge), (x1, y1, _) = vertices[i], vertices[(i + 1) % n]
        if abs(bulge) < 1e-12:
            out.append((x1, y1))
            continue
        c, _, _, r = bulge_to_arc((x0, y0), (x1, y1), bulge)
        a0, sweep = math.atan2(y0 - c.y, x0 - c.x), 4.0 * math.atan(bulge)
        for u in np.linspace(0.0, 1.0, max(8, int(abs(sweep) * r / STEP_MM) + 1))[1:]:
            out.append((c.x + r * math.cos(a0 + sweep * u), c.y + r * math.sin(a0 + sweep * u)))
    ocs = e.ocs()
    return np.array([tuple(ocs.to_wcs(Vec3(x, y, z))) for x, y in out])


def drawn_pieces(doc: Any) -> Iterator[tuple[Any, np.ndarray]]:
    """``(entity, (N, 2) mm points)`` of each primitive in model space, blocks placed."""

    def walk(layout: Any, m: Matrix44) -> Iterator[tuple[Any, np.ndarray]]:
        for e in layout:
            if e.dxftype() == "INSERT":
                yield from walk(doc.blocks[e.dxf.name], e.matrix44() @ m)
                continue
            points = primitive_points(e)
            if len(points):
                yield e, np.array([(p.x, p.y) for p in m.transform_vertices(points)])

    yield from walk(doc.modelspace(), Matrix44())


def densified(points: np.ndarray, step: float) -> np.ndarray:
    """``points`` with points added along each straight piece, at most ``step`` apart."""
    parts = [points[:1]]
    for a, b in itertools.pairwise(points):
        n = max(1, int(math.dist(a, b) / step))
        parts.append(a + (b - a) * np.linspace(0.0, 1.0, n + 1)[1:, None])
    return np.concatenate(parts)
