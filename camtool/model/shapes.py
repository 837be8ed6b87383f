"""Drawing geometry: Line, Arc, Contour, Drawing. Immutable, mm, Y up, arcs exact.

Design notes: docs/internals.md, ``camtool/model/shapes.py``.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, fields, replace
from typing import Any, Generic, TypeAlias, TypeVar, overload

from camtool.model.errors import GeometryError, UsageError
from camtool.model.plain import plain_fields, share_keys
from camtool.model.units import fmt_num

Point: TypeAlias = tuple[float, float]
BBox: TypeAlias = tuple[float, float, float, float]
"""``(xmin, ymin, xmax, ymax)`` in mm."""

TAU = 2.0 * math.pi
FULL_CIRCLE_EPS = 1e-12
"""An arc is a full circle when its ends are within this times ``max(1, radius)`` mm
(:attr:`Arc.is_full_circle`; the word-address writer and the ordering test it inline)."""
SPIRAL_EPS = 1e-9
"""An arc's ends at radii this times ``max(1, radius)`` mm apart are on one circle
(:attr:`Arc.spiral`): rounding, not a spiral."""

_T = TypeVar("_T")

_QUADRANTS = tuple(
    (k * math.pi / 2, math.cos(k * math.pi / 2), math.sin(k * math.pi / 2)) for k in range(4)
)
"""``(angle, cos, sin)`` of the quadrant angles ``k·π/2``: the very floats :meth:`Arc.bbox`
computed per call before (``math.cos(k * math.pi / 2)``), computed once."""


class cached_property(Generic[_T]):
    """A property computed once per instance and kept in its ``__dict__`` (lock-free).

    ``functools.cached_property`` takes a lock on every first access in Python 3.11; arcs
    are made by the hundred thousand and read once or twice, so that lock cost more than
    the angle it saved. The value is the one the function returns, so the same floats
    as a plain ``@property``; it is not a field (equality, hashing and ``repr`` ignore it).
    """

    def __init__(self, func: Callable[[Any], _T]) -> None:
        self.func = func
        self.name = func.__name__
        self.__doc__ = func.__doc__

    def __set_name__(self, owner: type, name: str) -> None:
        self.name = name

    @overload
    def __get__(self, instance: None, owner: type | None = None) -> cached_property[_T]: ...

    @overload
    def __get__(self, instance: object, owner: type | None = None) -> _T: ...

    def __get__(self, instance: object | None, owner: type | None = None) -> Any:
        if instance is None:
            return self
        value = self.func(instance)
        instance.__dict__[self.name] = value
        return value


def distance(a: Point, b: Point) -> float:
    """Euclidean distance between two points, mm."""
    return math.hypot(b[0] - a[0], b[1] - a[1])


def arc_sweep(
    start: Point, end: Point, centre: Point, clockwise: bool, radius: float, start_angle: float
) -> float:
    """:attr:`Arc.sweep` of that arc, radians (> 0 counter-clockwise), the same float.

    ``radius`` and ``start_angle`` are the arc's :attr:`Arc.radius` and
    :attr:`Arc.start_angle`; :func:`arc_length` computes them, :class:`Arc` keeps them.
    """
    if distance(start, end) <= FULL_CIRCLE_EPS * max(1.0, radius):  # Arc.is_full_circle
        return -TAU if clockwise else TAU
    end_angle = math.atan2(end[1] - centre[1], end[0] - centre[0])  # Arc.end_angle
    ccw = (end_angle - start_angle) % TAU
    if ccw == 0.0:
        ccw = TAU
    return -(TAU - ccw) if clockwise else ccw


def arc_length(start: Point, end: Point, centre: Point, clockwise: bool) -> float:
    """:attr:`Arc.length` of that arc, mm, the same float, without making the :class:`Arc`."""
    radius = distance(centre, start)
    start_angle = math.atan2(start[1] - centre[1], start[0] - centre[0])
    return abs(arc_sweep(start, end, centre, clockwise, radius, start_angle)) * radius


def fit_factor(box: BBox, fit: tuple[float, float]) -> float:
    """The uniform scale ``--fit W H`` applies to a drawing of extent ``box`` (mm).

    The largest factor that keeps the scaled box within ``W`` × ``H`` mm; ``math.inf``
    when the box has neither width nor height (such a drawing is left unscaled). The
    one rule of :func:`camtool.toolpath.plan.place` and of the importers' curve
    tolerance (:meth:`camtool.importers.options.ImportOptions.curve_tolerance`).
    """
    x0, y0, x1, y1 = box
    w, h = fit
    return min(w / (x1 - x0) if x1 > x0 else math.inf, h / (y1 - y0) if y1 > y0 else math.inf)


def bbox_union(boxes: Iterator[BBox] | list[BBox]) -> BBox:
    """Smallest box holding every box of ``boxes``.

    Raises:
        ValueError: ``boxes`` is empty.
    """
    boxes = list(boxes)
    if not boxes:
        raise ValueError("bbox of nothing")
    return (
        min(b[0] for b in boxes),
        min(b[1] for b in boxes),
        max(b[2] for b in boxes),
        max(b[3] for b in boxes),
    )


_new = object.__new__


def make_line(start: Point, end: Point) -> Line:
    """``Line(start, end)``, built without the frozen dataclass's checked ``__init__``.

    The same object: an instance whose ``__dict__`` holds the fields in the same order
    (what the dataclass ``__init__`` stores through ``object.__setattr__``), so equal, with
    the same hash, ``repr`` and pickle. For loops that make segments by the hundred
    thousand (transforms, reversals, pieces of a path), when :class:`Line` is a plain
    dataclass (:func:`~camtool.model.plain.plain_fields`; else the constructor).
    """
    if not _PLAIN_SEGMENTS:
        return Line(start, end)
    obj = _new(Line)
    d = obj.__dict__
    d["start"] = start
    d["end"] = end
    return obj


def make_arc(start: Point, end: Point, centre: Point, clockwise: bool) -> Arc:
    """``Arc(start, end, centre, clockwise)``, built as :func:`make_line` builds a line."""
    if not _PLAIN_SEGMENTS:
        return Arc(start, end, centre, clockwise)
    obj = _new(Arc)
    d = obj.__dict__
    d["start"] = start
    d["end"] = end
    d["centre"] = centre
    d["clockwise"] = clockwise
    return obj


@dataclass(frozen=True)
class Line:
    """A straight segment from ``start`` to ``end`` (mm)."""

    start: Point
    end: Point

    @cached_property
    def length(self) -> float:
        """Length in mm (computed once)."""
        return distance(self.start, self.end)

    def reversed(self) -> Line:
        """The same segment traversed from end to start."""
        return make_line(self.end, self.start)

    def bbox(self) -> BBox:
        """Bounding box ``(xmin, ymin, xmax, ymax)``, mm."""
        (x0, y0), (x1, y1) = self.start, self.end
        return (min(x0, x1), min(y0, y1), max(x0, x1), max(y0, y1))

    def points(self, tolerance: float) -> list[Point]:
        """Polyline approximation: ``[start, end]`` (exact)."""
        del tolerance
        return [self.start, self.end]

    def transformed(self, scale: float, dx: float, dy: float) -> Line:
        """Uniformly scaled about the origin (``scale`` > 0), then translated."""
        return make_line(_tf(self.start, scale, dx, dy), _tf(self.end, scale, dx, dy))


@dataclass(frozen=True)
class Arc:
    """A circular arc, exact: start, end, centre (mm) and direction.

    ``clockwise=True`` is clockwise seen from +Z (G02). The radius is the
    distance from the centre to ``start``; ``end`` is expected on the same
    circle (importers guarantee it to within their tolerance). An arc whose
    ``start == end`` is a full circle (sweep 2π).
    """

    start: Point
    end: Point
    centre: Point
    clockwise: bool

    @cached_property
    def radius(self) -> float:
        """Radius in mm, measured from the centre to the start point (computed once)."""
        return distance(self.centre, self.start)

    @cached_property
    def start_angle(self) -> float:
        """Angle of the start point seen from the centre, radians CCW from +X (computed once)."""
        return math.atan2(self.start[1] - self.centre[1], self.start[0] - self.centre[0])

    @property
    def end_angle(self) -> float:
        """Angle of the end point seen from the centre, radians CCW from +X."""
        return math.atan2(self.end[1] - self.centre[1], self.end[0] - self.centre[0])

    @property
    def is_full_circle(self) -> bool:
        """True when start and end coincide (sweep 2π)."""
        return distance(self.start, self.end) <= FULL_CIRCLE_EPS * max(1.0, self.radius)

    @cached_property
    def sweep(self) -> float:
        """Signed sweep angle in radians: > 0 counter-clockwise, < 0 clockwise.

        Its magnitude lies in (0, 2π]; a full circle has magnitude 2π.
        """
        return arc_sweep(
            self.start, self.end, self.centre, self.clockwise, self.radius, self.start_angle
        )

    @cached_property
    def length(self) -> float:
        """Arc length in mm (computed once)."""
        return abs(self.sweep) * self.radius

    @cached_property
    def axis_signs(self) -> tuple[tuple[int, ...], tuple[int, ...]]:
        """Successive directions (+1/-1) in which the arc moves X, and Y (computed once).

        X turns at the circle's left and right extremes, Y at its top and bottom; the
        first direction is the tangent's at the start (just after it at an extreme).
        Equal pairs are one shared tuple (:func:`_shared_signs`): read them, never change them.
        """
        return _shared_signs((arc_axis_signs(self, 0.0), arc_axis_signs(self, math.pi / 2)))

    @cached_property
    def spiral(self) -> float:
        """End radius less start radius, mm; 0.0 when they agree within :data:`SPIRAL_EPS`.

        A program read from code may give an arc whose end is off its circle by as much
        as the reader's tolerance; LinuxCNC cuts it as a spiral whose radius changes
        linearly with the angle (``pmCirclePoint``), and so do :meth:`point_at` and
        :meth:`points`, which meet the end exactly.
        """
        difference = distance(self.centre, self.end) - self.radius
        return difference if abs(difference) > SPIRAL_EPS * max(1.0, self.radius) else 0.0

    def point_at(self, fraction: float) -> Point:
        """The point a ``fraction`` (0…1) of the way along the arc (or its :attr:`spiral`)."""
        a = self.start_angle + self.sweep * fraction
        r = self.radius + self.spiral * fraction
        return (self.centre[0] + r * math.cos(a), self.centre[1] + r * math.sin(a))

    def reversed(self) -> Arc:
        """The same arc traversed from end to start (direction flips)."""
        return make_arc(self.end, self.start, self.centre, not self.clockwise)

    def split(self, parts: int) -> list[Arc]:
        """Split into ``parts`` arcs of equal sweep; the ends are kept exact."""
        pts = [self.start] + [self.point_at(k / parts) for k in range(1, parts)] + [self.end]
        return [Arc(pts[k], pts[k + 1], self.centre, self.clockwise) for k in range(parts)]

    def bbox(self) -> BBox:
        """Bounding box, including the extreme points of the circle the arc passes."""
        # min()/max() of [start, end, the extremes passed], kept as they go (the same
        # floats: a later value replaces only a strictly smaller/larger one)
        (sx, sy), (ex, ey) = self.start, self.end
        x0, x1 = (ex if ex < sx else sx), (ex if ex > sx else sx)
        y0, y1 = (ey if ey < sy else sy), (ey if ey > sy else sy)
        cx, cy = self.centre
        r = self.radius
        a0, sweep = self.start_angle, self.sweep
        span = abs(sweep)
        ccw = sweep > 0
        for quad, cos_q, sin_q in _QUADRANTS:
            # distance travelled along the sweep direction to reach angle `quad`
            delta = (quad - a0) % TAU if ccw else (a0 - quad) % TAU
            if delta <= span:
                x, y = cx + r * cos_q, cy + r * sin_q
                if x < x0:
                    x0 = x
                elif x > x1:
                    x1 = x
                if y < y0:
                    y0 = y
                elif y > y1:
                    y1 = y
        return (x0, y0, x1, y1)

    def points(self, tolerance: float) -> list[Point]:
        """Polyline through the arc (or its :attr:`spiral`), each chord within ``tolerance`` mm."""
        spiral = self.spiral
        n = chord_count(self.radius + max(spiral, 0.0), abs(self.sweep), tolerance)
        a0, sweep, r = self.start_angle, self.sweep, self.radius
        cx, cy = self.centre
        if spiral:
            inner = [(a0 + sweep * (k / n), r + spiral * (k / n)) for k in range(1, n)]
            return [
                self.start,
                *((cx + rk * math.cos(a), cy + rk * math.sin(a)) for a, rk in inner),
                self.end,
            ]
        angles = [a0 + sweep * (k / n) for k in range(1, n)]  # as point_at(k / n), bit for bit
        return [
            self.start,
            *((cx + r * math.cos(a), cy + r * math.sin(a)) for a in angles),
            self.end,
        ]

    def transformed(self, scale: float, dx: float, dy: float) -> Arc:
        """Uniformly scaled about the origin (``scale`` > 0), then translated."""
        return make_arc(
            _tf(self.start, scale, dx, dy),
            _tf(self.end, scale, dx, dy),
            _tf(self.centre, scale, dx, dy),
            self.clockwise,
        )


Segment: TypeAlias = Line | Arc


def _segment_length(segment: Segment) -> float:
    """``segment.length`` (the same float), not kept on the segment."""
    kept = segment.__dict__.get("length")
    return float(kept) if kept is not None else type(segment).length.func(segment)


MAX_CHORDS = 1_000_000
"""Most chords one arc may become (a 1 m radius within 1 nm needs about 70 000)."""
_SMALL_RATIO = 1e-6  # below this tolerance/radius, acos(1 − x) loses digits: use the asin form


def chord_count(radius: float, sweep: float, tolerance: float) -> int:
    """Fewest equal chords over an arc so that each deviates from it by ≤ ``tolerance``.

    The one chord rule of camtool: the planner and the writers (:meth:`Arc.points`), the
    fitter's statistics (:func:`camtool.geometry.arcfit.chord_equivalent`) and the
    verifier's ``sagitta`` chord model (machines with ``chords = "sagitta"``) all count
    chords here. The sagitta of a chord spanning angle θ is ``r·(1 − cos(θ/2))``
    (Munoz-22 §4.2, "chord error per segment"), so the widest chord spans
    ``2·acos(1 − t/r)`` and the count is ``⌈sweep / that⌉`` (less 1e-9, so that an exact
    quotient is not rounded up).

    Edge cases:

    - ``tolerance ≥ radius``: any chord is within the tolerance; ``⌈sweep/π⌉`` chords (at
      least 1), so that an arc over half a turn (a full circle) still goes round rather than
      becoming one chord from its start back to its start.
    - tiny ratio: for ``t/r`` under 1e-6, ``acos(1 − t/r)`` loses its digits (1 − t/r
      rounds), so the equal form ``4·asin(√(t/2r))`` is used.
    - zero sweep: 1 chord (from start to end; ``max(1, …)``).
    - the count is capped at :data:`MAX_CHORDS`: more is a tolerance far too small for the
      radius and raises instead of building millions of points.

    Args:
        radius: arc radius, mm (≥ 0, finite).
        sweep: unsigned sweep, radians (finite; a negative sweep gives 1 chord).
        tolerance: largest allowed chord error, mm (> 0, finite).

    Returns:
        Chord count, ``≥ 1``.

    Raises:
        GeometryError: ``radius`` or ``sweep`` is not finite (importers refuse such
            drawings: an internal check).
        UsageError: ``tolerance`` is not a finite number > 0, or the arc would need
            more than :data:`MAX_CHORDS` chords (the tolerance is far too small
            for the radius).
    """
    if not (math.isfinite(radius) and math.isfinite(sweep)):
        raise GeometryError(
            f"an arc has radius {radius!r} mm and sweep {sweep!r} rad; both must be finite"
        )
    if not (tolerance > 0 and math.isfinite(tolerance)):
        raise UsageError(
            f"chord tolerance must be a finite number > 0 mm (--tolerance), got {tolerance!r}"
        )
    if tolerance >= radius:
        return max(1, math.ceil(sweep / math.pi))
    ratio = tolerance / radius
    if ratio > _SMALL_RATIO:
        max_angle = 2.0 * math.acos(1.0 - ratio)
    else:
        max_angle = 4.0 * math.asin(math.sqrt(ratio / 2.0))
    count = sweep / max_angle if max_angle > 0 else math.inf
    if count > MAX_CHORDS:
        raise UsageError(
            f"an arc of radius {fmt_num(radius)} mm would need {count:.3g} chords to stay "
            f"within {tolerance:g} mm, more than the limit of {MAX_CHORDS}; give a larger "
            "--tolerance"
        )
    return max(1, math.ceil(count - 1e-9))


def _tf(p: Point, scale: float, dx: float, dy: float) -> Point:
    return (p[0] * scale + dx, p[1] * scale + dy)


_PLAIN_SEGMENTS = plain_fields(Line) == ("start", "end") and plain_fields(Arc) == (
    "start",
    "end",
    "centre",
    "clockwise",
)
"""Whether :func:`make_line` and :func:`make_arc` may skip the constructors
(:func:`camtool.model.plain.plain_fields`)."""


SIGN_EPS = 1e-9
"""Turning points closer than this (rad) to an arc's ends do not count."""


