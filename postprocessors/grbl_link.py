r"""GRBL 1.1's serial link: messages decoded, status reports read, resume, and a simulator.

The protocol itself (115200 baud, ``\\n``-ended lines, character counting against
the 127 bytes GRBL's 128-byte RX ring buffer holds, ``ok``/``error:N``,
``ALARM:N``, the ``Grbl 1.1h ['$' for help]`` banner, real-time ``?`` ``!`` ``~``
and Ctrl-X) is declared in ``grbl.toml``'s ``[link]`` table; this module adds
what needs Python (:data:`LINK`):

- :func:`decode`: ``error:N`` and ``ALARM:N`` in GRBL's own words, from its
  documented tables (gnea/grbl ``doc/csv/error_codes_en_US.csv`` and
  ``doc/csv/alarm_codes_en_US.csv``, v1.1h);
- :func:`status_state`: the state word of a ``<Idle|MPos:…|FS:…>`` report
  (gnea/grbl ``doc/markdown/interface.md``, "Real-time Status Reports");
- :func:`resume_blocks`: the modal state to restore before ``--from-line``;
- :class:`GrblDevice`: a simulated GRBL that speaks all of it.

Resuming (``--from-line K``). GRBL forgets nothing between lines, so before line
K the sender repeats, in one line, the last word lines 1…K−1 set in each modal
group the program used: units (G20/G21), distance (G90/G91), arc distance
(G91.1), feed mode (G93/G94), plane (G17–G19), work coordinate system
(G54–G59) and tool length offset cancel (G49); then the last feed ``F``; the
spindle (``M3``/``M4`` with the last ``S``, or ``M5``) and the spin-up dwell
the program had after starting it (``G4 P…``); the coolant (``M7``/``M8``/
``M9``). A group the program never set is left as the controller has it. When
line K has axis words but no motion word, the modal ``G0``/``G1`` is sent
alone before it (GRBL accepts a motion word without axes: no motion). Not
restored: a ``G92`` offset, ``G43.1`` dynamic tool length offsets, and the
position: the machine must stand where line K−1 ended, which is where
``camtool send`` leaves it when it stops and names line K. A line K that
continues a modal ``G2``/``G3`` without its own motion word is refused (resume
at the line that holds it). On an Arduino, opening the port resets GRBL
(DTR): the machine position is then zero where the carriage stands, and with
homing enabled it is in alarm until homed; re-establish the work zero before
resuming (docs/send.md).

Errors in flight. With character counting, lines already in GRBL's buffer
when it answers ``error:N`` still run (interface.md, "RESERVATION"); the
sender stops sending, waits for their answers, and names the line GRBL
refused and the line to resume at (the one after the last line sent).
"""

from __future__ import annotations

import re
from collections.abc import Sequence

from camtool.link.device import ANSWER_END, LineDevice
from camtool.link.spec import LinkHooks, LinkSpec, WireBlock
from camtool.model.errors import ParseError, UsageError

