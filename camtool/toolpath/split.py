"""Cutting paths by arc length: exact sub-segments, tangents and a :class:`Track` to walk.

Lines are split by fraction of their length, arcs by fraction of their sweep about
the same (exact) centre, so a piece of an arc is still an exact arc. Split points
that fall on a segment's end take that end's coordinates unchanged, so pieces meet
exactly where the original segments met.

Design notes: docs/internals.md, ``camtool/toolpath/split.py``.
"""

from __future__ import annotations

import bisect
import math
from collections.abc import Sequence
from dataclasses import dataclass

from camtool.model.shapes import (
    Arc,
    Contour,
    Point,
    Segment,
    cached_property,
    make_arc,
    make_line,
)

MIN_PIECE = 1e-9
"""Pieces shorter than this (mm) are dropped: a zero-length arc would read as a full circle."""


def sub_segment(seg: Segment, a: float, b: float) -> Segment:
    """The part of ``seg`` between arc lengths ``a`` and ``b`` from its start, mm.

    Args:
        seg: a line or an arc.
        a: start of the piece, mm from ``seg.start`` (clamped to ``[0, length]``).
        b: end of the piece, mm from ``seg.start`` (``b > a``).

    Returns:
        A :class:`Line` or an :class:`Arc` about the same centre and direction;
        an end at ``0`` or at ``length`` is the original end point, exactly.
    """
    length = seg.length
    f0, f1 = a / length, b / length
    if f0 <= 0.0 and f1 >= 1.0:
        return seg  # both ends are the segment's own (as _piece would rebuild it: equal)
    return _piece(seg, f0, f1)


def _piece(seg: Segment, f0: float, f1: float) -> Segment:
    start = _point_at(seg, f0)
    end = _point_at(seg, f1)
    if isinstance(seg, Arc):
        return make_arc(start, end, seg.centre, seg.clockwise)
    return make_line(start, end)


def _point_at(seg: Segment, f: float) -> Point:
    if f <= 0.0:
        return seg.start
    if f >= 1.0:
        return seg.end
    if isinstance(seg, Arc):
        return seg.point_at(f)
    (x0, y0), (x1, y1) = seg.start, seg.end
    return (x0 + (x1 - x0) * f, y0 + (y1 - y0) * f)


def start_tangent(seg: Segment) -> Point:
    """Unit direction of travel at the start of ``seg`` (an arc's tangent there)."""
    if isinstance(seg, Arc):
        return _arc_tangent(seg, seg.start)
    return _unit(seg.start, seg.end)


def end_tangent(seg: Segment) -> Point:
    """Unit direction of travel at the end of ``seg`` (an arc's tangent there)."""
    if isinstance(seg, Arc):
        return _arc_tangent(seg, seg.end)
    return _unit(seg.start, seg.end)


def _arc_tangent(arc: Arc, p: Point) -> Point:
    rx, ry = p[0] - arc.centre[0], p[1] - arc.centre[1]
    r = math.hypot(rx, ry)
    # counter-clockwise travel turns the radius vector by +90°, clockwise by -90°
    return (ry / r, -rx / r) if arc.clockwise else (-ry / r, rx / r)


def _unit(a: Point, b: Point) -> Point:
    d = math.hypot(b[0] - a[0], b[1] - a[1])
    return ((b[0] - a[0]) / d, (b[1] - a[1]) / d)


