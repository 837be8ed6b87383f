"""The words and blocks of the word-address writer: numbers in each word's format, modal words.

:class:`WordWriter` holds what the controller has been told (the words last written, the
position as written) and writes blocks of words; :class:`~camtool.post.wordaddress_write.
BlockWriter` writes a program's moves and commands with it.
"""

from __future__ import annotations

import math

from camtool.model.errors import DialectError
from camtool.model.machine import Machine
from camtool.model.program import Linear, Program, Rapid, Spindle
from camtool.model.shapes import Point
from camtool.post.base import WriterState, check_written_z, far_from_zero
from camtool.post.wordaddress_spec import WordAddressSpec

SAME_MM = 1e-9
"""Exact XY closer than this is the same point (a Z-only move)."""
_PRINTED_KEPT = 1 << 13
"""Coordinates per letter whose text a writer keeps (:meth:`WordWriter._print`)."""
_JOINED_BLOCKS = 4096
"""Blocks a writer holds apart before it joins them into text (:meth:`WordWriter.block`)."""


class WordWriter(WriterState[str]):
    """Writes one program; holds the controller's state as the written code sets it.

    The lines written are :attr:`blocks` (header and comment lines included:
    block numbers in messages are line numbers); what the dialect lacks is
    counted in :attr:`counts` by kind (``"feed"``, ``"spindle"``, ``"z-split"``,
    ``"tiny-arc"``...) and worded once at the end.

    Args:
        spec: the dialect.
        machine: the machine the program is for (work area, Z axis).

    Attributes:
        z: the Z the controller is at, mm (``None``: not set yet).
        written: the XY the controller holds, as written (rounded), mm.
        last: the last text of each word letter (modal words).
        grid_error_mm: largest change of a coordinate rounded to a step grid, mm.
    """

    def __init__(self, spec: WordAddressSpec, machine: Machine) -> None:
        super().__init__()
        self.spec, self.machine = spec, machine
        self.z: float | None = None
        self.by_hand: int | None = None  # a tool changed by hand, no Z written since
        self.spindle: Spindle | None = None  # turning, as last written
        self.speed: str | None = None  # an S word for the next motion block (a new speed)
        self.written: Point = (0.0, 0.0)
        self.last: dict[str, str] = {}
        self.grid_error_mm = 0.0
        self.program = Program(())
        # The formats of the words without a step grid (their text is the number's alone,
        # :meth:`text`) and the readers of every word, looked up once.
        self._formats = {
            letter: word.number.format
            for letter, word in spec.words.items()
            if word.number.grid_mm is None
        }
        self._parses = {letter: word.number.parse for letter, word in spec.words.items()}
        # The text and the value read back of each coordinate already written, by letter
        # and value (:meth:`_print`): the writer prints an arc's end twice (to see whether
        # it prints as its start, then in its block) and every end is read back.
        self._printed: dict[str, dict[float, tuple[str, float]]] = {
            letter: {} for letter in spec.words
        }
        self._quantum: float | None = None
        self._feed_text: tuple[float, str] | None = None
        # GRBL's mc_arc counts an arc's chords as ⌊|θ·r/2| / √($12·(2r − $12))⌋: an arc of
        # radius r ≤ $12/2 divides by zero or by the root of a negative number, and what the
        # controller then does is undefined (the verifier refuses it). Such an arc lies
        # within $12 of its chord, so it is written as a line (a millionth to spare).
        motion = machine.motion
        grbl_chords = motion.arc == "chords" and motion.chords in ("grbl", "grbl:grbl")
        self._arc_floor_mm = motion.chord_tolerance_mm * (1 + 1e-6) if grbl_chords else 0.0
        self._one_part = spec.max_arc_deg >= 360.0  # an arc but a full circle is one block
        _, _, self._cw, self._ccw = spec.motion_codes
        self._modal_g = "G" in spec.modal
        self._absolute_centre = spec.arc_centre == "absolute"
        self._done: list[str] = []  # blocks written out of :attr:`blocks`, as text
        self._done_blocks = 0

    @property
    def count(self) -> int:
        """Blocks written so far (header and comment lines included)."""
        return self._done_blocks + len(self.blocks)

    def where(self, contour: int | None = None, block: int | None = None) -> str:
        """:meth:`WriterState.where`, counting the blocks already joined into text."""
        return super().where(contour, self.count + 1 if block is None else block)

    def _join_blocks(self) -> None:
        """Move :attr:`blocks` into one text, so a long program is not a string a block."""
        end = self.spec.line_end
        self._done.append(end.join(self.blocks) + end)
        self._done_blocks += len(self.blocks)
        self.blocks.clear()

    # -- the program -------------------------------------------------------------

    def block(self, words: list[str]) -> None:
        """Append one block made of ``words``.

        Raises:
            DialectError: the block is longer than ``max_block_bytes``.
        """
        spec = self.spec
        text = spec.separator.join(words) + spec.block_end
        limit = spec.max_block_bytes
        # the size of ASCII text is its length
        if text.isascii() and (limit is None or len(text) + len(spec.line_end) <= limit):
            self.blocks.append(text)
            if len(self.blocks) >= _JOINED_BLOCKS:
                self._join_blocks()
            return
        size = len((text + spec.line_end).encode("ascii"))
        if limit is not None and size > limit:
            raise DialectError(
                f"{self.where()}: {text!r} is {size} bytes with its line end; "
                f"{self.spec.name} takes at most {limit} (max_block_bytes)"
            )
        self.blocks.append(text)

    # -- numbers -----------------------------------------------------------------

    def _z_text(self, z: float) -> str:
        """``z`` in the Z word's format, checked not to cross the top of the stock."""
        text = self.text("Z", z)
        check_written_z(z, self.spec.words["Z"].number.parse(text), self.where())
        return text

    def text(self, letter: str, value: float) -> str:
        """``value`` written in word ``letter``'s format (without the letter).

        Raises:
            DialectError: the number does not fit the word's integer digits.
        """
        plain = self._formats.get(letter)
        if plain is not None:
            try:
                return plain(value)  # no grid: the text alone (an error is worded below)
            except DialectError:
                pass
        number = self.spec.words[letter].number
        try:
            text = number.format(value)
        except DialectError as exc:
            raise DialectError(
                f"{self.where()}: {letter} = {exc} (value {value:g}); "
                f"{self.spec.name} writes at most {number.int_digits} integer digits"
                + (far_from_zero(self.program, letter, number.reach_mm()) if letter in "XY" else "")
            ) from exc
        if number.grid_mm is not None:
            self.grid_error_mm = max(self.grid_error_mm, abs(number.parse(text) - value))
        return text

    def _print(self, letter: str, value: float) -> tuple[str, float]:
        """``value``'s text in word ``letter`` and the value the controller reads from it, mm.

        The same as ``(text, parse(text))`` with :meth:`text` (which is a function of
        ``letter`` and ``value``, its step-grid error a running maximum): kept by value
        (up to :data:`_PRINTED_KEPT` per letter; ``0.0`` and ``-0.0`` print the same).

        Raises:
            DialectError: see :meth:`text` (errors are not kept).
        """
        kept = self._printed[letter]
        known = kept.get(value)
        if known is None:
            text = self.text(letter, value)
            known = (text, self._parses[letter](text))
            if len(kept) >= _PRINTED_KEPT:
                kept.clear()
            kept[value] = known
        return known

    @staticmethod
    def z_only(start: Point, move: Rapid | Linear) -> bool:
        """Whether ``move`` from ``start`` is written as a Z-only block (no X or Y word).

        A move that changes Z and not XY (by :data:`SAME_MM` at most): the module
        docstring.
        """
        return move.z is not None and math.dist(start, (move.x, move.y)) <= SAME_MM

    def written_xy(self, point: Point) -> Point:
        """Where the controller stands after a block that writes X and Y of ``point``, mm.

        Raises:
            DialectError: a number that does not fit its word (:meth:`text`).
        """
        return (self._print("X", point[0])[1], self._print("Y", point[1])[1])

    def _round(self, letter: str, value: float) -> float:
        """``value`` as the controller reads it back after writing."""
        number = self.spec.words[letter].number
        return number.parse(number.format(value))

    def _word(self, letter: str, text: str, words: list[str], *, force: bool = False) -> None:
        """Add ``letter`` + ``text`` unless modal and unchanged; remember it."""
        if force or letter not in self.spec.modal or self.last.get(letter) != text:
            words.append(letter + text)
        self.last[letter] = text

    def _code(self, code: str, words: list[str]) -> None:
        if "G" not in self.spec.modal or self.last.get("G") != code:
            words.append(code)
        self.last["G"] = code
