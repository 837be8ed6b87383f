"""The reader of word-address dialects: code back into a Program, by the same spec.

Strict: every block must be one the writer of the dialect could have written.
Whole-line comments in the dialect's own ``comment`` syntax (the job notes the
writer puts at the top) and the ``%`` tape marks of ``header``/``footer`` are
skipped.

Design notes: docs/internals.md, ``camtool/post/wordaddress_read.py``.
"""

from __future__ import annotations

import dataclasses
import re
from dataclasses import dataclass, field
from typing import Literal

from camtool.importers.textfile import text_lines
from camtool.model.errors import DialectError, ParseError, quoted
from camtool.model.program import (
    ArcMove,
    Command,
    Coolant,
    CoolantState,
    Dwell,
    Home,
    Linear,
    Move,
    Program,
    Rapid,
    Spindle,
    SpindleDirection,
    Stop,
    ToolChange,
)
from camtool.model.shapes import Point
from camtool.post.base import ContourCounter
from camtool.post.wordaddress_spec import WordAddressSpec

_WORD = re.compile(r"([A-Za-z])([^A-Za-z]*)")
_UPPER_WORD = re.compile(r"[A-Z][^A-Za-z]*")
_NUMBER = re.compile(r"[+-]?+(?:\d++\.?+\d*+|\.\d++)", re.ASCII)  # possessive: linear
_CLEAN_WORD = re.compile(r"[A-Za-z][^A-Za-z\s]*")
"""A token that passes every check of :meth:`BlockReader.words` on its form (one letter, no
space): the blocks the writer writes, tested once instead of check by check."""
_KEPT_VALUES = 4096
"""Distinct words whose values a reader keeps (a program repeats its F, Z and many X/Y)."""


@dataclass
class _State:
    """The modal state of the controller while reading."""

    x: float = 0.0
    y: float = 0.0
    z: float | None = None
    motion: str | None = None
    feed: float | None = None
    moves: list[Move] = field(default_factory=list)
    lines: list[int] = field(default_factory=list)
    commands: list[tuple[int, Command]] = field(default_factory=list)
    contours: ContourCounter = field(default_factory=ContourCounter)
    ended: int = 0
    spindle: SpindleDirection | None = None  # turning, as last read


class ControllerRefusal(ParseError):
    """A block in the dialect's spelling that the controller itself refuses (its arc check).

    Not a matter of spelling: an RS-274 reader would not accept it either.
    """


