"""Cutting order: contours inside others first, otherwise nearest first.

Nesting is found with shapely on the contours' polylines (arcs as chords within
a fine tolerance): a contour lies inside a closed contour when the closed
contour's polygon contains it. Among the contours whose inner contours are all
cut, the one whose start is nearest the tool goes next (greedy nearest
neighbour from the origin). Each contour keeps its drawn direction and start.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from camtool.geometry import Contour, Point, distance

_NEST_TOLERANCE_MM = 1e-4


@dataclass(frozen=True)
class Nesting:
    """Containment between contours.

    ``parents[i]`` lists the indices of the closed contours that contain contour
    ``i``; ``depth(i)`` is their count (0 = outermost). Even depth is an outer
    boundary of material, odd depth a hole (even-odd rule).
    """

    parents: tuple[tuple[int, ...], ...]

    def depth(self, index: int) -> int:
        """Number of closed contours around contour ``index``."""
        return len(self.parents[index])


def nesting(contours: Sequence[Contour]) -> Nesting:
    """Find which closed contours contain which contours.

    Args:
        contours: contours in mm.

    Returns:
        The containment relation, indexed like ``contours``.
    """
    from shapely import LineString, Polygon, STRtree

    # Closed contours as filled polygons (buffer(0) repairs self-touching outlines);
    # any contour, open or closed, is tested by its outline.
    outlines = [LineString(c.points(_NEST_TOLERANCE_MM)) for c in contours]
    closed = [i for i, c in enumerate(contours) if c.closed]
    polygons = [Polygon(outlines[i].coords).buffer(0) for i in closed]
    areas = {i: poly.area for i, poly in zip(closed, polygons, strict=True)}
    tree = STRtree(polygons)
    parents: list[tuple[int, ...]] = []
    for i, outline in enumerate(outlines):
        around = (closed[k] for k in tree.query(outline, predicate="covered_by"))
        # A polygon covers its own outline and that of an identical duplicate: a
        # parent must also be strictly larger.
        parents.append(tuple(sorted(j for j in around if areas[j] > areas.get(i, 0.0))))
    return Nesting(tuple(parents))


def order_contours(
    contours: Sequence[Contour], nest: Nesting, start: Point = (0.0, 0.0)
) -> list[int]:
    """Indices of ``contours`` in cutting order.

    A contour is cut only after every contour inside it; among those ready, the
    one whose start point is nearest the current tool position goes next (ties
    to the earlier index).

    Args:
        contours: contours in mm.
        nest: their containment, from :func:`nesting`.
        start: tool position before the first contour, mm.
    """
    inside: list[set[int]] = [set() for _ in contours]
    for i, parents in enumerate(nest.parents):
        for j in parents:
            inside[j].add(i)
    done: set[int] = set()
    order: list[int] = []
    here = start
    while len(order) < len(contours):
        ready = [i for i in range(len(contours)) if i not in done and inside[i] <= done]
        nxt = min(ready, key=lambda i: (distance(here, contours[i].start), i))
        order.append(nxt)
        done.add(nxt)
        here = contours[nxt].end
    return order
