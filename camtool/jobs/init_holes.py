"""``camtool job init``'s drilled circles: their hole sizes, and circles drawn around a smaller one.

A plan view draws a counterbore as two circles about one centre (the hole and the
counterbore), and a tapped hole by its drill circle and the thread's outer diameter
(ISO 6410-1 draws that one as a 3/4 arc, which is no circle, but many drawings close it).
From the plan alone the larger circle is a hole through the stock: ``job init`` cuts it so,
and says in the job file which circles it may be, for the user to give them their depth.

Design notes: docs/internals.md, ``camtool/jobs/init.py``.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from camtool.model.shapes import Point

CENTRE_DIGITS = 3
"""Centres are the same to 1 µm: the same point of the CAD drawing, written twice."""


def smallest_at(circles: Iterable[tuple[Point, float]]) -> dict[tuple[float, float], float]:
    """The smallest diameter (mm) drawn about each centre, by the centre rounded to 1 µm.

    ``circles``: each circle's centre (mm) and diameter (mm), as
    :func:`~camtool.model.shapes.circle_of` gives them.
    """
    smallest: dict[tuple[float, float], float] = {}
    for (x, y), d in circles:
        key = (round(x, CENTRE_DIGITS), round(y, CENTRE_DIGITS))
        smallest[key] = min(d, smallest.get(key, d))
    return smallest


def around_smaller(
    centre: Point, diameter: float, smallest: dict[tuple[float, float], float]
) -> bool:
    """Whether a smaller circle is drawn about ``centre`` (``smallest``: :func:`smallest_at`).

    Smaller by more than 1 µm: a circle drawn twice is the same circle.
    """
    key = (round(centre[0], CENTRE_DIGITS), round(centre[1], CENTRE_DIGITS))
    return smallest.get(key, diameter) < diameter - 1e-3


def around_note(count: int, cut: str, which: str = "of them") -> str:
    """What the job file says of ``count`` circles drawn around a smaller one.

    ``cut``: how the operation cuts them (``"drilled"``, ``"cut"``); ``which``: how the
    note names them among the operation's contours.
    """
    return (
        f"{count} {which} around a smaller circle at their centre (a counterbore, or a "
        f"thread's outer diameter, drawn in plan?): {cut} through the stock here; if so, give "
        "them an operation of their own with its depth"
    )


HOLE_SIZE_GAP_MM = 0.0005
"""Circles whose diameters lie closer than this (mm) to the next are one hole size."""


def hole_sizes(drilled: Sequence[tuple[float, bool]]) -> dict[float, list[tuple[float, bool]]]:
    """The drilled circles by hole size, each size its diameter (mm) to 1 µm.

    ``drilled``: each circle's diameter, mm, and whether it is drawn around a smaller one.
    Sorted diameters closer than :data:`HOLE_SIZE_GAP_MM` to their neighbour are one size
    (named by their median, rounded to 1 µm): two circles of 1.33349 and 1.33351 mm, which
    an exporter's floats put either side of a rounding, are one hole drilled by one drill,
    and two sizes' selections never take each other's circles.
    """
    sizes: dict[float, list[tuple[float, bool]]] = {}
    runs: list[list[tuple[float, bool]]] = []
    for hole in sorted(drilled):
        if runs and hole[0] - runs[-1][-1][0] < HOLE_SIZE_GAP_MM:
            runs[-1].append(hole)
        else:
            runs.append([hole])
    for run in runs:
        sizes.setdefault(round(run[len(run) // 2][0], 3), []).extend(run)
    return sizes