def arc_axis_signs(arc: Arc, phase: float) -> tuple[int, ...]:
    """Directions (+1/-1) of one axis along ``arc``: X for ``phase`` 0, Y for π/2.

    The coordinate is ``c + r·cos(θ - phase)``; it turns where ``θ = phase + kπ``.
    """
    a0, sweep = arc.start_angle, arc.sweep
    s = 1.0 if sweep > 0 else -1.0
    total = abs(sweep)
    turns = sorted(
        d
        for q in (phase, phase + math.pi)
        for d in ((s * (q - a0)) % TAU,)
        if SIGN_EPS < d < total - SIGN_EPS
    )
    bounds = [0.0, *turns, total]
    out = []
    for k in range(len(bounds) - 1):
        theta = a0 + s * (bounds[k] + bounds[k + 1]) / 2
        v = -s * math.sin(theta - phase)  # d/dt of cos(θ - phase) with dθ/dt = s
        out.append(1 if v > 0 else -1)
    return tuple(out)


@functools.lru_cache(maxsize=256)
def _shared_signs(
    pair: tuple[tuple[int, ...], tuple[int, ...]],
) -> tuple[tuple[int, ...], tuple[int, ...]]:
    """``pair`` itself, the first time an equal pair is seen: arcs share one each.

    An arc's X and Y each turn at most three times, so there are a few dozen distinct
    pairs; the cache holds small tuples of ints, never a segment.
    """
    return pair


