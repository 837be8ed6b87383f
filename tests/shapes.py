"""Canonical test drawings, written as real DXF files with ezdxf."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import ezdxf
import numpy as np

from camtool.model.shapes import Line, Point, Segment

# UNAM-GMM L1731: G02X02969.00Y03400.00I03012.00J03040.00F08;
GOLDEN_CENTRE = (3.012, 3.040)
GOLDEN_END = (2.969, 3.400)


def write_dxf(path: Path, build: Callable[[Any], None], *, insunits: int = 4) -> Path:
    """Write a DXF whose model space ``build(msp)`` fills; ``insunits`` as $INSUNITS."""
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = insunits
    build(doc.modelspace())
    doc.saveas(path)
    return path


def golden_arc_dxf(path: Path) -> Path:
    """An LWPOLYLINE with one clockwise (negative-bulge) arc ending at the golden point.

    The arc starts on the same circle at 180° (left of the centre) and runs
    clockwise over the top to the end point at about 96.8°.
    """
    cx, cy = GOLDEN_CENTRE
    ex, ey = GOLDEN_END
    r = math.hypot(ex - cx, ey - cy)
    start = (cx - r, cy)
    end_angle = math.atan2(ey - cy, ex - cx)
    sweep = end_angle - math.pi  # negative: clockwise
    bulge = math.tan(sweep / 4)

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(*start, bulge), (ex, ey, 0.0)], format="xyb")

    return write_dxf(path, build)


def kin47_arcs_dxf(path: Path, centre: Point) -> Path:
    """A 5 mm hole as LibreCAD's kinetics/kin47.dxf draws it: two copies of an ARC of radius
    2.5 mm about ``centre`` from 270° to 269.99999427° (a gap of 0.25 µm)."""

    def build(msp: Any) -> None:
        for _ in range(2):
            msp.add_arc(centre, 2.5, 270.0, 269.99999427)

    return write_dxf(path, build)


def rectangle_dxf(path: Path, w: float = 10.0, h: float = 5.0, *, insunits: int = 4) -> Path:
    """A closed LWPOLYLINE rectangle ``w`` × ``h`` with its lower-left corner at (1, 1)."""

    def build(msp: Any) -> None:
        msp.add_lwpolyline([(1, 1), (1 + w, 1), (1 + w, 1 + h), (1, 1 + h)], close=True)

    return write_dxf(path, build, insunits=insunits)


def segment_samples(segments: Sequence[Segment], per_segment: int = 64) -> np.ndarray:
    """``(N, 2)`` points along lines and arcs (both ends included), mm."""
    pts: list[Point] = []
    for seg in segments:
        if isinstance(seg, Line):
            (x0, y0), (x1, y1) = seg.start, seg.end
            pts += [
                (x0 + (x1 - x0) * k / per_segment, y0 + (y1 - y0) * k / per_segment)
                for k in range(per_segment + 1)
            ]
        else:
            pts += [seg.point_at(k / per_segment) for k in range(per_segment + 1)]
    return np.array(pts, dtype=np.float64)


def two_sided_error(
    point_at: Callable[[float], Point],
    t0: float,
    t1: float,
    segments: Sequence[Segment],
    tolerance: float,
    n: int = 5000,
) -> tuple[float, float]:
    """Distances between a true curve and the segments fitted to it, both ways, mm.

    The curve ``point_at(t)``, ``t0 <= t <= t1``, is sampled at ``n + 1`` equally spaced
    parameters and at the ``n`` mid-parameters. Returns ``(curve -> segments,
    segments -> curve)``:

    - the first is exact for all those samples (distance to the lines and arcs);
    - for the second, each point along the segments gets an upper bound of its distance
      to the curve: its distance to the nearest chord between samples plus the chords'
      own largest distance from the curve (measured at the mid-parameters). Where that
      bound exceeds ``tolerance`` the point is measured again exactly, by golden-section
      search over each sample interval that can hold its nearest curve point (chords
      within twice the chord error of the nearest one).
    """
    import shapely

    from camtool.geometry.arcfit import distances

    ts = np.linspace(t0, t1, n + 1)
    curve = np.array([point_at(float(t)) for t in ts], dtype=np.float64)
    mids = np.array([point_at(float(t)) for t in (ts[:-1] + ts[1:]) / 2], dtype=np.float64)
    forward = float(np.max(distances(np.vstack([curve, mids]), segments)))
    chords = shapely.linestrings(np.stack([curve[:-1], curve[1:]], axis=1))
    tree = shapely.STRtree(chords)
    sag = float(np.max(shapely.distance(shapely.points(mids), chords)))  # each to its own
    out = shapely.points(segment_samples(segments))
    (index, _), dist = tree.query_nearest(out, return_distance=True, all_matches=False)
    bound = np.full(len(out), np.inf)
    np.minimum.at(bound, index, dist + sag)
    for k in np.flatnonzero(bound > tolerance):
        near = tree.query(out[k], predicate="dwithin", distance=bound[k] + 2 * sag)
        q = shapely.get_coordinates(out[k])[0]
        exact = min(_distance_to_curve(point_at, q, ts[i], ts[i + 1]) for i in near)
        bound[k] = min(bound[k], exact)
    return forward, float(np.max(bound))


def _distance_to_curve(
    point_at: Callable[[float], Point], q: np.ndarray, a: float, b: float
) -> float:
    """Smallest distance from ``q`` to ``point_at(t)``, ``a <= t <= b`` (golden section)."""

    def dist(t: float) -> float:
        p = point_at(t)
        return math.hypot(p[0] - q[0], p[1] - q[1])

    g = (math.sqrt(5) - 1) / 2
    c, d = b - g * (b - a), a + g * (b - a)
    for _ in range(50):
        if dist(c) < dist(d):
            b, d = d, c
            c = b - g * (b - a)
        else:
            a, c = c, d
            d = a + g * (b - a)
    return min(dist(a), dist(b), dist(0.5 * (a + b)))


# Angel-11 §3, L3196–L3200: the Matlab GUI's 11-point star, as the thesis prints ``xy``:
# row 1 x, row 2 y, in 0.1 mm.
STAR_XY_01MM = (
    (151, 400, 630, 575, 815, 501, 400, 294, 6, 220, 153),
    (86, 265, 86, 431, 639, 642, 999, 645, 665, 428, 86),
)

STAR_LXY = [
    [249, 230, 55, 240, 314, 101, 106, 288, 214, 67],
    [179, 179, 345, 208, 3, 357, 354, 20, 237, 342],
]
"""The star's ``lxy`` as the thesis prints it (Angel-11 §3, L3212–L3228), 0.1 mm."""

STAR_VELXY = [
    [480, 480, -77, 480, -480, -136, -144, -480, 433, -94],
    [345, -374, 480, 416, 5, 480, -480, 33, -480, -480],
]
"""The star's ``velxy`` as the thesis prints it (Angel-11 §3, L3212–L3228), counts per 5 ms."""
