"""The G-code reader's fast path: a plain line (G0–G3 and numbers only) read without the lexer.

Most lines of a CAM program are plain: ``G1 X1.5 Y2 F300``. :class:`PlainLines` reads
such a line as the reader's full path would, without making its words; anything else
(a comment, another word, a value out of range) goes to the lexer. ``CAMTOOL_ACCEL=0``
sends every line there.
"""

from __future__ import annotations

import math
import re
from array import array

from camtool.importers.gcode_codes import Notes, g_key
from camtool.model.plain import slot_setters
from camtool.model.program import (
    ArcMove,
    Linear,
    Move,
    Rapid,
)
from camtool.model.shapes import Point
from camtool.model.units import INCH, LARGEST_VALUE

ARC_TOL_MM = (2 * 0.01 * math.sqrt(2), 100 * 2 * 0.01 * math.sqrt(2))
"""How far (mm, in G21) the end of an I/J arc may lie off its circle, as LinuxCNC's
interpreter allows it (``interp_arc.cc`` ``arc_data_ijk`` with the defaults of
``interp_internal.hh``, ``CENTER_ARC_RADIUS_TOLERANCE_MM``): the radii to the start and to
the end may differ by more than the first (≈ 0.0283 mm) only within 0.1 % of the larger
radius, and never by more than the second (100 times it). Measured against LinuxCNC 2.9's
``rs274`` (tests/importers/test_gcode.py). GRBL's and LinuxCNC's own checks of the numbers
written are :mod:`camtool.post.arccheck`'s."""
ARC_TOL_IN = (2 * 0.001 * math.sqrt(2), 100 * 2 * 0.001 * math.sqrt(2))
"""The same in inches (G20: ``CENTER_ARC_RADIUS_TOLERANCE_INCH``)."""
R_TOL_IN = 0.00005
"""How much (in, in G20) an R arc's radius may fall short of half its chord, read as a half
circle: LinuxCNC's ``RADIUS_TOLERANCE_INCH`` (``arc_data_r``), also the radius under which
it calls an arc "zero-radius". Measured against LinuxCNC 2.9's ``rs274``."""
R_TOL_MM = R_TOL_IN * 25.4
"""The same in mm (``RADIUS_TOLERANCE_MM``, 0.00127 mm)."""
SPIRAL_RELATIVE = 0.001
"""LinuxCNC's ``SPIRAL_RELATIVE_TOLERANCE``: of the larger radius."""
SPIRAL_NOTE_MM = 0.005
"""An I/J arc whose radii differ by more than this (mm; GRBL's own tolerance, which any
controller takes as one arc) is read with a note: LinuxCNC cuts it as a spiral, GRBL
refuses it beyond 0.1 % of its radius, and the verifier's machines cut the circle of its
start radius closed by a chord to the end written."""


def spiral_note(name: str, off: float) -> str | None:
    """The note for a ``name`` arc (``G2``, ``G3``) whose radii differ by ``off`` mm, if any."""
    if off <= SPIRAL_NOTE_MM:
        return None
    return (
        f"{name} ends {off:.4f} mm off its circle, read as written (LinuxCNC cuts it as a "
        "spiral; verify cuts it on its start's circle, then a chord to its end: the offset "
        "shows in its deviation)"
    )


def arc_limits(inch: bool, scale: float) -> tuple[float, float, float]:
    """``(small, large, r_short)``, mm, for a program in inches (``inch``) or mm, times ``scale``.

    :data:`ARC_TOL_MM` (or :data:`ARC_TOL_IN`) and :data:`R_TOL_MM` (or :data:`R_TOL_IN`).
    """
    (small, large), r_short = (ARC_TOL_IN, R_TOL_IN) if inch else (ARC_TOL_MM, R_TOL_MM)
    return small * scale, large * scale, r_short * scale


def arc_end_off(r_start: float, r_end: float, small: float, large: float) -> bool:
    """Whether LinuxCNC refuses an I/J arc of radii ``r_start``, ``r_end`` (mm, both > 0).

    ``small``, ``large``: :data:`ARC_TOL_MM` (or :data:`ARC_TOL_IN`) in the program's scale.
    The same float operations as ``arc_data_ijk`` (``abs_err``, ``rel_err``): the reader
    reads by it, and :func:`camtool.post.arccheck.arc_error` checks LinuxCNC's output by it.
    """
    off = abs(r_start - r_end)
    return off > large or (off / max(r_start, r_end) > SPIRAL_RELATIVE and off > small)