ERRORS: dict[int, tuple[str, str]] = {
    1: (
        "Expected command letter",
        ("G-code words consist of a letter and a value. Letter was not found."),
    ),
    2: (
        "Bad number format",
        ("Missing the expected G-code word value or numeric value format is not valid."),
    ),
    3: (
        "Invalid statement",
        ("Grbl '$' system command was not recognized or supported."),
    ),
    4: (
        "Value < 0",
        ("Negative value received for an expected positive value."),
    ),
    5: (
        "Setting disabled",
        ("Homing cycle failure. Homing is not enabled via settings."),
    ),
    6: (
        "Value < 3 usec",
        ("Minimum step pulse time must be greater than 3usec."),
    ),
    7: (
        "EEPROM read fail. Using defaults",
        ("An EEPROM read failed. Auto-restoring affected EEPROM to default values."),
    ),
    8: (
        "Not idle",
        (
            "Grbl '$' command cannot be used unless Grbl is IDLE. Ensures smooth operation "
            "during a job."
        ),
    ),
    9: (
        "G-code lock",
        ("G-code commands are locked out during alarm or jog state."),
    ),
    10: (
        "Homing not enabled",
        ("Soft limits cannot be enabled without homing also enabled."),
    ),
    11: (
        "Line overflow",
        ("Max characters per line exceeded. Received command line was not executed."),
    ),
    12: (
        "Step rate > 30kHz",
        ("Grbl '$' setting value cause the step rate to exceed the maximum supported."),
    ),
    13: (
        "Check Door",
        ("Safety door detected as opened and door state initiated."),
    ),
    14: (
        "Line length exceeded",
        ("Build info or startup line exceeded EEPROM line length limit. Line not stored."),
    ),
    15: (
        "Travel exceeded",
        ("Jog target exceeds machine travel. Jog command has been ignored."),
    ),
    16: (
        "Invalid jog command",
        ("Jog command has no '=' or contains prohibited g-code."),
    ),
    17: (
        "Setting disabled",
        ("Laser mode requires PWM output."),
    ),
    20: (
        "Unsupported command",
        ("Unsupported or invalid g-code command found in block."),
    ),
    21: (
        "Modal group violation",
        ("More than one g-code command from same modal group found in block."),
    ),
    22: (
        "Undefined feed rate",
        ("Feed rate has not yet been set or is undefined."),
    ),
    23: (
        "Invalid gcode ID:23",
        ("G-code command in block requires an integer value."),
    ),
    24: (
        "Invalid gcode ID:24",
        ("More than one g-code command that requires axis words found in block."),
    ),
    25: (
        "Invalid gcode ID:25",
        ("Repeated g-code word found in block."),
    ),
    26: (
        "Invalid gcode ID:26",
        (
            "No axis words found in block for g-code command or current modal state which "
            "requires them."
        ),
    ),
    27: (
        "Invalid gcode ID:27",
        ("Line number value is invalid."),
    ),
    28: (
        "Invalid gcode ID:28",
        ("G-code command is missing a required value word."),
    ),
    29: (
        "Invalid gcode ID:29",
        ("G59.x work coordinate systems are not supported."),
    ),
    30: (
        "Invalid gcode ID:30",
        ("G53 only allowed with G0 and G1 motion modes."),
    ),
    31: (
        "Invalid gcode ID:31",
        ("Axis words found in block when no command or current modal state uses them."),
    ),
    32: (
        "Invalid gcode ID:32",
        ("G2 and G3 arcs require at least one in-plane axis word."),
    ),
    33: (
        "Invalid gcode ID:33",
        ("Motion command target is invalid."),
    ),
    34: (
        "Invalid gcode ID:34",
        ("Arc radius value is invalid."),
    ),
    35: (
        "Invalid gcode ID:35",
        ("G2 and G3 arcs require at least one in-plane offset word."),
    ),
    36: (
        "Invalid gcode ID:36",
        ("Unused value words found in block."),
    ),
    37: (
        "Invalid gcode ID:37",
        ("G43.1 dynamic tool length offset is not assigned to configured tool length axis."),
    ),
    38: (
        "Invalid gcode ID:38",
        ("Tool number greater than max supported value."),
    ),
}
"""GRBL 1.1 ``error:N``: (v1.0 message, description), gnea/grbl doc/csv/error_codes_en_US.csv."""

ALARMS: dict[int, tuple[str, str]] = {
    1: (
        "Hard limit",
        (
            "Hard limit has been triggered. Machine position is likely lost due to sudden "
            "halt. Re-homing is highly recommended."
        ),
    ),
    2: (
        "Soft limit",
        (
            "Soft limit alarm. G-code motion target exceeds machine travel. Machine position "
            "retained. Alarm may be safely unlocked."
        ),
    ),
    3: (
        "Abort during cycle",
        (
            "Reset while in motion. Machine position is likely lost due to sudden halt. Re-"
            "homing is highly recommended."
        ),
    ),
    4: (
        "Probe fail",
        (
            "Probe fail. Probe is not in the expected initial state before starting probe "
            "cycle when G38.2 and G38.3 is not triggered and G38.4 and G38.5 is triggered."
        ),
    ),
    5: (
        "Probe fail",
        (
            "Probe fail. Probe did not contact the workpiece within the programmed travel for"
            " G38.2 and G38.4."
        ),
    ),
    6: (
        "Homing fail",
        ("Homing fail. The active homing cycle was reset."),
    ),
    7: (
        "Homing fail",
        ("Homing fail. Safety door was opened during homing cycle."),
    ),
    8: (
        "Homing fail",
        (
            "Homing fail. Pull off travel failed to clear limit switch. Try increasing pull-"
            "off setting or check wiring."
        ),
    ),
    9: (
        "Homing fail",
        (
            "Homing fail. Could not find limit switch within search distances. Try increasing"
            " max travel, decreasing pull-off distance, or check wiring."
        ),
    ),
    10: (
        "Homing fail",
        (
            "Homing fail. Second dual axis limit switch failed to trigger within configured "
            "search distance after first. Try increasing trigger fail distance or check "
            "wiring."
        ),
    ),
}
"""GRBL 1.1 ``ALARM:N``: (v1.0 message, description), gnea/grbl doc/csv/alarm_codes_en_US.csv."""

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


