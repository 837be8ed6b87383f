"""G-code importer: RS-274 programs as CAM programs write them, read into a Program.

Design notes: docs/internals.md, ``camtool/importers/gcode.py``.
"""

from __future__ import annotations

import dataclasses
import math
import re
from array import array
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import Literal, cast

from camtool import accel
from camtool.accel.collector import paused
from camtool.importers import gcode_ahead
from camtool.importers.gcode_codes import BlockWords, CommandReader, Notes, read_units, unused_word
from camtool.importers.gcode_cycles import CYCLES, CycleState
from camtool.importers.gcode_lexer import (
    Block,
    Word,
    cut_mid_word,
    lex_line,
    lines_with_words,
    refuse_words_after_percent,
)
from camtool.importers.gcode_params import expand_parameters
from camtool.importers.gcode_plain import arc_end_off, arc_limits, plain_words, spiral_note
from camtool.importers.gcode_start import StartRules
from camtool.importers.gcode_target import READ_AS_WRITTEN, LengthOffsets, Reading, path_control
from camtool.importers.textfile import program_text
from camtool.model.errors import InputError
from camtool.model.program import (
    ArcMove,
    Dwell,
    Home,
    Linear,
    Move,
    Plane,
    PlaneArc,
    Program,
    Rapid,
    WorkOffset,
)
from camtool.model.shapes import Point
from camtool.model.units import INCH

PLANE_CHORD_MM = 0.001
"""Chord error, mm, of the straight cuts a G18/G19 arc is read as (the default
``--tolerance``; LinuxCNC's and below GRBL's own $12 = 0.002 mm)."""
_PLANES = {"G17": "xy", "G18": "zx", "G19": "yz"}
_CENTRE_LETTERS = {"xy": ("I", "J"), "zx": ("K", "I"), "yz": ("J", "K")}
"""The offset words of an arc's centre in each plane, in the plane's (first, second) order."""
_PLANE_NAMES = {"xy": "XY plane (G17)", "zx": "ZX plane (G18)", "yz": "YZ plane (G19)"}


def read_gcode(
    path: str | Path,
    *,
    source_name: str | None = None,
    reading: Reading = READ_AS_WRITTEN,
) -> Program:
    """Read a G-code file (``.ngc``, ``.nc``, ``.tap``, ``.gcode`` …) into a program.

    Args:
        path: the file. UTF-8 (with or without BOM), else read as Latin-1 (binary data is
            refused).
        source_name: the name messages give the file (default: ``path``).
        reading: what the program is read for (:class:`~camtool.importers.gcode_target.
            Reading`: ``post --feed``, the target's length and work offsets).

    Returns:
        The moves in absolute mm, Y up, feeds in mm/min, with the warnings for
        what was converted or dropped (one per kind, with count and first line).

    Raises:
        InputError: the file cannot be read, holds no move, or uses a construct
            camtool refuses (see :func:`parse_gcode`); the message names the
            file, the line and the construct.
    """
    path = Path(path)
    source = source_name or str(path)
    try:
        text = program_text(path.read_bytes(), source)  # the bytes go as soon as they are text
    except OSError as exc:
        raise InputError(f"{source}: cannot read the file ({exc.strerror or exc})") from exc
    return parse_gcode(text, source=source, reading=reading)


def read_gcode_bytes(
    data: bytes,
    *,
    source: str,
    reading: Reading = READ_AS_WRITTEN,
) -> Program:
    """Read a G-code file given as its bytes (as :func:`read_gcode` reads the file's).

    Args:
        data: the file's bytes: UTF-8 (with or without BOM), UTF-16 or UTF-32 with their
            BOM, else read as Latin-1 (binary data is refused).
        source: the name messages give the file.
        reading: as :func:`read_gcode`'s.

    Raises:
        InputError: as :func:`parse_gcode`.
    """
    return parse_gcode(program_text(data, source), source=source, reading=reading)


_LINE_END = re.compile(r"\r\n|\r|\n")