def _kept(cls: type) -> tuple[str, ...]:
    """The names of ``cls``'s fields, in order, then of its :class:`cached_property` values."""
    cached = tuple(n for n, v in vars(cls).items() if isinstance(v, cached_property))
    return (*(f.name for f in fields(cls)), *cached)


share_keys(Line, _kept(Line))
share_keys(Arc, _kept(Arc))


@dataclass(frozen=True)
class Contour:
    """A chain of segments, each starting where the previous one ended.

    ``closed`` contours end where they start. ``layer`` is the drawing layer the
    contour came from; ``source`` names where it came from for messages (e.g.
    ``"LWPOLYLINE #2A"``). ``colour`` (``"#rrggbb"``, lower case; ``""``: not known) and
    ``linetype`` (the DXF linetype name in upper case, e.g. ``"CENTER"``, or ``"DASHED"``
    for a dashed SVG stroke; ``""``: continuous or not known) are how the entity is drawn,
    resolved through its layer and block; a job selects by them, and centre and hidden
    lines are construction (:mod:`camtool.model.construction`).
    """

    segments: tuple[Segment, ...]
    closed: bool
    layer: str = "0"
    source: str = ""
    colour: str = ""
    linetype: str = ""

    def __post_init__(self) -> None:
        if not self.segments:
            raise ValueError("a contour needs at least one segment")

    @property
    def start(self) -> Point:
        """First point, mm."""
        return self.segments[0].start

    @property
    def end(self) -> Point:
        """Last point, mm."""
        return self.segments[-1].end

    @cached_property
    def length(self) -> float:
        """Total length, mm (computed once)."""
        return sum(s.length for s in self.segments)

    def length_unkept(self) -> float:
        """:attr:`length` (the same float), neither kept nor keeping its segments' lengths.

        For a one-off look at many contours, which would otherwise each keep a length in
        their ``__dict__``, and their segments too.
        """
        kept = self.__dict__.get("length")
        if kept is not None:
            return float(kept)
        return sum(_segment_length(s) for s in self.segments)

    def bbox(self) -> BBox:
        """Bounding box ``(xmin, ymin, xmax, ymax)``, mm (computed once, then kept)."""
        box: BBox | None = self.__dict__.get("_bbox")
        if box is None:
            box = bbox_union([s.bbox() for s in self.segments])
            self.__dict__["_bbox"] = box
        return box

    def reversed(self) -> Contour:
        """The same contour traversed the other way."""
        segs = tuple(s.reversed() for s in reversed(self.segments))
        return Contour(segs, self.closed, self.layer, self.source, self.colour, self.linetype)

    def points(self, tolerance: float) -> list[Point]:
        """Polyline through the contour within ``tolerance`` mm (arcs as chords)."""
        out: list[Point] = [self.start]
        for seg in self.segments:
            out.extend(seg.points(tolerance)[1:])
        return out

    def signed_area(self) -> float:
        """Signed area in mm² (> 0 counter-clockwise), exact for lines and arcs; 0 if open.

        The shoelace sum over the segments' chords (and over any gap from one segment's end
        to the next one's start), plus for each arc the circular segment between its chord
        and the arc, ``r² (|θ| − sin |θ|) / 2`` with the sign of its sweep ``θ`` (a full
        circle: π r²).
        """
        if not self.closed:
            return 0.0
        twice = 0.0
        hx, hy = self.end  # where the last segment left off: a gap to the next is a chord
        for seg in self.segments:
            (x0, y0), (x1, y1) = seg.start, seg.end
            twice += hx * y0 - x0 * hy + x0 * y1 - x1 * y0
            hx, hy = x1, y1
            if type(seg) is Arc:
                sweep = seg.sweep
                turn = abs(sweep)
                bulge = seg.radius * seg.radius * (turn - math.sin(turn))
                twice += bulge if sweep > 0 else -bulge
        return 0.5 * twice

    def transformed(self, scale: float, dx: float, dy: float) -> Contour:
        """Uniformly scaled about the origin (``scale`` > 0), then translated."""
        segs = tuple(s.transformed(scale, dx, dy) for s in self.segments)
        return Contour(segs, self.closed, self.layer, self.source, self.colour, self.linetype)