class BlockReader:
    """Reads code of one dialect (see the module docstring for the rules).

    Args:
        spec: the dialect.
        source: the name messages give the code.
    """

    def __init__(self, spec: WordAddressSpec, source: str) -> None:
        self.spec, self.source = spec, source
        self.state = _State()
        self.line = 0
        self.values: dict[tuple[str, str], float] = {}  # (letter, text) -> value, checked
        rapid, linear, cw, ccw = spec.motion_codes
        self.motions = {rapid: "rapid", linear: "linear", cw: "cw", ccw: "ccw"}
        pairs: tuple[tuple[str | None, SpindleDirection], ...] = (
            (spec.spindle_cw, "cw"),
            (spec.spindle_ccw, "ccw"),
            (spec.spindle_off, "off"),
        )
        self.spindle = {code: direction for code, direction in pairs if code}
        coolant: tuple[tuple[str | None, CoolantState], ...] = (
            (spec.coolant_mist, "mist"),
            (spec.coolant_flood, "flood"),
            (spec.coolant_off, "off"),
        )
        self.coolant = {code: state for code, state in coolant if code}
        self.static = spec.static_codes()
        self.codes = set(self.motions) | set(self.spindle) | set(spec.end) | self.static
        self.codes |= set(self.coolant)
        self.codes |= {c for c in (spec.dwell, spec.tool_change) if c}
        self.codes |= {c for c in (spec.tool_length_offset, spec.stop, spec.optional_stop) if c}
        if spec.homes:
            self.codes |= {*spec.homes, "G90", "G91"}

    def fail(self, text: str) -> ParseError:
        """A ParseError naming the source and line."""
        return ParseError(f"{self.source}:{self.line}: {text}")

    def read(self, code: str | bytes) -> Program:
        """The program in ``code``.

        Raises:
            ParseError: a block that is not in the dialect, naming the line.
        """
        if isinstance(code, bytes):
            try:
                code = code.decode("ascii")
            except UnicodeDecodeError as exc:
                raise ParseError(f"{self.source}: byte {exc.start} is not ASCII text") from exc
        for number, raw in enumerate(text_lines(code), start=1):
            self.line = number
            if self.spec.is_comment(raw):
                continue  # the writer's own notes and tape marks
            text = self.uncomment(raw) if self.spec.comments else raw
            if text.strip():
                self.block(text)
        s = self.state
        return Program(tuple(s.moves), lines=tuple(s.lines), commands=tuple(s.commands))

    def uncomment(self, raw: str) -> str:
        """``raw`` without its comments (see the module docstring).

        Raises:
            ParseError: a nested or unclosed ``(``, or a ``)`` without ``(``.
        """
        if "(" not in raw and ")" not in raw and ";" not in raw:
            return raw  # no comment
        pieces: list[str] = []
        start = i = 0
        while i < len(raw) and raw[i] != ";":
            if raw[i] == ")":
                raise self.fail(f"')' without '(' in {quoted(raw)}")
            if raw[i] != "(":
                i += 1
                continue
            end = raw.find(")", i + 1)
            if end < 0:
                raise self.fail(f"comment '(' is not closed on its line: {quoted(raw)}")
            if "(" in raw[i + 1 : end]:
                raise self.fail(f"nested comment '(... (...' in {quoted(raw)}")
            pieces.append(raw[start:i])
            start = i = end + 1
        if start == 0 and i == len(raw):
            return raw  # no comment
        pieces.append(raw[start:i])
        return " ".join(p.strip() for p in pieces if p.strip())

    # -- one block ---------------------------------------------------------------

    def block(self, raw: str) -> None:
        """Read one non-blank line."""
        spec, s = self.spec, self.state
        if s.ended:
            raise self.fail(f"{quoted(raw)} after the program end on line {s.ended}")
        size = len((raw + spec.line_end).encode("ascii", errors="replace"))
        if spec.max_block_bytes is not None and size > spec.max_block_bytes:
            raise self.fail(
                f"block is {size} bytes with its line end; {spec.name} takes at most "
                f"{spec.max_block_bytes}"
            )
        codes, values = self.words(raw)
        if not codes and not values:
            raise self.fail(f"no word in {quoted(raw)}")
        static = self.static
        key = next((c for c in codes if c not in self.motions and c not in static), None)
        home = next((c for c in codes if c in spec.homes), None)
        if home is not None:
            key = home  # G91 G28 Z0: the G91 is the return's
        if key in spec.end:
            self._only(codes, values, key, "the program end")
            s.ended = self.line
        elif key in self.spindle:
            direction = self.spindle[key]
            self._only(codes, values, key, "a spindle", needs="S" if "S" in values else "")
            if direction == "off" and "S" in values:
                raise self.fail(f"S in a spindle-off block ({key})")
            s.commands.append((len(s.moves), Spindle(direction, values.get("S"))))
            s.spindle = None if direction == "off" else direction
        elif key in self.coolant:
            self._only(codes, values, key, "a coolant")
            s.commands.append((len(s.moves), Coolant(self.coolant[key])))
        elif key is not None and key == spec.dwell:
            self._only(codes, values, key, "a dwell", needs="P")
            s.commands.append((len(s.moves), Dwell(values["P"])))
        elif key is not None and key == spec.tool_change:
            self._only(codes, values, key, "a tool change", needs="T")
            # with a length offset code, the change has the offset only where one follows
            change = ToolChange(round(values["T"]), length_offset=not spec.tool_length_offset)
            s.commands.append((len(s.moves), change))
        elif key is not None and key == spec.tool_length_offset:
            self._only(codes, values, key, "a tool length offset", needs="H")
            self._offset_after_change(round(values["H"]))
        elif key is not None and key in spec.homes:
            self._home(codes, values, "G28" if key == "G28" else "G30" if key == "G30" else "G53")
        elif key is not None and key in (spec.stop, spec.optional_stop):
            self._only(codes, values, key, "a program stop")
            optional = key == spec.optional_stop and key != spec.stop
            s.commands.append((len(s.moves), Stop(optional)))
        elif codes and all(c in static for c in codes):
            if values:
                raise self.fail(f"{', '.join(values)} in a setup block ({' '.join(codes)})")
        else:
            self._motion(codes, values)

    def words(self, raw: str) -> tuple[list[str], dict[str, float]]:
        """The codes and the value words of a line, each checked against the spec."""
        spec = self.spec
        body = raw
        if spec.block_end:
            if not raw.endswith(spec.block_end):
                raise self.fail(f"block does not end with {spec.block_end!r}: {quoted(raw)}")
            body = raw[: -len(spec.block_end)]
        if spec.separator:
            tokens = body.split(spec.separator)
        else:
            tokens = [m.group(0) for m in _WORD.finditer(body)]
            if "".join(tokens) != body:
                raise self.fail(f"{spec.name} writes no spaces or other characters: {quoted(raw)}")
        clean = all(map(_CLEAN_WORD.fullmatch, tokens))
        for token in () if clean else tokens:  # the first bad token's own message
            glued = len(_UPPER_WORD.findall(token)) > 1
            if not token or glued or any(c.isspace() for c in token):
                raise self.fail(f"words must be separated by one space: {quoted(raw)}")
            if not _WORD.fullmatch(token):
                raise self.fail(
                    f"{quoted(token)} is not a word (a letter and a number) in {quoted(raw)}"
                )
        codes: list[str] = []
        values: dict[str, float] = {}
        for token in tokens:
            letter, text = token[0], token[1:]
            if letter in values or (letter in "GM" and token in codes):
                raise self.fail(f"{letter} appears twice in {quoted(raw)}")
            if letter in "GM":
                if token not in self.codes:
                    known = " ".join(sorted(self.codes))
                    raise self.fail(f"unknown code {token!r}; {spec.name} knows: {known}")
                codes.append(token)
            else:
                values[letter] = self.value(letter, text)
        return codes, values

    def value(self, letter: str, text: str) -> float:
        """The value of word ``letter`` written as ``text``, mm (or its word's unit)."""
        kept = self.values.get((letter, text))
        if kept is not None:
            return kept
        value = self._checked_value(letter, text)
        if len(self.values) >= _KEPT_VALUES:
            self.values.clear()
        self.values[(letter, text)] = value
        return value

    def _checked_value(self, letter: str, text: str) -> float:
        """:meth:`value`, parsed and checked against the word's format."""
        spec = self.spec.word(letter)
        if spec is None:
            known = " ".join(sorted(self.spec.words))
            raise self.fail(f"unknown word {letter}{text}; {self.spec.name} has: {known}")
        number = spec.number
        try:
            if not _NUMBER.fullmatch(text):
                raise ValueError(text)
            value = number.parse(text)
            ok = number.format(value) == text
        except (ValueError, ArithmeticError, DialectError):
            ok = False
        if not ok:
            example = number.format(-12.5 if letter in "XYZIJ" else 12.5)
            shown = text if len(text) <= 24 else f"{text[:16]}... ({len(text)} characters)"
            raise self.fail(
                f"{letter}{shown} is not in the format of {letter} (e.g. {letter}{example})"
            )
        return value

    def _home(
        self, codes: list[str], values: dict[str, float], key: Literal["G28", "G30", "G53"]
    ) -> None:
        """A return as the writer writes it: ``G28`` or ``G91 G28 Z0`` (G30 so), ``G53 G0 Z-5``.

        ``G28`` alone returns all three axes; ``G91 G28`` the axes it names, each at 0;
        ``G53 G0`` the axes it names, at their machine coordinates.
        """
        axes = "".join(a for a in "XYZ" if a in values)
        if key == "G53":
            rapid = self.spec.motion_codes[0]
            if codes != [key, rapid] or not axes or set(values) - set("XYZ"):
                raise self.fail(f"a rapid in machine coordinates is G53 {rapid} with axis words")
            at = tuple(values[a] for a in axes)
            home = Home(axes, key, at if any(v != 0.0 for v in at) else ())
            self.state.commands.append((len(self.state.moves), home))
            return
        incremental = codes == ["G91", key]
        if codes not in (["G91", key], [key]) or set(values) - set("XYZ"):
            raise self.fail(f"a return to the stored position is G91 {key} Z0 or {key} alone")
        if incremental != bool(axes) or any(values[a] != 0.0 for a in axes):
            raise self.fail(
                f"{key} goes through the point where the tool is: G91 {key} with axis words "
                f"at 0, or {key} alone"
            )
        self.state.commands.append((len(self.state.moves), Home(axes or "XYZ", key)))

    def _offset_after_change(self, tool: int) -> None:
        """The length offset (``G43 H<n>``) the writer puts right after a change to tool n."""
        commands = self.state.commands
        if commands and isinstance(last := commands[-1][1], ToolChange) and last.tool == tool:
            commands[-1] = (commands[-1][0], dataclasses.replace(last, length_offset=True))

    def _only(
        self, codes: list[str], values: dict[str, float], key: str, what: str, *, needs: str = ""
    ) -> None:
        """Check a non-motion block holds ``key``, the word ``needs`` and nothing else."""
        extra = [c for c in codes if c != key] + [k for k in values if k != needs]
        if extra:
            extras = ", ".join(extra)
            raise self.fail(f"{extras} in {what} block ({key}); one instruction per block")
        if needs and needs not in values:
            raise self.fail(f"{key} needs a {needs} word")

    # -- motion ------------------------------------------------------------------

    def _motion(self, codes: list[str], values: dict[str, float]) -> None:
        spec, s = self.spec, self.state
        moving = [c for c in codes if c in self.motions]
        if len(moving) != len(codes) or len(codes) > 1:
            raise self.fail(f"{' '.join(codes)}: one instruction per block")
        if codes:
            s.motion = self.motions[codes[0]]
        elif "G" not in spec.modal or s.motion is None:
            raise self.fail("a block without a motion code (" + " ".join(spec.motion_codes) + ")")
        assert s.motion is not None
        allowed = set("XYZF") | (set("IJ") if s.motion in ("cw", "ccw") else set())
        if spec.rs274 and s.spindle is not None:
            allowed.add("S")  # a new speed of the turning spindle (a laser's power)
        extra = sorted(set(values) - allowed)
        if extra:
            raise self.fail(f"{', '.join(extra)} not allowed in a {s.motion} motion block")
        if "S" in values and s.spindle is not None:
            s.commands.append((len(s.moves), Spindle(s.spindle, values["S"])))
        x, y, z = self._axes(values, s.motion)
        feed = self._feed(values, s.motion)
        if s.motion == "rapid":
            self._push(Rapid(x, y, z))
        elif s.motion == "linear":
            self._push(Linear(x, y, feed, z))
        else:
            centre = self._centre(values, (x, y))
            self._push(ArcMove(x, y, centre[0], centre[1], s.motion == "cw", feed, z))

    def _axes(self, values: dict[str, float], motion: str) -> tuple[float, float, float | None]:
        spec, s = self.spec, self.state
        has_xy = "X" in values or "Y" in values
        if "Z" in values and motion in ("cw", "ccw") and not spec.helix:
            raise self.fail(f"{spec.name} arcs take no Z word (no helix)")
        if spec.z_moves == "own-block" and "Z" in values and has_xy:
            raise self.fail(f"{spec.name} moves Z in blocks of its own (no X or Y with Z)")
        z_only = "Z" in values and not has_xy and motion in ("rapid", "linear")
        if not z_only:
            for letter in "XY":
                needed = letter not in spec.modal or motion in ("cw", "ccw")
                if letter not in values and needed:
                    raise self.fail(f"missing {letter} word ({spec.name} needs X and Y)")
        x, y = values.get("X", s.x), values.get("Y", s.y)
        return x, y, values.get("Z")

    def _feed(self, values: dict[str, float], motion: str) -> float:
        spec, s = self.spec, self.state
        if motion == "rapid":
            if "F" in values:
                raise self.fail("F in a rapid block; the writer puts F on cutting moves only")
            return 0.0
        if not spec.has("F"):
            return 0.0
        if "F" in values:
            if values["F"] <= 0:
                raise self.fail("F must be > 0")
            s.feed = values["F"]
        elif "F" not in spec.modal:
            raise self.fail(f"missing F word ({spec.name} writes F in every cutting block)")
        if s.feed is None:
            raise self.fail("a cutting move before any F word")
        return s.feed

    def _centre(self, values: dict[str, float], end: Point) -> Point:
        spec, s = self.spec, self.state
        for letter in "IJ":
            if letter not in values:
                raise self.fail(f"missing {letter} word (arcs need I and J)")
        if spec.arc_centre == "absolute":
            centre = (values["I"], values["J"])
        else:
            centre = (s.x + values["I"], s.y + values["J"])
        if centre == (s.x, s.y):
            raise self.fail("the arc's centre is its start point (radius 0)")
        if spec.arc_check != "none":
            from camtool.post.arccheck import arc_error

            reason = arc_error((s.x, s.y), end, centre, rule=spec.arc_check)
            if reason is not None:
                refused = f"{spec.arc_check} refuses this arc: {reason}"
                raise ControllerRefusal(f"{self.source}:{self.line}: {refused}")
        return centre

    def _push(self, move: Move) -> None:
        s = self.state
        move = dataclasses.replace(move, contour=s.contours.next(isinstance(move, Rapid)))
        s.moves.append(move)
        s.lines.append(self.line)
        s.x, s.y = move.x, move.y
        if move.z is not None:
            s.z = move.z
