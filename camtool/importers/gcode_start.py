"""A program's first moves: where the machine stands before the program gives X and Y.

A controller (LinuxCNC, GRBL) runs a program from wherever the tool stands; until the
program gives X and Y, the reader's (0, 0) is a guess (RS-274/NGC: an axis a block does
not name keeps its current position, and G91 moves from there). Read to be written again
(:attr:`~camtool.importers.gcode_target.Reading.known_start`), a move that depends on the
guess is refused here, naming its line: written from the guess it would be a move the
program did not ask for. Rules: docs/importers/gcode.md.
"""

from __future__ import annotations

from camtool.importers.gcode_lexer import Word
from camtool.importers.gcode_plain import PlainLines
from camtool.model.errors import InputError


class StartRules(PlainLines):
    """The reader's checks of its first moves (mixed into the reader, as :class:`PlainLines`).

    Attributes: the reader's; ``source`` names the file in messages, ``known_start`` is
    :attr:`Reading.known_start <camtool.importers.gcode_target.Reading.known_start>`.
    """

    source: str
    known_start: bool

    def where(self) -> str:
        """``FILE:LINE`` of the block being read, for messages."""
        return f"{self.source}:{self.line}"

    def check_first_xy(self, args: dict[str, Word], name: str) -> None:
        """For a program written again, refuse a first straight move that needs the start.

        Until the program gives X and Y, the reader's (0, 0) is a guess: a controller
        starts from wherever the tool stands. An absolute move naming both axes ends at
        the same point either way; one naming a single axis keeps the other axis where
        the machine stands, and an incremental one moves from there. Either would be
        written again from the guess (``G0 X3`` as ``G0 X3 Y0``), a move the program
        did not ask for, so both are refused, as an incremental Z before any absolute
        Z is (RS-274/NGC: the axes not named keep their current position).

        Raises:
            InputError: the move names one of X and Y, or names them in G91.
        """
        given = [letter for letter in "XY" if letter in args]
        if not self.absolute:
            word = args[given[0]]
            raise InputError(
                f"{self.where()}: incremental {word} (G91) before the program gives an "
                "absolute X and Y: the machine would move from wherever it stands, which "
                "camtool cannot know; give an absolute X and Y (G90) first, e.g. "
                "G90 G0 X0 Y0 if the program starts at the work zero"
            )
        if len(given) == 1:
            other = "Y" if given[0] == "X" else "X"
            raise InputError(
                f"{self.where()}: {name} {args[given[0]]} gives {given[0]} but not {other}, "
                f"and the program has not given {other} yet: the machine would keep the "
                f"{other} it stands at, which camtool cannot know; give both X and Y in the "
                "program's first move (e.g. G0 X0 Y0 if it starts at the work zero)"
            )

    def refuse_first_arc(self, name: str) -> None:
        """Refuse an arc before the program gives X and Y: its centre and end depend on its start.

        Raises:
            InputError: always, naming the line and the remedy.
        """
        raise InputError(
            f"{self.where()}: {name} starts from where the machine stands before the "
            "program gives an X and Y, which camtool cannot know: the arc's centre and "
            "end depend on it; move there first with G0 and absolute X and Y (e.g. "
            "G0 X0 Y0 if the program starts at the work zero)"
        )
