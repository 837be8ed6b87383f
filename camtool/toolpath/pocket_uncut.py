"""What a pocket's tool paths leave uncut, and which of it the user must hear about.

Design notes: docs/internals.md, ``camtool/toolpath/pocket_uncut.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import shapely
from shapely import LineString, Polygon
from shapely.geometry.base import BaseGeometry
from shapely.geometry.polygon import orient

from camtool.model.shapes import Contour, Point
from camtool.toolpath.cuts import Cut, Finding, where
from camtool.toolpath.options import PlanOptions

__all__ = ["polygons", "quad_segs", "sweep_piece", "swept_area", "uncut_findings"]

MAX_REPORTED = 5
"""Uncut pieces reported one by one per pocket; the rest are counted."""

SWEEP_PIECE = 4096
"""Most points of one piece of a path buffered at once by :func:`swept_area`."""

MIN_SWEEP_PIECE = 64
"""Fewest points a piece is cut to for a small step-over (:func:`sweep_piece`)."""

_PIECE_STEPOVER = 0.4
"""The step-over (fraction of the tool diameter) at which pieces hold :data:`SWEEP_PIECE` points."""

_MIN_QUAD_SEGS = 8
_MAX_QUAD_SEGS = 1024
_CORNER_CAP = math.radians(150.0)  # a turn this sharp is a slot end, not a corner
_ZONE_SLACK = 1.1


def polygons(geom: BaseGeometry) -> list[Polygon]:
    """The non-empty polygons of a shapely geometry (polygon, multi or collection)."""
    if geom.is_empty:
        return []
    if isinstance(geom, Polygon):
        return [geom]
    return [g for part in getattr(geom, "geoms", ()) for g in polygons(part)]


def quad_segs(radius: float, tolerance: float) -> int:
    """Buffer segments per quarter circle so chords of ``radius`` deviate ≤ ``tolerance / 4``."""
    sagitta = tolerance / 4
    if sagitta >= radius:
        return _MIN_QUAD_SEGS
    chord_angle = 2.0 * math.acos(1.0 - sagitta / radius)
    if chord_angle <= 0.0:  # sagitta / radius below float resolution: as fine as allowed
        return _MAX_QUAD_SEGS
    return min(_MAX_QUAD_SEGS, max(_MIN_QUAD_SEGS, math.ceil(math.pi / 2 / chord_angle)))


def sweep_piece(stepover: float) -> int:
    """Points per piece for :func:`swept_area` of a pocket cut at ``stepover`` (fraction, (0, 1]).

    A pocket's passes lie a step-over apart, so about ``1 / stepover`` of them pass
    within the tool's width of each other, and a piece holding many passes overlaps
    itself that many times: GEOS's buffer of such a piece costs far more than the union
    of smaller pieces' buffers (docs/performance.md). The pieces shrink with the
    step-over, from :data:`SWEEP_PIECE` points at :data:`_PIECE_STEPOVER` to
    :data:`MIN_SWEEP_PIECE`.
    """
    scaled = round(SWEEP_PIECE * stepover / _PIECE_STEPOVER)
    return min(SWEEP_PIECE, max(MIN_SWEEP_PIECE, scaled))


def swept_area(
    paths: Sequence[Contour], radius: float, tolerance: float, *, piece: int = SWEEP_PIECE
) -> BaseGeometry:
    """Area a round tool of ``radius`` mm sweeps along ``paths`` (arcs as chords), mm².

    Each path is buffered in pieces of at most ``piece`` points (≥ 2; consecutive pieces
    share their end point) and the pieces' areas united: the same area, since the tool's
    sweep of a path is the union of its sweeps of the path's pieces. GEOS nodes a
    buffer's whole offset curve at once, and a pocket's linked rings pass beside
    themselves at every step-over, so one buffer of the whole path is far slower
    (:func:`sweep_piece` sizes the pieces for a pocket's step-over).
    """
    quad = quad_segs(radius, tolerance)
    pieces = [
        LineString(xy[i : i + piece])
        for p in paths
        for xy in (np.asarray(p.points(tolerance / 4), dtype=float),)
        for i in range(0, max(1, len(xy) - 1), piece - 1)
    ]
    return shapely.union_all(shapely.buffer(np.array(pieces, dtype=object), radius, quad_segs=quad))


def uncut_findings(
    area: Polygon, boundary: Contour, cuts: Sequence[Cut], options: PlanOptions
) -> list[Finding]:
    """Findings for what ``cuts`` leave of ``area``: narrow pieces and corner fillets.

    Args:
        area: the pocket region, mm (exterior and holes).
        boundary: the pocket's boundary contour (names it in the messages).
        cuts: the region's cuts; none when the region is narrower than the tool.
        options: the tool diameter and tolerance are used.

    Returns:
        ``uncut`` findings (``at`` a point inside the piece, ``value`` its area
        mm²) and at most one ``tight-corner`` finding (``value`` the tool radius).
    """
    d, tol = options.tool_diameter, options.tolerance
    if not cuts:
        x, y = _at(area)
        return [
            Finding(
                "uncut",
                f"{where(boundary)}: the whole pocket ({area.area:.3g} mm² around "
                f"({x:.3f}, {y:.3f}) mm) is narrower than the {d:g} mm tool; use a smaller "
                "tool to clear it",
                (x, y),
                area.area,
            )
        ]
    piece = sweep_piece(options.stepover)
    swept = swept_area([c.path for c in cuts], options.radius + tol, tol, piece=piece)
    threshold = (0.01 * d) ** 2
    pieces = [p for p in polygons(area.difference(swept)) if p.area > threshold]
    centres, zone = _corners(area, options.radius)
    fillets = [p for p in pieces if _is_fillet(p, centres, zone, threshold)]
    narrow = sorted((p for p in pieces if not any(p is f for f in fillets)), key=lambda p: -p.area)
    reach = _reachable(area, options) if narrow else area
    missed = f"between passes; reduce --stepover (now {options.stepover:g})"
    too_narrow = f"narrower than the {d:g} mm tool; use a smaller tool to clear it"
    findings = [
        _uncut(p, boundary, missed if p.difference(reach).area <= threshold else too_narrow)
        for p in narrow[:MAX_REPORTED]
    ]
    rest = narrow[MAX_REPORTED:]
    if rest:
        findings.append(
            Finding(
                "uncut",
                f"{where(boundary)}: and {len(rest)} more uncut region(s) "
                f"({sum(p.area for p in rest):.3g} mm²) narrower than the {d:g} mm tool or "
                "between passes",
                None,
                sum(p.area for p in rest),
            )
        )
    if fillets:
        findings.append(_corner_finding(fillets, boundary, options.radius))
    return findings


def _at(piece: Polygon) -> Point:
    p = piece.representative_point()
    return (float(p.x), float(p.y))


def _reachable(area: Polygon, options: PlanOptions) -> BaseGeometry:
    """Where a tool of the plan's radius can reach at all (the opening of ``area``), mm²."""
    r, tol = options.radius, options.tolerance
    quad = quad_segs(r, tol)
    return area.buffer(-r, quad_segs=quad).buffer(r + tol, quad_segs=quad)


def _uncut(piece: Polygon, boundary: Contour, why: str) -> Finding:
    """The finding for one uncut ``piece`` of the pocket ``boundary``, ``why`` it is left."""
    x, y = _at(piece)
    return Finding(
        "uncut",
        f"{where(boundary)}: {piece.area:.3g} mm² left uncut at ({x:.3f}, {y:.3f}) mm, {why}",
        (x, y),
        piece.area,
    )


def _corner_finding(fillets: Sequence[Polygon], boundary: Contour, r: float) -> Finding:
    total = sum(p.area for p in fillets)
    return Finding(
        "tight-corner",
        f"{where(boundary)}: {len(fillets)} pocket corner(s) keep the {r:g} mm tool radius "
        f"({total:.3g} mm² uncut in all); a round tool cannot cut sharper inside corners",
        _at(fillets[0]),
        r,
    )


def _corners(area: Polygon, r: float) -> tuple[np.ndarray, np.ndarray]:
    """Convex vertices of ``area`` ``(N, 2)`` and the reach of their fillet zones ``(N,)``, mm."""
    area = orient(area, 1.0)  # interior on the left of every ring
    found_xy: list[np.ndarray] = []
    found_reach: list[np.ndarray] = []
    for ring in (area.exterior, *area.interiors):
        xy = np.asarray(ring.coords, dtype=np.float64)[:-1]
        if len(xy) < 3:
            continue
        e_out = np.roll(xy, -1, axis=0) - xy
        e_in = xy - np.roll(xy, 1, axis=0)
        cross = e_in[:, 0] * e_out[:, 1] - e_in[:, 1] * e_out[:, 0]
        dot = np.einsum("ij,ij->i", e_in, e_out)
        turn = np.arctan2(cross, dot)
        total = _window_sum(turn, np.hypot(e_out[:, 0], e_out[:, 1]), r)
        keep = (turn > 0) & (total > 0) & (total < _CORNER_CAP)
        found_xy.append(xy[keep])
        found_reach.append(_ZONE_SLACK * r * np.tan(total[keep] / 2))
    if not found_xy:
        return np.zeros((0, 2)), np.zeros(0)
    return np.vstack(found_xy), np.concatenate(found_reach)


def _window_sum(turn: np.ndarray, edge: np.ndarray, w: float) -> np.ndarray:
    """For each vertex of a closed ring, the sum of the turns within ``w`` along the ring."""
    n = len(turn)
    pos = np.concatenate([[0.0], np.cumsum(np.tile(edge, 3))])[: 3 * n] - edge.sum()
    turns = np.concatenate([[0.0], np.cumsum(np.tile(turn, 3))])
    middle = pos[n : 2 * n]
    lo = np.searchsorted(pos, middle - w, side="left")
    hi = np.searchsorted(pos, middle + w, side="right")
    return np.asarray(turns[hi] - turns[lo])


def _is_fillet(piece: Polygon, centres: np.ndarray, reach: np.ndarray, slack: float) -> bool:
    if not len(centres):
        return False
    near = shapely.distance(shapely.points(centres), piece) <= reach
    if not near.any():
        return False
    zones = shapely.buffer(shapely.points(centres[near]), reach[near], quad_segs=16)
    return bool(piece.difference(shapely.union_all(zones)).area <= slack)