@dataclass(frozen=True)
class Track:
    """A path that can be walked by arc length (see :meth:`pieces`).

    Attributes:
        segments: the path's segments, in travel order (zero-length ones dropped).
        closed: the path ends where it starts; arc lengths then wrap round.
    """

    segments: tuple[Segment, ...]
    closed: bool

    @classmethod
    def of(cls, contour: Contour) -> Track:
        """The track of a contour (zero-length segments dropped)."""
        return cls.from_segments(contour.segments, contour.closed)

    @classmethod
    def from_segments(cls, segments: Sequence[Segment], closed: bool) -> Track:
        """The track of ``segments`` (zero-length ones dropped)."""
        return cls(tuple(s for s in segments if s.length > MIN_PIECE), closed)

    @cached_property
    def ends(self) -> tuple[float, ...]:
        """Arc length at the end of each segment, mm: ``(N,)`` increasing, last = :attr:`length`.

        Computed once per track (a track is immutable).
        """
        out: list[float] = []
        total = 0.0
        for seg in self.segments:
            total += seg.length
            out.append(total)
        return tuple(out)

    @cached_property
    def length(self) -> float:
        """Total length, mm (0 for a track with no segment; computed once)."""
        return sum(s.length for s in self.segments)

    @property
    def start(self) -> Point:
        """First point, mm."""
        return self.segments[0].start

    @property
    def end(self) -> Point:
        """Last point, mm."""
        return self.segments[-1].end

    def reversed(self) -> Track:
        """The same track walked the other way (arc length ``s`` becomes ``length − s``)."""
        return Track(tuple(s.reversed() for s in reversed(self.segments)), self.closed)

    def point_at(self, s: float) -> Point:
        """The point at arc length ``s``, mm (wrapped on a closed track, clamped on an open one)."""
        total = self.length
        s = self._local(s, total)
        ends = self.ends
        i = min(bisect.bisect_right(ends, s), len(ends) - 1)
        a = ends[i - 1] if i else 0.0
        seg = self.segments[i]
        return _point_at(seg, (s - a) / seg.length)

    def pieces(self, s0: float, s1: float) -> list[tuple[Segment, float]]:
        """The path from arc length ``s0`` to ``s1`` (``s1 > s0``) as exact pieces.

        On a closed track ``s0``/``s1`` may lie beyond the length (the walk goes
        round again); on an open one they are clamped to ``[0, length]``.

        Returns:
            ``(segment, s_end)`` pairs in travel order, ``s_end`` the arc length
            (same unrolled scale as ``s0``/``s1``) at the piece's end. Pieces
            shorter than :data:`MIN_PIECE` are left out.
        """
        span = self._span(s0, s1)
        if span is None:
            return []
        s0, s1 = span
        total, ends = self.length, self.ends
        segments = self.segments
        n = len(segments)
        out: list[tuple[Segment, float]] = []
        lap = math.floor(s0 / total) if self.closed else 0
        while lap * total < s1 - MIN_PIECE:
            base = lap * total
            # the segments ending at or before s0 give no piece (hi <= s0 <= lo): skip them.
            # ``base + ends[i]`` grows with i, so all before the first i whose end (as the
            # loop computes it) is past s0 are skipped; bisect finds it, the while settles it
            i = min(bisect.bisect_left(ends, s0 - base), n - 1)
            while i > 0 and base + ends[i - 1] > s0:
                i -= 1
            while i < n:
                a = base + (ends[i - 1] if i else 0.0)
                if a >= s1:
                    break  # this and every later segment start at or after s1: no piece
                b = base + ends[i]
                lo, hi = max(a, s0), min(b, s1)
                if hi - lo > MIN_PIECE:
                    # a piece that runs to the segment's end (or from its start) is told so
                    # exactly: ``b - a`` is its length only to the rounding of ``ends``
                    seg = segments[i]
                    at = 0.0 if lo == a else lo - a
                    to = seg.length if hi == b else hi - a
                    out.append((sub_segment(seg, at, to), hi))
                i += 1
            lap += 1
            if not self.closed:
                break
        return out

    def _span(self, s0: float, s1: float) -> tuple[float, float] | None:
        """``(s0, s1)`` clamped to an open track's length; ``None`` when no piece can come."""
        total = self.length
        if total <= MIN_PIECE or s1 - s0 <= MIN_PIECE:
            return None
        if not self.closed:
            s0, s1 = max(s0, 0.0), min(s1, total)
        return s0, s1

    def _local(self, s: float, total: float) -> float:
        if self.closed:
            return s % total if total > 0 else 0.0
        return min(max(s, 0.0), total)