def _lines_at(text: str, start: int) -> Iterator[tuple[str, bool, int]]:
    """The lines of ``text`` from character ``start`` (a line's first), one at a time.

    Each with whether it is the last and the character where the next starts. Lines end
    with LF, CR LF or CR (a CR LF is one end); the last line is what follows the last line
    end, maybe empty: the lines splitting at each end would give, without a list of them
    all (a 50 MB program is 2.6 million lines).
    """
    for end in _LINE_END.finditer(text, start):
        yield text[start : end.start()], False, end.end()
        start = end.end()
    yield text[start:], True, len(text)


def _read_ahead(text: str, source: str, reading: Reading, position: int, number: int) -> bytes:
    """In the helper: the runs of plain lines from character ``position``, read from nothing.

    ``position`` is the start of line ``number + 1`` (:mod:`camtool.importers.gcode_ahead`).
    Lines that fail are passed over (a run's moves depend on its start alone); the last
    line, and what follows the program's end, are left to the reader.
    """
    reader = _Reader(source, reading)
    gcode_ahead.seed(reader, text, position)
    recorder = gcode_ahead.Recorder(reader)
    for raw, last, after in _lines_at(text, position):
        number += 1
        if last:
            break
        recorder.before(number)
        try:
            if raw.isascii() and reader.plain(plain_words(raw), number):
                recorder.plain(number, after)
                continue
            recorder.broken()
            block = lex_line(raw, number, source)
            if block is not None and reader.run(block):
                break  # the program's end
        except InputError:
            recorder.broken()
    return recorder.pack()


def parse_gcode(
    text: str,
    *,
    source: str,
    reading: Reading = READ_AS_WRITTEN,
) -> Program:
    """Read G-code text into a program (the rules are in this module's docstring).

    Args:
        text: the program; lines end with LF, CR LF or CR.
        source: the name messages give it; line numbers are 1-based file lines.
        reading: what the program is read for (:class:`~camtool.importers.gcode_target.
            Reading`): the feed of cuts before the first F word, and the target's length
            offsets and work offsets, kept where the program has them.

    Raises:
        InputError: O-words, ``#`` parameters but numbered ones set to numbers
            (:mod:`~camtool.importers.gcode_params`), ``[ ]`` expressions, G41/G42, G93/G95,
            coordinate-offset codes, unknown G/M codes or letters, two codes of one modal
            group, a repeated word, a word no code uses, a cut before any F, an arc without
            centre or off its circle beyond tolerance, a number out of range, a last line
            cut in a word, an empty text (nothing but blanks), no move at all, or no
            cutting move.

    Plain lines take the fast path (:meth:`_Reader.plain`, no word objects) unless
    ``CAMTOOL_ACCEL=0``; :func:`parse_gcode_slow` is the reference, with the same result.
    """
    if not text or text.isspace():  # stops at the first character that is not a blank
        raise InputError(
            f"{source}: empty file (nothing but blanks); export the program again from the "
            "CAM program"
        )
    with paused():  # the moves it makes stay; what it frees, counting frees
        text = expand_parameters(text, source)  # numbered parameters read as their numbers
        return _parse(text, source, plain=accel.enabled(), reading=reading)


def parse_gcode_slow(text: str, *, source: str) -> Program:
    """:func:`parse_gcode` with every line lexed into words and run block by block.

    The reference way of reading a line; :func:`parse_gcode` reads plain
    lines (:meth:`_Reader.plain`) without making words, to the same program with
    the same warnings and errors (tests/importers/test_gcode_plain.py compares the two).
    """
    return _parse(expand_parameters(text, source), source, plain=False)


