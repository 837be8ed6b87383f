"""Mode strings of the pic-mmh host link: jog, steps, frequency, backlash, home, stop.

Source: seed-000 §3.2 (Tabla 23, annex A.2, L3474–L3505) and §3.1 (how the
firmware decodes a string, Fig. 37, L1739–L1770); requirement S000-10. Each
string is sent on its own over RS-232 and ends with ``;``:

=========================  ================  =====================================
mode                       example (thesis)  class
=========================  ================  =====================================
joystick, one axis         ``JX+;``          :class:`Jog`
joystick, 2–3 axes         ``&X+Y-Z+;``      :class:`JogAxes`
steps (4 digits)           ``PX+1000;``      :class:`Steps`
run at a frequency (3 d.)  ``FX+250;``       :class:`Frequency`
set backlash (3 d., µm)    ``BX200;``        :class:`Backlash`
home                       ``H;``            :class:`GoHome`
stop ("alto")              ``A;``            :class:`Stop`
speed up / slow down       ``W;`` ``V;``     :class:`Faster` :class:`Slower`
store part zero            ``Q;``            :class:`StorePartZero`
=========================  ================  =====================================

G and M lines (the "line / program" mode) are written and read by
:class:`camtool_postprocessors.pic_mmh.PicMmhPost`, not here.

The parser :func:`parse_mode` reads as the firmware does (§3.1): the first
character alone selects the mode, the fields follow in a fixed order, the
direction character may be anything but only ``-`` means negative
("antihorario"; anything else is clockwise, L1765–L1768), digits must be
digits, and the string must end with ``;`` (L1743, "de no ser así, el código es
erróneo"). The classes (camtool's builder) are stricter: the axis is X, Y or Z,
the direction ``+`` or ``-``, and a number must fit its field.

Assumptions (the thesis does not say): the ``F`` number is a frequency in Hz,
the ``B`` number is µm (204 and 178 µm, the final compensations, fit 3 digits;
in steps they would not, §3.2 notes); which way "+" turns an axis is not
documented (§4.6).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from decimal import ROUND_HALF_UP, Decimal
from typing import ClassVar, Literal, TypeAlias, cast

from camtool.model.errors import DialectError, ParseError
from camtool.model.machine import Machine

Axis: TypeAlias = Literal["X", "Y", "Z"]
"""An axis letter of the mode strings (seed-000 §3.6 ``axis``)."""
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
        raise DialectError(f"axis {axis!r} is not one of X, Y, Z (seed-000 §3.2)")


def _check_sign(sign: str) -> None:
    if sign not in ("+", "-"):
        raise DialectError(f"direction {sign!r} is not '+' or '-' (seed-000 §3.2)")


def _check_count(what: str, value: int, most: int, unit: str) -> None:
    if isinstance(value, bool) or not isinstance(value, int) or not 0 <= value <= most:
        digits = len(str(most))
        raise DialectError(
            f"{what} {value!r} does not fit {digits} digits (0–{most} {unit}, seed-000 Tabla 23)"
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

    The unit is presumed Hz (seed-000 §3.2 notes); the serial link limits the
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
            "the controller would not run it (seed-000 §3.1)"
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
    """Read one mode string as the controller's firmware does (seed-000 §3.1, S000-10).

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
        "the mode: J & P F B H A W V Q (seed-000 Tabla 23)"
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

    Example: ``backlash_command("X", 204.0)`` → ``"BX204;"`` (seed-000 §5.2, the
    final X compensation); ``192.5`` (the first pass) → ``"BX193;"``.

    Raises:
        DialectError: ``axis`` is not X, Y or Z, or ``um`` is not a number that
            rounds to 0–999.
    """
    if isinstance(um, bool) or not isinstance(um, int | float) or not math.isfinite(um):
        raise DialectError(f"backlash {um!r} µm is not a number")
    whole = int(Decimal(repr(float(um))).quantize(Decimal(1), ROUND_HALF_UP))
    return Backlash(cast(Axis, axis.upper() if isinstance(axis, str) else axis), whole).to_string()


def backlash_commands(machine: Machine) -> tuple[str, ...]:
    """The ``B`` strings setting ``machine``'s compensation, one per axis that has one.

    For the ``mmh-gmm`` profile: ``("BX204;", "BY178;")`` (seed-000 §5.2, L2486–L2490).

    Raises:
        DialectError: a compensation does not fit 0–999 µm.
    """
    comp = machine.backlash.compensation_um
    return tuple(backlash_command(a, um) for a, um in zip(AXES, comp, strict=True) if um > 0)
