"""How the word-address writer writes an arc: conformed to its controller's arc check.

:class:`ArcWriter` holds what :class:`~camtool.post.wordaddress_write.BlockWriter` does for
one arc before it writes its blocks: the blocks that pass the controller's check
(:func:`~camtool.post.arcconform.conform_arc`), kept by the arc's arguments, taken from the
batch of plain arcs (:mod:`camtool.post.arcbatch`) or the conform-ahead helper
(:mod:`camtool.accel.conformahead`) when they have them; chords where no printable centre
passes, or where I and J cannot hold the centre.

Design notes: docs/internals.md, ``camtool/post/wordaddress_write.py``.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

from camtool.accel import conformahead
from camtool.model.errors import DialectError
from camtool.model.machine import Machine
from camtool.model.shapes import Arc, Point, make_arc
from camtool.post.wordaddress_spec import WordAddressSpec
from camtool.post.wordaddress_words import WordWriter

if TYPE_CHECKING:
    from camtool.post.arcbatch import ArcBatch
    from camtool.post.arcbatch import Blocks as ArcBlocks
    from camtool.post.arcbatch import Key as ArcKey
    from camtool.post.arcconform import ArcPiece

_CONFORMED_KEPT = 20_000
"""Arcs whose blocks a writer keeps (:meth:`ArcWriter._conformed`); then it starts anew."""
ARC_CHORD_TOLERANCE_MM = 0.002
"""Chord deviation, mm, of an arc no printable centre can write (GRBL's default ``$12``)."""
TINY_ARC_MM = 0.01
"""Radius (mm) up to which an arc that no printed centre writes (and of under ten quanta) is
a speck, written as a line to its end. A larger one is a line only where it lies within a
quantum of that line (:func:`_near_its_chord`), else chords: a dialect of whole millimetres
must not cut a 130° arc of 6 mm radius as one straight line."""


def _near_its_chord(arc: Arc, quantum: float) -> bool:
    """Whether every point of ``arc`` lies within ``quantum`` mm of the line start to end."""
    import numpy as np  # here: only an arc no printed centre writes comes this way

    from camtool.geometry.arcfit import dist_line

    xy = np.asarray(arc.points(quantum / 4), dtype=float)
    return bool(dist_line(xy, arc.start, arc.end).max() <= quantum)


CHORD: Point = (math.nan, math.nan)
"""The centre of a conformed block that is a chord of such an arc (by identity)."""
FAR_CHORD: Point = (math.nan, math.nan)
"""The centre of a chord of an arc whose centre the I and J words cannot hold (by identity)."""


class Conformed(dict[tuple[Any, ...], list[tuple[Point, Point | None]]]):
    """A writer's memory of the arcs it has conformed, by key (``ArcWriter._conformed_at``).

    ``ahead``: the helper conforming the program's arcs meanwhile
    (:mod:`camtool.accel.conformahead`), or ``None``; ``batch``: the plain arcs conformed
    in arrays as the writer nears them (:mod:`camtool.post.arcbatch`), or ``None``.
    """

    def __init__(self, ahead: conformahead.ConformAhead | None = None) -> None:
        super().__init__()
        self.ahead = ahead
        self.batch: ArcBatch | None = None


class ArcWriter(WordWriter):
    """A word-address writer's arcs: the blocks of each, conformed to the controller's check.

    Args:
        spec: the dialect.
        machine: the machine the program is for.
    """

    def __init__(self, spec: WordAddressSpec, machine: Machine) -> None:
        super().__init__(spec, machine)
        self._conformed_arcs = Conformed()

    def _conformed(self, piece: Arc) -> list[tuple[Point, Point | None]]:
        """End and absolute centre of each block of ``piece`` (after the arc check).

        A centre of ``None`` asks for a straight line: the arc is a few quanta
        across and no printable centre passes the controller's check.
        """
        return self._conformed_at(piece.start, piece.end, piece.centre, piece.clockwise, piece)

    def _conformed_at(
        self, start: Point, end: Point, centre: Point, clockwise: bool, piece: Arc | None = None
    ) -> list[tuple[Point, Point | None]]:
        """:meth:`_conformed` of the arc from ``start`` to ``end`` (``piece``, made if ``None``).

        An arc whose I or J has more integer digits than the dialect writes (an almost
        straight piece fitted with a radius of metres: FlashCut's four digits hold 9999.999
        mm) is its chords within :data:`ARC_CHORD_TOLERANCE_MM` (twice the quantum at least),
        counted as ``far-centre``.
        """
        ox, oy = (0.0, 0.0) if self._absolute_centre else self.written
        if self._beyond_digits(centre[0] - ox, centre[1] - oy):
            self.counts["far-centre"] += 1
            tolerance = max(2.0 * self.spec.quantum_mm(), ARC_CHORD_TOLERANCE_MM)
            arc = piece if piece is not None else make_arc(start, end, centre, clockwise)
            return [(point, FAR_CHORD) for point in arc.points(tolerance)[1:]]
        if self.spec.arc_check == "none":
            return [(end, centre)]
        key = (self.written, end, centre, clockwise, start)
        # The same arc from the same written start (a program that cuts a contour again at
        # another depth) gives the same blocks: conform_arc is a function of its arguments.
        # Zeros are left out: -0.0 equals 0.0 as a key, but not as an angle (atan2).
        kept = self._conformed_arcs
        known = kept.get(key)
        if known is not None:
            if not known:
                self.counts["tiny-arc"] += 1
            return known
        zero = 0.0 in key[0] or 0.0 in end or 0.0 in centre or 0.0 in start
        ahead = None
        if not zero:
            # the helper first: each lookup tells it where the writer is (it leaves the
            # batch's plain arcs to it), then the batch
            if kept.ahead is not None:
                ahead = kept.ahead.take(key)
            batch = kept.batch
            if ahead is None and batch is not None:
                ahead = batch.take(key)
        if ahead is not None:  # what _conform gives: conform_arc on the same key, elsewhere
            out = ahead
            if not out:
                self.counts["tiny-arc"] += 1
        else:
            out = self._conform(
                piece if piece is not None else make_arc(start, end, centre, clockwise)
            )
        if not zero:
            if len(kept) >= _CONFORMED_KEPT:
                kept.clear()
            kept[key] = out
        return out

    def plain_arcs(self, keys: list[ArcKey]) -> list[ArcBlocks | None]:
        """The blocks the writer's batch gives each arc ``keys`` holds (``None``: not plain).

        For :mod:`camtool.accel.conformahead`'s helper, which leaves those arcs to the
        writer's batch and conforms the others; all ``None`` when the writer has no batch
        (:func:`camtool.post.arcbatch.applies`).
        """
        batch = self._conformed_arcs.batch
        if batch is None:
            return [None] * len(keys)
        from camtool.post.arcbatch import plain_blocks

        return plain_blocks(batch.grid, batch.rule, keys)

    def checked(
        self, written: Point, end: Point, centre: Point, clockwise: bool, exact_start: Point
    ) -> list[ArcPiece]:
        """The blocks of an arc that pass the controller's check (``conform_arc``).

        Args:
            written: the start the controller holds, as written, mm.
            end: the exact end, mm.
            centre: the exact absolute centre, mm.
            clockwise: G2 when True.
            exact_start: the exact start, mm.

        A function of its arguments (the rule and the quantum are the dialect's): the
        writer keeps its answers by them (:meth:`_conformed_at`), and
        :mod:`camtool.accel.conformahead`'s helper calls it ahead of the writer.

        Raises:
            DialectError: :func:`~camtool.post.arcconform.conform_arc`'s, without the block.
        """
        from camtool.post.arcconform import conform_arc

        quantum = self._quantum
        if quantum is None:
            quantum = self._quantum = self.spec.quantum_mm()  # the same for every arc
        return conform_arc(
            written,
            end,
            centre,
            clockwise,
            rule=self.spec.arc_check,
            quantum_mm=quantum,
            exact_start=exact_start,
        )

    def _conform(self, piece: Arc) -> list[tuple[Point, Point | None]]:
        """:meth:`_conformed` without its memory of the arcs already conformed."""
        try:
            out = self.checked(self.written, piece.end, piece.centre, piece.clockwise, piece.start)
        except DialectError:
            quantum = self.spec.quantum_mm()
            if piece.radius <= 10 * quantum and (
                piece.radius <= TINY_ARC_MM or _near_its_chord(piece, quantum)
            ):
                return [(piece.end, None)]
            equalised = self._conform_equalised(piece, quantum)
            if equalised is None:
                # no printable centre passes the controller's check: chords, as the
                # controller itself would cut the arc (GRBL's $12 arc tolerance)
                tolerance = max(2.0 * quantum, ARC_CHORD_TOLERANCE_MM)
                return [(point, CHORD) for point in piece.points(tolerance)[1:]]
            out = equalised
        if not out:
            self.counts["tiny-arc"] += 1  # rounds away to nothing within a quantum
        return [(p.end, p.centre) for p in out]

    def _conform_equalised(self, piece: Arc, quantum: float) -> list[ArcPiece] | None:
        """``piece`` conformed about the centre that puts both its ends at one radius, or None.

        For an arc :func:`~camtool.post.arcconform.conform_arc` could not write (no printed
        centre the arc check takes within its deviation bound) whose ends lie at different
        distances from its centre (a joint snapped within ``--chain-tolerance`` keeps an
        arc's centre, so its start can move off its circle: LinuxCNC's ``conv_slot_l.svg``
        gave an arc 3.4 µm apart in radius, which no split could write; a program read from
        code may end an arc off its circle). The centre moves to the nearest
        point of its ends' perpendicular bisector; the warning gives both radii and the
        move. Only when the radii differ by no more than the controller's own absolute
        tolerance (GRBL 0.005 mm, LinuxCNC 0.028 mm: :func:`~camtool.post.arccheck.
        max_difference` at radius 0), numbers it would itself take as one arc, and when
        the circle it gives stays as near the arc as its two radii are apart (plus
        :data:`~camtool.post.arcconform.DEVIATION_QUANTA`): over a short chord (an arc of
        nearly 360°) the move grows as radius / chord times the radii's difference, 0.34 mm
        for 2.9 µm on a 359.5° arc of 10 mm, and would move the whole circle. ``None``
        otherwise, or when that does not help (the ends meet, the check still fails): the
        arc is then written as chords. Only arcs conform_arc could not write take this path.
        """
        from camtool.post.arccheck import max_difference
        from camtool.post.arcconform import DEVIATION_QUANTA

        (sx, sy), (ex, ey), (cx, cy) = piece.start, piece.end, piece.centre
        dx, dy = ex - sx, ey - sy
        chord = math.hypot(dx, dy)
        r0, r1 = math.hypot(sx - cx, sy - cy), math.hypot(ex - cx, ey - cy)
        if chord == 0.0 or r0 == r1 or abs(r1 - r0) > max_difference(self.spec.arc_check, 0.0):
            return None  # beyond the controller's own absolute tolerance: written as chords
        nx, ny = -dy / chord, dx / chord
        mx, my = (sx + ex) / 2.0, (sy + ey) / 2.0
        along = (cx - mx) * nx + (cy - my) * ny
        centre = (mx + along * nx, my + along * ny)
        moved, radius = math.dist(centre, piece.centre), math.dist(centre, piece.end)
        # a point of the new circle is at most this far from the arc's circle at its angle
        off = moved + max(abs(radius - r0), abs(radius - r1))
        if off > abs(r1 - r0) + DEVIATION_QUANTA * quantum:
            return None  # it would move the path further than the arc's own radii differ
        try:
            out = self.checked(self.written, piece.end, centre, piece.clockwise, piece.start)
        except DialectError:
            return None
        self.warn(
            f"{self.where()}: the arc starts {r0:.4f} mm and ends {r1:.4f} mm from its centre "
            f"({abs(r1 - r0) * 1000:.1f} µm apart): no printed centre near it gives an arc "
            f"{self.spec.name}'s arc check takes within {DEVIATION_QUANTA * quantum * 1000:g} µm "
            f"of it; written about the centre {moved * 1000:.1f} µm away that puts both ends "
            f"{radius:.4f} mm from it"
        )
        return out

    def _beyond_digits(self, ci: float, cj: float) -> bool:
        """Whether centre offset ``(ci, cj)`` mm has more integer digits than I or J writes."""
        for letter, value in (("I", ci), ("J", cj)):
            number = self.spec.words[letter].number
            if number.int_digits is None:
                continue
            half_unit = 0.5 * 10.0 ** (-number.decimals)  # what rounds up to the next digit
            if abs(value) * number.scale + half_unit >= 10.0**number.int_digits:
                return True
        return False