def _parse(
    text: str,
    source: str,
    *,
    plain: bool,
    reading: Reading = READ_AS_WRITTEN,
) -> Program:
    """:func:`parse_gcode`; ``plain``: take the plain-line path where it applies.

    With ``plain``, a long program's later plain lines are read ahead in a forked helper
    and taken where they fit (:mod:`camtool.importers.gcode_ahead`).
    """
    ahead = None
    if plain:
        ahead = gcode_ahead.start(
            text, lambda position, number: _read_ahead(text, source, reading, position, number)
        )
    lines = _lines_at(text, 0)
    reader = _Reader(source, reading)
    opened = False  # a '%' line before the first block: the next '%' ends the program
    ended = False
    runs: gcode_ahead.Runs | None = None
    number = 0
    try:
        while True:
            jumped = False
            for raw, last, _ in lines:
                number += 1
                if ahead is not None and number >= ahead[1]:  # the helper's lines: its runs
                    data = ahead[0].take()
                    runs = None if data is None else gcode_ahead.Runs(data)
                    ahead = None
                if runs is not None and (run := runs.take(reader, number)) is not None:
                    number = run.last  # its lines read: on after them
                    lines = _lines_at(text, run.after)
                    jumped = True
                    break
                if last and (cut := cut_mid_word(raw)) is not None:
                    raise InputError(
                        f"{source}:{number}: the file ends in the middle of a word ({cut!r}, "
                        "with no end of line after it): the last line is incomplete, the file "
                        "looks truncated; copy or export the program again"
                    )
                if plain and raw.isascii() and reader.plain(plain_words(raw), number):
                    continue
                block = lex_line(raw, number, source)
                reader.commands.operator_message(len(reader.moves), raw)
                if block is None:
                    if raw.lstrip().startswith("%"):
                        if opened:
                            reader.after_end((r for r, _, _ in lines), number)
                            ended = True
                            break
                        if reader.line:  # no '%' opened the program: LinuxCNC stops here
                            refuse_words_after_percent((r for r, _, _ in lines), number, source)
                            ended = True
                            break
                        opened = True
                    continue
                if reader.run(block):
                    reader.after_end((r for r, _, _ in lines), number)
                    ended = True
                    break
            if not jumped:
                break
    finally:
        if ahead is not None:
            ahead[0].close()
    if not ended and reader.line:
        reader.notes.add(
            "end",
            reader.line,
            "no M2/M30 (nor a closing '%'): the file may be truncated; check that its last "
            "moves are all there",
        )
    return reader.program()


