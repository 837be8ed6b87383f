r"""GRBL 1.1's serial link: messages decoded, status reports read, resume, and a simulator.

Design notes: docs/internals.md, ``postprocessors/grbl/link.py``.
"""

from __future__ import annotations

import math
import re
from array import array
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import replace
from typing import TYPE_CHECKING, Any

from camtool.link.device import ANSWER_END, LineDevice
from camtool.link.spec import LineBlocks, LinkHooks, LinkSpec, Status, WireBlock
from camtool.model.errors import CamtoolError, InputError, ParseError, UsageError
from camtool.model.program import ArcMove
from camtool.model.shapes import Arc
from camtool_postprocessors.grbl.codes import ALARMS, ERRORS, firmware

if TYPE_CHECKING:
    from camtool.model.program import Program
    from camtool.post.base import Target


BANNER = "Grbl 1.1h ['$' for help]"
"""What GRBL 1.1h prints when it starts or is reset (report.c ``report_init_message``)."""
RX_BUFFER_BYTES = 127
"""Bytes GRBL's RX ring buffer holds: RX_BUFFER_SIZE 128 less one (serial.h; stream.py)."""

_CODE = re.compile(r"(error|ALARM):(\d+)")
_STATE = re.compile(r"<([A-Za-z]+(?::\d)?)[|>]")


def decode(message: str) -> str:
    """``"error:22"`` → ``"error:22 (Undefined feed rate: Feed rate has not yet been set…)"``.

    Other messages come back as they are; an unknown code says so.
    """
    match = _CODE.fullmatch(message.strip())
    if match is None:
        return message
    table = ERRORS if match.group(1) == "error" else ALARMS
    code = int(match.group(2))
    if code not in table:
        return f"{message} (code {code} is not in GRBL 1.1's table)"
    short, long = table[code]
    return f"{message} ({short}: {long})"


def status_state(line: str) -> str | None:
    """A status report's state (``"Idle"``, ``"Run"``, ``"Hold:0"``, ``"Alarm"``), or ``None``."""
    match = _STATE.match(line)
    return match.group(1) if match else None


_BF = re.compile(r"\|Bf:(\d+),(\d+)")


def status(line: str) -> Status | None:
    """A status report read: its state and, when reported, the ``Bf:`` free counts.

    ``Bf:15,128`` is 15 free planner blocks and 128 free bytes of the RX ring
    buffer (report.c: ``plan_get_block_buffer_available``,
    ``serial_get_rx_buffer_available``, which says 128 for an empty buffer);
    GRBL 1.1 sends it when bit 1 (value 2) of ``$10`` is set (interface.md,
    "Buffer State").
    """
    state = status_state(line)
    if state is None:
        return None
    match = _BF.search(line)
    if match is None:
        return Status(state)
    return Status(state, int(match.group(1)), int(match.group(2)))


BUFFER_STATE = 2
"""``$10`` bit that adds ``Bf:`` to status reports (GRBL 1.1 settings.md, interface.md)."""


def setup(ask: Callable[[str], list[str]]) -> list[str]:
    """Turn on ``Bf:`` in status reports for the job; return the line that puts ``$10`` back.

    ``Bf:`` (planner blocks free) is what tells which lines GRBL has run: its
    ``ok`` means only that a line was queued. ``$$`` lists the settings; when
    ``$10`` lacks bit 1 it is set for the job (``$10=`` old value ``| 2``) and
    the old value is written back at the end. A controller whose ``$$`` has no
    ``$10`` is left as it is (then only sync lines and ``Idle`` say what ran).
    """
    mask = None
    for line in ask("$$"):
        if line.startswith("$10="):
            try:
                mask = int(float(line[4:].split()[0]))
            except (ValueError, IndexError):
                return []
    if mask is None or mask & BUFFER_STATE:
        return []
    ask(f"$10={mask | BUFFER_STATE}")
    return [f"$10={mask}"]


ARC_TOLERANCE_MARGIN = 4.0
"""An arc's planner blocks are counted as if ``$12`` were this many times the profile's
chord tolerance (GRBL's default 0.002 mm): fewer segments, so the count stays a lower
bound on a controller whose ``$12`` was raised up to that much."""


