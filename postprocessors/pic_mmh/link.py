"""Mode strings of the pic-mmh host link: jog, steps, frequency, backlash, home, stop.

Source: UNAM-GMM §3.2 (Tabla 23, annex A.2, L3474–L3505) and §3.1 (how the
firmware decodes a string, Fig. 37, L1739–L1770); requirement S000-10. Each
string is sent on its own over RS-232 and ends with ``;``:

Design notes: docs/internals.md, ``postprocessors/pic_mmh/link.py``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, replace
from decimal import ROUND_HALF_UP, Decimal
from typing import TYPE_CHECKING, Any, ClassVar, Literal, TypeAlias, cast

from camtool.link.device import Device
from camtool.link.spec import LinkHooks, LinkSpec, WireBlock
from camtool.model.errors import DialectError, InputError, ParseError
from camtool.model.machine import Machine

if TYPE_CHECKING:
    from camtool.model.program import Program
    from camtool.post.base import Target
    from camtool.verify.motion import StepTrace

Axis: TypeAlias = Literal["X", "Y", "Z"]
"""An axis letter of the mode strings (UNAM-GMM §3.6 ``axis``)."""
Sign: TypeAlias = Literal["+", "-"]
"""A direction character: ``-`` counter-clockwise, ``+`` clockwise (L1765–L1768)."""

AXES: tuple[Axis, ...] = ("X", "Y", "Z")
MAX_STEPS = 9999
"""``PX±####;``: four digits (Tabla 23, L3474–L3505)."""
MAX_FREQUENCY_HZ = 999
"""``FX±###;``: three digits (Tabla 23; ``FX+250;``)."""
MAX_BACKLASH_UM = 999
"""``BX###;``: three digits, no sign (Tabla 23; ``BX200;``, L3492)."""


def _check_axis(axis: str) -> None:
    if axis not in AXES:
        raise DialectError(f"axis {axis!r} is not one of X, Y, Z (UNAM-GMM §3.2)")


def _check_sign(sign: str) -> None:
    if sign not in ("+", "-"):
        raise DialectError(f"direction {sign!r} is not '+' or '-' (UNAM-GMM §3.2)")


