"""Canned drilling cycles in a program read from code: G81, G82, G83 and G73 as LinuxCNC runs them.

A cycle block (``G98 G81 X10 Y5 Z-2 R1 F80``, and each later block of the same series that
gives only ``X``/``Y``) is read as a :class:`~camtool.model.program.DrillCycle` command and
the rapids and feeds :func:`camtool.model.drilling.expand` makes of it, so every consumer
sees plain moves and a dialect with cycles may write the cycle again. The rules are
LinuxCNC's (G-code reference "G81", "G82", "G83", "G73", "G98, G99"; ``interp_cycles.cc``
``convert_cycle_xy``): ``R`` and ``Z`` are required in the block that starts a cycle and
kept for the blocks after it (so are ``Q`` and ``P``); G98 returns to the height the
series began at (or the R plane, if that is higher), G99 to the R plane. What camtool
does not read is refused with the line: incremental cycles (G91), repeats (``L``),
cycles in the ZX or YZ plane, and a series that changes between G98 and G99.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

from camtool.importers.gcode_lexer import Word
from camtool.model.drilling import expand
from camtool.model.errors import InputError
from camtool.model.program import DrillCycle, DrillKind, Dwell, Move

CYCLES: dict[str, DrillKind] = {"G81": "drill", "G82": "drill", "G83": "peck", "G73": "chip-break"}
"""The cycles read, and the kind of hole each drills."""


@dataclass
class CycleState:
    """What a series of cycle blocks keeps from one block to the next, mm and seconds.

    LinuxCNC's sticky ``cycle_r``, ``cycle_cc``, ``cycle_q``, ``cycle_p``, its motion mode
    and ``cycle_il`` (the height the series began at).
    """

    retract: Literal["initial", "r-plane"] | None = None  # None: no G98/G99 read yet
    r_z: float | None = None
    bottom_z: float | None = None
    peck_mm: float | None = None
    dwell_s: float | None = None
    last: str | None = None  # the cycle of the block before (LinuxCNC's motion mode)
    initial_z: float | None = None  # the height the series began at (``cycle_il``)
    series_retract: str | None = None
    note: Callable[[str], None] = lambda text: None  # a warning for the line being read

    def end_series(self) -> None:
        """A block that is no cycle: the next cycle starts a series (and needs R and Z)."""
        self.last = self.initial_z = self.series_retract = None

    def hole(
        self,
        code: str,
        args: dict[str, Word],
        here: tuple[float | None, float | None, float | None],
        feed_mm_min: float,
        scale: float,
        modes: tuple[bool, str],
        where: str,
    ) -> tuple[DrillCycle, list[Move | Dwell]]:
        """The cycle of one block (its ``moves`` counted) and its moves, from ``here`` (mm).

        Args:
            code: the cycle (a key of :data:`CYCLES`).
            args: the block's words.
            here: the tool's position; ``None`` where the program has not given it.
            feed_mm_min: the feed into the material.
            scale: mm per unit of the block's numbers.
            modes: whether distances are absolute (G90), and the plane (``"xy"``: G17).
            where: ``file:line``, for messages.

        Raises:
            InputError: a word the cycle needs is missing, a value is out of range, the
                position is not known, or the block asks for what camtool does not read.
        """
        absolute, plane = modes
        if not absolute or plane != "xy":
            mode = "the ZX or YZ plane" if absolute else "G91"
            raise InputError(
                f"{where}: {code} in {mode} is not read; write the cycle in G90 and G17 (XY)"
            )
        starts = self.last != code
        for letter, kept in (("R", self.r_z), ("Z", self.bottom_z)):
            if letter not in args and (starts or kept is None):
                raise InputError(f"{where}: {code} needs {letter} in the block that starts it")
        r_z = args["R"].value * scale if "R" in args else self.r_z
        bottom_z = args["Z"].value * scale if "Z" in args else self.bottom_z
        assert r_z is not None and bottom_z is not None
        peck = self._sticky(code, args, "Q", ("G83", "G73"), self.peck_mm, scale, where)
        dwell = self._sticky(code, args, "P", ("G82",), self.dwell_s, 1.0, where)
        hx, hy, hz = here
        if hx is None or hy is None or hz is None:
            raise InputError(
                f"{where}: {code} starts where the tool's position is not known; give X, Y "
                "and Z absolutely (G0) before the cycle"
            )
        x = args["X"].value * scale if "X" in args else hx
        y = args["Y"].value * scale if "Y" in args else hy
        if not bottom_z < r_z:
            raise InputError(
                f"{where}: {code} bottom Z{bottom_z / scale:g} is not below R{r_z / scale:g}"
            )
        retract = self.retract or "initial"
        if self.retract is None:
            self.note(
                f"{code} with neither G98 nor G99 given: it returns to the height its series "
                "began at (G98, as Fanuc and Haas controls start); LinuxCNC starts in G99 and "
                "would return to the R plane, lower; write G98 or G99 to say which"
            )
        if self.initial_z is None:
            self.initial_z, self.series_retract = hz, retract
        elif self.series_retract != retract:
            raise InputError(
                f"{where}: the cycle series changes between G98 and G99; end it with G80 "
                "and start the next series with its own R and Z"
            )
        start_z = self.initial_z if retract == "initial" else hz
        cycle = DrillCycle(
            CYCLES[code],
            x,
            y,
            bottom_z,
            r_z,
            feed_mm_min,
            peck_mm=peck,
            dwell_s=dwell or 0.0,
            retract=retract,
        )
        items = expand(cycle, (hx, hy, start_z))
        self.r_z, self.bottom_z, self.last = r_z, bottom_z, code
        self.peck_mm = peck if peck is not None else self.peck_mm
        self.dwell_s = dwell if dwell is not None else self.dwell_s
        count = sum(not isinstance(item, Dwell) for item in items)
        return dataclasses.replace(cycle, moves=count), items

    def _sticky(
        self,
        code: str,
        args: dict[str, Word],
        letter: str,
        codes: tuple[str, ...],
        kept: float | None,
        scale: float,
        where: str,
    ) -> float | None:
        """``Q`` (peck, mm) or ``P`` (dwell, s) for the cycles in ``codes``; ``None`` else."""
        if code not in codes:
            return None
        if letter in args:
            value = args[letter].value * scale
        elif self.last == code and kept is not None:
            value = kept
        else:
            raise InputError(f"{where}: {code} needs {letter} in the block that starts it")
        if letter == "Q" and not value > 0:
            raise InputError(f"{where}: {code} peck Q{value / scale:g} must be above 0")
        if letter == "P" and value < 0:
            raise InputError(f"{where}: {code} dwell P{value:g} must not be negative")
        return value