def arc_blocks(radius: float, sweep: float, tolerance: float) -> int:
    """Planner blocks GRBL's mc_arc makes of an arc: its segments, at least one.

    motion_control.c: ``segments = floor(|½·θ·r| / √(tol·(2r − tol)))`` with
    ``tol`` the ``$12`` arc tolerance, mm; θ in radians, r in mm.
    """
    if radius <= tolerance / 2:
        return 1
    return max(
        1, math.floor(abs(0.5 * sweep * radius) / math.sqrt(tolerance * (2 * radius - tolerance)))
    )


_SYNC_FLOW = ("M0", "M2", "M30")
"""Program flow: gcode.c runs protocol_buffer_synchronize() before a pause or an end."""


def expect(blocks: Sequence[WireBlock], program: Program, target: Target) -> Sequence[WireBlock]:
    """Each block with the fewest planner blocks it queues and whether GRBL syncs on it.

    ``queued``: one per move of the line that makes at least one step on some
    axis (planner.c drops a move of no steps); an arc the segments mc_arc cuts
    it into (:func:`arc_blocks`, ``$12`` taken as :data:`ARC_TOLERANCE_MARGIN`
    times the profile's chord tolerance: a lower bound). The first move counts none (where
    the machine stands before it is not known). ``sync``: GRBL answers the line
    only after the planner has emptied (gcode.c, protocol_buffer_synchronize):
    ``G4`` (mc_dwell), ``M0``/``M2``/``M30`` (program flow), and a spindle or
    coolant change (spindle_sync, coolant_sync, also an ``S`` change while the
    spindle runs) once the program itself has set that state (before that,
    GRBL's state is not known).
    """
    spm = target.machine.steps_per_mm
    tolerance = ARC_TOLERANCE_MARGIN * target.machine.motion.chord_tolerance_mm
    last_line = max((b.last_line for b in blocks[-1:]), default=0)
    queued = array("H", [0]) * (last_line + 1)  # by source line
    z: float | None = None
    for index, (move, segment) in enumerate(program.segments()):
        line = program.line_of(index)
        if line is None:
            return blocks
        dx, dy = abs(segment.end[0] - segment.start[0]), abs(segment.end[1] - segment.start[1])
        dz = abs(move.z - z) if move.z is not None and z is not None else 0.0
        z = move.z if move.z is not None else z
        steps = max(dx * spm[0], dy * spm[1], dz * spm[2])
        count = 1
        if isinstance(move, ArcMove) and isinstance(segment, Arc):
            steps = max(steps, segment.length * min(spm[0], spm[1]))
            count = arc_blocks(segment.radius, abs(segment.sweep), tolerance)
        if index and steps >= 1.0 and 0 < line <= last_line:
            queued[line] = min(queued[line] + count, 65535)
    modal = _SyncState()
    if isinstance(blocks, LineBlocks):  # block k is line k + 1
        syncs = bytes(modal.syncs(b.text) for b in blocks)
        return blocks.with_facts(queued[1:], syncs)
    return [
        replace(block, queued=queued[block.line], sync=modal.syncs(block.text)) for block in blocks
    ]


class _SyncState:
    """Spindle and coolant as the program sets them (``None``: not known yet)."""

    def __init__(self) -> None:
        self.spindle: str | None = None
        self.speed: str | None = None
        self.coolant: frozenset[str] | None = None

    def syncs(self, text: str) -> bool:
        found = words(text)
        codes = [f"{letter}{number}" for letter, number in found if letter in "GM"]
        speed = next((number for letter, number in found if letter == "S"), None)
        sync = "G4" in codes or any(code in _SYNC_FLOW for code in codes)
        spindle = next((code for code in codes if code in _SPINDLE), None)
        if spindle is not None:
            sync = sync or (self.spindle is not None and spindle != self.spindle)
            self.spindle = spindle
        elif speed is not None and self.spindle in ("M3", "M4") and self.speed is not None:
            sync = sync or float(speed) != float(self.speed)
        if speed is not None:
            self.speed = speed
        coolant = [code for code in codes if code in _COOLANT]
        if coolant:
            new = frozenset() if "M9" in coolant else (self.coolant or frozenset()) | set(coolant)
            sync = sync or (self.coolant is not None and new != self.coolant)
            self.coolant = new
        if any(code in ("M2", "M30") for code in codes):
            self.spindle, self.coolant = "M5", frozenset()
        return sync


