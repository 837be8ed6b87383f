"""The non-motion words of a G-code block kept as :data:`camtool.model.program.Command` values.

Spindle (``S``, ``M3``/``M4``/``M5``), dwell (``G4 P``), tool change (``T``,
``M6``) and return to machine zero (``G28``) become :attr:`Program.commands`,
each before the move that follows it, so that a target whose dialect has them
(e.g. pic-mmh ``M03S####;``, ``G04P##;``, ``M06T##;``, ``G28X0Y0;``, seed-000
Tablas 21–22) writes them again. Within a block they run in the RS-274/NGC
order of execution (LinuxCNC "Order of Execution"): ``S``, ``T``, ``M6``,
``M3``/``M4``/``M5``, ``G4``, then ``G28`` and the motion.

Rules:

- ``S`` is modal (rev/min, ≥ 0). ``M3``/``M4`` start the spindle at the last
  ``S`` (without any ``S`` before, as Gcodetools writes a bare ``M3``: 0 rev/min,
  the speed is not programmed); an ``S`` while the spindle turns changes its
  speed (a new spindle command); ``M5`` stops it.
- ``T`` selects a tool (a whole number ≥ 0); ``M6`` changes to the selected
  tool. A ``T`` that no ``M6`` uses, or an ``M6`` with no tool selected, is
  ignored with a warning.
- ``G4 P`` is a dwell of ``P`` seconds (LinuxCNC units).
"""

from __future__ import annotations

from camtool.importers.gcode_codes import BlockWords, Notes
from camtool.model.errors import InputError
from camtool.model.program import Command, Dwell, Spindle, SpindleDirection, ToolChange


class CommandReader:
    """Spindle, tool and dwell state of the interpreter, and the commands read so far."""

    def __init__(self, notes: Notes) -> None:
        """Collect commands; ``notes`` receives the warnings."""
        self.notes = notes
        self.commands: list[tuple[int, Command]] = []
        self.rpm: float | None = None
        self.direction: SpindleDirection = "off"
        self.tool: int | None = None
        self.tool_line = 0
        self.tool_used = True

    def add(self, index: int, command: Command) -> None:
        """Keep ``command`` to run before move ``index``."""
        self.commands.append((index, command))

    def block(self, w: BlockWords, index: int, line: int, where: str) -> None:
        """Read the S, T, M6, M3/M4/M5 and G4 words of one block (before its motion).

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
        if w.g_name("nonmodal") == "G4":
            p = w.args.get("P")
            if p is None or p.value < 0:
                raise InputError(f"{where}: G4 dwell needs a P word (seconds, ≥ 0)")
            self.add(index, Dwell(p.value))

    def finish(self) -> None:
        """Warn about a selected tool that no M6 used (call after the last block)."""
        if not self.tool_used:
            self._unused_tool()

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
            "tool number T ignored: no M6 after it changes to that tool",
        )
        self.tool_used = True

    def _change(self, index: int, line: int) -> None:
        if self.tool is None:
            self.notes.add("M6", line, "M6 without a T word: no tool selected, ignored")
            return
        self.add(index, ToolChange(self.tool))
        self.tool_used = True

    def _spindle(self, name: str, index: int) -> None:
        if name == "M5":
            self.direction = "off"
            self.add(index, Spindle("off"))
            return
        self.direction = "cw" if name == "M3" else "ccw"
        self.add(index, Spindle(self.direction, self.rpm or 0.0))
