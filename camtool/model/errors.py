"""One error tree for camtool; each error carries the process exit code.

Exit codes (the CLI contract in DESIGN.md): 0 ok, 1 error, 2 usage, 3 unreadable
or invalid input, 4 verified error over the limit. Errors mix in the builtin they
resemble, as ezdxf does (``DXFValueError(DXFError, ValueError)``).
"""

from __future__ import annotations

import os
import stat


class CamtoolError(Exception):
    """Base of every error camtool raises on purpose. Exit code 1."""

    exit_code = 1


class UsageError(CamtoolError, ValueError):
    """An option value or combination of options is invalid. Exit code 2."""

    exit_code = 2


class InputError(CamtoolError, ValueError):
    """An input file is missing, unreadable or holds nothing usable. Exit code 3."""

    exit_code = 3


def quoted(text: str, limit: int = 80) -> str:
    """``repr(text)`` for a message, or its start and its length when it is long.

    A text longer than ``limit`` characters shows as ``'G1X1Y2G1X1Y2'... (1000000
    characters)``, so that a hostile line still gives a message of one readable line.
    """
    if len(text) <= limit:
        return repr(text)
    return f"{text[: limit * 2 // 3]!r}... ({len(text)} characters)"


MAX_MESSAGE = 2000
"""The longest message :func:`readable` shows whole, in characters."""


def readable(message: str) -> str:
    """``message``, its middle left out when it is longer than :data:`MAX_MESSAGE`.

    The start (the file, line and what is wrong) and the end (what to do) are kept: a
    message that quotes a hostile input whole stays a message a user can read.
    """
    if len(message) <= MAX_MESSAGE:
        return message
    head, tail = MAX_MESSAGE * 2 // 3, MAX_MESSAGE // 4
    left_out = len(message) - head - tail
    return f"{message[:head]} ... ({left_out} characters left out) ... {message[-tail:]}"


def out_of_memory(exc: MemoryError) -> str:
    """What to say when the memory ran out (exit code 1): not a bug, a job too large.

    numpy names the array it could not allocate; Python's own ``MemoryError`` says nothing.
    """
    detail = f" ({exc})" if str(exc) else ""
    return (
        f"out of memory{detail}: the job needs more memory than this machine has; check the "
        "drawing's size and units and the machine profile (steps_per_mm), or split the job"
    )


def unexpected(exc: Exception) -> str:
    """The message of an exception that is no :class:`CamtoolError` (exit code 1).

    The memory ran out (:func:`out_of_memory`), or an internal error: a bug.
    """
    if isinstance(exc, MemoryError):
        return out_of_memory(exc)
    return f"internal error: {type(exc).__name__}: {exc}"


def not_a_file(path: object) -> InputError:
    """The error for an input ``path`` that is not a regular file: what it is instead.

    Missing, a folder, a symbolic link that leads nowhere (or round in a loop), or a FIFO,
    socket or device (not opened: reading one can block or never end).
    """
    try:
        mode = os.stat(str(path)).st_mode
    except OSError:
        if os.path.islink(str(path)):
            return InputError(f"{path}: a symbolic link that leads to no file (or round a loop)")
        return InputError(f"{path}: no such file")
    if stat.S_ISDIR(mode):
        return InputError(f"{path}: a folder, not a file; name a drawing or a program in it")
    return InputError(
        f"{path}: not a regular file (a FIFO, a socket or a device); camtool reads drawings "
        "and programs from files, or from standard input with '-'"
    )


class ToolpathError(CamtoolError, ValueError):
    """A toolpath cannot be planned (e.g. an offset fails). Exit code 1."""


class GeometryError(ToolpathError):
    """A shared geometry algorithm cannot give a result. Exit code 1.

    Raised by :mod:`camtool.geometry` and the model's shapes: a curve fit that does not
    converge, a curve point or an arc that is not finite, an end point that cannot be
    chained. Importers catch this one (never :class:`ToolpathError`) to name the entity;
    it stays a :class:`ToolpathError` so that the planner, which calls the same
    functions, reports it as it always did (same exit code, same message).
    """


class DialectError(CamtoolError, ValueError):
    """A program cannot be expressed in a target's dialect. Exit code 1.

    Raised for a value that does not fit its field, a feed outside the feed
    table, a point outside the machine's work area, or a move the dialect has no
    word for. The message names the contour and block.
    """


class TooLargeError(DialectError):
    """A drawing or toolpath is larger than the machine's travel. Exit code 1.

    Its own class so that a caller that knows why the drawing is that large (shapes off
    an SVG's page, which a viewer does not show) can say so with the refusal, before
    the user scales the part down with ``--fit``.
    """


class ParseError(InputError):
    """Code in a target's dialect cannot be read back. Exit code 3."""


class VerifyLimitError(CamtoolError):
    """The predicted machining error exceeds the requested limit. Exit code 4."""

    exit_code = 4


class LinkError(CamtoolError):
    """Sending a program to a machine failed or stopped. Exit code 1.

    Raised by :mod:`camtool.link`: the port cannot be opened or disappeared, the
    controller reported an error or an alarm, it did not answer in time, or the
    operator stopped the job. The message names the port, the block and its
    source line, the controller's own words, and the ``--from-line`` to resume.
    """