class _Reader(StartRules):
    """The modal state of the interpreter and the moves read so far."""

    def __init__(self, source: str, reading: Reading = READ_AS_WRITTEN) -> None:
        self.source = source
        self.notes = Notes(source)
        self.commands = CommandReader(self.notes)
        self.moves: list[Move] = []
        self.lines = array("q")
        self.line = 0
        self.x: float | None = 0.0
        self.y: float | None = 0.0
        self.z: float | None = None
        self.positioned = False  # no X or Y word yet: the machine's XY is the program's guess
        self.motion: str | None = None
        self.moded = False  # a motion code (G80 too) was given: no power-on mode is in effect
        self.plane = "xy"
        self.absolute = True
        self.arc_absolute = False
        self.inch = False
        self.units_seen = False
        self.feed_mm_min: float | None = None
        self.first_feed = reading.feed_mm_min  # the feed before the first F word (post --feed)
        self.reading = reading  # the offsets and path control modes the target writes
        self.known_start = reading.known_start  # written again: no move from the guessed XY
        self.coord: str | None = None
        self.offsets = (  # the target writes G43 H<n> after each change: kept as read
            LengthOffsets(self.commands, self.moves) if reading.length_offsets else None
        )
        self.home = ""
        self.cycles = CycleState(note=lambda text: self.notes.add("G98", self.line, text))
        self.contour = 1
        self.cut_in_contour = False

    @property
    def scale(self) -> float:
        """Millimetres per unit of the numbers in the current block."""
        return INCH if self.inch else 1.0

    def run(self, block: Block) -> bool:
        """Execute one block; True when it ends the program (M2/M30)."""
        self.line = block.line
        if block.block_delete:
            self.notes.add(
                "/", block.line, "'/' block delete: the line is read as if the switch were off"
            )
        words = BlockWords(block, self.where())
        self._modes(words)
        used = self._motion(words)
        self._check_unused(words, used)
        stop = words.m.get("stop")
        if stop is not None and stop.name in ("M0", "M1"):  # last in the order of execution
            self.commands.stop(len(self.moves), stop.name == "M1")
        return stop is not None and stop.name in ("M2", "M30")

    def after_end(self, rest: Iterable[str], end_line: int) -> None:
        """Warn about lines with words after M2/M30 on ``end_line``."""
        count, first = 0, 0
        for number in lines_with_words(rest, end_line + 1, self.source):
            count += 1
            first = first or number
        if count:
            plural = "line" if count == 1 else "lines"
            self.notes.add(
                "end", first, f"{count} {plural} after the program end on line {end_line} not read"
            )

    def program(self) -> Program:
        """The program read, or InputError if it has no move or no cutting move."""
        self.commands.finish()
        if not self.moves:
            raise InputError(
                f"{self.source}: no move (G0, G1, G2, G3) found; is this a G-code program?"
            )
        if all(isinstance(move, Rapid) for move in self.moves):
            raise InputError(
                f"{self.source}: no cutting move (G1, G2, G3): the program only moves in "
                f"rapids (G0, {len(self.moves)} of them), so there is nothing to cut"
            )
        return Program(
            tuple(self.moves),
            (0.0, 0.0),
            self.notes.warnings(),
            lines=self.lines,
            commands=tuple(
                self.commands.commands
                if self.offsets is None
                else self.offsets.commands_out(self.commands.commands)
            ),
        )

    # -- modes -------------------------------------------------------------------

    def _modes(self, w: BlockWords) -> None:
        """Everything a block sets before its motion (RS-274/NGC order of execution)."""
        if (
            inch := read_units(w, self.inch if self.units_seen else None, self.where())
        ) is not None:
            self.inch, self.units_seen = inch, True
        if (f := w.args.get("F")) is not None:
            if f.value < 0:
                raise InputError(f"{self.where()}: negative feed {f}; feeds are > 0")
            self.feed_mm_min = f.value * self.scale
        self.commands.block(w, len(self.moves), self.line, self.where())
        for code in (*w.m.values(), *w.g.values()):
            if code.action == "warn" and not self.reading.keeps(code):
                self.notes.add(code.name, self.line, code.note)
        if (path := w.g_name("path")) in self.reading.path_controls:
            self.commands.add(len(self.moves), path_control(w, str(path), self.scale, self.where()))
        if self.offsets is not None:
            self.offsets.block(w, self.where())
        if (coord := w.g_name("coord")) is not None:
            if self.coord not in (None, coord):
                raise InputError(
                    f"{self.where()}: {coord} after {self.coord}: camtool assumes one work "
                    "offset (the part zero); split the program at the change"
                )
            if self.coord is None and coord in self.reading.work_offsets:
                self.commands.add(len(self.moves), WorkOffset(coord))
            self.coord = coord
        if (plane := w.g_name("plane")) is not None:
            self.plane = _PLANES[plane]
        if (distance := w.g_name("distance")) is not None:
            self.absolute = distance == "G90"
        if (arc_distance := w.g_name("arc_distance")) is not None:
            self.arc_absolute = arc_distance == "G90.1"
        if (retract := w.g_name("retract")) is not None:
            self.cycles.retract = "initial" if retract == "G98" else "r-plane"

    def _check_unused(self, w: BlockWords, used: set[str]) -> None:
        """Refuse words that no code in the block uses (LinuxCNC does the same)."""
        if "H" in w.args and w.g_name("length") == "G43":
            used.add("H")
        if w.g_name("path") == "G64":
            used |= {"P", "Q"}  # blending tolerances, ignored with G64 (LinuxCNC "G64")
        for letter in "XYZIJRPHKQ":
            word = w.args.get(letter)
            if word is None or letter in used:
                continue
            if letter in "IJK" and self.motion in ("G2", "G3") and used:
                first, second = sorted(_CENTRE_LETTERS[self.plane])
                if word.value == 0:  # FreeCAD's grbl post writes K0 on every XY arc
                    self.notes.add(
                        f"{letter}0 arc",
                        self.line,
                        f"{word} on an arc in the {_PLANE_NAMES[self.plane]} ignored: a zero "
                        "offset off the plane, which GRBL ignores too (LinuxCNC refuses it)",
                    )
                    continue
                raise InputError(
                    f"{self.where()}: {word}: an arc in the {_PLANE_NAMES[self.plane]} takes "
                    f"its centre from {first} and {second}; select the plane of {word.letter} "
                    "(G17 XY: I J, G18 ZX: I K, G19 YZ: J K) or remove it"
                )
            raise InputError(f"{self.where()}: {unused_word(word, self.moded)}")

    # -- motion ------------------------------------------------------------------

    def _motion(self, w: BlockWords) -> set[str]:
        """Execute G28/G30/G53 or the motion of the block; the letters it used."""
        used = {"P"} if w.g_name("nonmodal") == "G4" else set()
        axes = {letter for letter in "XYZ" if letter in w.args}
        motion = w.g_name("motion")
        if motion is not None:
            self.motion = None if motion == "G80" else motion
            self.moded = True
        home = w.g_name("nonmodal")
        if home == "G53":
            self._machine_coordinates(w.args)
            return used | axes
        if home in ("G28", "G30"):
            if axes and motion not in (None, "G80"):
                raise InputError(
                    f"{self.where()}: {home} and {motion} both use the axis words; "
                    "put them in separate blocks"
                )
            self._home("G28" if home == "G28" else "G30", w.args)
            return used | axes
        if self.motion in CYCLES:
            if motion in CYCLES or axes:
                self._cycle(w.args)
                return used | {letter for letter in "XYZRQP" if letter in w.args}
            return used
        self.cycles.end_series()
        if self.motion in ("G2", "G3"):
            letters = "XYZRP" + "".join(_CENTRE_LETTERS[self.plane])
            arc_words = {letter for letter in letters if letter in w.args}
            if arc_words - {"P"}:
                self._arc(w.args)
                return used | arc_words
        elif self.motion is not None and axes:
            self._line(w.args)
            return used | axes
        return used

    def _target(self, args: dict[str, Word]) -> tuple[float | None, float | None, float | None]:
        """The end point of a move in mm; ``None`` for an axis whose position is unknown."""
        out: list[float | None] = []
        for letter, here in (("X", self.x), ("Y", self.y), ("Z", self.z)):
            word = args.get(letter)
            if word is None:
                out.append(here)
            elif self.absolute:
                out.append(word.value * self.scale)
            elif here is not None:
                out.append(here + word.value * self.scale)
            elif word.value == 0:
                out.append(None)
            else:
                after = f"after {self.home}" if self.home and letter != "Z" else "yet"
                raise InputError(
                    f"{self.where()}: incremental {word} (G91) but the {letter} position is not "
                    f"known {after}; give an absolute {letter} (G90) first"
                )
        return out[0], out[1], out[2]

    def _end_xy(self, args: dict[str, Word], name: str) -> tuple[float, float, float | None]:
        """Target of a motion block, whose XY must be known."""
        tx, ty, tz = self._target(args)
        if tx is None or ty is None:
            raise InputError(
                f"{self.where()}: {name} ends at an unknown position after {self.home}; "
                "give absolute X and Y (G90)"
            )
        return tx, ty, tz

    def _start_xy(self, name: str) -> Point:
        """Start of a cutting move, which must be known."""
        if self.x is None or self.y is None:
            raise InputError(
                f"{self.where()}: {name} starts from the position after {self.home}, which "
                "camtool does not know; move there first with G0 and absolute X and Y"
            )
        return self.x, self.y

    def _z_out(self, args: dict[str, Word], tz: float | None) -> float | None:
        """The ``z`` a move carries: its Z when the Z word changes Z, else None."""
        return tz if "Z" in args and tz is not None and tz != self.z else None

    def _feed(self, name: str) -> float:
        if self.feed_mm_min is None and self.first_feed is not None:
            return self.first_feed  # post --feed: it sets every cut's feed
        if self.feed_mm_min is None:
            raise InputError(
                f"{self.where()}: {name} before any F word, which a controller refuses "
                "(GRBL: error 22); set the feed (e.g. F100) first, or write the program "
                "again with camtool post --feed MM_PER_MIN"
            )
        if self.feed_mm_min == 0:
            raise InputError(f"{self.where()}: {name} with feed F0; set a feed above 0")
        return self.feed_mm_min

    def _push(self, move: Move, tx: float | None, ty: float | None, tz: float | None) -> None:
        """Append ``move`` (its contour set here) and make its end the current position."""
        if not self.units_seen:
            self.units_seen = True
            self.notes.add(
                "units", self.line, "no G20/G21 before the first move: coordinates read as mm"
            )
        if isinstance(move, Rapid):
            if self.cut_in_contour:
                self.contour += 1
            self.cut_in_contour = False
        else:
            self.cut_in_contour = True
        self.moves.append(dataclasses.replace(move, contour=self.contour))
        self.lines.append(self.line)
        self.x, self.y, self.z = tx, ty, tz

    def _line(self, args: dict[str, Word]) -> None:
        name = self.motion or "G1"
        tx, ty, tz = self._end_xy(args, name)
        z = self._z_out(args, tz)
        gives_xy = "X" in args or "Y" in args
        if gives_xy and not self.positioned and self.known_start:
            self.check_first_xy(args, name)
        if gives_xy and not self.positioned and z is not None and (tx, ty) == (self.x, self.y):
            self._first_positioning(name, tx, ty, tz, z)
            return
        feed = None if name == "G0" else self._feed(name)  # refused without, as LinuxCNC
        if not gives_xy and z is None and not self.positioned:
            return  # moves nowhere, and XY is only assumed: a move there would be a guess
        self.positioned = self.positioned or gives_xy
        if feed is None:
            self._push(Rapid(tx, ty, z), tx, ty, tz)
            return
        self._start_xy(name)
        self._push(Linear(tx, ty, feed, z), tx, ty, tz)

    def _first_positioning(
        self, name: str, tx: float, ty: float, tz: float | None, z: float
    ) -> None:
        """A first ``X Y Z`` block to the assumed start position: keep its XY explicit.

        Before any X or Y word the machine's XY is not known (the reader assumes the
        program's zero); an explicit ``G0 X0 Y0 Z5`` there must not become a Z-only move
        when written again. It is read as two moves, Z first when rising, XY first when
        going down (with Z not yet known: above Z 0 counts as rising), so the XY
        travel is not made lower than the program made it.
        """
        self.positioned = True
        feed = None if name == "G0" else self._feed(name)

        def xy() -> Move:
            return Rapid(tx, ty) if feed is None else Linear(tx, ty, feed)

        def up_down() -> Move:
            return Rapid(tx, ty, z) if feed is None else Linear(tx, ty, feed, z)

        rising = z > 0.0 if self.z is None else z >= self.z  # unknown Z: above the top rises
        first, second = (up_down(), xy()) if rising else (xy(), up_down())
        self._push(first, tx, ty, tz if rising else self.z)
        self._push(second, tx, ty, tz)

    def _arc(self, args: dict[str, Word]) -> None:
        name = self.motion or "G2"
        feed = self._feed(name)
        if not self.positioned and self.known_start:
            self.refuse_first_arc(name)
        start = self._start_xy(name)
        tx, ty, tz = self._end_xy(args, name)
        self.positioned = True
        turns = args.get("P")
        if turns is not None and turns.value != 1:
            raise InputError(
                f"{self.where()}: {name} {turns}: multi-turn arcs are not supported; "
                "write each turn as its own G2/G3"
            )
        if self.plane != "xy":
            self._plane_arc(args, name, feed, (tx, ty, tz))
            return
        clockwise = name == "G2"
        cx, cy = self._centre(args, start, (tx, ty), clockwise, name)
        arc = ArcMove(tx, ty, cx, cy, clockwise, feed, self._z_out(args, tz))
        self._push(arc, tx, ty, tz)

    def _centre(
        self, args: dict[str, Word], start: Point, end: Point, clockwise: bool, name: str
    ) -> Point:
        """The absolute centre of an arc from ``start`` to ``end`` in the current plane."""
        letters = _CENTRE_LETTERS[self.plane]
        if "R" in args:
            if any(letter in args for letter in letters):
                raise InputError(
                    f"{self.where()}: {name} with both R and {'/'.join(sorted(letters))}; "
                    "keep one form"
                )
            return self._centre_r(args["R"], start, end, clockwise, name)
        return self._centre_ij(args, start, end, name, letters)

    def _plane_arc(
        self, args: dict[str, Word], name: str, feed: float, end: tuple[float, float, float | None]
    ) -> None:
        """An arc in the ZX or YZ plane: a :class:`PlaneArc` command and its chords."""
        if self.z is None or end[2] is None:
            raise InputError(
                f"{self.where()}: {name} in the {_PLANE_NAMES[self.plane]} starts or ends at "
                f"an unknown Z{f' after {self.home}' if self.home else ''}; give an absolute "
                "Z (G90) first"
            )
        assert self.x is not None and self.y is not None  # _start_xy checked them
        start3 = (self.x, self.y, self.z)
        end3 = (end[0], end[1], end[2])
        plane = cast(Plane, self.plane)
        probe = PlaneArc(plane, start3, end3, (0.0, 0.0), name == "G2")
        a, b = probe.in_plane(start3), probe.in_plane(end3)
        centre = self._centre(args, a, b, probe.clockwise, name)
        points = dataclasses.replace(probe, centre=centre).points(PLANE_CHORD_MM)
        arc = dataclasses.replace(probe, centre=centre, moves=len(points) - 1)
        self.commands.add(len(self.moves), arc)
        for x, y, z in points[1:]:
            self._push(Linear(x, y, feed, z), x, y, z)

    def _centre_ij(
        self,
        args: dict[str, Word],
        start: Point,
        end: Point,
        name: str,
        letters: tuple[str, str] = ("I", "J"),
    ) -> Point:
        """The centre from the offset words ``letters`` (the plane's first and second axis)."""
        i, j = args.get(letters[0]), args.get(letters[1])
        both = " and ".join(sorted(letters))
        if i is None and j is None:
            stray = " ".join(str(args[c]) for c in "IJK" if c in args)
            plane = f" in the {_PLANE_NAMES[self.plane]}" + (f", not {stray}" if stray else "")
            raise InputError(
                f"{self.where()}: {name} without a centre{plane}; give {both} (or R) words"
            )
        di = i.value * self.scale if i is not None else 0.0
        dj = j.value * self.scale if j is not None else 0.0
        if self.arc_absolute:
            if i is None or j is None:
                raise InputError(
                    f"{self.where()}: {name} in G90.1 (absolute centre) needs both {both}"
                )
            centre = (di, dj)
        else:
            centre = (start[0] + di, start[1] + dj)
        self._check_radius(start, end, centre, name)
        return centre

    def _check_radius(self, start: Point, end: Point, centre: Point, name: str) -> None:
        r_start, r_end = math.dist(start, centre), math.dist(end, centre)
        if r_start == 0:
            raise InputError(f"{self.where()}: {name} centre is its start point (radius 0)")
        small, large, _ = arc_limits(self.inch, self.scale)
        off = abs(r_start - r_end)
        if arc_end_off(r_start, r_end, small, large):
            mode = "absolute (G90.1)" if self.arc_absolute else "incremental from the start (G91.1)"
            raise InputError(
                f"{self.where()}: {name} end point is {off:.4g} mm off its circle (radius "
                f"{r_start:.4f} mm at the start, {r_end:.4f} mm at the end; LinuxCNC allows "
                f"{small:.4f} mm, or 0.1 % of the larger radius up to {large:.2f} mm); the "
                f"centre words are read as {mode}: check them or export with more decimals"
            )
        note = spiral_note(name, off)
        if note:  # one note however many arcs: the first one's line, and a count
            self.notes.add("spiral", self.line, note)

    def _centre_r(
        self, r_word: Word, start: Point, end: Point, clockwise: bool, name: str
    ) -> Point:
        r = r_word.value * self.scale
        chord = math.dist(start, end)
        if chord == 0:
            raise InputError(
                f"{self.where()}: {name} {r_word} ends where it starts; a full circle cannot "
                "be written with R: use I and J"
            )
        if r == 0:
            raise InputError(f"{self.where()}: {name} with R0; give the arc's radius")
        half = chord / 2
        if abs(r) < half - arc_limits(self.inch, self.scale)[2]:
            raise InputError(
                f"{self.where()}: {name} {r_word}: radius {abs(r):.4f} mm is less than half "
                f"the distance to the end point ({half:.4f} mm); check R"
            )
        h = math.sqrt(max(r * r - half * half, 0.0))
        # The centre lies right of the chord for G2 with R > 0 (the short way).
        side = (1.0 if clockwise else -1.0) * (1.0 if r > 0 else -1.0)
        ux, uy = (end[0] - start[0]) / chord, (end[1] - start[1]) / chord
        mx, my = (start[0] + end[0]) / 2, (start[1] + end[1]) / 2
        return mx + side * h * uy, my - side * h * ux

    def _cycle(self, args: dict[str, Word]) -> None:
        """A canned cycle's command and moves (:meth:`CycleState.hole` says what it refuses)."""
        code, modes = cast(str, self.motion), (self.absolute, self.plane)
        here, feed = (self.x, self.y, self.z), self._feed(code)
        cycle, items = self.cycles.hole(code, args, here, feed, self.scale, modes, self.where())
        self.commands.add(len(self.moves), cycle)
        for item in items:
            if isinstance(item, Dwell):
                self.commands.add(len(self.moves), item)
            else:
                self._push(item, item.x, item.y, self.z if item.z is None else item.z)
        self.positioned = True

    def _machine_coordinates(self, args: dict[str, Word]) -> None:
        """G53: a G0 rapid in machine coordinates is a :class:`Home` coded ``"G53"``.

        With its coordinates (``G53 G0 Z0``; Carbide Create's ``G53 G0 Z-5``); no axis
        words, no move.

        Any other G53 move (G1, or in G91) is refused, not dropped (a dropped retract
        would leave the next rapid at cutting depth).
        """
        words = [str(args[letter]) for letter in "XYZIJKR" if letter in args]
        axes = "".join(letter for letter in "XYZ" if letter in args)
        if words and len(axes) == len(words) and self.motion == "G0" and self.absolute:
            at = tuple(args[a].value * self.scale for a in axes)
            zero = all(v == 0 for v in at)
            what = "G53 G0 rapid to machine zero" if zero else "G53 G0 rapid in machine coordinates"
            self._returned(Home(axes, "G53", () if zero else at), what)
            return
        if words:
            raise InputError(
                f"{self.where()}: G53 {' '.join(words)} moves in machine coordinates, which "
                "camtool reads only as a G0 rapid in absolute mode (G90 G53 G0 Z-5); write "
                "the program in part coordinates (e.g. a retract as G0 Z with the work "
                "offset's clearance height)"
            )
        self.notes.add("G53", self.line, "G53 without axis words moves nowhere: read as no move")

    def _home(self, name: Literal["G28", "G30"], args: dict[str, Word]) -> None:
        """G28/G30: a rapid to the intermediate point, then the axes are unknown.

        Kept as a :class:`Home` command on the axes it names (all three when it names
        none), with its code: G30 is the second stored position, not G28's.
        """
        axes = [letter for letter in "XYZ" if letter in args]
        if axes:
            tx, ty, tz = self._target(args)
            z = self._z_out(args, tz)
            if (
                tx is not None
                and ty is not None
                and ((tx, ty) != (self.x, self.y) or z is not None)
            ):
                self._push(Rapid(tx, ty, z), tx, ty, tz)
        home = Home("".join(axes) or "XYZ", name)
        self._returned(home, f"{name} return to the machine's stored position")

    def _returned(self, home: Home, what: str) -> None:
        """Keep ``home`` as a command; the axes it moves are unknown after it (a warning)."""
        for letter in home.axes:
            setattr(self, letter.lower(), None)
        self.home = f"{home.code} on line {self.line}"
        self.commands.add(len(self.moves), home)
        self.notes.add(
            home.code,
            self.line,
            f"{what}: kept as a command, but camtool does not know that position, so the "
            "verifier does not simulate the move; moves after it must give absolute X and Y",
        )


# ------------------------------------------------------------------ non-motion words
