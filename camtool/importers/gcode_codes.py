"""The G and M codes the G-code reader knows: modal group and what it does with each.

Three actions (docs/importers/gcode.md lists them for users):

Design notes: docs/internals.md, ``camtool/importers/gcode_codes.py``.
"""

from __future__ import annotations

from dataclasses import dataclass
from types import MappingProxyType
from typing import Literal

from camtool.importers.gcode_lexer import Block, Word
from camtool.model.errors import InputError

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
        ("G4", "nonmodal", "read", ""),
        ("G28 G30", "nonmodal", "read", ""),
        ("G40", "cutter", "warn", "G40 (cutter compensation off) read as a no-op"),
        ("G43", "length", "warn", "G43 tool length offset assumed 0: Z is read as written"),
        ("G49", "length", "warn", "G49 (tool length offset off) read as a no-op"),
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
        ("G98 G99", "retract", "warn", "{code} canned-cycle return mode ignored (no cycles)"),
        ("G97", "spindle_mode", "warn", "G97 spindle speed mode ignored"),
        ("G17.1 G18.1 G19.1", "plane", "error", _PLANE),
        (
            "G41 G42 G41.1 G42.1",
            "cutter",
            "error",
            "{code} (cutter radius compensation) is not supported: camtool compensates "
            "the tool itself; remove G41/G42 and post the drawing with --offset",
        ),
        ("G73 G76 G81 G82 G83 G84 G85 G86 G87 G88 G89", "motion", "error", _CANNED),
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
        (
            "G53",
            "nonmodal",
            "error",
            "G53 moves in machine coordinates, which camtool does not know; "
            "write the program in part coordinates",
        ),
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
        ("M7 M8 M9", "coolant", "warn", "coolant {code} ignored"),
    )
)
"""M codes by number, read-only."""

READ_CODES = (
    "G0 G1 G2 G3 G4 G17 G18 G19 G20 G21 G28 G30 G80 G90 G91 G90.1 G91.1 G94 "
    "M0 M1 M2 M3 M4 M5 M6 M30"
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


def lookup_code(word: Word, where: str) -> Code:
    """The known code of a G or M word; raises for unknown and refused codes."""
    code: Code | None
    if word.letter == "G":
        key = g_key(word.value)
        code = G_CODES.get(key) if key is not None else None
    else:
        whole = word.value == int(word.value) and word.value >= 0
        code = M_CODES.get(int(word.value)) if whole else None
    if code is None:
        raise InputError(
            f"{where}: unknown or unsupported code {word}; camtool reads {READ_CODES} "
            "and converts the harmless codes listed in docs/importers/gcode.md"
        )
    if code.action == "error":
        raise InputError(f"{where}: {code.note}")
    return code