def _check_count(what: str, value: int, most: int, unit: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= most:
        digits = len(str(most))
        raise DialectError(
            f"{what} {value!r} does not fit {digits} digits (0–{most} {unit}, UNAM-GMM Tabla 23)"
        )


@dataclass(frozen=True)
class Jog:
    """``J<axis><sign>;``: move one axis while jogging, at the joystick rate (170 Hz, L1789)."""

    axis: Axis
    sign: Sign = "+"

    def __post_init__(self) -> None:
        _check_axis(self.axis)
        _check_sign(self.sign)

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"JX+;"`` (L1730)."""
        return f"J{self.axis}{self.sign};"


@dataclass(frozen=True)
class JogAxes:
    """``&<axis><sign>…;``: jog two or three axes at once (``&X+Y-Z+;``, Tabla 23).

    Attributes:
        axes: ``((axis, sign), ...)``, 2 or 3 pairs with different axes, in the
            order they are written.
    """

    axes: tuple[tuple[Axis, Sign], ...]

    def __post_init__(self) -> None:
        letters = [axis for axis, _ in self.axes]
        if not 2 <= len(letters) <= 3 or len(set(letters)) != len(letters):
            raise DialectError(
                f"'&' jogs 2 or 3 different axes (\"más de un eje\", Tabla 23), not {letters}"
            )
        for axis, sign in self.axes:
            _check_axis(axis)
            _check_sign(sign)

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"&X+Y-Z+;"``."""
        return "&" + "".join(a + s for a, s in self.axes) + ";"


@dataclass(frozen=True)
class Steps:
    """``P<axis><sign>####;``: move ``steps`` motor steps (0–9999; ``PX+1000;``).

    The GUI offers 1, 14, 28, 10, 50, 100 and 1000 steps (L1273–L1277).
    """

    axis: Axis
    sign: Sign
    steps: int

    def __post_init__(self) -> None:
        _check_axis(self.axis)
        _check_sign(self.sign)
        _check_count("step count", self.steps, MAX_STEPS, "steps")

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"PX+1000;"`` or ``"PX+0014;"``."""
        return f"P{self.axis}{self.sign}{self.steps:04d};"


@dataclass(frozen=True)
class Frequency:
    """``F<axis><sign>###;``: run one axis at ``hz`` steps/s (0–999; ``FX+250;``).

    The unit is presumed Hz (UNAM-GMM §3.2 notes); the serial link limits the
    machine to 166 Hz (L3198), so higher rates run slower.
    """

    axis: Axis
    sign: Sign
    hz: int

    def __post_init__(self) -> None:
        _check_axis(self.axis)
        _check_sign(self.sign)
        _check_count("frequency", self.hz, MAX_FREQUENCY_HZ, "Hz")

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"FX+250;"``."""
        return f"F{self.axis}{self.sign}{self.hz:03d};"


@dataclass(frozen=True)
class Backlash:
    """``B<axis>###;``: set the backlash compensation of an axis, µm (0–999; ``BX200;``)."""

    axis: Axis
    um: int

    def __post_init__(self) -> None:
        _check_axis(self.axis)
        _check_count("backlash", self.um, MAX_BACKLASH_UM, "µm")

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"BX200;"`` (L3492)."""
        return f"B{self.axis}{self.um:03d};"


@dataclass(frozen=True)
class _Bare:
    """A mode string of one letter and ``;``."""

    letter: ClassVar[str] = ""

    def to_string(self) -> str:
        """The string sent to the controller, e.g. ``"H;"``."""
        return f"{self.letter};"


@dataclass(frozen=True)
class GoHome(_Bare):
    """``H;``: home Z, then X, then Y to the switches, back off 400 steps (L1698–L1705)."""

    letter: ClassVar[str] = "H"


@dataclass(frozen=True)
class Stop(_Bare):
    """``A;``: stop ("alto"); the phase state is kept (L1709–L1712)."""

    letter: ClassVar[str] = "A"


@dataclass(frozen=True)
class Faster(_Bare):
    """``W;``: raise the jog speed (only while jogging, L1610–L1612)."""

    letter: ClassVar[str] = "W"


@dataclass(frozen=True)
class Slower(_Bare):
    """``V;``: lower the jog speed (only while jogging, L1610–L1612)."""

    letter: ClassVar[str] = "V"


@dataclass(frozen=True)
class StorePartZero(_Bare):
    """``Q;``: store the current position as the part zero (as ``G54;``, §7)."""

    letter: ClassVar[str] = "Q"


ModeString: TypeAlias = (
    Jog | JogAxes | Steps | Frequency | Backlash | GoHome | Stop | Faster | Slower | StorePartZero
)
"""Any mode string of Tabla 23."""

_BARE: dict[str, type[GoHome | Stop | Faster | Slower | StorePartZero]] = {
    c.letter: c for c in (GoHome, Stop, Faster, Slower, StorePartZero)
}


class _Cursor:
    """Reads a mode string field by field, as the firmware's routines do."""

    def __init__(self, text: str, source: str) -> None:
        self.text, self.source, self.pos = text, source, 1

    def fail(self, what: str) -> ParseError:
        return ParseError(
            f"{self.source}: {what} at character {self.pos + 1} of {self.text!r}; "
            "the controller would not run it (UNAM-GMM §3.1)"
        )

    def axis(self) -> Axis:
        """The firmware's "obtén de eje": one of X, Y, Z."""
        char = self.text[self.pos : self.pos + 1]
        if char not in AXES:
            raise self.fail(f"expected an axis X, Y or Z, found {_shown(char)}")
        self.pos += 1
        return cast(Axis, char)

    def sign(self) -> Sign:
        """The firmware's "obtén sentido de giro": any one character; only ``-`` is negative."""
        if self.pos >= len(self.text):
            raise self.fail("expected a direction '+' or '-', found the end")
        char = self.text[self.pos]
        self.pos += 1
        return "-" if char == "-" else "+"

    def digits(self, count: int) -> int:
        """The firmware's "obtención de N dígitos": exactly ``count`` decimal digits."""
        chunk = self.text[self.pos : self.pos + count]
        if len(chunk) != count or not (chunk.isascii() and chunk.isdigit()):
            raise self.fail(f"expected {count} digits, found {_shown(chunk)}")
        self.pos += count
        return int(chunk)

    def end(self) -> None:
        """The firmware's "esperar fin de línea": ``;`` and nothing after it."""
        if self.text[self.pos :] != ";":
            rest = self.text[self.pos :]
            raise self.fail(f"expected ';' to end the string, found {_shown(rest)}")


def _shown(text: str) -> str:
    """``text`` quoted for a message, or "the end" when empty."""
    return repr(text) if text else "the end"


def parse_mode(text: str, *, source: str = "<mode string>") -> ModeString:
    """Read one mode string as the controller's firmware does (UNAM-GMM §3.1, S000-10).

    Args:
        text: one string, ``;`` included, nothing after it (no line end).
        source: the name messages give the string.

    Returns:
        The mode string; any direction character other than ``-`` reads as ``+``.

    Raises:
        ParseError: an unknown first character (G/M lines are not mode strings:
            read them with ``PicMmhPost.parse``), a field the firmware could not
            decode, or no ``;`` right after the fields; names ``source``, the
            character and the string.
    """
    cursor = _Cursor(text, source)
    mode = text[:1]
    if mode in _BARE:
        cursor.end()
        return _BARE[mode]()
    if mode == "J":
        jog = Jog(cursor.axis(), cursor.sign())
        cursor.end()
        return jog
    if mode == "&":
        return _multi(cursor)
    if mode in ("P", "F"):
        axis, sign = cursor.axis(), cursor.sign()
        number = cursor.digits(4 if mode == "P" else 3)
        cursor.end()
        return Steps(axis, sign, number) if mode == "P" else Frequency(axis, sign, number)
    if mode == "B":
        axis = cursor.axis()
        um = cursor.digits(3)
        cursor.end()
        return Backlash(axis, um)
    hint = " (a G/M line: read it with PicMmhPost.parse)" if mode in ("G", "M") else ""
    raise ParseError(
        f"{source}: {text!r} is not a mode string{hint}; the first character selects "
        "the mode: J & P F B H A W V Q (UNAM-GMM Tabla 23)"
    )


def _multi(cursor: _Cursor) -> JogAxes:
    """``&`` then axis/sign pairs until ``;`` (up to three, distinct)."""
    pairs: list[tuple[Axis, Sign]] = []
    while cursor.text[cursor.pos : cursor.pos + 1] != ";" or not pairs:
        if len(pairs) == 3:
            raise cursor.fail("more than three axes")
        axis = cursor.axis()
        if any(axis == a for a, _ in pairs):
            raise cursor.fail(f"axis {axis} twice")
        pairs.append((axis, cursor.sign()))
    cursor.end()
    if len(pairs) == 1:
        raise cursor.fail("'&' with one axis (use J)")
    return JogAxes(tuple(pairs))


def backlash_command(axis: str, um: float) -> str:
    """``B<axis>###;`` for a compensation of ``um`` µm, rounded half up to whole µm.

    Example: ``backlash_command("X", 204.0)`` → ``"BX204;"`` (UNAM-GMM §5.2, the
    final X compensation); ``192.5`` (the first pass) → ``"BX193;"``.

    Raises:
        DialectError: ``axis`` is not X, Y or Z, or ``um`` is not a number that
            rounds to 0–999.
    """
    if isinstance(um, bool) or not isinstance(um, int | float) or not math.isfinite(um):
        raise DialectError(f"backlash {um!r} µm is not a number")
    if not -1e6 < um < 1e6:  # no compensation; and more digits than Decimal's 28 to round
        raise DialectError(f"backlash {um:g} µm does not round to 0–999 µm")
    whole = int(Decimal(repr(float(um))).quantize(Decimal(1), ROUND_HALF_UP))
    return Backlash(cast(Axis, axis.upper() if isinstance(axis, str) else axis), whole).to_string()


def backlash_commands(machine: Machine) -> tuple[str, ...]:
    """The ``B`` strings setting ``machine``'s compensation, one per axis that has one.

    For the ``mmh-gmm`` profile: ``("BX204;", "BY178;")`` (UNAM-GMM §5.2, L2486–L2490).

    Raises:
        DialectError: a compensation does not fit 0–999 µm.
    """
    comp = machine.backlash.compensation_um
    return tuple(backlash_command(a, um) for a, um in zip(AXES, comp, strict=True) if um > 0)


# -- the host link ------------------------------------------------------------------------

RECEIVE_BUFFER = 35
"""Elements of the firmware's receive vector ``CadenaControl`` (L1739–L1744)."""
FEEDBACK = 0x80
"""Bit 7 marks a feedback byte (camtool's assumption: the thesis gives no encoding)."""
_DWELL = re.compile(r"G0?4P(\d+);")


def feedback_byte(axis: int, step: int) -> int:
    """The feedback byte of one motor step: ``axis`` 0 X, 1 Y, 2 Z; ``step`` +1 or −1.

    camtool's assumption (module docstring): ``80H | axis << 1 | (step < 0)``.
    """
    return FEEDBACK | axis << 1 | (1 if step < 0 else 0)


def is_feedback(answer: str) -> bool:
    """True for a feedback byte (one motor step), False for an echo."""
    return len(answer) == 1 and ord(answer) & 0xF8 == FEEDBACK and ord(answer) & 0x07 < 6


def frame(code: bytes, spec: LinkSpec, source: str) -> list[WireBlock]:
    """One block per non-empty line: the ``;``-ended string, without the line end.

    Raises:
        InputError: a line that is not one string ending with ``;``, naming it.
    """
    end = spec.block_end
    blocks: list[WireBlock] = []
    for number, raw in enumerate(code.split(b"\n"), start=1):
        data = raw.rstrip(b"\r")
        if not data.strip():
            continue
        if not data.endswith(end) or data.count(end) != 1:
            raise InputError(
                f"{source}, line {number}: {data.decode('latin-1')!r} is not one string ending "
                f"with {end.decode('latin-1')!r} (UNAM-GMM §2.4): one block per line"
            )
        blocks.append(WireBlock(len(blocks) + 1, number, number, data))
    return blocks


def split_answers(buffer: bytearray) -> list[str]:
    """The PIC's answers in ``buffer`` (taken out): feedback bytes, and echoes up to ``;``.

    Line ends between answers are skipped (the thesis does not say the echo has one).
    """
    out: list[str] = []
    while buffer:
        first = buffer[0]
        if first & FEEDBACK or first in b"\r\n":
            if first & FEEDBACK:
                out.append(chr(first))
            del buffer[0]
            continue
        cut = buffer.find(b";")
        if cut < 0:
            break
        out.append(buffer[: cut + 1].decode("latin-1"))
        del buffer[: cut + 1]
    return out


def step_events(program: Program, machine: Machine) -> dict[int, bytes]:
    """The feedback bytes each source line's moves send, by camtool's interpolator.

    The verifier's step simulation (:func:`camtool.verify.trace_sources.simulate`:
    the DDA and DSM of annexes A.3/A.6, backlash compensation included) gives
    each move's step rows; every non-zero entry is one motor step, one byte.
    """
    from camtool.verify.trace_sources import simulate

    if not program.moves:
        return {}
    return _events_by_line(simulate(program, machine), program)


def _events_by_line(trace: StepTrace, program: Program) -> dict[int, bytes]:
    """:func:`step_events` of ``program`` from its step simulation ``trace``."""
    out: dict[int, bytearray] = {}
    for move in range(len(program.moves)):
        line = program.line_of(move) or 0
        rows = trace.rows[trace.block_start[move] : trace.block_start[move + 1]]
        data = out.setdefault(line, bytearray())
        for row in rows.tolist():
            data += bytes(feedback_byte(axis, v) for axis, v in enumerate(row) if v)
    return {line: bytes(data) for line, data in out.items()}


def expect(blocks: Sequence[WireBlock], program: Program, target: Target) -> list[WireBlock]:
    """Each block with its feedback count (motor steps) and a dwell's seconds.

    Raises:
        DialectError: a ``G28`` block (homing: its step count is unknown).
    """
    events = step_events(program, target.machine)
    out = []
    for block in blocks:
        text = block.text
        if text.startswith("G28"):
            raise DialectError(
                f"line {block.line}: {text} homes to the switches: camtool cannot know its step "
                "count, so it could not tell when the homing ends (a new string would abort "
                "it); home at the machine ('H;') and send the program without G28"
            )
        dwell = _DWELL.fullmatch(text)
        out.append(
            replace(
                block,
                events=len(events.get(block.line, b"")),
                busy_s=float(dwell.group(1)) if dwell else 0.0,
            )
        )
    return out


def resume(before: Sequence[WireBlock], first: WireBlock, spec: LinkSpec) -> list[WireBlock]:
    """The spindle string still on before ``first`` (the PIC keeps everything else)."""
    spindle = None
    for block in before:
        if block.text.startswith(("M03", "M04")):
            spindle = block.data
        elif block.text.startswith("M05"):
            spindle = None
    return [WireBlock(0, 0, 0, spindle)] if spindle else []


class PicMmhDevice(Device):
    """A simulated PIC18F8720 controller: echo, one feedback byte per step, abort, 35 characters.

    A string (up to ``;``) is stored and echoed; a G/M line is read with
    camtool's reader in the context of the lines run before it, and its motion
    is the steps of camtool's interpolator for it, sent as feedback bytes
    (:func:`feedback_byte`) ``steps_per_tick`` at a time. Anything received
    while a motion runs aborts it (the PIC checks its receive flag after every
    step, L1801–L1807): :attr:`aborted` lists ``(block, steps sent, steps)``, and a
    ``G00`` line to where the motion stopped joins :attr:`executed` (the PIC's position
    after the steps it made: a block sent again makes only the steps left of it).
    ``A;`` stops a motion too (:attr:`stops`). Mode strings are echoed and
    otherwise not modelled.

    ``fail_at_block`` is a transmission error: the PIC stores that string with
    its last digit changed (echoed and run as misread); ``drop_at_block``
    closes the port when that string arrives; :attr:`stop_after` ``(block, steps)``
    stops that block's motion after so many steps, silently (a stop at the machine).

    Args:
        spec: the pic-mmh link.
        on_the_fly: the firmware parses fields as they arrive, so a string of
            any length fits (the evidence of the thesis's 43-character G02);
            False: a strict :data:`RECEIVE_BUFFER`-character buffer, the
            characters after the 35th are lost (the ``;`` still ends the string).
        steps_per_tick: feedback bytes sent per :meth:`step`.
        **options: as :class:`camtool.link.device.Device`.
    """

    def __init__(
        self,
        spec: LinkSpec,
        *,
        on_the_fly: bool = True,
        steps_per_tick: int = 40,
        **options: Any,
    ) -> None:
        super().__init__(spec, **options)
        self.on_the_fly = on_the_fly
        self.steps_per_tick = steps_per_tick
        self.rx = bytearray()
        self.length = 0
        self.motion = bytearray()
        self.motion_steps = 0
        self.running: bytes | None = None
        self.stepping: tuple[StepTrace, Program, int] | None = None
        self.stop_after: tuple[int, int] | None = None
        self.aborted: list[tuple[int, int, int]] = []
        self.stops = 0
        self.lost = 0
        self.longest = 0

    def feed(self, data: bytes) -> bytes:
        """Store the characters (a strict buffer loses those past the 35th); no answer."""
        for byte in data:
            if byte == ord(";"):
                self.length = 0
            elif not self.on_the_fly and self.length >= RECEIVE_BUFFER - 1:
                self.lost += 1
                continue
            else:
                self.length += 1
            self.rx.append(byte)
        return b""

    def pending(self) -> bool:
        """A motion runs, or a whole string waits."""
        return bool(self.motion) or b";" in self.rx

    def step(self) -> bytes:
        """Send the next feedback bytes, or take, echo and start the next string."""
        if self.motion:
            if self.rx:  # a new string arrived: "Alto" (L1801-L1807)
                self._abort()
                return b""
            count = self.steps_per_tick
            if self.stop_after is not None and self.stop_after[0] == len(self.blocks):
                count = min(count, self.stop_after[1] - (self.motion_steps - len(self.motion)))
                if count <= 0:  # stopped at the machine: no more steps, nothing said
                    self.stop_after = None
                    self._abort()
                    return b""
            batch = bytes(self.motion[:count])
            del self.motion[:count]
            if not self.motion and self.running is not None:
                self.executed.append(self.running)
                self.running = None
            return batch
        cut = self.rx.find(b";")
        if cut < 0:
            return b""
        string = bytes(self.rx[: cut + 1])
        del self.rx[: cut + 1]
        return self._string(string)

    def _abort(self) -> None:
        done = self.motion_steps - len(self.motion)
        self.aborted.append((len(self.blocks), done, self.motion_steps))
        self.motion.clear()
        if self.running is not None and done and self.stepping is not None:
            self.executed.append(self._stopped_at(done, *self.stepping))
        self.running = None

    def _stopped_at(self, done: int, trace: StepTrace, program: Program, line: int) -> bytes:
        """A ``G00`` line to where the PIC stands after ``done`` feedback bytes of ``line``.

        The PIC's logical position (whole steps: the steps of the line's rows sent so
        far, backlash-compensation rows left out, from where the line started), so that
        what runs next starts there, as on the machine: the same line sent again makes
        only the steps left of it.
        """
        moves = [m for m in range(len(program.moves)) if program.line_of(m) == line]
        first, last = moves[0], moves[-1]
        rows = slice(int(trace.block_start[first]), int(trace.block_start[last + 1]))
        moved, count = [0, 0], 0
        for row, compensation in zip(
            trace.rows[rows].tolist(), trace.compensation[rows].tolist(), strict=True
        ):
            for axis, step in enumerate(row):
                if step and count < done:
                    count += 1
                    moved[axis] += 0 if compensation else step
        start = trace.logical_end[first - 1] if first else (0, 0)
        assert self.target is not None
        per_mm = self.target.machine.steps_per_mm
        x, y = ((int(start[a]) + moved[a]) / per_mm[a] for a in (0, 1))
        coord = self.target.post.coord  # type: ignore[attr-defined]
        return f"G00X{coord.format(x)}Y{coord.format(y)};\n".encode()

    def _string(self, string: bytes) -> bytes:
        self.received += string
        self.blocks.append(string)
        self.longest = max(self.longest, len(string))
        number = len(self.blocks)
        if number == self.drop_at_block:
            self.dropped = True
            return b""
        if number == self.fail_at_block:
            string = _misread(string)
        text = string.decode("latin-1")
        if text == "A;":
            self.stops += 1
        elif text[:1] in ("G", "M"):
            self._run(string)
        return string

    def _run(self, string: bytes) -> None:
        """Start the motion of a G/M line: camtool's steps for it, after the lines run so far."""
        assert self.target is not None
        lines = [*(s.rstrip(b"\n") for s in self.executed), string]
        code = b"\n".join(lines).decode("latin-1") + "\n"
        try:
            program = self.target.parse(code)
        except ParseError:
            return  # "no ejecuta tarea alguna" (L1755-L1757)
        from camtool.verify.trace_sources import simulate

        trace = simulate(program, self.target.machine) if program.moves else None
        events = {} if trace is None else _events_by_line(trace, program)
        self.motion = bytearray(events.get(len(lines), b""))
        self.motion_steps = len(self.motion)
        self.stepping = None if trace is None else (trace, program, len(lines))
        line = string + b"\n"
        if self.motion:
            self.running = line
        else:
            self.executed.append(line)


def _misread(string: bytes) -> bytes:
    """``string`` with its last digit changed (a transmission error the echo shows)."""
    digits = [i for i, c in enumerate(string) if chr(c).isdigit()]
    if not digits:
        return string
    i = digits[-1]
    return string[:i] + str((int(chr(string[i])) + 1) % 10).encode() + string[i + 1 :]


LINK = LinkHooks(
    frame=frame,
    split=split_answers,
    feedback=is_feedback,
    expect=expect,
    resume=resume,
    device=PicMmhDevice,
)
"""pic-mmh's link hooks (``camtool send -t pic-mmh``, ``camtool simulate-device -t pic-mmh``)."""
