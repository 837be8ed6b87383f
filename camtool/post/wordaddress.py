"""Word-address dialects declared in TOML: one writer and one reader for all of them.

A target file with ``dialect = "word-address"`` describes its G-code in its
``[dialect_options]`` table (every key: docs/dialects.md); no Python is needed.
The built-in ``flashcut``, ``valcnc``, ``grbl`` and ``linuxcnc`` targets are
such files (postprocessors/*.toml), for example ValCNC (Munoz-22 §3.4)::

Design notes: docs/internals.md, ``camtool/post/wordaddress.py``.
"""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from camtool.model.errors import ParseError
from camtool.model.machine import Machine
from camtool.model.program import (
    ArcMove,
    PlaneArc,
    Program,
)
from camtool.post.base import (
    PostProcessor,
    PostResult,
)
from camtool.post.wordaddress_read import BlockReader, ControllerRefusal
from camtool.post.wordaddress_spec import WordAddressSpec, load_spec
from camtool.post.wordaddress_write import BlockWriter

if TYPE_CHECKING:
    pass


class WordAddressPost(PostProcessor):
    """Writer and reader of one word-address dialect.

    Args:
        spec: the dialect (see :func:`load_spec`).

    The one output format is ``"code"``, with the file ending ``spec.suffix``.
    """

    def __init__(self, spec: WordAddressSpec) -> None:
        self.spec = spec
        # formats is a class attribute elsewhere; each spec has its own file ending.
        vars(self)["formats"] = MappingProxyType({"code": spec.suffix})

    @property
    def z_with_xy(self) -> bool:
        """True when the spec writes Z in the XY block (``z_moves = "with-xy"``)."""
        return self.spec.z_moves == "with-xy"

    @property
    def helix(self) -> bool:
        """True when the spec lets an arc carry a Z word (``helix = true``)."""
        return self.spec.helix

    @property
    def planes(self) -> bool:
        """True when the spec writes arcs in the ZX and YZ planes (``planes = true``)."""
        return self.spec.planes

    def resolution_mm(self) -> float | None:
        """The coarsest resolution of the X, Y, I and J words, mm (``spec.quantum_mm()``)."""
        return self.spec.quantum_mm()

    def written_z(self, z: float, machine: Machine) -> float | None:
        """``z`` as the Z word prints it, read back (``None``: no Z word)."""
        word = self.spec.word("Z")
        if word is None:
            return None
        return word.number.parse(word.number.format(z))

    @property
    def writes_feeds(self) -> bool:
        """True when the spec has an F word."""
        return self.spec.has("F")

    @property
    def tool_changes(self) -> str:
        """How the spec changes tools: ``code``, ``stop`` or ``none``.

        ``code`` with a ``tool_change`` code; ``stop`` when it changes tools ``by_hand``
        with a stop (and comments); else ``none``, one program per tool.
        """
        if self.spec.tool_change:
            return "code"
        by_stop = self.spec.by_hand == "stop" and self.spec.stop and self.spec.comment
        return "stop" if by_stop else "none"

    @property
    def stops(self) -> bool:
        """True when the spec has a ``stop`` code."""
        return bool(self.spec.stop)

    @property
    def length_offsets(self) -> bool:
        """True with a ``tool_length_offset`` code (LinuxCNC's ``G43 H<n>`` after each change)."""
        return bool(self.spec.tool_length_offset)

    @property
    def homes(self) -> tuple[str, ...]:
        """The spec's returns to machine positions (G28, G30 and G53 with ``home``)."""
        return self.spec.homes

    @property
    def work_offsets(self) -> tuple[str, ...]:
        """The spec's ``work_offsets`` (LinuxCNC's G54 … G59.3, GRBL's G54 … G59)."""
        return self.spec.work_offsets

    @property
    def path_controls(self) -> tuple[str, ...]:
        """The spec's ``path_controls`` (LinuxCNC's G61, G61.1 and G64)."""
        return self.spec.path_controls

    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` for ``machine`` (rules: the module docstring).

        Raises:
            DialectError: a Z move without a Z word, a helix the dialect cannot
                write, a point outside the work area, a number over its field, a
                block over ``max_block_bytes`` or an arc the controller's check
                cannot accept; the message names the contour and block.
            UsageError: ``fmt`` is not ``"code"``.
        """
        self.check_format(fmt)
        writer = BlockWriter(self.spec, machine)
        code = writer.write(program)
        return PostResult(code, writer.count, tuple(writer.warnings), "code")

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read code of this dialect (rules: :mod:`camtool.post.wordaddress_read`).

        ``Program.lines`` holds the 1-based source line of each move. Feeds of
        a dialect without an F word read as 0 (the machine's own speed).

        A dialect with ``rs274`` (its controller runs any RS-274 program) reads code
        the strict reader refuses with the RS-274 reader of
        :mod:`camtool.importers.gcode`: another CAM's program verifies as the
        controller would run it.

        Raises:
            ParseError: a block that is not in the dialect, naming ``source`` and
                the line.
            InputError: (``rs274``) what the RS-274 reader refuses too, naming the line.
        """
        try:
            return BlockReader(self.spec, source).read(code)
        except ControllerRefusal:
            raise
        except ParseError:
            if not self.spec.rs274:
                raise
        from camtool.importers.gcode import parse_gcode

        text = code.decode("ascii", errors="replace") if isinstance(code, bytes) else code
        program = parse_gcode(text, source=source)
        self._check_arcs(program, source)
        return program

    def _check_arcs(self, program: Program, source: str) -> None:
        """Hold code read by the RS-274 reader to the controller's own arc check.

        Raises:
            ControllerRefusal: an arc the controller refuses, naming the line.
        """
        if self.spec.arc_check == "none":
            return
        from camtool.post.arccheck import arc_error

        for index, command in program.commands:
            if isinstance(command, PlaneArc):
                reason = arc_error(
                    command.in_plane(command.start),
                    command.in_plane(command.end),
                    command.centre,
                    rule=self.spec.arc_check,
                )
                if reason is not None:
                    raise ControllerRefusal(
                        f"{source}:{program.line_of(index)}: {self.spec.arc_check} refuses this "
                        f"arc: {reason}"
                    )
        for index, (start, move) in enumerate(program.steps()):
            if not isinstance(move, ArcMove):
                continue
            reason = arc_error(
                start, (move.x, move.y), (move.cx, move.cy), rule=self.spec.arc_check
            )
            if reason is not None:
                line = program.line_of(index)
                raise ControllerRefusal(
                    f"{source}:{line}: {self.spec.arc_check} refuses this arc: {reason}"
                )


def word_address_dialect(options: Mapping[str, Any], where: str) -> WordAddressPost:
    """The dialect a target file's ``[dialect_options]`` table declares.

    Args:
        options: the ``[dialect_options]`` table.
        where: the target file's name, for messages.

    Raises:
        InputError: an unknown key or a bad value, naming ``where`` and the key.
    """
    return WordAddressPost(load_spec(options, where))