_PLAIN_NUMBER = r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)"
PLAIN_WORDS = re.compile(r"[ \t]*([GXYZIJRFN](?=[+-]?\.?[0-9])|)(" + _PLAIN_NUMBER + r"|[^ \t].*)")
"""The words of a plain line (:meth:`_Reader.plain`), found in the line in upper case: a
(letter, number text) pair per word of these letters with an ASCII number, blanks between
words only. Anything else (a comment, another letter or character, a blank inside a word)
gives a pair whose letter is empty (the rest of the line its text): the line is not plain
and goes to the lexer. A line with a non-ASCII character goes there unsearched. One search
per line: the line no longer has to match a pattern of the whole line first."""
_FIND_PLAIN = PLAIN_WORDS.findall


def plain_words(raw: str) -> list[tuple[str, str]]:
    """What :data:`PLAIN_WORDS` finds in line ``raw`` in upper case, its end blanks left out.

    Blanks that end a line match nothing: ``findall`` would try each of them as a start and
    run to the end of the line from there, a time quadratic in their number. A line longer
    than :data:`PLAIN_LINE_CHARS` is not searched (one pair with an empty letter: not plain):
    the lexer reads it, or refuses it before making its words.
    """
    if len(raw) > PLAIN_LINE_CHARS:
        return [("", "")]
    return _FIND_PLAIN(raw.upper().rstrip(" \t"))


PLAIN_LINE_CHARS = 4096
"""Longest line :func:`plain_words` searches: a plain line holds nine words at most, so
longer is blanks (read by the lexer the same) or a line the lexer refuses."""


_PLAIN_MOTION = {0: "G0", 10: "G1", 20: "G2", 30: "G3"}
_PLAIN_G = {0.0: "G0", 1.0: "G1", 2.0: "G2", 3.0: "G3"}
""":data:`_PLAIN_MOTION` by the G word's value, for the values ``g_key`` gives those keys."""


_new_move = object.__new__
_RAPID_SET = slot_setters(Rapid)
_LINEAR_SET = slot_setters(Linear)
_ARC_SET = slot_setters(ArcMove)
_FAST_MOVES = (
    _RAPID_SET is not None
    and _LINEAR_SET is not None
    and _ARC_SET is not None
    and tuple(Rapid.__dataclass_fields__) == ("x", "y", "z", "contour")
    and tuple(Linear.__dataclass_fields__) == ("x", "y", "feed_mm_min", "z", "contour")
    and tuple(ArcMove.__dataclass_fields__)
    == ("x", "y", "cx", "cy", "clockwise", "feed_mm_min", "z", "contour")
)
"""Whether the plain reader makes its moves without their (frozen, slow) ``__init__``."""
if _FAST_MOVES:
    assert _RAPID_SET is not None and _LINEAR_SET is not None and _ARC_SET is not None
    _RX, _RY, _RZ, _RC = _RAPID_SET
    _LX, _LY, _LF, _LZ, _LC = _LINEAR_SET
    _AX, _AY, _ACX, _ACY, _ACW, _AF, _AZ, _AC = _ARC_SET


def _rapid(x: float, y: float, z: float | None, contour: int) -> Rapid:
    """``Rapid(x, y, z, contour)`` (without its ``__init__`` when :data:`_FAST_MOVES`)."""
    if not _FAST_MOVES:
        return Rapid(x, y, z, contour)
    move = _new_move(Rapid)
    _RX(move, x)
    _RY(move, y)
    _RZ(move, z)
    _RC(move, contour)
    return move


def _linear(x: float, y: float, feed: float, z: float | None, contour: int) -> Linear:
    """``Linear(x, y, feed, z, contour)`` (as :func:`_rapid`)."""
    if not _FAST_MOVES:
        return Linear(x, y, feed, z, contour)
    move = _new_move(Linear)
    _LX(move, x)
    _LY(move, y)
    _LF(move, feed)
    _LZ(move, z)
    _LC(move, contour)
    return move


