"""The calibration coupon: test features that measure what a machine profile models.

Every feature is the UNAM-GMM §5 procedure or a direct extension of it (UNAM-GMM §5.2, Tablas
13-15; Yanez-07 §5 and §6.1; Munoz-22 §5.1):

Design notes: docs/internals.md, ``camtool/calibrate/coupon.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

from camtool.model.errors import UsageError
from camtool.model.machine import AXES, Machine
from camtool.model.program import ArcMove, Linear, Move, Program, Rapid
from camtool.model.shapes import BBox, Point
from camtool.toolpath.options import DEFAULT_CLEARANCE_Z

if TYPE_CHECKING:
    from camtool.post.base import Target

DIAMETER_ANGLES_DEG: tuple[float, ...] = tuple(22.5 * k for k in range(8))
"""Directions of the eight diameters of a circle (UNAM-GMM Tabla 15 measured ø1-ø8; the angles
are only in the lost Fig. 54, so every 22.5° is our choice)."""
SEGMENTS = 10
"""Segments of a long move (Munoz-22 §5.1: "10 tramos de 8mm")."""
SAFE_Z_MM = 2.0
"""Height of the rapids between features on a machine with Z, mm above the work."""
MIN_STEPS = 40
"""Fewest motor steps across the smallest feature (a ø2 circle at scale 1) for it to be
measurable; a smaller travel is refused."""
MAX_CIRCLE_STEPS = 2_000_000
"""Most motor steps around the largest circle (the simulation's size)."""
SCALES: tuple[float, ...] = (
    *(10, 8, 6, 5, 4, 3, 2.5, 2, 1.5, 1.2, 1),
    *(0.8, 0.6, 0.5, 0.4, 0.3, 0.25, 0.2, 0.15, 0.12, 0.1),
)
"""Coupon scales tried, largest first (1 = the UNAM-GMM sizes: U 2.5/1.2 mm, squares 2.5 mm,
circles ø6/4/2 mm)."""


@dataclass(frozen=True)
class Measure:
    """One number a machinist measures on the coupon.

    Attributes:
        id: the feature id and the measure (``"UX-2.back"``): the sheet's row key.
        what: what to measure, for the sheet.
        at_mm: where, mm (work coordinates): the middle of the mark.
        nominal_mm: the value if the machine were perfect, mm.
        kind: ``"length"`` (extent along ``axis`` of the marks of ``strokes``),
            ``"diameter"`` (mean width of the marks of ``strokes`` across the
            directions ``angles_deg``) or ``"position"`` (distance along ``axis`` from
            the start of the first stroke to the end of ``strokes[-1]``).
        axis: 0 = X, 1 = Y, 2 = Z (``length``, ``position``); -1 for ``diameter``.
        strokes: indices into the feature's :attr:`Feature.strokes`.
        angles_deg: directions of the diameters (``diameter``), degrees from +X.
    """

    id: str
    what: str
    at_mm: Point
    nominal_mm: float
    kind: str
    axis: int
    strokes: tuple[int, ...]
    angles_deg: tuple[float, ...] = DIAMETER_ANGLES_DEG


@dataclass(frozen=True)
class Feature:
    """A test feature: its lead-in, its strokes and what is measured on them.

    Attributes:
        id: short id (``"UX-2"``, ``"SQ1"``, ``"C6"``, ``"LX"``).
        title: one line for the sheet.
        origin_mm: where the tool stands before ``lead`` (the approach's start), mm.
        lead: the approach moves (take up the play; not measured).
        strokes: the measured moves, in order.
        measures: what is measured.
        region: the backlash region the feature measures, ``""`` for none
            (``"x: y 2.333…4.667 mm"``).
    """

    id: str
    title: str
    origin_mm: Point
    lead: tuple[Move, ...]
    strokes: tuple[Move, ...]
    measures: tuple[Measure, ...]
    region: str = ""

    @property
    def moves(self) -> tuple[Move, ...]:
        """Lead and strokes, in order."""
        return (*self.lead, *self.strokes)

    def program(self) -> Program:
        """The feature alone, from its origin (what :mod:`camtool.calibrate.predict` runs)."""
        return Program(self.moves, origin=self.origin_mm)

    def bbox(self) -> BBox:
        """Footprint in XY (origin, lead and strokes, arcs by their extremes), mm."""
        return self.program().bbox()

    def moved(self, dx: float, dy: float) -> Feature:
        """The feature translated by ``(dx, dy)`` mm."""
        return replace(
            self,
            origin_mm=(self.origin_mm[0] + dx, self.origin_mm[1] + dy),
            lead=tuple(translated(m, dx, dy) for m in self.lead),
            strokes=tuple(translated(m, dx, dy) for m in self.strokes),
            measures=tuple(
                replace(m, at_mm=(m.at_mm[0] + dx, m.at_mm[1] + dy)) for m in self.measures
            ),
        )


def translated(move: Move, dx: float, dy: float) -> Move:
    """``move`` translated by ``(dx, dy)`` mm (an arc's centre too)."""
    if isinstance(move, ArcMove):
        return replace(move, x=move.x + dx, y=move.y + dy, cx=move.cx + dx, cy=move.cy + dy)
    return replace(move, x=move.x + dx, y=move.y + dy)


@dataclass(frozen=True)
class Coupon:
    """A coupon for one target.

    Attributes:
        target: the target's name.
        scale: size of the features against UNAM-GMM's (1: U 2.5/1.2 mm, squares 2.5 mm,
            circles ø6/4/2 mm); ``0`` for a coupon of hand-made features.
        features: the features, in cutting order.
        program: the coupon program (every feature with rapids between), mm.
    """

    target: str
    scale: float
    features: tuple[Feature, ...]
    program: Program

    @property
    def measures(self) -> tuple[Measure, ...]:
        """Every measure of every feature, in sheet order."""
        return tuple(m for f in self.features for m in f.measures)


# --- features (local builders, absolute mm) -------------------------------------------------


def u_pattern(
    fid: str, axis: int, start: Point, length: float, gap: float, approach: float, feed: float
) -> Feature:
    """The UNAM-GMM §5.2 U pattern along ``axis`` (0 = X, 1 = Y) from ``start``.

    Out along +axis by ``length``, across by ``gap`` (+ the other axis), back by ``length``.
    Measures: ``out`` and ``back`` lengths (UNAM-GMM Tabla 13: their difference is the backlash).
    """
    other = 1 - axis
    x0, y0 = start
    name = AXES[axis].upper()

    def at(along: float, across: float) -> Point:
        p = [0.0, 0.0]
        p[axis], p[other] = along, across
        return (x0 + p[0], y0 + p[1])

    strokes = (
        Linear(*at(length, 0.0), feed),
        Linear(*at(length, gap), feed),
        Linear(*at(0.0, gap), feed),
    )
    measures = (
        Measure(
            f"{fid}.out",
            f"length of the first {name} line (cut in +{name}), end to end",
            at(length / 2, 0.0),
            length,
            "length",
            axis,
            (0,),
        ),
        Measure(
            f"{fid}.back",
            f"length of the second {name} line (cut in -{name}, after the reversal), end to end",
            at(length / 2, gap),
            length,
            "length",
            axis,
            (2,),
        ),
    )
    return Feature(
        fid,
        f"U pattern along {name}: {length:g} mm lines {gap:g} mm apart",
        _before(start, (1.0, 1.0), approach),
        (Linear(x0, y0, feed),),
        strokes,
        measures,
    )


def rectangle(
    fid: str, corner: Point, size: tuple[float, float], approach: float, feed: float
) -> Feature:
    """A rectangle cut counter-clockwise from its lower-left ``corner`` (UNAM-GMM Tabla 14).

    Measures: ``dx``, the top edge (cut in -X after the X reversal), and ``dy``, the left
    edge (cut in -Y after the Y reversal), each end to end.
    """
    x0, y0 = corner
    w, h = size
    strokes = (
        Linear(x0 + w, y0, feed),
        Linear(x0 + w, y0 + h, feed),
        Linear(x0, y0 + h, feed),
        Linear(x0, y0, feed),
    )
    measures = (
        Measure(
            f"{fid}.dx",
            "length of the top edge (cut in -X), from the top-right corner to the end of the mark",
            (x0 + w / 2, y0 + h),
            w,
            "length",
            0,
            (2,),
        ),
        Measure(
            f"{fid}.dy",
            "length of the left edge (cut in -Y), from the top-left corner to the end of the mark",
            (x0, y0 + h / 2),
            h,
            "length",
            1,
            (3,),
        ),
    )
    kind = "square" if w == h else "rectangle"
    return Feature(
        fid,
        f"{w:g} x {h:g} mm {kind}, counter-clockwise from the lower-left corner",
        _before(corner, (1.0, 1.0), approach),
        (Linear(x0, y0, feed),),
        strokes,
        measures,
    )


def circle(fid: str, centre: Point, diameter: float, approach: float, feed: float) -> Feature:
    """A full circle cut clockwise from its top (UNAM-GMM Tabla 15).

    Measures: ``h`` and ``v``, the horizontal and vertical diameters (Yanez-07 §6.2), and
    ``mean``, the mean of eight diameters every 22.5° (:data:`DIAMETER_ANGLES_DEG`, UNAM-GMM
    Tabla 15).
    """
    cx, cy = centre
    r = diameter / 2.0
    top = (cx, cy + r)
    across = "from the centre line of the mark to the centre line opposite"
    measures = (
        Measure(
            f"{fid}.h",
            f"horizontal diameter (along X), {across}",
            centre,
            diameter,
            "diameter",
            -1,
            (0,),
            (0.0,),
        ),
        Measure(
            f"{fid}.v",
            f"vertical diameter (along Y), {across}",
            centre,
            diameter,
            "diameter",
            -1,
            (0,),
            (90.0,),
        ),
        Measure(
            f"{fid}.mean",
            f"mean of 8 diameters every 22.5° from the X axis, {across}",
            centre,
            diameter,
            "diameter",
            -1,
            (0,),
        ),
    )
    return Feature(
        fid,
        f"ø{diameter:g} mm circle, clockwise from the top",
        _before(top, (1.0, -1.0), approach),
        (Linear(*top, feed),),
        (ArcMove(cx, cy + r, cx, cy, True, feed),),
        measures,
    )


def long_move(
    fid: str, axis: int, start: Point, segment: float, approach: float, feed: float
) -> Feature:
    """A long move along +``axis`` (0 = X, 1 = Y) in :data:`SEGMENTS` equal segments.

    Measures ``p1`` … ``p10``: travel from the start to the end of each segment, measured on the
    carriage (Munoz-22 Tables 14-16: a vernier after each move of 8 mm).
    """
    name = AXES[axis].upper()
    direction = (1.0, 0.0) if axis == 0 else (0.0, 1.0)
    x0, y0 = start
    strokes = []
    measures = []
    for i in range(1, SEGMENTS + 1):
        end = (x0 + direction[0] * segment * i, y0 + direction[1] * segment * i)
        strokes.append(Linear(*end, feed))
        measures.append(
            Measure(
                f"{fid}.p{i}",
                f"travel along {name} from the start to the end of segment {i} (the carriage "
                "against a vernier or dial indicator, as Munoz-22 measured it)",
                end,
                segment * i,
                "position",
                axis,
                tuple(range(i)),
            )
        )
    return Feature(
        fid,
        f"long move along +{name}: {SEGMENTS} segments of {segment:g} mm",
        _before(start, (1.0, 1.0), approach),
        (Linear(x0, y0, feed),),
        tuple(strokes),
        tuple(measures),
    )


def long_move_z(fid: str, at: Point, segment: float, approach: float, feed: float) -> Feature:
    """A long move along +Z (up from the work) in :data:`SEGMENTS` segments (Munoz-22 Table 14).

    Measures ``p1`` … ``p10`` with a height gauge or the vernier's depth rod: the height of
    each stop above the first.
    """
    x, y = at
    strokes = [Linear(x, y, feed, z=approach + segment * i) for i in range(1, SEGMENTS + 1)]
    measures = tuple(
        Measure(
            f"{fid}.p{i}",
            f"height of stop {i} above the start (Z), e.g. with a dial gauge on the spindle",
            at,
            segment * i,
            "position",
            2,
            tuple(range(i)),
        )
        for i in range(1, SEGMENTS + 1)
    )
    return Feature(
        fid,
        f"long move along +Z: {SEGMENTS} segments of {segment:g} mm (no mark: measure the stops)",
        at,
        (Linear(x, y, feed, z=0.0), Linear(x, y, feed, z=approach)),
        tuple(strokes),
        measures,
    )


def _before(point: Point, direction: tuple[float, float], approach: float) -> Point:
    """Where an approach of ``approach`` mm towards ``point`` along ``direction`` starts."""
    return (point[0] - direction[0] * approach, point[1] - direction[1] * approach)


# --- the coupon -------------------------------------------------------------------------------


def coupon_from_features(
    target: Target, features: Sequence[Feature], *, scale: float = 0.0
) -> Coupon:
    """A coupon of ``features`` (in cutting order) for ``target``: its program joins them.

    On a machine with Z it starts and ends as every planned program does
    (:mod:`camtool.toolpath.passes`): a Z-only rise to the default clearance
    (:data:`~camtool.toolpath.options.DEFAULT_CLEARANCE_Z`) where the tool stands,
    XY at clearance, down to :data:`SAFE_Z_MM`; between features up to
    :data:`SAFE_Z_MM`, XY, and down to Z 0; at the end up to clearance. The
    target's spindle (``spindle_rpm``, when it has one) runs from the first move to
    the last.

    Raises:
        UsageError: two features share an id.
    """
    ids = [f.id for f in features]
    if len(set(ids)) != len(ids):
        raise UsageError(f"coupon features must have distinct ids, got {ids}")
    has_z = target.machine.has_z
    feed = target.default_feed_mm_min
    moves: list[Move] = []
    here = features[0].origin_mm if features else (0.0, 0.0)
    for n, feature in enumerate(features):
        ox, oy = feature.origin_mm
        if has_z:
            moves.append(Rapid(*here, z=DEFAULT_CLEARANCE_Z if n == 0 else SAFE_Z_MM))
            moves.append(Rapid(ox, oy))
            if n == 0:
                moves.append(Rapid(ox, oy, z=SAFE_Z_MM))
            first = feature.lead[0] if feature.lead else None
            if not (isinstance(first, Linear) and first.z == 0.0):
                moves.append(Linear(ox, oy, feed, z=0.0))
        elif moves:
            moves.append(Rapid(ox, oy))
        moves.extend(feature.moves)
        last = feature.moves[-1]
        here = (last.x, last.y)
    top = next((m.z for m in reversed(moves) if m.z is not None), None)
    if has_z and (top is None or top < DEFAULT_CLEARANCE_Z):  # a rise, never a descent
        moves.append(Rapid(*here, z=DEFAULT_CLEARANCE_Z))
    origin = features[0].origin_mm if features else (0.0, 0.0)
    notes: tuple[str, ...] = (
        f"calibration coupon for {target.name}: {len(features)} features "
        f"({', '.join(ids)}); measure them as the sheet says",
    )
    if has_z:
        notes = (
            *notes,
            f"cuts at Z 0 (set work zero Z where the tool should mark the stock); rapids at "
            f"Z {SAFE_Z_MM:g}, clearance Z {DEFAULT_CLEARANCE_Z:g} mm",
        )
    program = Program(tuple(moves), origin=origin, notes=notes)
    if target.spindle_rpm:
        program = program.with_spindle(target.spindle_rpm)
    return Coupon(target.name, scale, tuple(features), program)


def approach_mm(machine: Machine, scale: float) -> float:
    """Length of every feature's approach at ``scale``, mm: longer than any backlash known.

    1.5 × the largest true or compensated backlash of X and Y (regions included), at least
    0.2 mm per unit of scale and 20 motor steps. It does not depend on the travel, so that
    a larger travel never needs more room for the same coupon.
    """
    b = machine.backlash
    largest = max(
        [*b.true_um[:2], *b.compensation_um[:2], *(r.true_um for r in b.regions)], default=0.0
    )
    return max(1.5 * largest / 1000.0, 0.2 * scale, 20.0 / min(machine.steps_per_mm[:2]))


def build_coupon(target: Target) -> Coupon:
    """The default coupon of ``target``, laid out in its work area at the largest scale that fits.

    Scale 1 is UNAM-GMM's sizes; a machine with a larger travel gets a larger coupon (up to
    10×, and no circle of more than :data:`MAX_CIRCLE_STEPS` steps), a smaller one a smaller
    coupon, down to :data:`MIN_STEPS` steps across the smallest circle. Features: a long move
    along X (at the top of the work area) and along Y (at its right), each as long as the
    travel allows (and Z on a machine with Z), a U pattern per axis and per backlash region of
    the profile (one per axis when it has none), three squares and three concentric circles.

    The scale never decreases when the travel grows: whether scale ``s`` fits is decided in
    boxes whose size depends only on ``s`` and the profile (:data:`ASPECTS`), at the lower
    left of the work area, so what fits in a travel fits in every larger one.

    Raises:
        UsageError: the travel is too small for a measurable coupon (names the size needed).
    """
    machine = target.machine
    spm = min(machine.steps_per_mm[:2])
    largest = min(10.0, MAX_CIRCLE_STEPS / (math.pi * 6.0 * spm))
    smallest = MIN_STEPS / (2.0 * spm)
    scales = [s for s in SCALES if smallest <= s <= largest]
    for scale in scales:
        features = _layout(target, scale)
        if features is not None:
            return coupon_from_features(target, features, scale=scale)
    w, h = machine.travel_mm
    least = scales[-1] if scales else max(smallest, SCALES[-1])
    need = _travel_needed(target, least)
    regions = " with a U pattern in each backlash region" if machine.backlash.regions else ""
    raise UsageError(
        f"the travel of {target.name} ({w:g} x {h:g} mm) is too small for a calibration coupon "
        f"(the smallest, at scale {least:g}{regions}, needs {need}); give the real "
        "work_area_mm with --machine"
    )


def _travel_needed(target: Target, scale: float) -> str:
    """The smallest square travel from the work area's corner that holds the coupon at ``scale``."""
    x0, y0, x1, y1 = target.machine.work_area_mm
    side = max(x1 - x0, y1 - y0)
    for _ in range(80):
        side *= 1.1
        machine = replace(target.machine, work_area_mm=(x0, y0, x0 + side, y0 + side))
        if _layout(replace(target, machine=machine), scale) is not None:
            return f"about {side:.3g} x {side:.3g} mm"
    return "a larger travel"


ASPECTS: tuple[float, ...] = (1.0, 1.5, 1 / 1.5, 1.75, 1 / 1.75, 2.5, 1 / 2.5)
"""Width/height of the boxes the scaled features are packed in, tried in this order."""
GROWTH = 1.08
"""Each box tried is this much larger than the one before (from the features' total area)."""


def _layout(target: Target, scale: float) -> list[Feature] | None:
    """The default features placed in the work area at ``scale``, or ``None`` if they do not fit.

    The long moves run along the top and the right of the work area (as long as it allows);
    the other features are packed at its lower left in the smallest box of one of
    :data:`ASPECTS` (sizes growing by :data:`GROWTH`) where they fit; that box depends on the
    scale and the profile only, never on the travel.
    """
    machine = target.machine
    feed = target.default_feed_mm_min
    a = approach_mm(machine, scale)
    x0, y0, x1, y1 = machine.work_area_mm
    m = a  # beyond the approach, which the footprints include
    ix0, iy0, ix1, iy1 = x0 + m, y0 + m, x1 - m, y1 - m
    seg_x = _nice_floor((ix1 - ix0 - a) / SEGMENTS)
    seg_y = _nice_floor((iy1 - iy0 - 3 * a) / SEGMENTS)
    if seg_x <= 0 or seg_y <= 0:
        return None
    lx = long_move("LX", 0, (0.0, 0.0), seg_x, a, feed)
    ly = long_move("LY", 1, (0.0, 0.0), seg_y, a, feed)
    lx = _at(lx, (ix0, iy1 - _size(lx)[1]))
    ly = _at(ly, (ix1 - _size(ly)[0], iy0))
    cw, ch = ix1 - ix0 - _size(ly)[0] - a, iy1 - iy0 - _size(lx)[1] - a
    if cw <= 0 or ch <= 0:
        return None
    items = _scaled_features(target, scale, a, feed)
    area = sum(_size(f)[0] * _size(f)[1] for group in items for f in group[0])
    for aspect in ASPECTS:
        side = math.sqrt(max(area, 1e-12))
        fit_side = min(cw / math.sqrt(aspect), ch * math.sqrt(aspect))
        while side <= fit_side * (1 + 1e-12):
            w, h = side * math.sqrt(aspect), side / math.sqrt(aspect)
            placed = _pack(items, (ix0, iy0, ix0 + w, iy0 + h), a)
            if placed is not None:
                return [lx, ly, *placed]
            side *= GROWTH
    return None


def _scaled_features(
    target: Target, scale: float, a: float, feed: float
) -> list[tuple[list[Feature], BBox | None]]:
    """The features other than the long moves, in packing order, each group with its region."""
    machine = target.machine
    out: list[tuple[list[Feature], BBox | None]] = []
    regions = machine.backlash.regions
    for axis, length in ((0, 2.5 * scale), (1, 1.2 * scale)):
        gap = 0.3 * scale
        mine = [r for r in regions if r.axis == AXES[axis]]
        name = "UX" if axis == 0 else "UY"
        for i, region in enumerate(mine or [None], start=1):
            fid = f"{name}-{i}" if region is not None else name
            feature = u_pattern(fid, axis, (0.0, 0.0), length, gap, a, feed)
            bounds = None
            if region is not None:
                bounds = (region.x_mm[0], region.y_mm[0], region.x_mm[1], region.y_mm[1])
                feature = replace(feature, region=_region_text(region.x_mm, region.y_mm))
            out.append(([feature], bounds))
    for i in range(1, 4):
        out.append(([rectangle(f"SQ{i}", (0.0, 0.0), (2.5 * scale,) * 2, a, feed)], None))
    out.append(([circle(f"C{d:g}", (0.0, 0.0), d * scale, a, feed) for d in (6, 4, 2)], None))
    if machine.has_z:
        seg_z = _nice_floor(min(20.0, 4.0 * scale) / SEGMENTS)
        out.append(([long_move_z("LZ", (0.0, 0.0), seg_z, a, feed)], None))
    return out


def _pack(
    items: Sequence[tuple[list[Feature], BBox | None]], box: BBox, gap: float
) -> list[Feature] | None:
    """``items`` packed bottom-left in ``box`` (``None``: they do not all fit)."""
    packer = _Packer(box, gap=gap)
    out: list[Feature] = []
    for group, within in items:
        placed = packer.place_group(group, within=within)
        if placed is None:
            return None
        out.extend(placed)
    return out


def _size(feature: Feature) -> tuple[float, float]:
    x0, y0, x1, y1 = feature.bbox()
    return (x1 - x0, y1 - y0)


def _at(feature: Feature, corner: Point) -> Feature:
    """``feature`` moved so that its footprint's lower-left corner is ``corner``."""
    x0, y0, _, _ = feature.bbox()
    return feature.moved(corner[0] - x0, corner[1] - y0)


def _region_text(x_mm: tuple[float, float], y_mm: tuple[float, float]) -> str:
    parts = []
    if x_mm[0] > -999 or x_mm[1] < 999:
        parts.append(f"X {x_mm[0]:g}…{x_mm[1]:g}")
    if y_mm[0] > -999 or y_mm[1] < 999:
        parts.append(f"Y {y_mm[0]:g}…{y_mm[1]:g}")
    return " ".join(parts) + " mm" if parts else "everywhere"


def _nice_floor(value: float) -> float:
    """The largest of 1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k not above ``value`` (0 if <= 0)."""
    if value <= 0:
        return 0.0
    power = 10.0 ** math.floor(math.log10(value))
    for m in (8.0, 6.0, 5.0, 4.0, 3.0, 2.5, 2.0, 1.5, 1.2, 1.0):
        if m * power <= value * (1 + 1e-12):
            return m * power
    return power


class _Packer:
    """Bottom-left placement of footprints in a box without overlaps (local to one layout)."""

    def __init__(self, box: BBox, *, gap: float) -> None:
        self.box, self.gap = box, gap
        self.placed: list[BBox] = []

    @property
    def width(self) -> float:
        return self.box[2] - self.box[0]

    @property
    def height(self) -> float:
        return self.box[3] - self.box[1]

    def place(self, feature: Feature, *, within: BBox | None = None) -> Feature | None:
        group = self.place_group([feature], within=within)
        return None if group is None else group[0]

    def place_group(
        self, features: Sequence[Feature], *, within: BBox | None = None
    ) -> list[Feature] | None:
        """The features moved together to the lowest, then leftmost, free spot (``None``: none)."""
        boxes = [f.bbox() for f in features]
        fx0 = min(b[0] for b in boxes)
        fy0 = min(b[1] for b in boxes)
        fw = max(b[2] for b in boxes) - fx0
        fh = max(b[3] for b in boxes) - fy0
        area = self.box
        if within is not None:
            area = (
                max(area[0], within[0]),
                max(area[1], within[1]),
                min(area[2], within[2]),
                min(area[3], within[3]),
            )
        xs = {area[0], *(b[2] + self.gap for b in self.placed)}
        ys = {area[1], *(b[3] + self.gap for b in self.placed)}
        for y in sorted(ys):
            for x in sorted(xs):
                spot = (x, y, x + fw, y + fh)
                if spot[2] > area[2] + 1e-9 or spot[3] > area[3] + 1e-9:
                    continue
                if x < area[0] - 1e-9 or y < area[1] - 1e-9:
                    continue
                if any(_overlap(spot, b, self.gap) for b in self.placed):
                    continue
                self.placed.append(spot)
                return [f.moved(x - fx0, y - fy0) for f in features]
        return None


def _overlap(a: BBox, b: BBox, gap: float) -> bool:
    return not (
        a[2] + gap <= b[0] + 1e-9
        or b[2] + gap <= a[0] + 1e-9
        or a[3] + gap <= b[1] + 1e-9
        or b[3] + gap <= a[1] + 1e-9
    )
