"""The G and M codes the G-code reader knows: modal group and what it does with each.

Three actions (docs/importers/gcode.md lists them for users):

Design notes: docs/internals.md, ``camtool/importers/gcode_codes.py``.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

from camtool.importers.gcode_lexer import Block, Word, operator_message
from camtool.model.errors import InputError
from camtool.model.program import (
    Command,
    Coolant,
    CoolantState,
    Dwell,
    Spindle,
    SpindleDirection,
    Stop,
    ToolChange,
)

Action = Literal["read", "warn", "error"]


@dataclass(frozen=True)
class Code:
    """One G or M code.

    Attributes:
        name: as users write it, e.g. ``"G90.1"`` or ``"M6"``.
        group: modal group (``"motion"``, ``"units"`` …; ``"nonmodal"`` for G4/G28).
        action: ``"read"``, ``"warn"`` or ``"error"``.
        note: for ``warn`` what camtool did, for ``error`` why and what to do.
    """

    name: str
    group: str
    action: Action
    note: str = ""


def g_key(value: float) -> int | None:
    """A G number in tenths (``G90.1`` → 901), or ``None`` if not of the form N or N.N."""
    tenths = round(value * 10)
    return tenths if abs(value * 10 - tenths) < 1e-6 and tenths >= 0 else None


def _g(*rows: tuple[str, str, Action, str]) -> dict[int, Code]:
    table: dict[int, Code] = {}
    for names, group, action, note in rows:
        for name in names.split():
            table[round(float(name[1:]) * 10)] = Code(
                name, group, action, note.replace("{code}", name)
            )
    return table


_CANNED = (
    "{code} is a canned cycle, which camtool does not expand; "
    "ask your CAM to write the cycle as plain G0/G1 moves"
)
_PLANE = (
    "{code} selects a plane in the UVW axes, which camtool does not have; camtool reads "
    "arcs in the XY, ZX and YZ planes (G17, G18, G19)"
)

G_CODES = MappingProxyType(
    _g(
        ("G0 G1 G2 G3 G80", "motion", "read", ""),
        ("G17 G18 G19", "plane", "read", ""),
        ("G90 G91", "distance", "read", ""),
        ("G90.1 G91.1", "arc_distance", "read", ""),
        ("G94", "feed_mode", "read", ""),
        ("G20 G21", "units", "read", ""),
        # DIN 66025's units codes, which Vectric's Mach2/3 posts write after G21 (G71) or
        # G20 (G70); LinuxCNC and Fanuc lathes read G70/G71 with P, Q... as lathe cycles
        ("G70", "units", "warn", "G70 read as G20 (inches), DIN 66025's units code"),
        ("G71", "units", "warn", "G71 read as G21 (millimetres), DIN 66025's units code"),
        ("G4", "nonmodal", "read", ""),
        ("G28 G30", "nonmodal", "read", ""),
        ("G40", "cutter", "warn", "G40 (cutter compensation off) read as a no-op"),
        ("G43", "length", "warn", "G43 tool length offset assumed 0: Z is read as written"),
        ("G49", "length", "warn", "G49 (tool length offset off) read as a no-op"),
        # the cancels of modes camtool refuses (G16, G68, G51.1 below): a no-op wherever read
        ("G15", "polar", "warn", "G15 (polar coordinates off) read as a no-op"),
        ("G69", "rotation", "warn", "G69 (coordinate rotation off) read as a no-op"),
        ("G50.1", "mirror", "warn", "G50.1 (mirror image off) read as a no-op"),
        (
            "G16",
            "polar",
            "error",
            "G16 (polar coordinates: X is a radius, Y an angle) is not supported; ask your "
            "CAM for cartesian X and Y",
        ),
        (
            "G68 G68.2",
            "rotation",
            "error",
            "{code} rotates the coordinate system, which camtool cannot follow; ask your CAM "
            "for the moves in part coordinates, without the rotation",
        ),
        (
            "G51.1",
            "mirror",
            "error",
            "G51.1 (mirror image) is not supported; ask your CAM for the mirrored moves",
        ),
        (
            "G54 G55 G56 G57 G58 G59 G59.1 G59.2 G59.3",
            "coord",
            "warn",
            "{code} work offset assumed 0: coordinates are taken from the part zero",
        ),
        (
            "G61 G61.1",
            "path",
            "warn",
            "{code} path control mode ignored (the verifier simulates the target's own)",
        ),
        (
            "G64",
            "path",
            "warn",
            "G64 path blending (with its P/Q tolerances, if any) ignored: the verifier "
            "simulates the target's own path control",
        ),
        ("G98 G99", "retract", "read", ""),
        ("G97", "spindle_mode", "warn", "G97 spindle speed mode ignored"),
        ("G17.1 G18.1 G19.1", "plane", "error", _PLANE),
        (
            "G41 G42 G41.1 G42.1",
            "cutter",
            "error",
            "{code} (cutter radius compensation) is not supported: camtool compensates "
            "the tool itself; remove G41/G42 and post the drawing with --offset",
        ),
        ("G73 G81 G82 G83", "motion", "read", ""),
        ("G76 G84 G85 G86 G87 G88 G89", "motion", "error", _CANNED),
        (
            "G93 G95",
            "feed_mode",
            "error",
            "{code} (inverse-time / per-revolution feed) is not supported; "
            "write feeds in units per minute (G94)",
        ),
        (
            "G92 G92.1 G92.2 G92.3 G52 G10",
            "nonmodal",
            "error",
            "{code} changes the coordinate offsets, which camtool cannot follow; "
            "write the program in part coordinates",
        ),
        (
            "G54.1",
            "coord",
            "error",
            "G54.1 (extended work offsets G54.1 P…) is not supported; use one of G54–G59, "
            "which camtool reads as the part zero",
        ),
        ("G53", "nonmodal", "read", ""),
        (
            "G5 G5.1 G5.2 G5.3",
            "motion",
            "error",
            "{code} splines are not supported; ask your CAM for lines and arcs",
        ),
    )
)
"""G codes by number in tenths (:func:`g_key`), read-only."""


def _m(*rows: tuple[str, str, Action, str]) -> dict[int, Code]:
    table: dict[int, Code] = {}
    for names, group, action, note in rows:
        for name in names.split():
            table[int(name[1:])] = Code(name, group, action, note.replace("{code}", name))
    return table


M_CODES = MappingProxyType(
    _m(
        ("M2 M30", "stop", "read", ""),
        ("M3 M4 M5", "spindle", "read", ""),
        ("M0 M1", "stop", "read", ""),
        ("M6", "tool", "read", ""),
        ("M7 M8 M9", "coolant", "read", ""),
    )
)
"""M codes by number, read-only."""

COOLANT_STATES: Mapping[str, CoolantState] = MappingProxyType(
    {"M7": "mist", "M8": "flood", "M9": "off"}
)
"""The coolant codes and the state each sets."""

READ_CODES = (
    "G0 G1 G2 G3 G4 G17 G18 G19 G20 G21 G28 G30 G53 G80 G90 G91 G90.1 G91.1 G94 "
    "M0 M1 M2 M3 M4 M5 M6 M7 M8 M9 M30"
)
"""What camtool reads, for messages about unknown codes."""

WORD_LETTERS = frozenset("GMNXYZIJKRFSTPHQ")
"""Word letters the reader knows (others are refused, see :data:`OTHER_LETTERS`)."""

OTHER_LETTERS = MappingProxyType(
    {
        **dict.fromkeys("ABCUVW", "is an axis camtool does not have (it reads X, Y and Z)"),
        "E": (
            "is a 3D-printer extrusion word, or an exponent (G-code numbers are plain "
            "decimals: write 1000, not 1e3); camtool reads CNC milling programs"
        ),
        "D": "is a cutter compensation register, used only with G41/G42",
        "L": "is a repeat/table word (G10, canned cycles) camtool does not read",
    }
)
"""Why letters outside :data:`WORD_LETTERS` are refused."""

PRINTER_M_CODES = frozenset((82, 83, 84, 104, 106, 107, 109, 140, 190))
"""M codes only 3D printers use (Marlin: extruder modes, motors off, fan, temperatures)."""

_AXES_NEED = "axis words need G0, G1, G2 or G3 (or modal motion) before them"
UNUSED_LETTERS = MappingProxyType(
    {
        **dict.fromkeys("XYZ", _AXES_NEED),
        "P": "P belongs to G4 (dwell), G2/G3 (turns) or G64 (tolerance)",
        "H": "H belongs to G43",
        "Q": "Q belongs to G64, G83 or G73",
        **dict.fromkeys("IJKR", "I, J, K and R belong to G2/G3 arcs"),
    }
)
"""Which codes use a word the block gives without one of them."""


def unused_word(word: Word, moded: bool) -> str:
    """Why ``word`` is refused in a block without a code that uses it.

    ``moded``: a motion code (G80 too) came before; without one an axis word has no
    motion to go with, which LinuxCNC refuses and GRBL runs in its power-on ``G0``.
    """
    hint = UNUSED_LETTERS[word.letter]
    if word.letter in "XYZ" and not moded:
        hint += (
            " (none is in effect here: LinuxCNC refuses the block, while GRBL moves in its "
            "power-on G0, as Fusion 360's GRBL programs expect after a tool change; write "
            f"G0 {word} if a rapid is meant)"
        )
    return f"{word} has no code to use it; {hint}"


class Notes:
    """Warnings, one per kind: the first line it happened on and how often."""

    def __init__(self, source: str) -> None:
        self.source = source
        self.kinds: dict[str, tuple[int, str, int]] = {}

    def add(self, kind: str, line: int, message: str) -> None:
        """Count one ``kind`` on ``line``; the first message of a kind is kept."""
        first, text, count = self.kinds.get(kind, (line, message, 0))
        self.kinds[kind] = (first, text, count + 1)

    def warnings(self) -> tuple[str, ...]:
        """``file:line: message (N times)``, in the order of their first line."""
        out = []
        for first, text, count in sorted(self.kinds.values()):
            times = f" ({count} times)" if count > 1 else ""
            out.append(f"{self.source}:{first}: {text}{times}")
        return tuple(out)


class BlockWords:
    """The words of one block sorted out: G and M codes by modal group, other words."""

    def __init__(self, block: Block, where: str) -> None:
        """Sort the words of ``block``; ``where`` (``file:line``) prefixes messages.

        Raises:
            InputError: an unknown or refused code, two codes of one modal
                group, a repeated word or an unknown letter.
        """
        self.g: dict[str, Code] = {}
        self.m: dict[str, Code] = {}
        self.args: dict[str, Word] = {}
        for word in block.words:
            if word.letter == "E":  # named before the block's codes: G92 E0 is a printer's
                raise InputError(f"{where}: {word} {OTHER_LETTERS['E']}")
        for word in block.words:
            if word.letter == "N":
                continue
            if word.letter in "GM":
                self._add_code(lookup_code(word, where), where)
            elif word.letter in WORD_LETTERS:
                if word.letter in self.args:
                    first = self.args[word.letter]
                    raise InputError(
                        f"{where}: two {word.letter} words ({first}, {word}); keep one"
                    )
                self.args[word.letter] = word
            else:
                why = OTHER_LETTERS.get(word.letter, "is not a word camtool reads")
                raise InputError(f"{where}: {word} {why}")

    def _add_code(self, code: Code, where: str) -> None:
        table = self.g if code.name[0] == "G" else self.m
        other = table.get(code.group)
        names = {code.name, other.name} if other is not None else set()
        if other is not None and code.group == "motion" and "G80" in names and len(names) == 2:
            # G0 G80 (a CAM's safety line): LinuxCNC makes the move, and so does camtool
            table["motion"] = other if code.name == "G80" else code
            return
        if other is not None:
            group = code.group.replace("_", " ")
            raise InputError(
                f"{where}: {other.name} and {code.name} are both {group} codes; "
                "one block takes one of them"
            )
        table[code.group] = code

    def g_name(self, group: str) -> str | None:
        """Name of the block's G code of modal ``group``, if any."""
        code = self.g.get(group)
        return code.name if code else None