# -- what GRBL 1.1h refuses (gnea/grbl grbl/gcode.c gc_execute_line step 1, protocol.c) ----

G_CODES = frozenset(
    (
        *("0", "1", "2", "3", "4", "10", "17", "18", "19", "20", "21", "28", "28.1", "30"),
        *("30.1", "38.2", "38.3", "38.4", "38.5", "40", "43.1", "49", "53", "54", "55", "56"),
        *("57", "58", "59", "61", "80", "90", "91", "91.1", "92", "92.1", "93", "94"),
    )
)
"""G codes gcode.c takes (its ``switch (int_value)`` for ``'G'``; G38.x needs probing, G43.1
dynamic tool length); any other is ``error:20``, a fraction where none is taken ``error:23``
(``error:20`` for the codes whose fraction gcode.c reads itself: G28 G30 G38 G43 G61 G90 G91
G92)."""
_FRACTIONS_READ = frozenset(("28", "30", "38", "43", "61", "90", "91", "92"))
M_CODES = frozenset(("0", "1", "2", "30", "3", "4", "5", "8", "9"))
"""M codes of the default build: no ``M6`` (no tool change), no ``M7`` (``ENABLE_M7`` is off
in config.h), no ``M56`` (``ENABLE_PARKING_OVERRIDE_CONTROL`` off): ``error:20``."""
LETTERS = frozenset("FIJKLNPRSTXYZ")
"""Value words gcode.c takes; any other letter (A B C D E H O Q U V W) is ``error:20``."""
NOT_NEGATIVE = frozenset("FNPST")
"""Words whose value may not be negative: ``error:4``."""
MAX_TOOL_NUMBER = 255
"""``T`` above it is ``error:38`` (config.h MAX_TOOL_NUMBER)."""
LINE_CHARACTERS = 79
"""Characters a line keeps after spaces and comments go: LINE_BUFFER_SIZE 80 less one
(protocol.c); one more is ``error:11``."""
_G_GROUPS = (
    ("4", "10", "28", "30", "53", "92", "28.1", "30.1", "92.1"),
    ("0", "1", "2", "3", "38.2", "38.3", "38.4", "38.5", "80"),
    ("17", "18", "19"),
    ("90", "91"),
    ("91.1",),
    ("93", "94"),
    ("20", "21"),
    ("40",),
    ("43.1", "49"),
    ("54", "55", "56", "57", "58", "59"),
    ("61",),
)
"""Modal groups (gcode.h): two G codes of one group in a line are ``error:21``."""
_M_GROUPS = (("0", "1", "2", "30"), ("3", "4", "5"), ("7", "8", "9"))
_AXIS_COMMANDS = (
    *("0", "1", "2", "3", "10", "28", "30", "92"),
    *("38.2", "38.3", "38.4", "38.5", "43.1", "49"),
)
"""Codes that use the axis words (gcode.c ``axis_command``): a second one is ``error:24``,
found before the modal group's ``error:21``."""
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)")


def kept_characters(text: str) -> str:
    """A line as protocol.c keeps it: no spaces, ``/``, ``(…)`` or ``;…``; letters upper-cased."""
    out = []
    comment = False
    for char in text:
        if comment:
            comment = char != ")"
        elif char <= " " or char == "/":
            continue
        elif char == "(":
            comment = True
        elif char == ";":
            break
        else:
            out.append(char.upper() if "a" <= char <= "z" else char)
    return "".join(out)


def refusal(text: str) -> int | None:
    """The ``error:N`` GRBL 1.1h answers ``text`` with on parsing it, or ``None``.

    Checks what gcode.c checks word by word, before any modal state counts:
    the letter (1), the number (2), G and M codes (20, 23), two codes that use
    the axis words (24), the value letters (20), repeated words (25), negative
    F N P S T (4), ``T`` over 255 (38), two codes of one modal group (21), and
    the line length (11, protocol.c). What depends on the modal state (a feed
    not yet set, error:22) is left to GRBL.
    ``$`` lines (GRBL's own commands) are not checked.
    """
    line = kept_characters(text)
    if not line or line.startswith("$"):
        return None
    if len(line) > LINE_CHARACTERS:
        return 11
    seen: set[str] = set()
    groups: set[tuple[str, ...]] = set()
    at = 0
    while at < len(line):
        letter = line[at]
        if not "A" <= letter <= "Z":
            return 1
        number = _NUMBER.match(line, at + 1)
        if number is None:
            return 2
        at = number.end()
        value = float(number.group())
        error = _word(letter, value, seen, groups)
        if error is not None:
            return error
    return None


