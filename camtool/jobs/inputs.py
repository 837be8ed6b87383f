"""A job's inputs: what a name reads as, and which files a batch posts.

A name is read by its ending (:func:`read_input`, :func:`read_code`,
:func:`read_program`): a drawing (:data:`camtool.importers.DRAWING_SUFFIXES`), or a
G-code program (:data:`PROGRAM_SUFFIXES`), which is already a toolpath and is
re-posted, not planned; ``-`` is standard input.

Design notes: docs/internals.md, ``camtool/jobs/inputs.py``.
"""

from __future__ import annotations

import glob
import os
import re
import shlex
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.importers import (
    DRAWING_SUFFIXES,
    POINT_SUFFIXES,
    read_drawing,
    read_drawing_bytes,
)
from camtool.importers.textfile import decoded
from camtool.model.errors import InputError, UsageError, not_a_file
from camtool.model.tomlfile import read_toml_file

if TYPE_CHECKING:
    from collections.abc import Callable

    from camtool.importers.options import ImportOptions
    from camtool.model.program import Program
    from camtool.model.shapes import BBox, Drawing
    from camtool.post.base import Target

_MAGIC = re.compile(r"[*?[]")

NOTE_PEEK_BYTES = 65536
"""How much of a ``.txt`` file a batch reads to tell a point list from a note."""

PROGRAM_SUFFIXES = (".ngc", ".nc", ".gcode", ".tap", ".cnc", ".gc", ".g")
"""File endings read as existing G-code programs (re-posted, not planned)."""


def is_program_file(name: str | Path) -> bool:
    """True when ``name`` is a G-code program by its ending (see :data:`PROGRAM_SUFFIXES`)."""
    return Path(name).suffix.lower() in PROGRAM_SUFFIXES


STDIN = "<stdin>"
"""The name messages give standard input."""

_SNIFF_BYTES = 1 << 16
"""How much of standard input :func:`stdin_kind` looks at."""
_DXF_CODES = ("0", "999")
_GCODE_WORD = re.compile(r"/?\s*+(?:[A-Za-z]\s*+[-+]?\s*+[\d.#\[<]|#[\d<])")
"""The start of a G-code block: a word (``G0``, ``X-1.5``, ``F#1``, ``o<sub>``), a parameter
(``#1=``, ``#<x>=``), after an optional block delete ``/``."""
_MATLAB = re.compile(r"[A-Za-z_]\w*\s*=")
_EXCEL_SEPARATOR = re.compile(r'"?sep=.?"?', re.IGNORECASE)
"""Excel's first line naming a CSV's column separator (``sep=;``)."""
_POINT_ROW = re.compile(r'"?[-+.\d]')
"""The start of a point list's row: a number, perhaps quoted (``"1.5","2"``)."""
_HEADER = re.compile(r"[A-Za-z_]\w*+(?:[\s,;]++[A-Za-z_]\w*+)*+|[^\d<A-Za-z]*+[A-Za-z]\D*+")
"""A point list's header row: words (``x,y,z``, ``x1;y1``), or any line of letters without
digits (``X (in),Y (in)``, ``"x","y"``). Possessive quantifiers (``*+``) keep the match
linear in the line's length (each run is the only one that can match)."""


def stdin_kind(data: bytes) -> str:
    """The kind of the file piped on standard input, as the ending such a file has.

    ``.dxf`` (ASCII: group code 0 then ``SECTION``, or a 999 comment first; binary: its
    sentinel), ``.svg`` (XML: the first character ``<``), ``.svgz`` (gzip's magic number),
    ``.nc`` (a G-code program: its first line that is not a comment, ``(…)``, ``;…`` or
    ``%``, starts with a word or a parameter; or comments only), ``.m`` (a Matlab
    assignment, ``xy = [...]``), ``.csv`` (a point list: a number first, a ``#`` comment,
    Excel's ``sep=;``, or a header of words then a row of numbers). Only the first 64 KiB
    are looked at.

    Raises:
        InputError: empty, or none of these (the message quotes the first line).
    """
    if data.startswith(b"AutoCAD Binary DXF"):
        return ".dxf"
    if data.startswith(b"\x1f\x8b"):  # gzip: a compressed SVG (.svgz)
        return ".svgz"
    text = decoded(data[:_SNIFF_BYTES], "replace").lstrip("\ufeff \t\r\n")
    if not text:
        raise InputError(
            f"{STDIN}: empty input; pipe a drawing (DXF, SVG, a point list) into camtool"
        )
    if text.startswith("<"):
        return ".svg"
    lines = [line.strip() for line in text.splitlines() if line.strip()]
    if lines[0] in _DXF_CODES and (lines[0] == "999" or lines[1:2] == ["SECTION"]):
        return ".dxf"
    for at, line in enumerate(lines):
        if line[0] in "(;%":
            continue  # a G-code comment or the tape mark
        if _GCODE_WORD.match(line) and "," not in re.split(r"[(;]", line, maxsplit=1)[0]:
            return PROGRAM_SUFFIXES[1]  # a comma outside a comment is no G-code: a header
        if at == 0 and _EXCEL_SEPARATOR.fullmatch(line):
            return ".csv"  # Excel's line naming the separator, not a Matlab assignment
        if _MATLAB.match(line):
            return ".m"
        if _POINT_ROW.match(line) or line.startswith("#"):
            return ".csv"
        if _HEADER.fullmatch(line) and _POINT_ROW.match(
            lines[at + 1] if at + 1 < len(lines) else ""
        ):
            return ".csv"
        break
    else:  # comments only: a program (that moves nowhere, which its reader says)
        return PROGRAM_SUFFIXES[1]
    raise InputError(
        f"{STDIN}: cannot tell what it holds (it starts {lines[0][:40]!r}); camtool reads a "
        "DXF, an SVG or a point list from stdin: save it to a file with its ending (.dxf, "
        ".svg, .csv) and give that file"
    )