def read_units(w: BlockWords, inch: bool | None, where: str) -> bool | None:
    """Whether the block's units code makes the program inches (``None``: none in the block).

    ``G70``/``G71`` (DIN 66025) are read as ``G20``/``G21``. ``inch`` is what the program
    stated before (``None``: nothing yet).

    Raises:
        InputError: ``G70``/``G71`` with a lathe cycle's words (``P``, ``Q``, ``R``, ``I``,
            ``K``), or against the units the program stated before.
    """
    units = w.g_name("units")
    if units in ("G70", "G71"):
        cycle = [str(w.args[letter]) for letter in "PQRIK" if letter in w.args]
        if cycle:
            raise InputError(
                f"{where}: {units} with {cycle[0]} is a lathe cycle (LinuxCNC, Fanuc), which "
                f"camtool does not read; alone, {units} is read as DIN 66025's units code"
            )
        if inch is not None and inch != (units == "G70"):
            stated = "inches (G20)" if inch else "millimetres (G21)"
            raise InputError(
                f"{where}: {units} after the program stated {stated}: {units} is inches or "
                "millimetres only on controls that read DIN 66025's units codes; give G20 or "
                "G21 for the units the program is written in"
            )
    return None if units is None else units in ("G20", "G70")


def lookup_code(word: Word, where: str) -> Code:
    """The known code of a G or M word; raises for unknown and refused codes."""
    code: Code | None
    if word.letter == "G":
        key = g_key(word.value)
        code = G_CODES.get(key) if key is not None else None
    else:
        whole = word.value == int(word.value) and word.value >= 0
        code = M_CODES.get(int(word.value)) if whole else None
    if code is None and word.letter == "M" and word.value in PRINTER_M_CODES:
        raise InputError(
            f"{where}: {word} is a 3D printer's code (Marlin: temperatures, fans, "
            "extruder modes, motors off); camtool reads CNC milling programs"
        )
    if code is None:
        raise InputError(
            f"{where}: unknown or unsupported code {word}; camtool reads {READ_CODES} "
            "and converts the harmless codes listed in docs/importers/gcode.md"
        )
    if code.action == "error":
        raise InputError(f"{where}: {code.note}")
    return code