def _word(letter: str, value: float, seen: set[str], groups: set[tuple[str, ...]]) -> int | None:
    if letter in "GM":
        whole = int(value)
        mantissa = round(100 * (value - whole))
        code = str(whole) if not mantissa else f"{whole}.{mantissa:02d}".rstrip("0")
        known = G_CODES if letter == "G" else M_CODES
        if code not in known:
            fraction = mantissa and str(whole) in known and str(whole) not in _FRACTIONS_READ
            return 23 if fraction else 20
        if letter == "G" and code in _AXIS_COMMANDS:
            if _AXIS_COMMANDS in groups:
                return 24
            groups.add(_AXIS_COMMANDS)
        for group in _G_GROUPS if letter == "G" else _M_GROUPS:
            if code in group:
                if group in groups:
                    return 21
                groups.add(group)
        return None
    if letter not in LETTERS:
        return 20
    if letter in seen:
        return 25
    seen.add(letter)
    if letter in NOT_NEGATIVE and value < 0:
        return 4
    if letter == "T" and value > MAX_TOOL_NUMBER:
        return 38
    return None


MAX_DIGITS = 8
"""``nuts_bolts.c`` ``MAX_INT_DIGITS``: the digits of a number ``read_float`` keeps (leading
zeros count); an integer digit after them reads as 0, a decimal one is dropped."""
MISREAD = 0.0005
"""How far (in the program's units) a number read short must move to be refused: half the
0.001 of the codes camtool writes; ``X12.34567891`` read as 12.345678 is sent."""
_LONG = re.compile(r"[0-9.]{9,}")
"""A run that may hold more than :data:`MAX_DIGITS` digits (a quick test first)."""


def misread(text: str) -> str | None:
    """The first number of ``text`` GRBL 1.1 reads as another, as ``X238379.324 as X238379.32``.

    ``read_float`` keeps the first :data:`MAX_DIGITS` digits: a number whose dropped digits
    amount to :data:`MISREAD` or more moves the machine elsewhere than written, with no
    error. ``None`` when every number reads as written, to less than that (``$`` lines are
    not checked).
    """
    line = kept_characters(text)
    if not line or line.startswith("$") or not _LONG.search(line):
        return None
    for word in _WORD.finditer(line):
        letter, number = word.groups()
        kept, count, dropped, decimal = [], 0, False, False
        for ch in number:
            decimal |= ch == "."
            if ch.isdigit():
                count += 1
                if count > MAX_DIGITS:
                    dropped |= ch != "0"
                    if decimal:
                        continue
                    ch = "0"
            kept.append(ch)
        read = "".join(kept).rstrip(".")
        if dropped and abs(float(number) - float(read)) >= MISREAD:
            return f"{letter}{number} as {letter}{read}"
    return None


def check(blocks: Sequence[WireBlock], source: str) -> None:
    """Refuse, before the first byte, a line GRBL 1.1h refuses or misreads.

    A line it would answer with ``error:N`` (:func:`refusal`), or with a number it would
    read as another (:func:`misread`).

    Raises:
        InputError: naming the file, the line, the text and GRBL's own words.
    """
    for block in blocks:
        error = refusal(block.text)
        where = f"line {block.line}" if block.index else "a restore line"
        if error is not None:
            raise InputError(
                f"{source}, {where}: {block.shown!r}: GRBL 1.1 would refuse it with "
                f"{decode(f'error:{error}')}; change the line (or post the drawing again "
                "for grbl)"
            )
        wrong = misread(block.text)
        if wrong is not None:
            raise InputError(
                f"{source}, {where}: {block.shown!r}: GRBL 1.1 reads the first {MAX_DIGITS} "
                f"digits of a number (nuts_bolts.c read_float): it would read {wrong}; "
                "write it with fewer digits, nearer its work zero (or post "
                "the drawing again for grbl)"
            )