def read_input(
    name: str,
    settings: ImportOptions | None = None,
    check: Callable[[BBox], None] | None = None,
) -> Drawing:
    """The drawing at ``name`` read by its ending (``-``: stdin, read by its kind).

    ``check``: as for :func:`camtool.importers.read_drawing`.

    Raises:
        InputError: the drawing cannot be read (see :mod:`camtool.importers`); stdin holds
            a program or cannot be told (:func:`stdin_kind`).
        Whatever ``check`` raises.
    """
    if name == "-":
        data = sys.stdin.buffer.read()
        return read_drawing_bytes(
            data, name=STDIN, suffix=drawing_kind(data), options=settings, check=check
        )
    return read_drawing(name, settings, check=check)


def drawing_kind(data: bytes, remedy: str = "this needs a drawing (DXF, SVG, a point list)") -> str:
    """:func:`stdin_kind` of a drawing.

    A program on stdin is refused, not read as G-code: a dialect's code (``pic-mmh``'s
    ``G01X03600.00Y01400.00F08;`` in µm) looks like G-code, and only a file's ending or a
    named target says which it is.

    Raises:
        InputError: as :func:`stdin_kind`, or the input is a program (``remedy`` says what
            to do instead).
    """
    kind = stdin_kind(data)
    if kind in PROGRAM_SUFFIXES:
        raise InputError(
            f"{STDIN}: holds a program, which camtool does not read from stdin without "
            f"knowing its dialect (a target's code looks like G-code); {remedy}"
        )
    return kind


def read_code(name: str, *, binary: bool = False) -> str | bytes:
    """A code file (``-``: stdin): bytes for a binary dialect, else text.

    Text is read as the G-code importer reads it (UTF-8, or UTF-16/32 with a byte-order
    mark; the mark dropped): a
    comment may hold any character (``(Linéal)``); the dialect's reader refuses one
    outside a comment, naming the line.

    Raises:
        InputError: missing, unreadable, or (text) not UTF-8, naming the file.
    """
    if binary:
        try:
            return sys.stdin.buffer.read() if name == "-" else Path(name).read_bytes()
        except FileNotFoundError as exc:
            raise not_a_file(name) from exc
        except OSError as exc:
            raise InputError(f"{name}: cannot read ({exc.strerror or exc})") from exc
    if name == "-":
        return sys.stdin.read()
    try:
        return decoded(Path(name).read_bytes())
    except FileNotFoundError as exc:
        raise not_a_file(name) from exc
    except UnicodeDecodeError as exc:
        code = exc.encoding.upper().removesuffix("-SIG")
        raise InputError(f"{name}: not a text program (byte {exc.start} is not {code})") from exc
    except OSError as exc:
        raise InputError(f"{name}: cannot read ({exc.strerror or exc})") from exc


def check_not_drawing(name: str, target: Target, then: str) -> None:
    """Refuse a DXF or SVG drawing given where a program is read, saying what to do.

    Args:
        name: the program's file name as given.
        target: the target the program is read for.
        then: what to do with the posted ``PROGRAM`` (``{name}``: the drawing's name),
            e.g. ``"send PROGRAM"``.

    Raises:
        InputError: ``name`` is a file with a drawing's ending (DXF, SVG; not a point
            list's, which a program may share: ``.txt``, ``.m``) that ``target`` does not
            write (a missing one is left to the reader's "no such file").
    """
    suffix = Path(name).suffix.lower()
    drawing = suffix in DRAWING_SUFFIXES and suffix not in POINT_SUFFIXES
    drawing = drawing and suffix not in target.post.formats.values()
    if drawing and Path(name).is_file():
        quoted = shlex.quote(name)
        raise InputError(
            f"{name}: a drawing, not a program. Post it first (camtool post {quoted} "
            f"-t {target.name} -o PROGRAM), then " + then.format(name=quoted)
        )


