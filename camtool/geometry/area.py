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


def enclosed(points: Sequence[tuple[float, float]]) -> BaseGeometry:
    """The area the closed polyline ``points`` encloses, by the nonzero winding rule, mm.

    A polyline that neither crosses nor touches itself gives its polygon as shapely's
    ``buffer(0)`` does. One that does is noded where it crosses itself (GEOS), its faces
    made (shapely's ``polygonize``), and the faces it winds around at least once, either
    way, united: both lobes of a bow-tie, the centre of a five-pointed star; a face it
    winds around once each way (a loop drawn back over itself) is left out.

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
    faces = shapely.get_parts(shapely.polygonize(shapely.get_parts(shapely.node(LineString(ring)))))
    kept = [face for face in faces if winding(ring, face.representative_point().coords[0]) != 0]
    if not kept:
        return Polygon()
    return shapely.union_all(kept)


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