def _arc_move(
    x: float,
    y: float,
    cx: float,
    cy: float,
    clockwise: bool,
    feed: float,
    z: float | None,
    contour: int,
) -> ArcMove:
    """``ArcMove(x, y, cx, cy, clockwise, feed, z, contour)`` (as :func:`_rapid`)."""
    if not _FAST_MOVES:
        return ArcMove(x, y, cx, cy, clockwise, feed, z, contour)
    move = _new_move(ArcMove)
    _AX(move, x)
    _AY(move, y)
    _ACX(move, cx)
    _ACY(move, cy)
    _ACW(move, clockwise)
    _AF(move, feed)
    _AZ(move, z)
    _AC(move, contour)
    return move


class PlainLines:
    """The reader's plain-line path (mixed into the reader, whose modal state it reads).

    Attributes: the reader's, as the G-code reader (:mod:`camtool.importers.gcode`) sets them.
    """

    notes: Notes
    moves: list[Move]
    lines: array[int]
    line: int
    x: float | None
    y: float | None
    z: float | None
    positioned: bool
    motion: str | None
    plane: str
    absolute: bool
    arc_absolute: bool
    inch: bool
    units_seen: bool
    feed_mm_min: float | None
    contour: int
    cut_in_contour: bool

    def plain(self, words: list[tuple[str, str]], line: int) -> bool:
        """Execute a plain line as :meth:`run` would, if it is one; False leaves all as it was.

        ``words`` are what :data:`PLAIN_WORDS` finds in the line: (upper-case letter,
        number text) pairs of G, X, Y, Z, I, J, R, F and N words, and pairs with an empty
        letter where the line holds anything else. Such a line is read here without
        making its :class:`Word` objects when it can end in nothing but what :meth:`run`
        does without a warning or an error: only those words, each letter once, numbers
        in range, a G word that is G0 to G3, absolute distances (G90), a known position,
        a feed > 0 for a cut, and for an arc a centre within the radius tolerance. Every
        other line (False, nothing changed) goes through the lexer and :meth:`run`, which
        give its warning or error. The arithmetic is :meth:`run`'s, operation for
        operation, so the moves are the same floats.
        """
        if not words:
            return False  # a blank line
        args: dict[str, float] = {}
        for letter, text in words:
            if not letter:
                return False  # not only plain words
            value = float(text)
            if not abs(value) < LARGEST_VALUE:
                return False
            if letter == "N":
                continue
            if letter in args:
                return False
            args[letter] = value
        motion = self.motion
        if motion is not None and motion not in _PLAIN_MOTION.values():
            return False  # a canned cycle's X Y: run() drills there
        g = args.pop("G", None)
        if g is not None:
            motion = _PLAIN_G.get(g)
            if motion is None:
                motion = _PLAIN_MOTION.get(g_key(g))  # type: ignore[arg-type]
                if motion is None:
                    return False
        f = args.pop("F", None)
        if f is not None and f < 0:
            return False
        scale = INCH if self.inch else 1.0
        feed = self.feed_mm_min if f is None else f * scale
        if args:  # the motion of the X Y Z I J R words
            if motion is None or not self.absolute or self.x is None or self.y is None:
                return False  # without motion run() refuses the words; the rest is not plain
            if motion == "G2" or motion == "G3":
                if self.plane != "xy":
                    return False  # run() reads arcs in the other planes
                if not self._plain_arc(args, motion, feed, scale, line, (self.x, self.y)):
                    return False
            elif not self._plain_move(args, motion, feed, scale, line, (self.x, self.y)):
                return False
        self.line = line
        self.motion = motion
        self.feed_mm_min = feed
        return True

    def _plain_move(
        self,
        args: dict[str, float],
        motion: str,
        feed: float | None,
        scale: float,
        line: int,
        start: Point,
    ) -> bool:
        """The straight motion of a plain line with X Y Z I J R words in ``args``.

        :meth:`plain` checks first that there is a motion, a known position (``start``)
        and absolute distances, and reads arcs (G2, G3) itself.
        """
        if "I" in args or "J" in args or "R" in args:
            return False  # run() refuses them
        if "X" not in args and "Y" not in args and "Z" not in args:
            return False
        return self._plain_line(args, motion, feed, scale, line, start)

    def _plain_line(
        self,
        args: dict[str, float],
        name: str,
        feed: float | None,
        scale: float,
        line: int,
        start: Point,
    ) -> bool:
        """:meth:`_line` for :meth:`plain`; False (nothing changed) where it would not be plain."""
        x, y, z = args.get("X"), args.get("Y"), args.get("Z")
        tx = start[0] if x is None else x * scale
        ty = start[1] if y is None else y * scale
        tz = self.z if z is None else z * scale
        z_out = tz if z is not None and tz != self.z else None
        gives_xy = x is not None or y is not None
        if gives_xy and not self.positioned:
            return False  # the first X/Y: _line checks it (check_first_xy, _first_positioning)
        cut = name != "G0"
        if cut and (feed is None or feed == 0):
            return False
        if not gives_xy and z_out is None and not self.positioned:
            return True  # moves nowhere from an assumed XY: no move (_line)
        self.positioned = self.positioned or gives_xy
        if not cut:
            self._plain_push(_rapid(tx, ty, z_out, self._contour(True)), tx, ty, tz, line)
            return True
        assert feed is not None  # checked above
        move = _linear(tx, ty, feed, z_out, self._contour(False))
        self._plain_push(move, tx, ty, tz, line)
        return True

    def _plain_arc(
        self,
        args: dict[str, float],
        name: str,
        feed: float | None,
        scale: float,
        line: int,
        start: Point,
    ) -> bool:
        """:meth:`_arc` for :meth:`plain`; False (nothing changed) where it would not be plain."""
        if feed is None or feed == 0 or not self.positioned:
            return False  # from where the machine stands: _arc refuses it
        x, y, z = args.get("X"), args.get("Y"), args.get("Z")
        tx = start[0] if x is None else x * scale
        ty = start[1] if y is None else y * scale
        tz = self.z if z is None else z * scale
        end = (tx, ty)
        r_value, i, j = args.get("R"), args.get("I"), args.get("J")
        if r_value is not None:
            if i is not None or j is not None:
                return False
            r = r_value * scale
            chord = math.dist(start, end)
            if chord == 0 or r == 0:
                return False
            half = chord / 2
            if abs(r) < half - arc_limits(self.inch, scale)[2]:
                return False
            h = math.sqrt(max(r * r - half * half, 0.0))
            side = (1.0 if name == "G2" else -1.0) * (1.0 if r > 0 else -1.0)
            ux, uy = (end[0] - start[0]) / chord, (end[1] - start[1]) / chord
            mx, my = (start[0] + end[0]) / 2, (start[1] + end[1]) / 2
            cx, cy = mx + side * h * uy, my - side * h * ux
        else:
            if i is None and j is None:
                return False
            di = i * scale if i is not None else 0.0
            dj = j * scale if j is not None else 0.0
            if self.arc_absolute:
                if i is None or j is None:
                    return False
                cx, cy = di, dj
            else:
                cx, cy = start[0] + di, start[1] + dj
            r_start, r_end = math.dist(start, (cx, cy)), math.dist(end, (cx, cy))
            if r_start == 0:
                return False
            if abs(r_start - r_end) > SPIRAL_NOTE_MM:
                return False  # refused, or read with a note: _Reader._check_radius
        z_out = tz if z is not None and tz != self.z else None
        self.positioned = True
        self.cut_in_contour = True  # _contour(False)
        arc = _arc_move(tx, ty, cx, cy, name == "G2", feed, z_out, self.contour)
        self._plain_push(arc, tx, ty, tz, line)
        return True

    def _contour(self, rapid: bool) -> int:
        """The contour of the next move, as :meth:`_push` counts it."""
        if rapid:
            if self.cut_in_contour:
                self.contour += 1
            self.cut_in_contour = False
        else:
            self.cut_in_contour = True
        return self.contour

    def _plain_push(
        self, move: Move, tx: float | None, ty: float | None, tz: float | None, line: int
    ) -> None:
        """:meth:`_push` of a move whose contour is set (:meth:`_contour`)."""
        if not self.units_seen:
            self.units_seen = True
            self.notes.add(
                "units", line, "no G20/G21 before the first move: coordinates read as mm"
            )
        self.moves.append(move)
        self.lines.append(line)
        self.x, self.y, self.z = tx, ty, tz