def read_program(name: str, target: Target | None) -> Program:
    """A program by its ending: the target's dialect, or G-code through the importer.

    Read with the ``target``'s own reader when its ending is one that target writes
    or is not a G-code ending (``logo.pic``); else a G-code file (``.ngc .nc .gcode
    .tap ...``) goes through the G-code importer (no target needed). ``-`` reads code
    in the target's dialect from stdin.

    Raises:
        InputError: no such file, or the code cannot be read.
        UsageError: neither a G-code ending nor a target to read it with.
    """
    if name != "-" and not Path(name).is_file():
        raise not_a_file(name)
    suffix = Path(name).suffix.lower()
    if target is not None and (not is_program_file(name) or suffix in target.post.formats.values()):
        return target.post.parse(read_code(name, binary=target.post.binary), source=name)
    if name != "-" and is_program_file(name):
        from camtool.importers.gcode import read_gcode

        return read_gcode(name)
    raise UsageError(
        f"{name} is not a drawing nor a G-code program ({', '.join(PROGRAM_SUFFIXES)}): "
        "give --target NAME to read it as that target's code"
    )


def preview_inputs(
    input_name: str, program_name: str | None, target: Target | None, settings: ImportOptions
) -> tuple[Drawing | None, Program | None]:
    """The drawing and the program ``camtool preview`` draws.

    ``input_name`` is a drawing by its ending (then ``program_name``, if given, is
    drawn over it), else a program (:func:`read_program`).

    Raises:
        InputError: a file is missing or unreadable.
        UsageError: ``program_name`` given while ``input_name`` is not a drawing, or a
            program that cannot be read without a target.
    """
    if input_name == "-" and target is None:  # no dialect named: a drawing, told by content
        data = sys.stdin.buffer.read()
        drawing = read_drawing_bytes(
            data,
            name=STDIN,
            suffix=drawing_kind(data, "give --target NAME to draw it"),
            options=settings,
        )
        return drawing, read_program(program_name, target) if program_name else None
    if input_name != "-" and Path(input_name).suffix.lower() in DRAWING_SUFFIXES:
        if not Path(input_name).is_file():
            raise not_a_file(input_name)
        drawing = read_drawing(input_name, settings)
        program = read_program(program_name, target) if program_name else None
        return drawing, program
    if program_name is not None:
        raise UsageError(
            f"--program draws a program over a drawing, but INPUT {input_name} is not a "
            "drawing (.dxf, .svg, point list)"
        )
    return None, read_program(input_name, target)


def default_preview_path(input_name: str) -> str:
    """``part.dxf`` → ``part.preview.svg`` beside it (never the input itself); ``-`` → stdout."""
    if input_name == "-":
        return "-"
    path = Path(input_name)
    return str(path.with_name(f"{path.stem}.preview.svg"))


def readable_suffixes() -> tuple[str, ...]:
    """File endings a batch picks up in directories and globs, lowercase.

    The drawing endings of :data:`camtool.importers.DRAWING_SUFFIXES` and the
    G-code endings of :data:`PROGRAM_SUFFIXES`.
    """
    return DRAWING_SUFFIXES + PROGRAM_SUFFIXES


@dataclass(frozen=True)
class BatchInput:
    """One file a batch posts.

    Attributes:
        path: the file, as found (relative to the working directory when the
            input was).
        relative: its path below its input's root (e.g. ``a/b.dxf``); outputs
            keep it.
    """

    path: Path
    relative: Path


def expand_inputs(inputs: Sequence[str], *, exclude: Path | None = None) -> tuple[BatchInput, ...]:
    """Expand a batch's files, directories and globs into the files to post (module docstring).

    Args:
        inputs: what the user gave, in order.
        exclude: a directory (the batch's output directory) never searched by
            directories and globs; explicitly named files are kept.

    Returns:
        The files, sorted by path, each once.

    Raises:
        UsageError: an input is ``-`` (a batch reads files, not stdin).
        InputError: an input matches nothing camtool reads (the message names it
            and lists the readable endings); checked for every input before any
            work starts.
    """
    skip = _real(exclude) if exclude is not None else None
    found: dict[Path, BatchInput] = {}
    for text in inputs:
        for item in _expand_one(text, skip):
            found.setdefault(_real(item.path), item)
    return tuple(sorted(found.values(), key=lambda item: item.path.as_posix()))


