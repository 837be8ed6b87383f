"""The word-address writer: one :class:`BlockWriter` writes a program for every such dialect.

Its dialect is :class:`camtool.post.wordaddress.WordAddressPost`; the grammar it writes is
:class:`~camtool.post.wordaddress_spec.WordAddressSpec`.

Design notes: docs/internals.md, ``camtool/post/wordaddress_write.py``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Iterator
from itertools import islice

from camtool.accel import conformahead, splitwrite
from camtool.model.errors import DialectError
from camtool.model.program import (
    PLANE_AXES,
    ArcMove,
    Command,
    Coolant,
    Dwell,
    Home,
    LengthOffset,
    Linear,
    Move,
    PathControl,
    PlaneArc,
    Program,
    Rapid,
    Spindle,
    Stop,
    ToolChange,
    WorkOffset,
)
from camtool.model.shapes import FULL_CIRCLE_EPS, Arc, Point, make_arc
from camtool.post.base import (
    check_placement,
    check_work_area,
    input_line,
    program_tolerance,
)
from camtool.post.wordaddress_arcs import (
    ARC_CHORD_TOLERANCE_MM,
    CHORD,
    FAR_CHORD,
    ArcWriter,
    Conformed,
)
from camtool.post.wordaddress_spec import PLANE_CODES
from camtool.post.wordaddress_summary import closing_warnings, rounding_warnings
from camtool.post.wordaddress_words import SAME_MM

_MOVES = (Rapid, Linear, ArcMove)
"""The kinds of move (a tuple: ``isinstance`` takes it faster than ``Rapid | Linear | ...``)."""

FEED_NOISE = 1e-6
"""A written feed this far from the asked one (relative) is the same feed: an inch program's
``F19.68504`` is 500.000016 mm/min, written ``F500`` without a warning. A feed the dialect
rounds further (``F99.6`` as ``F100``) is warned of."""


class BlockWriter(ArcWriter):
    """Writes one program: its moves, arcs and commands as blocks (:class:`ArcWriter`).

    Args:
        spec: the dialect.
        machine: the machine the program is for (work area, Z axis).
    """

    def write(self, program: Program) -> str:
        """The whole program as text.

        In order: the ``header`` lines, the program's notes as comments (when the
        dialect has comments), the preamble, the moves and commands, the
        postamble, the end code and the ``footer`` lines.

        Raises:
            DialectError: see the module docstring; the message names the block.
        """
        self.here = program.origin
        self.program = program
        # a long program's second half written by a helper meanwhile (it needs none of
        # what follows), or else the arcs' blocks conformed ahead in a helper when there
        # are many; held by the memory of conformed arcs, not as a 30th attribute of the
        # writer: that one made every block of the re-post benchmark ~8 % slower (CPython
        # 3.11 stops sharing the keys of instances with that many attributes)
        # the plain arcs' prediction (a walk of every move) made once, before the helpers
        # are forked: they share it
        from camtool.post import arcbatch

        batch = self._conformed_arcs.batch = arcbatch.start(self, program)
        split = splitwrite.start(self, program)
        ahead = None
        try:
            self.warnings.extend(check_placement(program, self.machine))
            self.written = (
                self._round("X", program.origin[0]),
                self._round("Y", program.origin[1]),
            )
            self.blocks.extend(self.spec.header)
            for note in program.notes:
                comment = self.spec.comment_line(note)
                if comment is not None:
                    self.blocks.append(comment)
            for codes in self.spec.preamble:
                self.block(list(codes))
            if split is None:
                ahead = conformahead.start(self, program)
            self._conformed_arcs = Conformed(ahead)
            self._conformed_arcs.batch = batch
            items = program.items()
            if split is None:
                self.write_items(items, 0, 0)
            else:
                index, written = self.write_items(islice(items, split.at), 0, 0)
                if not split.join(self, index, written):
                    self.write_items(items, index, written)
                split = None
        finally:
            if ahead is not None:
                ahead.close()
            if split is not None:
                split.close()
        self._flush_speed()
        for codes in self.spec.postamble:
            self.block(list(codes))
        if self.spec.end:
            self.block([self.spec.end[0]])
        self.blocks.extend(self.spec.footer)
        self.warnings.extend(
            closing_warnings(self.spec, self.counts, self.grid_error_mm, ARC_CHORD_TOLERANCE_MM)
        )
        tolerance = program_tolerance(program, self.machine)
        self.warnings.extend(
            rounding_warnings(self.spec, program, self.machine.steps_per_mm, tolerance)
        )
        if self.blocks:
            self._join_blocks()
        return "".join(self._done)

    def write_items(
        self, items: Iterator[Move | Command | PlaneArc], index: int, written: int
    ) -> tuple[int, int]:
        """Write ``items`` (:meth:`Program.items`); the moves taken before are ``index``.

        ``written``: the moves already written (a plane arc writes its chords' moves).
        Returns ``index`` and ``written`` after ``items``.
        """
        for item in items:
            try:
                if isinstance(item, _MOVES):
                    index += 1
                    if index > written:
                        self.move(item)
                elif isinstance(item, PlaneArc):
                    written = self.plane_arc(item, index)
                else:
                    self.command(item)
            except DialectError as exc:
                raise self._from_source(exc, item, index) from None
        return index, written

    def _from_source(self, exc: DialectError, item: object, index: int) -> DialectError:
        """``exc`` naming the line of the program read from code it comes from, if any.

        A move is move ``index - 1`` of the program; a command stands before move ``index``,
        or after the last move when there is none.
        """
        move = isinstance(item, (*_MOVES, PlaneArc))
        where = input_line(self.program, index - 1 if move else index, move=move)
        return DialectError(f"{exc} ({where})") if where else exc

    # -- moves -------------------------------------------------------------------

    def move(self, move: Move) -> None:
        """Write one move (one or more blocks).

        Raises:
            DialectError: see the module docstring.
        """
        if move.contour:
            self.contour = move.contour
        start = self.here
        if self.machine.coordinates != "work":
            self._check_area(start, move)
        if move.z is not None:
            if self._same_z(move.z):
                move = dataclasses.replace(move, z=None)  # Z does not change as written
            else:
                self._check_z(move)
        if self.by_hand is not None:
            self._after_change_by_hand(start, move)
        if isinstance(move, ArcMove):
            self._arc(start, move)
        else:
            self._straight(start, move)
        self.here = (move.x, move.y)
        if move.z is not None:
            self.z = move.z

    def _after_change_by_hand(self, start: Point, move: Move) -> None:
        """Warn when the first move after a tool change by hand goes sideways before any Z.

        The new tool has another length and its Z zero is set again by hand: until a Z is
        written, the tool stands at a height the program does not know. A job's program
        rises first; a re-posted program moves as it is written, so this says so.
        """
        if move.z is None and (move.x, move.y) != start:
            self.warn(
                f"{self.where()}: after the tool change to T{self.by_hand} by hand "
                f"({self.spec.name} pauses with {self.spec.stop}), the program moves X/Y "
                "before any Z move: that move runs at whatever height the new tool was left; "
                "add a move up to a safe height after the change"
            )
        self.by_hand = None

    def _same_z(self, z: float) -> bool:
        """True when ``z`` prints as the Z the controller is at."""
        if self.z is None or not self.spec.has("Z"):
            return False
        return self.text("Z", z) == self.text("Z", self.z)

    def _check_area(self, start: Point, move: Move) -> None:
        if self.machine.coordinates != "work":  # in work coordinates any position runs
            program = self.program
            check_work_area(
                start, move, self.machine, self.where(), program, reposted=program.from_code
            )

    def _check_z(self, move: Move) -> None:
        if not self.spec.has("Z") or not self.machine.has_z:
            raise DialectError(
                f"{self.where()}: {self.spec.name} has no Z axis (z = {move.z:g} mm); "
                "set the depth by hand or use a target with a Z axis"
            )
        if isinstance(move, ArcMove) and not self.spec.helix:
            raise DialectError(
                f"{self.where()}: an arc that moves Z (a helix) cannot be written in "
                f"{self.spec.name}; cut the arc at one depth and move Z in its own move"
            )

    def _straight(self, start: Point, move: Rapid | Linear) -> None:
        if self.z_only(start, move):
            self._line(move, None, move.z)  # a Z-only move: no X or Y word (module docstring)
            return
        if move.z is None or self.spec.z_moves == "with-xy":
            self._line(move, (move.x, move.y), move.z)
            return
        self.counts["z-split"] += 1
        if self.z is not None and move.z < self.z:
            self._line(move, (move.x, move.y), None)
            self._line(move, None, move.z)
        else:
            self._line(move, None, move.z)
            self._line(move, (move.x, move.y), None)

    def _line(self, move: Rapid | Linear, xy: Point | None, z: float | None) -> None:
        """A G0/G1 block to ``xy`` (``None``: a Z-only block) and/or ``z``."""
        rapid, linear, _, _ = self.spec.motion_codes
        words: list[str] = []
        self._code(rapid if isinstance(move, Rapid) else linear, words)
        if xy is not None:
            (tx, px), (ty, py) = self._print("X", xy[0]), self._print("Y", xy[1])
            unchanged = self.last.get("X") == tx and self.last.get("Y") == ty
            force = unchanged and z is None
            self._word("X", tx, words, force=force)
            self._word("Y", ty, words, force=force)
            self.written = (px, py)
        if z is not None:
            self._word("Z", self._z_text(z), words, force=xy is None)
        if isinstance(move, Linear):
            self._feed(move, words)
        self._with_speed(words)
        self.block(words)

    def _with_speed(self, words: list[str]) -> None:
        """Put a new spindle speed (:attr:`speed`) in this motion block (``G1 X20 S800``).

        A laser program does so: GRBL in laser mode runs on through such blocks, where a
        block of its own (``M4 S800``) stops the motion to change the speed (gcode.c, a
        spindle sync). It gets its own block first where the motion block would grow
        beyond ``max_block_bytes``.
        """
        if self.speed is None:
            return
        spec = self.spec
        size = len(spec.separator.join([*words, self.speed]) + spec.block_end + spec.line_end)
        if spec.max_block_bytes is not None and size > spec.max_block_bytes:
            self._flush_speed()
            return
        words.append(self.speed)
        self.speed = None

    def _flush_speed(self) -> None:
        """Write a new spindle speed still waiting for a motion block in a block of its own."""
        if self.speed is not None and self.spindle is not None:
            code = self.spec.spindle_cw if self.spindle.direction == "cw" else self.spec.spindle_ccw
            assert code is not None  # the spindle was turned on with it
            self.block([code, self.speed])
        self.speed = None

    def _feed(self, move: Linear | ArcMove, words: list[str]) -> None:
        same = self._feed_text
        if same is not None and same[0] == move.feed_mm_min:
            self._word("F", same[1], words)  # the feed before: checked and warned about
            return
        spec = self.spec.word("F")
        if spec is None:
            self.counts["feed"] += 1
            return
        text = self._above_zero("F", move.feed_mm_min, "feed", "mm/min", "")
        written = spec.number.parse(text)
        if abs(written - move.feed_mm_min) > FEED_NOISE * max(1.0, move.feed_mm_min):
            msg = f"feed {move.feed_mm_min:g} mm/min written as F{text} ({written:g} mm/min)"
            self.warn(msg)
        self._feed_text = (move.feed_mm_min, text)
        self._word("F", text, words)

    def _above_zero(self, letter: str, value: float, what: str, unit: str, hint: str) -> str:
        """The text of word ``letter`` for ``value`` > 0, refused where it rounds to zero.

        ``F0`` stops the feed and ``M3 S0`` runs a spindle that does not turn: neither is
        what was asked for.

        Raises:
            DialectError: naming the block, the value, the smallest the dialect writes
                and ``hint``.
        """
        text = self.text(letter, value)
        word = self.spec.word(letter)
        if word is not None and word.number.parse(text) <= 0:
            raise DialectError(
                f"{self.where()}: {what} {value:g} {unit} rounds to {letter}{text}; the "
                f"smallest {what} {self.spec.name} writes is {word.number.resolution_mm():g}"
                f"{hint}"
            )
        return text

    # -- arcs --------------------------------------------------------------------

    def _arc(self, start: Point, move: ArcMove) -> None:
        end, centre, clockwise = (move.x, move.y), (move.cx, move.cy), move.clockwise
        printed = self._printed
        tx = printed["X"].get(end[0]) or self._print("X", end[0])
        ty = printed["Y"].get(end[1]) or self._print("Y", end[1])
        # Arc(start, end, centre).is_full_circle; the arc itself is made only where needed
        radius = math.hypot(start[0] - centre[0], start[1] - centre[1])
        full_circle = math.hypot(end[0] - start[0], end[1] - start[1]) <= (
            FULL_CIRCLE_EPS * max(1.0, radius)
        )
        arc: Arc | None = None
        if (tx[1], ty[1]) == self.written:
            arc = make_arc(start, end, centre, clockwise)
            if abs(arc.sweep) > math.pi:
                # within the resolution of a full circle: the controller reads one
                arc = make_arc(start, start, centre, clockwise)
                full_circle = arc.is_full_circle
        if self._one_part and not full_circle:
            parts = 1
        else:
            arc = arc or make_arc(start, end, centre, clockwise)
            parts = self._parts(arc, full_circle)
        blocks: list[tuple[Point, Point | None, bool]] = []
        if parts == 1:
            if arc is None:
                conformed = self._conformed_at(start, end, centre, clockwise)
            else:
                conformed = self._conformed(arc)
            full = full_circle and len(conformed) == 1
            if len(conformed) == 1 and move.z is None:  # the usual arc: one block, no helix
                block_end, block_centre = conformed[0]
                xy = (tx, ty) if block_end == end else None  # its end is printed
                self._arc_block(move, block_end, block_centre, None, full, xy)
                return
            blocks += [(e, c, full) for e, c in conformed]
        else:
            assert arc is not None  # made for _parts
            # each piece is checked from where the controller stands when it starts: the
            # end of the piece before, as written (the blocks are written after; the
            # check from the arc's own start refused the second piece with a ValueError)
            written = self.written
            try:
                for piece in arc.split(parts):
                    conformed = self._conformed(piece)
                    full = piece.is_full_circle and len(conformed) == 1
                    blocks += [(e, c, full) for e, c in conformed]
                    if conformed:
                        self.written = self.written_xy(conformed[-1][0])
            finally:
                self.written = written  # _arc_block moves it, block by block
        for k, (block_end, block_centre, full) in enumerate(blocks, start=1):
            z = move.z  # a helix climbs evenly over the blocks it is written in
            if move.z is not None and self.z is not None:
                z = self.z + (move.z - self.z) * k / len(blocks)
            self._arc_block(move, block_end, block_centre, z, full)

    def _parts(self, arc: Arc, full_circle: bool) -> int:
        """How many equal arcs ``arc`` is written as (``max_arc_deg``, ``full_circle``).

        ``full_circle`` is ``arc.is_full_circle``.
        """
        limit = self.spec.max_arc_deg
        if limit >= 360.0:
            if not full_circle:
                return 1  # a sweep is at most 360° (the formula below gives 1 too)
            parts = 1
        else:
            sweep = math.degrees(abs(arc.sweep))
            parts = max(1, math.ceil(sweep / limit - 1e-9))
        if full_circle and self.spec.full_circle == "split":
            parts = max(2, parts)
        elif full_circle:
            parts = 1
        return parts

    def _arc_block(
        self,
        move: ArcMove,
        end: Point,
        centre: Point | None,
        z: float | None,
        full: bool,
        xy: tuple[tuple[str, float], tuple[str, float]] | None = None,
    ) -> None:
        """One G2/G3 block, or a G1 block when the arc vanishes at this resolution.

        ``full`` says the arc is meant as a full circle (its written end is its
        written start); any other arc whose written end is its written start, or
        whose written centre is its start (or no centre, see :meth:`_conformed`),
        is too small to write. ``xy``: what :meth:`_print` gives the end's X and Y,
        when the caller has it.
        """
        printed = self._printed
        if xy is None:
            xy = (
                printed["X"].get(end[0]) or self._print("X", end[0]),
                printed["Y"].get(end[1]) or self._print("Y", end[1]),
            )
        (tx, px), (ty, py) = xy
        written = (px, py)
        before = self.written
        ox, oy = (0.0, 0.0) if self._absolute_centre else before
        ti = tj = ""
        if centre is CHORD or centre is FAR_CHORD:
            if centre is CHORD:  # far centres are counted per arc, in _conformed_at
                self.counts["arc-chords"] += 1
            self._line(Linear(*end, move.feed_mm_min, contour=move.contour), end, z)
            return
        tiny = centre is None or (written == before and not full)
        if centre is not None:
            ci, cj = centre[0] - ox, centre[1] - oy
            ti, i = printed["I"].get(ci) or self._print("I", ci)
            tj, j = printed["J"].get(cj) or self._print("J", cj)
            tiny = tiny or (i + ox, j + oy) == before
            if self._arc_floor_mm:
                tiny = tiny or 2.0 * math.hypot(i + ox - before[0], j + oy - before[1]) <= (
                    self._arc_floor_mm
                )
        if tiny:
            self.counts["tiny-arc"] += 1
            linear = Linear(end[0], end[1], move.feed_mm_min, contour=move.contour)
            self._line(linear, end, z)
            return
        code = self._cw if move.clockwise else self._ccw
        last = self.last
        words = [] if self._modal_g and last.get("G") == code else [code]  # _code
        last["G"] = code
        words += ["X" + tx, "Y" + ty]  # _word(..., force=True)
        last["X"], last["Y"] = tx, ty
        if z is not None:
            self._word("Z", self._z_text(z), words)
        words += ["I" + ti, "J" + tj]
        self.written = written
        self._feed(move, words)
        self._with_speed(words)
        self.block(words)

    # -- arcs in the ZX and YZ planes -----------------------------------------------

    def plane_arc(self, arc: PlaneArc, index: int) -> int:
        """Write ``arc`` as ``G18``/``G19`` arc block(s) then ``G17``, if it can be.

        ``index`` is the arc's first move in the program. It is written as an arc when
        the dialect has ``planes``, the machine a Z axis, the ``arc.moves`` moves from
        ``index`` are still its chords (:meth:`~camtool.model.program.Program.has_chords_of`)
        and it starts where the controller is; its printed numbers must pass the
        controller's arc check (``arc_check``, in the plane) and print an arc (not a
        point, not a centre on the start). Otherwise nothing is written here, and the
        chords are written as the moves they are (with a warning when only the printed
        numbers stood in the way).

        Returns:
            The number of the program's moves written once this returns: ``index +
            arc.moves`` when the arc was written, else ``index``.

        Raises:
            DialectError: a number over its field, a block over ``max_block_bytes`` or a
                chord outside the work area.
        """
        spec = self.spec
        if not (spec.planes and self.machine.has_z and self._starts_here(arc, index)):
            return index
        chords = self.program.moves[index : index + arc.moves]
        blocks = self._plane_blocks(arc)
        if blocks is None:
            self.counts["plane-chords"] += 1
            return index
        first = chords[0]
        assert isinstance(first, Linear)  # has_chords_of checked
        if first.contour:
            self.contour = first.contour
        here = self.here
        for chord in chords:
            self._check_area(here, chord)
            here = (chord.x, chord.y)
        self._flush_speed()
        for k, words in enumerate(blocks):
            if k == 0:
                words.insert(0, PLANE_CODES[arc.plane])
            self._feed(first, words)
            self.block(words)
        self.block([PLANE_CODES["xy"]])
        self.here, self.z = (arc.end[0], arc.end[1]), arc.end[2]
        return index + arc.moves

    def _starts_here(self, arc: PlaneArc, index: int) -> bool:
        """Whether ``arc``'s chords follow ``index`` and it starts where the controller is."""
        if self.z is None or not self.program.has_chords_of(index, arc):
            return False
        sx, sy, sz = arc.start
        same_z = self.text("Z", sz) == self.text("Z", self.z)
        return math.dist(self.here, (sx, sy)) <= SAME_MM and same_z

    def _plane_blocks(self, arc: PlaneArc) -> list[list[str]] | None:
        """The words of each block of ``arc`` (no plane code, no F), or ``None``: chords.

        Split as XY arcs are (``max_arc_deg``, ``full_circle``); each block's offsets
        are from its printed start, as the controller takes them. ``None`` when a
        block's printed numbers fail the arc check or print no arc.
        """
        axes = PLANE_AXES[arc.plane]
        letters = ["XYZ"[i] for i in axes]  # first, second, linear
        offsets = ["IJK"[i] for i in axes[:2]]
        whole = arc.arc()
        full = whole.is_full_circle
        pieces = whole.split(self._parts(whole, full))
        assert self.z is not None  # _starts_here checked
        position = [self.written[0], self.written[1], self._round("Z", self.z)]
        lin0, lin1 = arc.start[axes[2]], arc.end[axes[2]]
        out: list[list[str]] = []
        for k, piece in enumerate(pieces, start=1):
            start = (position[axes[0]], position[axes[1]])
            texts: dict[str, str] = {}
            linear = lin1 if k == len(pieces) else lin0 + (lin1 - lin0) * k / len(pieces)
            values = (piece.end[0], piece.end[1], linear)
            printed = []
            for letter, value in zip(letters, values, strict=True):
                text = self._z_text(value) if letter == "Z" else self.text(letter, value)
                printed.append(self._parses[letter](text))
                if letter != letters[2] or printed[-1] != position[axes[2]]:
                    texts[letter] = text  # the linear axis only when it moves
            centre = []
            for letter, c, s0 in zip(offsets, piece.centre, start, strict=True):
                origin = 0.0 if self._absolute_centre else s0
                texts[letter] = self.text(letter, c - origin)
                centre.append(self._parses[letter](texts[letter]) + origin)
            end = (printed[0], printed[1])
            if not self._printable(start, end, (centre[0], centre[1]), full and len(pieces) == 1):
                return None
            for i, value in zip(axes, printed, strict=True):
                position[i] = value
            code = self._cw if arc.clockwise else self._ccw
            out.append([code] + [c + texts[c] for c in "XYZIJK" if c in texts])
        self.written = (position[0], position[1])
        self.last["X"], self.last["Y"] = "", ""  # modal X/Y: written again after the arc
        self.last.pop("Z", None)
        self.last["G"] = ""
        return out

    def _printable(self, start: Point, end: Point, centre: Point, full: bool) -> bool:
        """Whether a plane arc block's printed numbers make an arc the controller accepts."""
        if centre == start or (end == start and not full):
            return False
        if self._arc_floor_mm and 2.0 * math.dist(centre, start) <= self._arc_floor_mm:
            return False
        if self.spec.arc_check == "none":
            return True
        from camtool.post.arccheck import arc_error

        return arc_error(start, end, centre, rule=self.spec.arc_check) is None

    # -- commands ----------------------------------------------------------------

    def command(self, command: Command) -> None:
        """Write a spindle, dwell, tool change or stop, or count it as dropped.

        A tool change or a stop is never dropped: a dialect that cannot write it
        refuses the program (a job of several tools is split per tool before).

        Raises:
            DialectError: a tool change or stop the dialect cannot write.
        """
        spec = self.spec
        self._flush_speed()  # a new speed before this command: in its place, not after it
        if isinstance(command, Spindle):
            code = {"cw": spec.spindle_cw, "ccw": spec.spindle_ccw, "off": spec.spindle_off}[
                command.direction
            ]
            if code is None:
                self.drop(command)
                return
            turning = self.spindle
            self.spindle = None if command.direction == "off" else command
            words = [code]
            rpm = None if command.direction == "off" else command.rpm
            if rpm is not None and not spec.has("S"):
                self.counts["speed"] += 1
            elif rpm == 0:  # S0 as programmed: a laser's power off with M4 still on
                words.append("S" + self.text("S", 0.0))
            elif rpm is not None:
                hint = " (give a faster --spindle-rpm, or the tool's rpm in the job file)"
                text = self._above_zero("S", rpm, "spindle speed", "rev/min", hint)
                word = spec.word("S")
                if word is not None and word.number.parse(text) != rpm:
                    self.warn(f"spindle speed {rpm:g} rev/min written as S{text}")
                words.append("S" + text)
            same = turning is not None and turning.direction == command.direction
            if spec.rs274 and len(words) == 2 and same:  # a new speed only
                self.speed = words[1]
                return
            self.block(words)
        elif isinstance(command, Coolant):
            code = {"mist": spec.coolant_mist, "flood": spec.coolant_flood}.get(
                command.state, spec.coolant_off
            )
            if code is None:
                self.drop(command)
            else:
                self.block([code])
        elif isinstance(command, Dwell):
            if spec.dwell is None:
                self.drop(command)
                return
            self.block([spec.dwell, "P" + self.text("P", command.seconds)])
        elif isinstance(command, ToolChange):
            self._tool_change(command)
        elif isinstance(command, Stop):
            self._stop(command.optional, command.message)
        elif isinstance(command, LengthOffset):
            self._length_offset(command)
        elif isinstance(command, WorkOffset) and command.code in self.spec.work_offsets:
            self.block([command.code])
        elif isinstance(command, PathControl) and command.code in self.spec.path_controls:
            given = zip("PQ", (command.tolerance_mm, command.naive_mm), strict=True)
            self.block([command.code, *(k + self._tolerance(v) for k, v in given if v is not None)])
        elif isinstance(command, Home) and command.code in spec.homes:
            self._home(command)
        elif isinstance(command, Home | WorkOffset | PathControl):
            self.drop(command)

    def _tolerance(self, mm: float) -> str:
        """A G64 tolerance (mm) as written: rounded down, never looser than asked.

        A positive one below the dialect's quantum is written as the quantum, not as 0:
        LinuxCNC reads ``G64 P0`` as no tolerance at all, blending at any cost.
        """
        quantum = self.spec.quantum_mm()
        if mm > 0:
            mm = max(quantum, math.floor(mm / quantum + 1e-6) * quantum)
        return self.text("X", mm)

    def _home(self, home: Home) -> None:
        """A return to the stored position: ``G91 G28 Z0``, ``G90`` (``G28`` for XYZ).

        RS-274 writes it so, through the point where the tool is; a rapid in machine
        coordinates is ``G53`` with the rapid code and the axes at their machine
        coordinates (``G53 G0 Z0``, ``G53 G0 Z-5``).

        A program's ``G28 G91 Z0`` before its first move is its retract: dropped, the
        first rapid would run at whatever height the tool was left. The axes it moves
        are written again in the next move that gives them.
        """
        axes, code = home.axes, home.code
        if code == "G53":
            at = (a + self.text(a, home.machine_at(a)) for a in axes)
            self.block([code, self.spec.motion_codes[0], *at])
        elif axes == "XYZ":
            self.block([code])
        else:
            self.block(["G91", code, *(a + self.text(a, 0.0) for a in axes)])
            self.block(["G90"])
        for axis in axes:
            self.last.pop(axis, None)
        if "Z" in axes:
            self.z = None

    def _length_offset(self, offset: LengthOffset) -> None:
        """``G43 H1`` or ``G49`` where a program read from code had it; the next Z again.

        Raises:
            DialectError: the dialect has no length offset code (or none that cancels).
        """
        spec = self.spec
        cancel = {"G43": "G49"}.get(spec.tool_length_offset or "")
        code = spec.tool_length_offset if offset.tool is not None else cancel
        if code is None:
            what = "G49" if offset.tool is None else f"G43 H{offset.tool}"
            raise DialectError(
                f"{self.where()}: {spec.name} cannot write the tool length offset {what}, "
                "and the program's Z is measured with it; post for a target that has one"
            )
        words = [code] if offset.tool is None else [code, "H" + self.text("H", offset.tool)]
        self.block(words)
        self.z = None  # measured with another offset: the next Z is written again
        self.last.pop("Z", None)

    def _tool_change(self, change: ToolChange) -> None:
        """``T2 M6`` (and ``G43 H2``), or by hand: spindle off, a comment, a stop."""
        spec = self.spec
        text = self.text("T", float(change.tool)) if spec.has("T") else str(change.tool)
        if spec.tool_change is not None:
            self.block(["T" + text, spec.tool_change])
            if spec.tool_length_offset is not None and change.length_offset:
                self.block([spec.tool_length_offset, "H" + self.text("H", float(change.tool))])
            self.z = None  # the new tool's length: the next Z is written again
            self.last.pop("Z", None)
            return
        what = f"change to T{change.tool}" + (
            f": {change.description}" if change.description else ""
        )
        if spec.stop is None or spec.comment is None:
            raise DialectError(
                f"{self.where()}: {spec.name} cannot change tools ({what}): it has no tool "
                "change code and no program stop with a comment, and camtool never drops a tool "
                "change: post one program per tool (a job does so for such a target)"
            )
        turning = self.spindle
        if turning is not None and spec.spindle_off is not None:
            self.block([spec.spindle_off])
            self.spindle = None  # stopped: the restart below is a whole M3 S… block
        self._stop(False, what)
        # the new tool is another length, and its Z zero is set again by hand: the next Z
        # is written again, so the first move after the change goes to a known height
        self.z = None
        self.last.pop("Z", None)
        self.by_hand = change.tool
        if turning is not None:
            self.command(turning)  # the spindle as it was, for the new tool

    def _stop(self, optional: bool, message: str) -> None:
        """A program stop (``M0``; ``M1`` when ``optional``), after a comment saying why.

        The comment is a ``(MSG, ...)`` the controller shows where the dialect has
        :attr:`~camtool.post.wordaddress_spec.WordAddressSpec.operator_messages`.
        """
        spec = self.spec
        code = (spec.optional_stop or spec.stop) if optional else spec.stop
        if code is None:
            kind = "optional stop (M1)" if optional else "program stop (M0)"
            reason = f" ({message})" if message else ""
            raise DialectError(
                f"{self.where()}: {spec.name} has no {kind}{reason}; a stop is never dropped: "
                "post the program for a target that stops, or take the stop out of it"
            )
        prefix = "MSG, " if spec.operator_messages else ""
        comment = spec.comment_line(message, prefix) if message else None
        if comment is not None:
            self.blocks.append(comment)
        self.block([code])
