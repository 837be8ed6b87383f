"""PostProcessor (a dialect: ``emit`` and ``parse``) and Target (dialect + machine)."""

from __future__ import annotations

from abc import ABC, abstractmethod
from dataclasses import dataclass
from typing import ClassVar

from camtool.machine import Machine
from camtool.program import Program


@dataclass(frozen=True)
class PostResult:
    """Emitted code and what the post-processor had to say.

    Attributes:
        code: the program in the dialect (``str`` for text dialects).
        blocks: number of blocks (lines) written.
        warnings: messages for the user (rounded feeds, rate limits...).
    """

    code: str | bytes
    blocks: int
    warnings: tuple[str, ...] = ()


class PostProcessor(ABC):
    """A dialect: writes a :class:`Program` and reads its own code back.

    The reader exists so that the verifier simulates exactly what was emitted;
    ``parse(emit(p).code)`` gives the moves of ``p`` within the dialect's
    resolution.
    """

    suffix: ClassVar[str] = ".nc"
    """File name ending for programs in this dialect."""

    @abstractmethod
    def emit(self, program: Program, machine: Machine) -> PostResult:
        """Write ``program`` for ``machine``.

        Raises:
            DialectError: something the dialect or the machine cannot express,
                naming the contour and block.
        """

    @abstractmethod
    def parse(self, code: str, *, source: str = "<code>") -> Program:
        """Read code in this dialect back into a program.

        Raises:
            ParseError: a block does not follow the dialect, naming ``source``
                and the line.
        """


@dataclass(frozen=True)
class Target:
    """A machine and its dialect, as ``camtool targets`` lists them.

    Attributes:
        name: the name given to ``--target``.
        description: one line for listings.
        post: the dialect.
        machine: the machine profile.
        default_feed_mm_min: feed used when ``--feed`` is not given, mm/min.
        source: the thesis section the target comes from.
    """

    name: str
    description: str
    post: PostProcessor
    machine: Machine
    default_feed_mm_min: float
    source: str = ""

    def emit(self, program: Program) -> PostResult:
        """Write ``program`` in this target's dialect for its machine."""
        return self.post.emit(program, self.machine)