class GrblDevice(LineDevice):
    """A simulated GRBL 1.1h: banner, RX buffer, ``ok``/``error:N``, status, hold, reset, alarms.

    Real-time bytes (``?`` ``!`` ``~`` Ctrl-X) are picked out of the stream the
    moment they arrive and never enter the RX buffer (interface.md). Other bytes
    go into a buffer of :data:`RX_BUFFER_BYTES`; :attr:`max_rx` is the most it
    ever held and :attr:`overflowed` is set if a host sent more (a real GRBL
    would lose bytes). :meth:`step` takes one line out of it and answers
    ``ok`` (``error:N`` for ``fail_at_block``; ``ALARM:N`` and the alarm state
    for ``alarm_at_block``; ``error:9`` for any line while in alarm). The
    position in status reports is where the lines that ran leave the tool,
    read back with camtool's reader of the target.

    Args:
        spec: the grbl link.
        alarm_at_block: 1-based block that raises ``ALARM:<alarm>``.
        alarm: the alarm code (default 1, hard limit).
        **options: as :class:`camtool.link.device.Device`.
    """

    def __init__(
        self,
        spec: LinkSpec,
        *,
        alarm_at_block: int | None = None,
        alarm: int = 1,
        **options: object,
    ) -> None:
        super().__init__(spec, **options)
        self.alarm_at_block = alarm_at_block
        self.alarm = alarm
        self.state = "Idle"
        self.held = False
        self.max_rx = 0
        self.overflowed = False
        self.wco_sent = False

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
                self.held = self.held or bool(self.rx)
            elif char == b"~":
                self.held = False
            elif char == b"\x18":
                out += self._reset()
            else:
                self.rx += char
                self.max_rx = max(self.max_rx, len(self.rx))
                self.overflowed = self.overflowed or len(self.rx) > RX_BUFFER_BYTES
        return out

    def _reset(self) -> bytes:
        moving = self.spec.block_end in self.rx
        self.rx.clear()
        self.held = False
        out = b""
        if moving:
            self.state = "Alarm"
            out = b"ALARM:3" + ANSWER_END
        return out + self._banner()

    def pending(self) -> bool:
        """A whole line waits, and no feed hold."""
        return not self.held and super().pending()

    def step(self) -> bytes:
        """Run one line: ``ok``, ``error:N`` or ``ALARM:N``."""
        block = self.take_block()
        if block is None:
            return b""
        text = block.strip()
        if text == b"$X":
            self.state = "Idle"
            return b"[MSG:Caution: Unlocked]" + ANSWER_END + b"ok" + ANSWER_END
        if self.state == "Alarm":
            return b"error:9" + ANSWER_END
        if len(self.blocks) + 1 == self.alarm_at_block:
            self.received += block
            self.blocks.append(block)
            self.state = "Alarm"
            self.rx.clear()
            return f"ALARM:{self.alarm}".encode() + ANSWER_END
        return self.run_block(block)

    def status_report(self) -> bytes:
        """``<State|MPos:x,y,z|FS:0,0>`` (``|WCO:0.000,0.000,0.000`` in the first)."""
        state = "Alarm" if self.state == "Alarm" else ("Hold:0" if self.held else "Idle")
        if state == "Idle" and self.pending():
            state = "Run"
        try:
            x, y, z = self.position() if self.executed and self.target else (0.0, 0.0, 0.0)
        except (ParseError, ValueError):
            x = y = z = 0.0
        report = f"<{state}|MPos:{x:.3f},{y:.3f},{z:.3f}|FS:0,0"
        if not self.wco_sent:
            report += "|WCO:0.000,0.000,0.000"
            self.wco_sent = True
        return (report + ">").encode() + ANSWER_END


LINK = LinkHooks(decode=decode, resume=resume_blocks, device=GrblDevice, status_state=status_state)
"""GRBL's link hooks (``camtool send -t grbl``, ``camtool simulate-device -t grbl``)."""