share_keys(Contour, (*_kept(Contour), "_bbox"))


def circle_of(contour: Contour) -> tuple[Point, float] | None:
    """The centre and diameter (mm) of a contour that is a whole circle, else ``None``.

    A circle is a closed contour of arcs about one centre with one radius (a DXF CIRCLE
    is one arc from a point back to itself; a polyline of two bulges is two), to 1e-9 of
    the radius.
    """
    segs = contour.segments
    if not contour.closed or not all(isinstance(s, Arc) for s in segs):
        return None
    first = segs[0]
    assert isinstance(first, Arc)
    r = math.dist(first.start, first.centre)
    if r <= 0:
        return None
    for s in segs:
        assert isinstance(s, Arc)
        if math.dist(s.centre, first.centre) > 1e-9 * r or abs(s.radius - r) > 1e-9 * r:
            return None
        if s.clockwise != first.clockwise:
            return None
    return first.centre, 2.0 * r


@dataclass(frozen=True)
class Mark:
    """A point of the drawing (a DXF POINT, an SVG dot): nothing to cut, a place to drill.

    ``at`` in mm; ``layer``, ``source``, ``colour`` as a :class:`Contour`'s.
    """

    at: Point
    layer: str = "0"
    source: str = ""
    colour: str = ""

    def transformed(self, scale: float, dx: float, dy: float) -> Mark:
        """Uniformly scaled about the origin (``scale`` > 0), then translated."""
        x, y = self.at
        return Mark((x * scale + dx, y * scale + dy), self.layer, self.source, self.colour)