class CommandReader:
    """Spindle, tool and dwell state of the interpreter, and the commands read so far."""

    def __init__(self, notes: Notes) -> None:
        """Collect commands; ``notes`` receives the warnings."""
        self.notes = notes
        self.commands: list[tuple[int, Command]] = []
        self.rpm: float | None = None
        self.direction: SpindleDirection = "off"
        self.tool: int | None = None
        self.last_change: tuple[int, ToolChange] | None = None  # (before move, the change)
        self.tool_line = 0
        self.tool_used = True
        self.message: tuple[int, str] | None = None  # (before move, text) of a (MSG, ...)

    def operator_message(self, index: int, raw: str) -> None:
        """Note line ``raw``'s ``(MSG, text)``, before move ``index``, if it has one.

        LinuxCNC shows the text to the operator. It goes with a stop (M0, M1) that comes
        before the next move (pcb2gcode's "Change tool bit to mill diameter 0.12000mm"
        before its ``M0``): the stop's message. Any other is a comment, dropped as every
        comment is.
        """
        said = operator_message(raw) if "(" in raw else None
        if said is not None and (text := " ".join(said.split())):
            self.message = (index, text)

    def add(self, index: int, command: Command) -> None:
        """Keep ``command`` to run before move ``index``."""
        self.commands.append((index, command))

    def block(self, w: BlockWords, index: int, line: int, where: str) -> None:
        """Read the S, T, M6, M3/M4/M5, M7/M8/M9 and G4 words of one block (before its motion).

        Args:
            w: the block's words.
            index: the number of moves read so far (the commands run before the
                next one).
            line: the block's 1-based line, for warnings.
            where: ``file:line`` for errors.

        Raises:
            InputError: a negative ``S``, a ``T`` that is not a whole number ≥ 0,
                or ``G4`` without ``P`` (or with ``P`` < 0).
        """
        spindle = w.m.get("spindle")
        if (s := w.args.get("S")) is not None:
            if s.value < 0:
                raise InputError(f"{where}: negative spindle speed {s}; S is rev/min ≥ 0")
            changed = s.value != self.rpm
            self.rpm = s.value
            if changed and spindle is None and self.direction != "off":
                self.add(index, Spindle(self.direction, s.value))
        if (t := w.args.get("T")) is not None:
            self._select(t.value, str(t), line, where)
        if (tool := w.m.get("tool")) is not None and tool.name == "M6":
            self._change(index, line)
        if spindle is not None:
            self._spindle(spindle.name, index)
        if (coolant := w.m.get("coolant")) is not None:  # after the spindle (RS-274 order)
            self.add(index, Coolant(COOLANT_STATES[coolant.name]))
        if w.g_name("nonmodal") == "G4":
            p = w.args.get("P")
            if p is None or p.value < 0:
                raise InputError(f"{where}: G4 dwell needs a P word (seconds, ≥ 0)")
            self.add(index, Dwell(p.value))

    def finish(self) -> None:
        """Warn about a selected tool that no M6 used (call after the last block)."""
        if not self.tool_used:
            self._unused_tool()

    def stop(self, index: int, optional: bool) -> None:
        """M0 (``optional``: M1) before move ``index``: a :class:`Stop`, never dropped.

        A tool selected (``T``) with no ``M6`` since is changed by hand at this stop (a
        drill program's ``T02`` then ``M00``): the stop's message names it, then the
        text of a ``(MSG, ...)`` since the last move (:meth:`operator_message`).
        """
        said = [self.message[1]] if self.message is not None and self.message[0] == index else []
        self.message = None
        if not self.tool_used and self.tool is not None:
            said.insert(0, f"change to T{self.tool}")
            self.tool_used = True
        self.add(index, Stop(optional, ": ".join(said)))

    def _select(self, value: float, text: str, line: int, where: str) -> None:
        if value < 0 or value != int(value):
            raise InputError(f"{where}: {text}: tool numbers are whole numbers ≥ 0")
        if not self.tool_used:
            self._unused_tool()
        self.tool, self.tool_line, self.tool_used = int(value), line, False

    def _unused_tool(self) -> None:
        self.notes.add(
            "T",
            self.tool_line,
            f"tool number T{self.tool} ignored: no M6 after it changes to that tool",
        )
        self.tool_used = True

    def _change(self, index: int, line: int) -> None:
        if self.tool is None:
            self.notes.add("M6", line, "M6 without a T word: no tool selected, ignored")
            return
        self.last_change = (index, ToolChange(self.tool))
        self.add(*self.last_change)
        self.tool_used = True

    def _spindle(self, name: str, index: int) -> None:
        if name == "M5":
            self.direction = "off"
            self.add(index, Spindle("off"))
            return
        self.direction = "cw" if name == "M3" else "ccw"
        self.add(index, Spindle(self.direction, self.rpm))