def _expand_one(text: str, skip: Path | None) -> list[BatchInput]:
    """The files one input names (see :func:`expand_inputs`)."""
    if text == "-":
        raise UsageError("a batch reads files, not stdin ('-'); use `camtool post -` for a pipe")
    path = Path(text)
    if path.is_dir():
        items = _walk(path, path, skip)
    elif path.exists():
        return [BatchInput(path, Path(path.name))]
    elif not _MAGIC.search(text):
        raise InputError(f"{text}: no such file or directory")
    else:
        items = _rebase(_glob(text, skip))
    if not items:
        endings = ", ".join(readable_suffixes())
        what = "holds" if path.is_dir() else "matches"
        raise InputError(f"{text}: {what} no file camtool reads ({endings})")
    return items


def _real(path: Path) -> Path:
    """``path`` with its symbolic links followed (``os.path.realpath``).

    A link in a loop is left as it is, where ``Path.resolve`` raises: the file is then
    refused when it is read, in its own row of the batch.
    """
    return Path(os.path.realpath(path))


def _rebase(items: list[BatchInput]) -> list[BatchInput]:
    """Relative paths below the files' common folder when one would climb out with ``..``.

    A glob such as ``a/*/../../x/*.dxf`` matches ``a/s/../../x/f.dxf``, which is
    ``../x/f.dxf`` below the glob's leading part ``a``: written below ``-o`` as it is,
    it would land outside. Such a glob's files are named below the deepest folder
    that holds them all instead (``f.dxf``); :func:`camtool.jobs.batch.plan_batch` still
    checks every output resolves inside ``-o``.
    """
    if not any(item.relative.parts[:1] == ("..",) for item in items):
        return items
    absolute = [os.path.normpath(os.path.abspath(item.path)) for item in items]
    common = os.path.commonpath([os.path.dirname(a) for a in absolute])
    return [
        BatchInput(item.path, Path(os.path.relpath(a, common)))
        for item, a in zip(items, absolute, strict=True)
    ]


def _glob(pattern: str, skip: Path | None) -> list[BatchInput]:
    """Files a glob matches, relative to its leading part without wildcards."""
    parts = Path(pattern).parts
    fixed = next((i for i, part in enumerate(parts) if _MAGIC.search(part)), len(parts))
    root = Path(*parts[:fixed]) if fixed else Path()
    if skip is not None and _below(_real(root), skip):
        skip = None  # the user globbed inside the output directory on purpose
    items: list[BatchInput] = []
    for match in sorted(glob.glob(pattern, recursive=True)):
        path = Path(match)
        if skip is not None and _below(_real(path), skip):
            continue
        if path.is_dir():
            items.extend(_walk(path, root, skip))
        elif _readable(path):
            items.append(BatchInput(path, Path(os.path.relpath(path, root))))
    return items


def _walk(directory: Path, root: Path, skip: Path | None) -> list[BatchInput]:
    """Readable, non-hidden files below ``directory``, relative to ``root``, sorted."""
    items: list[BatchInput] = []
    for here, dirs, files in os.walk(directory):
        dirs[:] = sorted(
            d
            for d in dirs
            if not d.startswith(".") and (skip is None or _real(Path(here) / d) != skip)
        )
        for name in sorted(files):
            path = Path(here) / name
            if not name.startswith(".") and _readable(path):
                items.append(BatchInput(path, Path(os.path.relpath(path, root))))
    return items


def _readable(path: Path) -> bool:
    """Whether a batch found ``path`` in a folder or a glob posts it.

    Its ending is one camtool reads; a ``.txt`` must also hold a row of numbers or a
    G-code block in its first 64 KiB (:func:`~camtool.importers.points.holds_rows`): a
    README or a licence beside the drawings is passed over, not an error.
    """
    suffix = path.suffix.lower()
    if suffix not in readable_suffixes():
        return False
    if suffix != ".txt":
        return True
    from camtool.importers.points import holds_rows

    try:
        with path.open("rb") as file:
            head = file.read(NOTE_PEEK_BYTES)
    except OSError:
        return True  # posting it says what is wrong
    return holds_rows(decoded(head, errors="replace"))


def _below(path: Path, directory: Path) -> bool:
    """True when resolved ``path`` is ``directory`` or inside it."""
    return path == directory or directory in path.parents


def read_small_toml(path: str | Path, *, what: str, limit_bytes: int) -> dict[str, object]:
    """A small TOML file read safely (:func:`camtool.model.tomlfile.read_toml_file`)."""
    return read_toml_file(path, what=what, limit_bytes=limit_bytes)