# -- resume -------------------------------------------------------------------------------

_WORD = re.compile(r"([A-Z])([-+]?(?:\d+\.?\d*|\.\d+))")
_GROUPS = {
    "units": ("G20", "G21"),
    "distance": ("G90", "G91"),
    "arc_distance": ("G91.1",),
    "feed_mode": ("G93", "G94"),
    "plane": ("G17", "G18", "G19"),
    "wcs": ("G54", "G55", "G56", "G57", "G58", "G59"),
    "tool_length": ("G49",),
}
_MOTION = ("G0", "G1", "G2", "G3")
_SPINDLE = ("M3", "M4", "M5")
_COOLANT = ("M7", "M8", "M9")


def words(text: str) -> list[tuple[str, str]]:
    """A GRBL line's words, normalised: ``("G", "1")``, ``("X", "-2.5")``.

    Comments ``(…)`` and from ``;`` on are dropped, spaces removed, letters
    upper-cased, as GRBL's protocol.c does; numbers of G and M words lose
    leading zeros (``G01`` → ``G1``).
    """
    text = re.sub(r"\([^)]*\)", "", text).split(";", 1)[0].upper().replace(" ", "")
    out = []
    for letter, number in _WORD.findall(text):
        if letter in "GM":
            whole, _, frac = number.partition(".")
            number = str(int(whole or "0")) + (f".{frac}" if frac else "")
        out.append((letter, number))
    return out


class _Modal:
    """The modal state GRBL keeps, as lines set it (see the module docstring)."""

    def __init__(self) -> None:
        self.groups: dict[str, str] = {}
        self.motion: tuple[str, int] | None = None
        self.feed = ""
        self.speed = ""
        self.spindle = ""
        self.spin_dwell = ""
        self.dwell_pending = False
        self.coolant: list[str] = []

    def read(self, block: WireBlock) -> None:
        found = words(block.text)
        codes = [f"{letter}{number}" for letter, number in found if letter in "GM"]
        for code in codes:
            self._code(code, block.line)
        for letter, number in found:
            if letter == "F":
                self.feed = number
            elif letter == "S":
                self.speed = number
            elif letter == "P" and "G4" in codes and self.dwell_pending:
                self.spin_dwell = number
        if not any(c in _SPINDLE for c in codes) and "G4" not in codes and codes:
            self.dwell_pending = False

    def _code(self, code: str, line: int) -> None:
        for group, members in _GROUPS.items():
            if code in members:
                self.groups[group] = code
        if code in _MOTION:
            self.motion = (code, line)
        elif code in _SPINDLE:
            self.spindle, self.spin_dwell = code, ""
            self.dwell_pending = code != "M5"
        elif code == "M9":
            self.coolant = ["M9"]
        elif code in _COOLANT:
            self.coolant = [c for c in self.coolant if c != "M9" and c != code] + [code]

    def blocks(self, first: WireBlock) -> list[str]:
        """The lines that restore this state before ``first``."""
        out = [" ".join(self.groups[g] for g in _GROUPS if g in self.groups)]
        if self.feed:
            out.append(f"F{self.feed}")
        if self.spindle in ("M3", "M4"):
            out.append(f"{self.spindle} S{self.speed}" if self.speed else self.spindle)
            if self.spin_dwell:
                out.append(f"G4 P{self.spin_dwell}")
        elif self.spindle:
            out.append(self.spindle)
        out += self.coolant
        found = words(first.text)
        has_motion = any(f"{a}{n}" in _MOTION for a, n in found if a == "G")
        has_axes = any(a in "XYZ" for a, _ in found)
        if has_axes and not has_motion and self.motion is not None:
            code, line = self.motion
            if code in ("G2", "G3"):
                raise UsageError(
                    f"--from-line {first.line} continues the arc mode {code} of line {line} "
                    f"without its own motion word: resume at line {line} or at a later line "
                    "that has its own G0/G1/G2/G3"
                )
            out.append(code)
        return [line for line in out if line]


def resume_blocks(before: Sequence[WireBlock], first: WireBlock, spec: LinkSpec) -> list[WireBlock]:
    """The blocks that put GRBL back in the modal state lines before ``first`` left it.

    Raises:
        UsageError: ``first`` continues a modal arc (G2/G3) without its own motion word.
    """
    modal = _Modal()
    for block in before:
        modal.read(block)
    end = spec.block_end
    return [WireBlock(0, 0, 0, text.encode("ascii") + end) for text in modal.blocks(first)]