@dataclass(frozen=True)
class Drawing:
    """What an importer read: contours in mm, Y up, plus what it had to say.

    ``warnings`` are messages for the user (skipped entity types, assumed
    units); the CLI prints them on stderr. ``source`` is the file name. ``marks``
    are the drawing's points (DXF POINT entities, SVG dots): only a drill operation that
    selects them uses them. ``size_note`` says why the drawing is larger than its
    file shows (an SVG's shapes off its page), for a refusal of its size ("": none).
    """

    contours: tuple[Contour, ...]
    source: str = ""
    warnings: tuple[str, ...] = field(default=())
    marks: tuple[Mark, ...] = field(default=())
    size_note: str = ""

    def bbox(self) -> BBox:
        """Bounding box of every contour and mark (a point's box is the point), mm.

        Raises:
            ValueError: the drawing has neither contours nor marks.
        """
        marks = [(*m.at, *m.at) for m in self.marks]
        return bbox_union([*(c.bbox() for c in self.contours), *marks])

    def transformed(self, scale: float, dx: float = 0.0, dy: float = 0.0) -> Drawing:
        """Uniformly scaled about the origin (``scale`` > 0), then translated."""
        contours = tuple(c.transformed(scale, dx, dy) for c in self.contours)
        marks = tuple(m.transformed(scale, dx, dy) for m in self.marks)
        return replace(self, contours=contours, marks=marks)

    def without(self, indices: frozenset[int]) -> Drawing:
        """The drawing without the contours at ``indices`` (itself when there are none)."""
        if not indices:
            return self
        kept = tuple(c for i, c in enumerate(self.contours) if i not in indices)
        return replace(self, contours=kept)
