"""The area a closed contour encloses, also when it crosses or touches itself.

A closed polyline that does not cross itself is a polygon. One that does (a bow-tie, a
figure eight, a star drawn as one crossing line) is not, and shapely's usual repair, a
buffer of 0, keeps only the loops that turn the same way as the one GEOS meets first: a
bow-tie's other lobe vanishes, and a cut of "the area the contour encloses" would leave
half the part uncut. :func:`enclosed` gives the area by the nonzero winding rule instead
(SVG's default fill rule): every point the contour winds around, whichever way.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    import numpy as np
    from numpy.typing import NDArray
    from shapely.geometry.base import BaseGeometry

NODING_GRID_MM = 1e-6
"""Grid of the snap-rounding noder :func:`enclosed` falls back on, mm (1 nm: far below any
machine's step, far above float64's rounding of a coordinate of metres)."""


def enclosed(points: Sequence[tuple[float, float]]) -> BaseGeometry:
    """The area the closed polyline ``points`` encloses, by the nonzero winding rule, mm.

    A polyline that neither crosses nor touches itself gives its polygon as shapely's
    ``buffer(0)`` does. One that does is noded where it crosses itself (GEOS), its faces
    made (shapely's ``polygonize``), and the faces it winds around at least once, either
    way, united: both lobes of a bow-tie, the centre of a five-pointed star; a face it
    winds around once each way (a loop drawn back over itself) is left out, and so is a
    face less than :data:`NODING_GRID_MM` wide on average (twice its area over its
    perimeter): the slivers between an arc's chords drawn one way and back the other,
    whose points differ by roundings. Where GEOS's
    noder does not converge (a small arc drawn there and back over itself, as boxes.py draws
    its corners), the line is noded by snap-rounding on a :data:`NODING_GRID_MM` grid.

    Args:
        points: the polyline's vertices, mm, the last equal to the first or not (closed
            either way); at least 3.

    Returns:
        A ``Polygon`` or ``MultiPolygon``; empty (``Polygon()``) when the polyline
        encloses no area (drawn there and back).
    """
    import numpy as np
    import shapely
    from shapely import LineString, Polygon

    poly = Polygon(points)
    if poly.is_valid:
        return poly.buffer(0)
    ring = np.asarray(poly.exterior.coords, dtype=float)
    try:
        noded = shapely.node(LineString(ring))
    except shapely.errors.GEOSException:
        # GEOS's noder can fail to converge where the line runs back over itself within
        # a rounding (a corner arc drawn there and back); snap-rounding always converges.
        noded = shapely.union_all([LineString(ring)], grid_size=NODING_GRID_MM)
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(noded)))
    kept = [
        face
        for face in faces
        if 2.0 * face.area > face.length * NODING_GRID_MM  # wider than a rounding, on average
        and winding(ring, face.representative_point().coords[0]) != 0
    ]
    if not kept:
        return Polygon()
    return shapely.union_all(kept)


def inscribed_width(area: BaseGeometry, tolerance: float) -> float:
    """The widest tool that fits in ``area``: twice its largest inscribed circle's radius, mm.

    Args:
        area: a polygon or multipolygon (:func:`enclosed`), mm; empty gives 0.
        tolerance: how close to the true radius the search goes (shapely's
            ``maximum_inscribed_circle``, the pole of inaccessibility), mm.
    """
    from shapely import maximum_inscribed_circle

    if area.is_empty:
        return 0.0
    return 2.0 * float(maximum_inscribed_circle(area, tolerance).length)


def winding(ring: NDArray[np.float64], point: tuple[float, float]) -> int:
    """How many times the closed polyline ``ring`` winds around ``point`` (> 0: anticlockwise).

    Args:
        ring: ``(N, 2)`` vertices, mm, the last equal to the first.
        point: a point off the polyline, mm.
    """
    x, y = point
    x0, y0, x1, y1 = ring[:-1, 0], ring[:-1, 1], ring[1:, 0], ring[1:, 1]
    side = (x1 - x0) * (y - y0) - (x - x0) * (y1 - y0)  # > 0: the point left of the edge
    up = (y0 <= y) & (y1 > y) & (side > 0)
    down = (y0 > y) & (y1 <= y) & (side < 0)
    return int(up.sum()) - int(down.sum())