# -- the simulator --------------------------------------------------------------------------


DEVICE_ARC_TOLERANCE = 0.002
"""The simulated GRBL's ``$12`` (defaults.h DEFAULT_ARC_TOLERANCE), mm."""
PLANNER_BLOCKS = 15
"""Planner blocks GRBL 1.1h holds: BLOCK_BUFFER_SIZE 16 less one (planner.h; ``$I`` says
``[OPT:V,15,128]``)."""
_SYNCS = ("G4", *_SYNC_FLOW, *_SPINDLE, *_COOLANT)


class GrblDevice(LineDevice):
    """A simulated GRBL 1.1h: banner, RX buffer, planner, ``ok``/``error:N``, status, hold, reset.

    Real-time bytes (``?`` ``!`` ``~`` Ctrl-X) are picked out of the stream the
    moment they arrive and never enter the RX buffer (interface.md). Other bytes
    go into a buffer of :data:`RX_BUFFER_BYTES`; :attr:`max_rx` is the most it
    ever held and :attr:`overflowed` is set if a host sent more (a real GRBL
    would lose bytes). Each :meth:`step` parses the lines that fit the planner
    (:data:`PLANNER_BLOCKS`; one block per line with axis words) and answers
    them ``ok`` at once, as GRBL does (``ok`` means queued); a line GRBL syncs
    on (``G4``, M codes) waits until the planner is empty. Then it runs the
    oldest planner block (unless held): :attr:`executed` holds the lines run
    to their end. ``error:N`` for ``fail_at_block``; ``ALARM:N`` and the alarm
    state for ``alarm_at_block``; ``error:9`` for any line while in alarm.
    Status reports say ``Run`` while the planner holds blocks, and carry
    ``Bf:`` when ``$10`` has bit 1 (``$$`` and ``$10=`` are answered). A feed
    hold stops running (``Hold:0``), ``~`` resumes; ``M0`` holds too, and is answered
    (and the next line read) only at the ``~`` that resumes it; a reset empties the buffers,
    and raises ``ALARM:3`` only if it came while moving. The position in status
    reports is where the lines that ran leave the tool, read back with
    camtool's reader of the target.

    Faults a test can ask for: ``merge_at_block`` loses that line's line end
    (GRBL takes it and the next as one line: one ``ok`` fewer);
    ``mute_at_block`` answers no line from that one on (status reports go on);
    ``deaf_at_block`` answers nothing at all from then on; ``ack_word`` answers
    lines with another word (``"OK"``); ``run_forever`` reports ``Run`` forever;
    ``noise_at_block`` answers that line with 8 KiB of bytes and no line end (a wrong baud
    rate, or noise on the wire); ``chatter_at_block`` sends 1 500 ``[MSG:…]`` lines before
    that line's answer.

    Args:
        spec: the grbl link.
        alarm_at_block: 1-based block that raises ``ALARM:<alarm>``.
        alarm: the alarm code (default 1, hard limit).
        status_mask: ``$10`` (GRBL's default 1: no ``Bf:``).
        **options: as :class:`camtool.link.device.Device`, and the faults above.
    """

    def __init__(
        self,
        spec: LinkSpec,
        *,
        alarm_at_block: int | None = None,
        alarm: int = 1,
        status_mask: int = 1,
        merge_at_block: int | None = None,
        mute_at_block: int | None = None,
        deaf_at_block: int | None = None,
        ack_word: str = "ok",
        run_forever: bool = False,
        noise_at_block: int | None = None,
        chatter_at_block: int | None = None,
        **options: object,
    ) -> None:
        super().__init__(spec, **options)
        self.alarm_at_block = alarm_at_block
        self.alarm = alarm
        self.status_mask = status_mask
        self.merge_at_block = merge_at_block
        self.mute_at_block = mute_at_block
        self.deaf_at_block = deaf_at_block
        self.ack_word = ack_word
        self.run_forever = run_forever
        self.noise_at_block = noise_at_block
        self.chatter_at_block = chatter_at_block
        self.state = "Idle"
        self.held = False
        self.max_rx = 0
        self.overflowed = False
        self.wco_sent = False
        self.planner: deque[list[Any]] = deque()  # [line, its blocks queued now]
        self.queued = 0
        self.waiting: tuple[list[Any], int, bytes] | None = None
        self.accepted: list[bytes] = []
        self.line_ends = 0
        self.deaf = False
        self.holds = 0
        self.resets = 0
        self.paused: bytes | None = None  # an M0's answer, given once the operator resumes
        self.pauses = 0

    def connect(self) -> bytes:
        """GRBL prints its banner when the port opens (an Arduino resets on DTR)."""
        super().connect()
        return self._banner()

    def _banner(self) -> bytes:
        text = ANSWER_END + BANNER.encode() + ANSWER_END
        if self.state == "Alarm":
            text += b"[MSG:'$H'|'$X' to unlock]" + ANSWER_END
        return text

    def feed(self, data: bytes) -> bytes:
        """Real-time bytes answered at once; the rest into the RX buffer."""
        out = b""
        for byte in data:
            char = bytes([byte])
            if char == b"?":
                out += self.status_report()
            elif char == b"!":
                self.held = self.held or self.state != "Alarm"
                self.holds += 1
            elif char == b"~":
                self.held = False
                if self.paused is not None:  # the M0 line's execution ends: its answer
                    out += self.paused
                    self.paused = None
            elif char == b"\x18":
                out += self._reset()
            else:
                if char == b"\n":
                    self.line_ends += 1
                    if self.line_ends == self.merge_at_block:
                        continue  # lost on the wire
                self.rx += char
                self.max_rx = max(self.max_rx, len(self.rx))
                self.overflowed = self.overflowed or len(self.rx) > RX_BUFFER_BYTES
        return b"" if self.deaf else out

    def _reset(self) -> bytes:
        moving = self.queued > 0 and not self.held
        self._flush()
        self.held = False
        self.paused = None
        self.resets += 1
        out = b""
        if moving:
            self.state = "Alarm"
            out = b"ALARM:3" + ANSWER_END
        return out + self._banner()

    def pending(self) -> bool:
        """A line to parse, or a planner block to run."""
        return self._parsable() or (self.queued > 0 and not self.held)

    def _parsable(self) -> bool:
        cut = self.rx.find(self.spec.block_end)
        if not self.startup_seen or cut < 0 or self.waiting is not None or self.paused:
            return False
        if self.queued >= PLANNER_BLOCKS:
            return False
        codes = {f"{a}{n}" for a, n in words(self.rx[:cut].decode("latin-1")) if a in "GM"}
        return not (codes & set(_SYNCS) and self.planner)

    def step(self) -> bytes:
        """Parse the lines that fit (``ok`` once queued), then run one planner block."""
        out = b""
        while self._parsable():
            block = self.take_block()
            assert block is not None
            out += self._parse(block)
        if self.queued and not self.held:
            entry = self.planner[0]
            entry[1] -= 1
            self.queued -= 1
            if not entry[1] and (self.waiting is None or self.waiting[0] is not entry):
                self.planner.popleft()
                self.executed.append(entry[0])
            out += self._queue_waiting()
        return b"" if self.deaf else out

    def _queue_waiting(self) -> bytes:
        """Queue more of the line whose blocks did not all fit; its answer once all are in."""
        if self.waiting is None:
            return b""
        entry, left, answer = self.waiting
        more = min(left, PLANNER_BLOCKS - self.queued)
        entry[1] += more
        self.queued += more
        if more < left:
            self.waiting = (entry, left - more, answer)
            return b""
        self.waiting = None
        return answer

    def _parse(self, block: bytes) -> bytes:
        text = block.strip()
        if text == b"$X":
            self.state = "Idle"
            return b"[MSG:Caution: Unlocked]" + ANSWER_END + self._ack()
        if text.startswith(b"$"):
            return self._setting(text.decode("latin-1"))
        if self.state == "Alarm":
            return b"error:9" + ANSWER_END
        number = len(self.blocks) + 1
        if number == self.deaf_at_block:
            self.deaf = True
        if number == self.noise_at_block:
            return bytes(range(128, 256)) * 64
        if number == self.chatter_at_block:
            self.chatter_at_block = None
            return b"".join(b"[MSG:%d]" % k + ANSWER_END for k in range(1500)) + self._parse(block)
        if number == self.alarm_at_block:
            self.received += block
            self.blocks.append(block)
            self.state = "Alarm"
            self._flush()
            return f"ALARM:{self.alarm}".encode() + ANSWER_END
        answer = self.run_block(block)
        muted = self.mute_at_block is not None and number >= self.mute_at_block
        answer = b"" if muted else answer
        if not (self.executed and self.executed[-1] is block):
            return answer
        self.executed.pop()  # accepted: queued, not yet run
        self.accepted.append(block)
        count = self._blocks_of(block)
        if not count:
            self.executed.append(block)
            if "M0" in {f"{a}{n}" for a, n in words(text.decode("latin-1")) if a == "M"}:
                # gcode.c: M0 is a feed hold inside the line's execution (the planner is
                # empty, synchronised): no answer, and no line read, until cycle start
                self.held, self.paused = True, answer
                self.pauses += 1
                return b""
            return answer
        entry = [block, 0]
        self.planner.append(entry)
        self.waiting = (entry, count, answer)
        return self._queue_waiting()

    def _blocks_of(self, block: bytes) -> int:
        """Planner blocks of an accepted line: one per move, an arc its mc_arc segments."""
        if self.target is None or not any(a in "XYZ" for a, _ in words(block.decode("latin-1"))):
            return 0
        code = b"".join(self.accepted).decode("latin-1")
        try:
            program = self.target.parse(code)
        except CamtoolError:  # not readable alone (rapids only, say): one block
            return 1
        line = len(self.accepted)
        count = 0
        for index, (move, segment) in enumerate(program.segments()):
            if program.line_of(index) != line:
                continue
            if isinstance(move, ArcMove) and isinstance(segment, Arc):
                count += arc_blocks(segment.radius, abs(segment.sweep), DEVICE_ARC_TOLERANCE)
            else:
                count += 1
        return count

    def _flush(self) -> None:
        self.rx.clear()
        self.planner.clear()
        self.queued = 0
        self.waiting = None

    def run_block(self, block: bytes) -> bytes:
        """Record ``block`` and answer it (``ack_word`` for an accepted line)."""
        answer = super().run_block(block)
        if answer == self.spec.ack.encode() + ANSWER_END:
            return self._ack()
        return answer

    def _ack(self) -> bytes:
        return self.ack_word.encode() + ANSWER_END

    def _setting(self, text: str) -> bytes:
        """``$$`` lists ``$10`` and ``$12``; ``$10=N`` sets the status mask; other ``$``: ``ok``."""
        if text == "$$":
            listed = f"$10={self.status_mask}\r\n$12=0.002\r\n".encode()
            return listed + self._ack()
        if text.startswith("$10="):
            self.status_mask = int(text[4:])
        return self._ack()

    def status_report(self) -> bytes:
        """``<State|MPos:x,y,z|Bf:p,r|FS:0,0>`` (``|WCO:0.000,0.000,0.000`` in the first)."""
        state = "Alarm" if self.state == "Alarm" else ("Hold:0" if self.held else "Idle")
        if state == "Idle" and (self.queued or self._parsable() or self.run_forever):
            state = "Run"
        try:
            x, y, z = self.position() if self.executed and self.target else (0.0, 0.0, 0.0)
        except (ParseError, ValueError):
            x = y = z = 0.0
        report = f"<{state}|MPos:{x:.3f},{y:.3f},{z:.3f}"
        if self.status_mask & BUFFER_STATE:
            free = (PLANNER_BLOCKS - self.queued, RX_BUFFER_BYTES + 1 - len(self.rx))
            report += f"|Bf:{free[0]},{free[1]}"
        report += "|FS:0,0"
        if not self.wco_sent:
            report += "|WCO:0.000,0.000,0.000"
            self.wco_sent = True
        return (report + ">").encode() + ANSWER_END


LINK = LinkHooks(
    decode=decode,
    resume=resume_blocks,
    device=GrblDevice,
    status_state=status_state,
    status=status,
    setup=setup,
    expect=expect,
    check=check,
    firmware=firmware,
)
"""GRBL's link hooks (``camtool send -t grbl``, ``camtool simulate-device -t grbl``)."""
