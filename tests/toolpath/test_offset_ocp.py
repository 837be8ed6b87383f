"""The offsets made through OCP directly equal the ones made through build123d (issue 17).

:mod:`camtool.toolpath.offset` calls OpenCASCADE's bindings (OCP) itself instead of
importing build123d (2 s and 160 MB). The build123d code it replaced is kept here as the
reference (the same OCCT offset, wires and edges through build123d's ``Wire`` and
``Edge``); on random and canonical contours both give the same pieces, float for float
(``repr`` equality: the same numbers of the same types), or the same error.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from camtool.model.errors import ToolpathError
from camtool.model.shapes import Arc, Contour, Line, Point, Segment, distance
from camtool.toolpath import offset
from tests.toolpath.contours import circle, polygon, rect, stadium

build123d = pytest.importorskip("build123d")


def _reference_occt_offset(contour: Contour, amount: float) -> list[Any]:
    """The build123d form of :func:`camtool.toolpath.offset._occt_offset` (before issue 17)."""
    from build123d import Wire
    from OCP.BRepOffsetAPI import BRepOffsetAPI_MakeOffset
    from OCP.GeomAbs import GeomAbs_JoinType
    from OCP.TopAbs import TopAbs_WIRE
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    builder = BRepOffsetAPI_MakeOffset()
    builder.Init(GeomAbs_JoinType.GeomAbs_Arc)
    builder.AddWire(_reference_wire(contour).wrapped)
    builder.Perform(amount)
    if not builder.IsDone():
        raise ToolpathError(f"OpenCASCADE's 2D offset by {amount:+.4g} mm did not finish")
    wires = []
    explorer = TopExp_Explorer(builder.Shape(), TopAbs_WIRE)
    while explorer.More():
        wires.append(Wire(TopoDS.Wire(explorer.Current())))
        explorer.Next()
    return wires


def _reference_wire(contour: Contour) -> Any:
    from build123d import Edge, Location, Plane, Vector, Wire

    segs: list[Segment] = list(contour.segments)
    if len(segs) == 1 and isinstance(segs[0], Arc):
        segs = list(segs[0].split(2))
    edges = []
    for seg in segs:
        if isinstance(seg, Line):
            edges.append(Edge.make_line(Vector(*seg.start), Vector(*seg.end)))
        elif seg.is_full_circle:
            plane = Plane.XY.move(Location((seg.centre[0], seg.centre[1], 0.0)))
            edges.append(Edge.make_circle(seg.radius, plane))
        else:
            mid = seg.point_at(0.5)
            edges.append(
                Edge.make_three_point_arc(Vector(*seg.start), Vector(*mid), Vector(*seg.end))
            )
    return Wire(edges)


def _reference_from_edge(edge: Any, contour: Contour) -> Segment:
    def xy(v: Any) -> Point:
        return (float(v.X), float(v.Y))

    kind = edge.geom_type.name
    start, end = xy(edge.position_at(0.0)), xy(edge.position_at(1.0))
    if kind == "LINE":
        return Line(start, end)
    if kind == "CIRCLE":
        centre = xy(edge.arc_center)
        a, b = xy(edge.position_at(0.25)), xy(edge.position_at(0.5))
        turn = (a[0] - start[0]) * (b[1] - a[1]) - (a[1] - start[1]) * (b[0] - a[0])
        if distance(start, end) < offset._JOIN_MM:
            end = start
        return Arc(start, end, centre, turn < 0)
    raise ToolpathError(f"the offset holds a {kind.lower()} curve")


def _with_build123d(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(offset, "_occt_offset", _reference_occt_offset)
    monkeypatch.setattr(offset, "_wire_edges", lambda wire: list(wire.edges()))
    monkeypatch.setattr(offset, "_from_edge", _reference_from_edge)


def _result(contour: Contour, amount: float) -> tuple[str, str | None]:
    try:
        r = offset.offset_checked(contour, amount, 0.001)
    except ToolpathError as exc:
        return (f"error {exc}", None)
    return (repr(r.pieces), r.fallback)


def _contours() -> list[Contour]:
    rng = np.random.default_rng(17)
    out = [
        rect(0.0, 0.0, 100.0, 60.0),
        circle(10.0, 8.0, 2.5),
        circle(-3.3, 7.1, 0.4),
        stadium(0.0, 12.5, 3.0, 1.75),
        polygon([(0, 0), (10, 0), (10, 10), (6, 10), (6, 2), (4, 2), (4, 10), (0, 10)]),  # a U
        polygon([(0, 0), (30, 0), (30, 1.5), (16, 1.5), (16, 10), (14, 10), (14, 1.5), (0, 1.5)]),
        rect(0.0, 0.0, 100.0, 60.0).reversed(),
    ]
    for _ in range(25):  # random stars, some with an arc for an edge
        n = int(rng.integers(3, 10))
        angles = np.sort(rng.uniform(0, 2 * math.pi, n))
        radii = rng.uniform(3.0, 20.0, n)
        pts = [
            (float(r * math.cos(t)), float(r * math.sin(t)))
            for r, t in zip(radii, angles, strict=True)
        ]
        segs: list[Segment] = []
        for i in range(n):
            p, q = pts[i], pts[(i + 1) % n]
            if i == 0 and distance(p, q) > 1.0:
                mx, my = (p[0] + q[0]) / 2, (p[1] + q[1]) / 2
                # bulge the first edge outwards: an arc through a point beyond its middle
                nx, ny = -(q[1] - p[1]), q[0] - p[0]
                k = 0.2 / math.hypot(nx, ny) * distance(p, q)
                segs.extend(_arc3(p, (mx - nx * k, my - ny * k), q))
            else:
                segs.append(Line(p, q))
        out.append(Contour(tuple(segs), True))
    return out


def _arc3(p: Point, m: Point, q: Point) -> list[Segment]:
    """The arc from ``p`` through ``m`` to ``q`` (its circle through the three points)."""
    ax, ay, bx, by, cx, cy = *p, *m, *q
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    ux = (ax**2 + ay**2) * (by - cy) + (bx**2 + by**2) * (cy - ay) + (cx**2 + cy**2) * (ay - by)
    uy = (ax**2 + ay**2) * (cx - bx) + (bx**2 + by**2) * (ax - cx) + (cx**2 + cy**2) * (bx - ax)
    centre = (ux / d, uy / d)
    clockwise = (bx - ax) * (cy - by) - (by - ay) * (cx - bx) < 0
    return [Arc(p, q, centre, clockwise)]


@pytest.mark.parametrize("amount", [1.5, -1.5, 0.5, -0.2, 3.0])
def test_offsets_through_ocp_equal_the_build123d_ones(
    amount: float, monkeypatch: pytest.MonkeyPatch
) -> None:
    contours = _contours()
    got = [_result(c, amount) for c in contours]
    _with_build123d(monkeypatch)
    want = [_result(c, amount) for c in contours]
    assert got == want
    assert sum(1 for g in got if g[1] is None and not g[0].startswith("error")) >= 20


def test_the_offset_does_not_import_build123d() -> None:
    import subprocess
    import sys

    code = (
        "import sys\n"
        "from camtool.toolpath.offset import offset_pieces\n"
        "from tests.toolpath.contours import rect\n"
        "offset_pieces(rect(0, 0, 10, 5), 1.0)\n"
        "print('build123d' in sys.modules)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
