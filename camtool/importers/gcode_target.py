"""What a G-code program is read for: the target's side of the reader, and its length offsets.

A program re-posted for a target is read knowing what that target writes (:class:`Reading`):
the feed ``post --feed`` gives cuts before the first F word, whether the target applies the
tool table's length offsets itself (LinuxCNC's ``G43 H<n>`` after each change to tool ``n``),
and which work offset codes it writes. Where it applies length offsets, the program's own
``G43``/``G49`` are kept where they are (:class:`LengthOffsets`); dropped, the tool stood a
tool length off (LinuxCNC's ``rs274`` shows it as ``USE_TOOL_LENGTH_OFFSET``).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Iterable, Iterator
from dataclasses import dataclass

from camtool.importers.gcode_codes import BlockWords, Code, CommandReader
from camtool.model.errors import InputError
from camtool.model.program import Command, LengthOffset, Move, PathControl, ToolChange


@dataclass(frozen=True)
class Reading:
    """How a program is read for the target it is posted to.

    Attributes:
        feed_mm_min: the feed of cuts before the program's first F word, mm/min (``post
            --feed``, which then sets every cut's feed); ``None``: such a cut is refused.
        length_offsets: the target applies tool length offsets itself (a dialect with
            ``tool_length_offset``): the program's ``G43`` and ``G49`` are kept
            (:class:`LengthOffsets`); otherwise they are read as no offset, with a warning.
        work_offsets: the work offset codes the target writes (``G54`` …, its dialect's
            ``work_offsets``): the one the program selects, if among them, is a
            ``WorkOffset`` command written before its first move; otherwise it is read as
            the part zero, with a warning.
        path_controls: the path control codes the target writes (``G61``, ``G61.1``,
            ``G64``; its dialect's ``path_controls``): the program's are kept as
            :class:`~camtool.model.program.PathControl` commands (:func:`path_control`);
            otherwise they are ignored, with a warning.
        known_start: the program is written again: a move whose end or centre depends on
            where the machine stands before the program gives X and Y (an incremental X
            or Y, a move naming one of them, an arc) is refused, naming its line;
            otherwise it is read from the program's zero, the reader's guess (RS-274/NGC
            and GRBL start from the machine's position, which camtool cannot know).
    """

    feed_mm_min: float | None = None
    length_offsets: bool = False
    work_offsets: tuple[str, ...] = ()
    known_start: bool = False
    path_controls: tuple[str, ...] = ()

    def keeps(self, code: Code) -> bool:
        """Whether a code the reader otherwise ignores with a warning is kept for the target."""
        if code.group == "length":
            return self.length_offsets
        return code.name in (self.work_offsets if code.group == "coord" else self.path_controls)


READ_AS_WRITTEN = Reading()
"""No feed given, no offsets kept: a program read for no target in particular."""


class LengthOffsets:
    """G43/G49 of a program read for a target that writes ``G43 H<n>`` after each change.

    A ``G43`` after the change to its tool and before any Z move is the one the target
    writes with the change (an XY move between, as in ``T1 M6``, ``G0 X Y``, ``G43 H1 Z2``,
    does not depend on it; LinuxCNC's ``G43`` without H takes the tool in the spindle); a
    change without one is written without one (:attr:`ToolChange.length_offset`); any other
    ``G43``, and a ``G49`` that cancels an offset, is a :class:`LengthOffset` command
    written where the program had it.

    Args:
        commands: the reader's commands (its tool changes, and where these go).
        moves: the reader's moves, read as they grow.
    """

    def __init__(self, commands: CommandReader, moves: list[Move]) -> None:
        self.commands, self.moves = commands, moves
        self.on = False  # a G43 applied an offset that no G49 cancelled since
        self.own: set[int] = set()  # id() of the changes whose G43 is their own
        self.written: set[int] = set()  # id() of the changes a LengthOffset followed
        self.z_scan: tuple[ToolChange | None, int, bool] = (None, 0, False)

    def block(self, w: BlockWords, where: str) -> None:
        """The block's ``G43`` or ``G49``, if any (before its motion).

        Raises:
            InputError: a ``G43`` without H before any tool change (the tool in the
                spindle is not known).
        """
        code = w.g_name("length")
        if code == "G43":
            h = w.args.get("H")
            last = self.commands.last_change
            changed = None if last is None else last[1].tool
            wanted = changed if h is None else round(h.value)
            if wanted is None:
                raise InputError(
                    f"{where}: G43 without H before any tool change: the tool whose length "
                    "offset it applies is the one in the spindle, which the program does "
                    "not say; write G43 H<n> with the tool's number"
                )
            if (
                last is not None
                and wanted == changed
                and id(last[1]) not in self.written
                and not self._z_since(*last)
            ):
                self.own.add(id(last[1]))
            else:
                self._write(LengthOffset(int(wanted)))
            self.on = True
        elif code == "G49" and self.on:
            self._write(LengthOffset(None))
            self.on = False

    def _write(self, offset: LengthOffset) -> None:
        """``offset`` where the program has it; after it, no G43 is the last change's own."""
        self.commands.add(len(self.moves), offset)
        if self.commands.last_change is not None:
            self.written.add(id(self.commands.last_change[1]))

    def _z_since(self, index: int, change: ToolChange) -> bool:
        """Whether a move since ``change`` (before move ``index``) gave Z (each move seen once)."""
        seen, upto, moved = self.z_scan
        if seen is not change:
            upto, moved = index, False
        moves = self.moves
        moved = moved or any(moves[i].z is not None for i in range(upto, len(moves)))
        self.z_scan = (change, len(moves), moved)
        return moved

    def commands_out(
        self, commands: Iterable[tuple[int, Command]]
    ) -> Iterator[tuple[int, Command]]:
        """``commands``, each tool change that had no G43 of its own saying so."""
        for index, command in commands:
            if isinstance(command, ToolChange) and id(command) not in self.own:
                command = dataclasses.replace(command, length_offset=False)
            yield index, command


def path_control(w: BlockWords, code: str, scale: float, where: str) -> PathControl:
    """The block's path control mode ``code``, its G64 P and Q in mm (``scale``: mm per unit).

    Raises:
        InputError: a negative tolerance (LinuxCNC refuses it too), naming ``where``.
    """
    p, q = w.args.get("P"), w.args.get("Q")
    for word in (p, q):
        if code == "G64" and word is not None and word.value < 0:
            raise InputError(f"{where}: G64 {word}: a blending tolerance is ≥ 0 (0: no limit)")
    if code != "G64":
        return PathControl(code)
    return PathControl(
        code,
        None if p is None else p.value * scale,
        None if q is None else q.value * scale,
    )
