"""The word-address dialect specification and its strict TOML loader.

Design notes: docs/internals.md, ``camtool/post/wordaddress_spec.py``.
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from camtool.model.errors import InputError
from camtool.post.numfmt import SIGN_POLICIES, NumberFormat

WORD_LETTERS = "XYZIJKFSPTH"
"""Value words a dialect may have: axes X Y Z (mm), arc centre I J K (mm; K only with
``planes``), feed F (mm/min), spindle speed S (rev/min), dwell P (s), tool number T, tool
length offset H."""

PLANE_CODES = MappingProxyType({"xy": "G17", "zx": "G18", "yz": "G19"})
"""The RS-274 plane codes a dialect with ``planes`` writes."""

MOTIONS = ("rapid", "linear", "cw", "ccw")
"""Keys of ``motion_codes``: G0, G1, G2 (clockwise) and G3 (counter-clockwise)."""

MODAL_LETTERS = "GXYZF"
"""Letters ``modal`` may name (``G`` = the motion code)."""

ARC_CENTRES = ("incremental", "absolute")
COOLANT_KEYS = ("coolant_mist", "coolant_flood", "coolant_off")
"""The spec keys of the coolant codes: mist (M7), flood (M8), off (M9)."""
HOMES = ("G28",)
"""The return to the stored position a dialect may write (RS-274's; GRBL and LinuxCNC)."""
FULL_CIRCLES = ("one-block", "split")
Z_MOVES = ("own-block", "with-xy", "none")
BY_HAND = ("programs", "stop")
"""How a dialect without a tool change code changes tools (``by_hand``)."""
ARC_CHECKS = ("none", "grbl", "linuxcnc")
LINE_ENDS = ("\n", "\r\n")
COMMENTS = ("()", ";")
"""Values of ``comment``: ``"()"`` writes ``(text)`` (RS-274), ``";"`` writes ``; text``."""
TAPE_MARK = "%"
"""The one non-comment line ``header``/``footer`` may hold (RS-274 tape start/end)."""

_CODE = re.compile(r"[GM]\d+(?:\.\d+)?")
_BLOCK_END = re.compile(r"[^\sA-Za-z0-9.+-]{0,4}")
_SUFFIX = re.compile(r"\.[A-Za-z0-9]{1,8}")


@dataclass(frozen=True)
class WordSpec:
    """How one value word is written.

    Attributes:
        letter: the address letter (one of :data:`WORD_LETTERS`).
        number: its number format: ``scale`` is units written per mm (X Y Z I
            J), per mm/min (F), per rev/min (S), per second (P) or per tool (T).
    """

    letter: str
    number: NumberFormat


@dataclass(frozen=True)
class WordAddressSpec:
    """A word-address dialect (see docs/dialects.md for every field and its default).

    Attributes:
        name: the dialect's name in messages (the target file's stem).
        words: the value words the dialect has, by letter. A letter that is
            absent is a word the dialect lacks: no F drops feeds, no S drops
            spindle speeds (each with one warning), no Z makes Z moves errors.
        separator: between words: ``""`` (``G01X1Y2``) or ``" "``.
        block_end: written after the last word of every block (``";"``).
        line_end: LF or CR LF (:data:`LINE_ENDS`).
        suffix: file name ending of the code, e.g. ``".nc"``.
        preamble: blocks written before the first move, each a tuple of codes.
        postamble: blocks written after the last move, before the end code.
        motion_codes: spellings of rapid, linear, clockwise and
            counter-clockwise motion, e.g. ``("G00", "G01", "G02", "G03")``.
        arc_centre: ``"incremental"`` (I/J from the arc start, RS-274) or
            ``"absolute"``.
        max_arc_deg: arcs sweeping more than this are split into equal pieces.
        full_circle: ``"one-block"`` or ``"split"`` (into
            ``max(2, ceil(360 / max_arc_deg))`` equal arcs).
        z_moves: ``"own-block"`` (Z alone in its block, Yanez-07 R7),
            ``"with-xy"`` or ``"none"`` (no Z word).
        helix: whether an arc may carry a Z word (``with-xy`` only).
        planes: whether the controller selects the arc plane, as RS-274 does (GRBL,
            LinuxCNC): G17 XY with I J, G18 ZX with I K, G19 YZ with J K. A program's
            arcs in the ZX and YZ planes (:class:`~camtool.model.program.PlaneArc`)
            are then written as arcs, else as chords. Needs I, J, K and Z words,
            ``helix`` and ``rs274`` (the RS-274 reader reads them back).
        max_block_bytes: longest block in bytes with its block end and line
            end; ``None``: no limit.
        comments: whether the controller skips comments, as RS-274/NGC
            controllers (GRBL, LinuxCNC) do: ``( ... )`` and ``;`` to the end of
            the line. The writer writes none; the reader removes them first.
        rs274: the controller runs any RS-274 program, not only camtool's own
            spelling of it (GRBL, LinuxCNC): code the strict reader refuses (another
            CAM's ``X0`` for ``X0.000``, modal codes, comments anywhere) is read
            by the RS-274 reader of :mod:`camtool.importers.gcode` instead, so
            ``camtool verify other.gcode -t grbl`` works.
        modal: letters written only when their value changes (``G`` for the
            motion code); the others are written in every block that uses them.
        arc_check: ``"none"``, ``"grbl"`` or ``"linuxcnc"``: arcs are written
            so that the rounded numbers pass that controller's check
            (:mod:`camtool.post.arccheck`).
        spindle_cw: code that starts the spindle clockwise (``None``: none).
        spindle_ccw: code that starts it counter-clockwise.
        spindle_off: code that stops it.
        coolant_mist: code that turns mist coolant on (``M7``; ``None``: none).
        coolant_flood: code that turns flood coolant on (``M8``; a laser's air assist).
        coolant_off: code that turns coolant off (``M9``). A program read from code keeps
            its coolant commands where the dialect has the code; the others are dropped,
            with a warning.
        dwell: dwell code, followed by the P word (seconds).
        tool_change: tool change code; the block is ``T<n> <code>`` (LinuxCNC ``T2 M6``).
        tool_length_offset: code that applies the new tool's length offset after a
            change, followed by the H word (LinuxCNC ``G43 H2``); ``None``: none.
        work_offsets: the work offset codes the controller has (``G54`` … ``G59.3``): a
            program read from code that selects one keeps it (written before its first
            move); ``()``: a program runs in the work offset the user has active.
        path_controls: the path control codes the controller has (``G61``, ``G61.1``,
            ``G64`` with its P and Q tolerances in mm): a program read from code keeps
            its own where it had them (``rs274`` reads them back); ``()``: they are
            ignored, with a warning.
        home: ``"G28"``: a program read from code keeps its returns to the machine's
            stored positions and machine zero (:class:`~camtool.model.program.Home`;
            G28's, G30's and G53's, :attr:`homes`), written as RS-274 writes them:
            ``G91 G28 Z0`` then ``G90`` for the axes one names (the intermediate point
            where the tool is), ``G28`` alone for all three, ``G53 G0 Z0`` for machine
            zero; ``None``: they are dropped, with a warning, and
            refused where a move after one would run at the height it left
            (:func:`camtool.post.base.check_dropped_homes`).
        stop: program stop code (``M0``): the machine waits for the operator.
        by_hand: how a dialect without ``tool_change`` changes tools: ``"programs"``,
            one program per tool (the operator sets Z zero for each tool between
            them, GRBL 1.1: no Z zero can be set while its ``M0`` pauses), or
            ``"stop"`` (with a stop and comments), one program whose change is a
            comment naming the tool, then the stop (for tools preset in length).
        optional_stop: optional stop code (``M1``); ``None``: an optional stop is
            written as a stop.
        end: program-end codes; the writer ends with the first, the reader
            accepts any of them.
        operator_messages: a stop's message is written ``(MSG, text)``, which an RS-274/NGC
            controller shows the operator as it reaches the line (LinuxCNC's G-code
            reference, "Messages"); otherwise as a plain comment. Needs ``comment = "()"``.
        comment: how the dialect writes a comment line (:data:`COMMENTS`):
            ``"()"`` or ``";"``; ``None``: it has no comments, and the job notes
            (:attr:`Program.notes <camtool.model.program.Program.notes>`) are not written.
        header: lines written verbatim first, before the job notes and the
            preamble; each is ``"%"`` or a comment in the ``comment`` syntax.
        footer: lines written verbatim after the end code, the same kinds.
    """

    name: str
    words: Mapping[str, WordSpec]
    separator: str = " "
    block_end: str = ""
    line_end: str = "\n"
    suffix: str = ".nc"
    preamble: tuple[tuple[str, ...], ...] = ()
    postamble: tuple[tuple[str, ...], ...] = ()
    motion_codes: tuple[str, str, str, str] = ("G0", "G1", "G2", "G3")
    arc_centre: str = "incremental"
    max_arc_deg: float = 360.0
    full_circle: str = "one-block"
    z_moves: str = "with-xy"
    helix: bool = False
    planes: bool = False
    max_block_bytes: int | None = None
    comments: bool = False
    rs274: bool = False
    modal: frozenset[str] = frozenset("F")
    arc_check: str = "none"
    spindle_cw: str | None = None
    spindle_ccw: str | None = None
    spindle_off: str | None = None
    coolant_mist: str | None = None
    coolant_flood: str | None = None
    coolant_off: str | None = None
    dwell: str | None = None
    tool_change: str | None = None
    tool_length_offset: str | None = None
    work_offsets: tuple[str, ...] = ()
    path_controls: tuple[str, ...] = ()
    home: str | None = None
    stop: str | None = None
    by_hand: str = "programs"
    optional_stop: str | None = None
    end: tuple[str, ...] = ()
    comment: str | None = None
    operator_messages: bool = False
    header: tuple[str, ...] = ()
    footer: tuple[str, ...] = ()

    def word(self, letter: str) -> WordSpec | None:
        """The word ``letter``, or ``None`` when the dialect lacks it."""
        return self.words.get(letter)

    def has(self, letter: str) -> bool:
        """True when the dialect has the value word ``letter``."""
        return letter in self.words

    @property
    def homes(self) -> tuple[str, ...]:
        """The returns written: ``G28``, ``G30`` and ``G53`` (to machine zero) with :attr:`home`.

        RS-274's two stored positions and its machine coordinates (LinuxCNC "G28, G28.1",
        "G30, G30.1", "G53"; GRBL 1.1 gcode.c the same); ``()`` without ``home``.
        """
        return ("G28", "G30", "G53") if self.home else ()

    def quantum_mm(self) -> float:
        """The coarsest written step of X, Y, I and J, mm: the grid arcs must land on."""
        return max(self.words[c].number.resolution_mm() for c in "XYIJ" if c in self.words)

    def comment_line(self, text: str, prefix: str = "") -> str | None:
        """``text`` as one comment line of this dialect, ``None`` without comments.

        ``prefix`` (such as ``"MSG, "``) is written before the text, inside the comment.

        Characters a comment cannot hold are replaced: anything outside printable
        ASCII by ``?``, and ``(``/``)`` by ``[``/``]`` (RS-274 comments do not
        nest). The line is cut (ending ``...``) to fit ``max_block_bytes`` with its
        line end.
        """
        if self.comment is None:
            return None
        clean = comment_text(text)
        wrap = ("(" + prefix, ")") if self.comment == "()" else ("; " + prefix, "")
        room = None
        if self.max_block_bytes is not None:
            room = self.max_block_bytes - len(self.line_end) - sum(map(len, wrap))
        if room is not None and len(clean) > room:
            clean = clean[: max(0, room - 3)] + "..."
        return wrap[0] + clean + wrap[1]

    def is_comment(self, line: str) -> bool:
        """True when ``line`` is a whole-line comment of this dialect (or ``%``)."""
        if line == TAPE_MARK and (TAPE_MARK in self.header or TAPE_MARK in self.footer):
            return True
        if self.comment is None:
            return False
        return _comment_pattern(self.comment).fullmatch(line) is not None

    def static_codes(self) -> frozenset[str]:
        """Codes of the preamble and postamble, and the work offsets (no effect on the path)."""
        framed = (code for block in self.preamble + self.postamble for code in block)
        return frozenset((*framed, *self.work_offsets))


PATH_CONTROLS = ("G61", "G61.1", "G64")
"""The RS-274/NGC path control codes (exact path, exact stop, blending)."""


def comment_text(text: str) -> str:
    """``text`` as a comment holds it: outside printable ASCII ``?``, ``(``/``)`` ``[``/``]``.

    RS-274 comments do not nest; surrounding spaces dropped
    (:meth:`WordAddressSpec.comment_line`, which also cuts a long line short).
    """
    clean = "".join(c if " " <= c <= "~" else "?" for c in text)
    return clean.replace("(", "[").replace(")", "]").strip()


def _comment_pattern(style: str) -> re.Pattern[str]:
    """A whole-line comment in ``style`` (one of :data:`COMMENTS`), printable ASCII."""
    return re.compile(r"\([ -'*-~]*\)" if style == "()" else r";[ -~]*")


def _show(value: Any) -> str:
    """A value as a TOML user would recognise it in a message."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_show(v) for v in value) + "]"
    if isinstance(value, Mapping):
        return "a table"
    return repr(value)


class _Table:
    """Strict reader of one TOML table: typed getters, unknown keys an error."""

    def __init__(self, data: Any, path: str, where: str) -> None:
        self.path, self.where = path, where
        if not isinstance(data, Mapping):
            raise self.error("", f"expected a table, got {_show(data)}")
        self.data: Mapping[str, Any] = data
        self.seen: set[str] = set()

    def error(self, key: str, text: str) -> InputError:
        path = f"{self.path}.{key}" if key else self.path
        return InputError(f"{self.where}: {path}: {text}")

    def get(self, key: str) -> Any:
        self.seen.add(key)
        return self.data.get(key)

    def string(self, key: str, default: str | None, *, choices: tuple[str, ...] = ()) -> Any:
        value = self.get(key)
        if value is None:
            return default
        if not isinstance(value, str):
            raise self.error(key, f"expected a string, got {_show(value)}")
        if choices and value not in choices:
            raise self.error(key, f"expected one of {_show(list(choices))}, got {_show(value)}")
        self._ascii(key, value)
        return value

    def _ascii(self, key: str, value: str) -> None:
        """Machine code is ASCII: a controller reads bytes, not an encoding."""
        if not value.isascii() or any(c < " " and c not in "\t\r\n" for c in value):
            raise self.error(
                key, f"expected printable ASCII (what a controller reads), got {_show(value)}"
            )

    def integer(self, key: str, default: int | None, *, low: int = 0, high: int = 15) -> int | None:
        value = self.get(key)
        if value is None:
            return default
        if isinstance(value, bool) or not isinstance(value, int):
            raise self.error(key, f"expected an integer, got {_show(value)}")
        if not low <= value <= high:
            raise self.error(key, f"expected an integer from {low} to {high}, got {value}")
        return value

    def number(
        self, key: str, default: float | None, *, low: float = 1e-6, high: float = 1e6
    ) -> float | None:
        """A positive number from ``low`` to ``high`` (a grid in mm, a scale)."""
        value = self.get(key)
        if value is None:
            return default
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.error(key, f"expected a number, got {_show(value)}")
        if not math.isfinite(value) or not low <= value <= high:
            raise self.error(key, f"expected a number from {low:g} to {high:g}, got {_show(value)}")
        return float(value)

    def flag(self, key: str, default: bool) -> bool:
        value = self.get(key)
        if value is None:
            return default
        if not isinstance(value, bool):
            raise self.error(key, f"expected true or false, got {_show(value)}")
        return value

    def strings(self, key: str) -> list[str]:
        value = self.get(key)
        if value is None:
            return []
        if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
            raise self.error(key, f"expected a list of strings, got {_show(value)}")
        for v in value:
            self._ascii(key, v)
        return list(value)

    def table(self, key: str) -> _Table:
        value = self.get(key)
        return _Table({} if value is None else value, f"{self.path}.{key}", self.where)

    def done(self) -> None:
        unknown = sorted(set(self.data) - self.seen)
        if unknown:
            known = ", ".join(sorted(self.seen))
            raise self.error(
                "", f"unknown key(s) {', '.join(_show(k) for k in unknown)}; known: {known}"
            )


def load_spec(options: Mapping[str, Any], where: str) -> WordAddressSpec:
    """Build a :class:`WordAddressSpec` from a target's ``[dialect_options]`` table.

    Args:
        options: the table as TOML gives it.
        where: the target file's name, for messages (its stem names the dialect).

    Raises:
        InputError: an unknown key, a value of the wrong type, or options that
            contradict each other, naming ``where`` and the key path.
    """
    t = _Table(options, "dialect_options", where)
    words = _words(t.table("words"))
    codes = _codes(t)
    z_default = "with-xy" if "Z" in words else "none"
    spec = WordAddressSpec(
        name=Path(where).stem or "word-address",
        words=MappingProxyType(words),
        separator=t.string("separator", " ", choices=("", " ")),
        block_end=_pattern(t, "block_end", "", _BLOCK_END, "up to 4 punctuation characters"),
        line_end=t.string("line_end", "\n", choices=LINE_ENDS),
        suffix=_pattern(t, "suffix", ".nc", _SUFFIX, 'a file ending such as ".nc"'),
        preamble=_blocks(t, "preamble"),
        postamble=_blocks(t, "postamble"),
        arc_centre=t.string("arc_centre", "incremental", choices=ARC_CENTRES),
        max_arc_deg=_max_arc(t),
        full_circle=t.string("full_circle", "one-block", choices=FULL_CIRCLES),
        z_moves=t.string("z_moves", z_default, choices=Z_MOVES),
        helix=t.flag("helix", False),
        planes=t.flag("planes", False),
        max_block_bytes=t.integer("max_block_bytes", None, low=8, high=1 << 20),
        comments=t.flag("comments", False),
        rs274=t.flag("rs274", False),
        modal=_modal(t, words),
        arc_check=t.string("arc_check", "none", choices=ARC_CHECKS),
        comment=t.string("comment", None, choices=COMMENTS),
        operator_messages=t.flag("operator_messages", False),
        header=tuple(t.strings("header")),
        footer=tuple(t.strings("footer")),
        home=t.string("home", None, choices=HOMES),
        by_hand=t.string("by_hand", "programs", choices=BY_HAND),
        **codes,
    )
    t.done()
    _check(spec, t)
    return spec


def _pattern(t: _Table, key: str, default: str, pattern: re.Pattern[str], want: str) -> str:
    value: str = t.string(key, default)
    if not pattern.fullmatch(value):
        raise t.error(key, f"expected {want}, got {_show(value)}")
    return value


def _max_arc(t: _Table) -> float:
    value = t.number("max_arc_deg", 360.0, low=1.0, high=360.0)
    assert value is not None
    if not 1.0 <= value <= 360.0:
        raise t.error("max_arc_deg", f"expected a number from 1 to 360, got {_show(value)}")
    return value


def _code(t: _Table, key: str, value: Any) -> str:
    if not isinstance(value, str) or not _CODE.fullmatch(value):
        raise t.error(key, f'expected a code such as "G01" or "M30", got {_show(value)}')
    return value


def _same_code(code: str, other: str) -> bool:
    """``G04`` is ``G4``: one letter, one number."""
    return code[0] == other[0] and float(code[1:]) == float(other[1:])


def _codes(t: _Table) -> dict[str, Any]:
    """The code keys: motion codes, spindle, dwell, tool change and end."""
    motion = t.table("motion_codes")
    defaults = dict(zip(MOTIONS, ("G0", "G1", "G2", "G3"), strict=True))
    given = {m: motion.get(m) for m in MOTIONS}
    spelled = tuple(_code(motion, m, defaults[m] if v is None else v) for m, v in given.items())
    motion.done()
    for m, code, number in zip(MOTIONS, spelled, range(4), strict=True):
        # a spelling only: rapid = "G1" cut every rapid at feed and every cut at rapid
        if not _same_code(code, f"G{number}"):
            raise motion.error(
                m, f"the {m} code is G{number} (spelled G{number} or G0{number}), got {_show(code)}"
            )
    out: dict[str, Any] = {"motion_codes": spelled}
    keys = ("spindle_cw", "spindle_ccw", "spindle_off", "dwell", "tool_change", *COOLANT_KEYS)
    for key in (*keys, "tool_length_offset", "stop", "optional_stop"):
        value = t.get(key)
        out[key] = None if value is None else _code(t, key, value)
        fixed = _FIXED_G.get(key)
        code = out[key]
        if code is not None and fixed is not None and not _same_code(code, fixed):
            raise t.error(key, f"the {key} code is {fixed}, got {_show(code)}")
        if code is not None and fixed is None and not code.startswith("M"):
            raise t.error(key, f"{key} is an M code (a G code moves or sets a mode), got {code}")
    out["end"] = tuple(_code(t, "end", v) for v in t.strings("end"))
    for code in out["end"]:
        if not code.startswith("M"):
            raise t.error("end", f"an end code is an M code (M2, M30), got {_show(code)}")
    out["work_offsets"] = tuple(_code(t, "work_offsets", v) for v in t.strings("work_offsets"))
    for code in out["work_offsets"]:
        if not re.fullmatch(r"G5[4-9](\.[1-3])?", code):
            raise t.error("work_offsets", f"a work offset is G54 to G59.3, got {_show(code)}")
    out["path_controls"] = tuple(_code(t, "path_controls", v) for v in t.strings("path_controls"))
    for code in out["path_controls"]:
        if code not in PATH_CONTROLS:
            raise t.error("path_controls", f"a path control code is G61, G61.1 or G64, got {code}")
    return out


def _blocks(t: _Table, key: str) -> tuple[tuple[str, ...], ...]:
    blocks = []
    for i, text in enumerate(t.strings(key)):
        codes = tuple(text.split())
        if not codes or not all(_CODE.fullmatch(c) for c in codes):
            raise t.error(
                f"{key}[{i}]",
                f'expected codes separated by spaces (such as "G21 G90 G17"), got {_show(text)}',
            )
        blocks.append(codes)
    return tuple(blocks)


def _modal(t: _Table, words: Mapping[str, WordSpec]) -> frozenset[str]:
    value = t.get("modal")
    letters = ["F"] if value is None else t.strings("modal")
    for letter in letters:
        if letter not in MODAL_LETTERS:
            raise t.error(
                "modal", f"expected letters among {_show(list(MODAL_LETTERS))}, got {_show(letter)}"
            )
        if letter != "G" and letter not in words and value is not None:
            raise t.error("modal", f"{_show(letter)} is not a word of this dialect (see words)")
    return frozenset(letters) & (frozenset("G") | frozenset(words))


POSITION_LETTERS = "XYZIJK"
"""The words that write a position or an arc centre (mm on the machine)."""
MAX_POSITION_STEP_MM = 10.0
"""The coarsest step a position word may write, mm: whole centimetres (a machine's step is
far finer; a coarser word puts the whole part on a grid wider than its details)."""


def _words(t: _Table) -> dict[str, WordSpec]:
    """The ``words`` table; a key of several letters (``XYIJ``) sets each of them."""
    words: dict[str, WordSpec] = {}
    for key in list(t.data):
        sub = t.table(key)
        if not key or any(c not in WORD_LETTERS for c in key):
            raise t.error(key, f"unknown word; words are among {_show(list(WORD_LETTERS))}")
        number = _number_format(sub)
        step = number.resolution_mm()
        if step > MAX_POSITION_STEP_MM and any(c in POSITION_LETTERS for c in key):
            raise t.error(
                key,
                f"scale {number.scale:g} with decimals = {number.decimals}"
                + ("" if number.grid_mm is None else f" on grid_mm {number.grid_mm:g}")
                + f" writes a position in steps of {step:g} mm, coarser than "
                f"{MAX_POSITION_STEP_MM:g} mm: every move would land on that grid; give the "
                "scale of the unit written (units per mm: 1 for mm, 0.03937 for inches), more "
                "decimals or the machine's step as grid_mm",
            )
        for letter in key:
            if letter in words:
                raise t.error(key, f"word {letter} is defined twice")
            words[letter] = WordSpec(letter, number)
    t.done()
    for letter in "XY":
        if letter not in words:
            raise t.error("", f"the X and Y words are required, {letter} is missing")
    if "T" in words and words["T"].number.decimals != 0:
        raise t.error("T.decimals", "a tool number is an integer: use decimals = 0")
    return words


def _number_format(t: _Table) -> NumberFormat:
    decimals = t.integer("decimals", 3, high=9)
    min_decimals = t.integer("min_decimals", None, high=9)
    assert decimals is not None
    if min_decimals is not None and min_decimals > decimals:
        raise t.error("min_decimals", f"expected at most decimals ({decimals}), got {min_decimals}")
    number = NumberFormat(
        scale=t.number("scale", 1.0) or 1.0,
        decimals=decimals,
        int_digits=t.integer("int_digits", None, low=1),
        sign=t.string("sign", "negative", choices=SIGN_POLICIES),
        min_decimals=min_decimals,
        pad=t.flag("zero_pad", False),
        grid_mm=t.number("grid_mm", None),
    )
    t.done()
    if number.grid_mm is not None:
        step = 10.0 ** (-decimals) / number.scale
        if abs(number.grid_mm / step - round(number.grid_mm / step)) > 1e-6:
            raise t.error(
                "grid_mm",
                f"{number.grid_mm:g} mm is not a multiple of the {step:g} mm the word can write",
            )
    return number


def _check_arc_grid(spec: WordAddressSpec, t: _Table) -> None:
    """X and Y write one step, and I and J that step or a whole fraction of it.

    Conformed arcs (:mod:`camtool.post.arcconform`) put an arc's ends and centre on
    one grid, the coarsest step of X, Y, I and J: ends written more finely than it are
    off it, and a centre on it must be printable by I and J.
    """
    steps = {c: spec.words[c].number.resolution_mm() for c in "XYIJ" if c in spec.words}
    grid = max(steps.values())
    ends = [steps[c] for c in "XY" if c in steps]
    ratios = [grid / steps[c] for c in "IJ"]
    if all(math.isclose(s, grid, rel_tol=1e-9) for s in ends) and all(
        abs(r - round(r)) < 1e-6 for r in ratios
    ):
        return
    written = ", ".join(f"{c} {step:g} mm" for c, step in steps.items())
    raise t.error(
        "words",
        f'an arc\'s ends and centre are placed on one grid (arc_check = "{spec.arc_check}"), '
        f"but the words write {written}: give X and Y one step (decimals, scale, grid_mm), "
        "and I and J that step or a finer one that divides it",
    )


def _check(spec: WordAddressSpec, t: _Table) -> None:
    """Cross-key rules (each error names the key to change)."""
    if spec.arc_check != "none" or "I" in spec.words or "J" in spec.words:
        for letter in "IJ":
            if letter not in spec.words:
                raise t.error("words", f"arcs need both I and J words; {letter} is missing")
        if spec.arc_check != "none":
            _check_arc_grid(spec, t)
    if spec.has("Z") != (spec.z_moves != "none"):
        want = '"own-block" or "with-xy"' if spec.has("Z") else '"none" (there is no Z word)'
        raise t.error("z_moves", f"expected {want}, got {_show(spec.z_moves)}")
    if spec.operator_messages and spec.comment != "()":
        raise t.error("operator_messages", '(MSG, ...) messages need comment = "()"')
    if spec.helix and spec.z_moves != "with-xy":
        raise t.error("helix", 'a helix needs z_moves = "with-xy"')
    if spec.planes and not all(spec.has(c) for c in "ZIJK"):
        missing = ", ".join(c for c in "ZIJK" if not spec.has(c))
        raise t.error(
            "planes", f"arcs in the ZX and YZ planes need Z, I, J and K words; {missing} missing"
        )
    if spec.path_controls and not spec.rs274:
        raise t.error("path_controls", "path control modes need rs274 = true (read back by it)")
    if spec.planes and not (spec.helix and spec.rs274):
        raise t.error("planes", "arcs in other planes need helix = true and rs274 = true")
    if spec.has("K") and not spec.planes:
        raise t.error(
            "words", "a K word is written only in the ZX and YZ planes: set planes = true"
        )
    if spec.dwell and not spec.has("P"):
        raise t.error("dwell", "a dwell code needs a P word (seconds) in words")
    if spec.home and not (spec.rs274 and all(spec.has(c) for c in "XYZ")):
        raise t.error(
            "home", "G28 and G30 (written G91 G28 Z0, as RS-274) need rs274 = true and X, Y, Z"
        )
    if spec.by_hand == "stop" and not (spec.stop and spec.comment):
        raise t.error("by_hand", "changing tools with a stop needs a stop code and a comment")
    if spec.tool_change and not spec.has("T"):
        raise t.error("tool_change", "a tool change code needs a T word in words")
    if spec.tool_length_offset and not (spec.tool_change and spec.has("H")):
        raise t.error(
            "tool_length_offset", "a tool length offset needs tool_change and an H word in words"
        )
    if (spec.coolant_mist or spec.coolant_flood) and not spec.coolant_off:
        raise t.error("coolant_off", "coolant that can be turned on needs a code that turns it off")
    if spec.optional_stop and not spec.stop:
        raise t.error("optional_stop", "an optional stop needs a stop code (stop)")
    roles = [*spec.motion_codes, *spec.end]
    roles += [c for c in (spec.spindle_cw, spec.spindle_ccw, spec.spindle_off) if c]
    roles += [c for c in (spec.dwell, spec.tool_change, spec.tool_length_offset) if c]
    roles += [c for c in (spec.stop, spec.optional_stop) if c] + list(spec.homes)
    roles += [c for c in (spec.coolant_mist, spec.coolant_flood, spec.coolant_off) if c]
    if len(set(roles)) != len(roles):
        twice = sorted({c for c in roles if roles.count(c) > 1})
        raise t.error("", f"code(s) {', '.join(twice)} given two meanings")
    for key, blocks in (("preamble", spec.preamble), ("postamble", spec.postamble)):
        for code in (c for block in blocks for c in block):
            _check_static(t, key, code, spec, set(roles))
    for key, lines in (("header", spec.header), ("footer", spec.footer)):
        for i, line in enumerate(lines):
            _check_frame_line(t, f"{key}[{i}]", line, spec)


def _check_frame_line(t: _Table, key: str, line: str, spec: WordAddressSpec) -> None:
    """A header or footer line is ``%`` or a comment the reader skips: it cannot move."""
    if line == TAPE_MARK:
        return
    if spec.comment is None:
        raise t.error(
            key, f'expected "%" (the dialect has no comment syntax: see comment), got {_show(line)}'
        )
    if not spec.is_comment(line):
        example = "(text)" if spec.comment == "()" else "; text"
        raise t.error(key, f'expected "%" or a comment such as {_show(example)}, got {_show(line)}')
    size = len((line + spec.line_end).encode("ascii"))
    if spec.max_block_bytes is not None and size > spec.max_block_bytes:
        raise t.error(key, f"{size} bytes with its line end, over max_block_bytes")


def _check_static(t: _Table, key: str, code: str, spec: WordAddressSpec, roles: set[str]) -> None:
    """A preamble or postamble code must not move the tool or contradict the spec."""
    value = float(code[1:])
    if code in roles:
        raise t.error(key, f"{code} has its own key; the {key} holds setup codes only")
    if code[0] == "G" and value in (0, 1, 2, 3):
        raise t.error(key, f"{code} is a motion code; the {key} holds setup codes only")
    if code[0] == "G" and value == 91:
        raise t.error(key, "G91 (incremental coordinates): camtool writes absolute coordinates")
    if code[0] == "G" and value not in _SETUP_G:
        raise t.error(
            key,
            f"{code} is not a setup code camtool can write before its own moves (it would "
            "change how they are read: a plane, feed mode, compensation, cycle or offset); "
            f"the {key} may hold {_SETUP_G_TEXT} and M codes",
        )
    if code[0] == "M" and value in _FLOW_M:
        raise t.error(
            key, f"{code} changes tools or the program's flow; the {key} holds setup codes only"
        )
    if code[0] == "G" and value == 90.1 and spec.arc_centre != "absolute":
        raise t.error(key, 'G90.1 (absolute arc centre) needs arc_centre = "absolute"')
    if code[0] == "G" and value == 91.1 and spec.arc_centre != "incremental":
        raise t.error(key, 'G91.1 (incremental arc centre) needs arc_centre = "incremental"')
    if code[0] == "G" and value in _UNIT_CODES:
        unit, per_mm = _UNIT_CODES[value]
        for letter in POSITION_LETTERS:
            word = spec.words.get(letter)
            if word is not None and not math.isclose(word.number.scale, per_mm, rel_tol=1e-9):
                raise t.error(
                    key,
                    f"{code} sets {unit}, but words.{letter} has scale = "
                    f"{word.number.scale:g} (units written per mm): the controller would read "
                    f"every {letter} in {unit}, {word.number.scale / per_mm:.4g} times the "
                    f"distance meant; give that word scale = {per_mm!r}, or the code of its unit",
                )


_FIXED_G = {"dwell": "G4", "tool_length_offset": "G43"}
"""The code keys that are G codes, each of one number in every G-code dialect (RS-274,
LinuxCNC, Fanuc); the other code keys are M codes, whose numbers vary by controller."""

_SETUP_G = frozenset(
    {17.0, 20.0, 21.0, 40.0, 43.0, 49.0, 54.0, 55.0, 56.0, 57.0, 58.0, 59.0, 59.1, 59.2, 59.3}
    | {61.0, 61.1, 64.0, 80.0, 90.0, 90.1, 91.0, 91.1, 94.0, 97.0, 98.0, 99.0}
    | {8.0, 13.1, 15.0, 50.0, 50.1, 67.0, 69.0}
)
"""G codes a preamble or postamble may hold (G91 and the arc-centre modes are checked
apart): the XY plane, units, feed per minute, absolute distance, work offsets (G54-G59.3),
path control, tool length offset on (G43) and the cancels (compensation G40, length offset
G49, cycles G80, polar G15, scaling G50, mirror G50.1, macros G67, rotation G69, polar
interpolation G13.1, diameter mode G8, constant surface speed G97) and cycle return
(G98, G99), as LinuxCNC's and Fanuc's G-code lists name them. Refused: another plane
(G18/G19: camtool's arcs are in XY), inverse-time or per-revolution feed (G93/G95), cutter
compensation (G41/G42), G92 offsets, diameter mode (G7), polar coordinates (G16), motion
and cycles."""

_SETUP_G_TEXT = ", ".join(f"G{code:g}" for code in sorted(_SETUP_G - {91.0}))
"""The codes of :data:`_SETUP_G` a message names (G91 is refused apart)."""

_FLOW_M = frozenset((6.0, 61.0, 98.0, 99.0))
"""M codes refused in a preamble or postamble: tool change (M6, M61) and subprogram call
and return (M98, M99: a return in the main program runs it again from its start)."""

_UNIT_CODES = {20.0: ("inches", 1.0 / 25.4), 21.0: ("mm", 1.0)}
"""RS-274's unit codes (G20, G21): the unit and the word scale (units written per mm)."""
