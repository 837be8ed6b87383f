"""Point-list importer: X,Y(,Z) text files and the thesis GUI's Matlab ``xy`` matrices.

Each stroke becomes one contour of straight lines through its points (no fitting here: turning
dense strokes into arcs is a planning step, :func:`~camtool.toolpath.arcfit.fit_polyline`). A
stroke whose last point equals its first is closed. Points in a row that repeat the previous
point are dropped. The drawing is 2D: a Z column is read, kept out of the drawing, and a
warning says so when it is not constant.

Text files (``.csv``, ``.txt``, ``.xy``): one point per line, ``X,Y`` or ``X,Y,Z``, separated
by a comma, semicolon, tab or spaces; a blank line or a row of ``NaN`` ends a stroke; one
header line (no numbers) may come first; lines starting with ``#`` are comments. Units: the
``--units`` option, default mm.

Matlab files (``.m``): ``xy = [ x1 x2 ...; y1 y2 ... ]`` as the Matlab GUI of seed-002 §3 shows
it (row 1 x, row 2 y, in 0.1 mm unless ``--units`` says otherwise), over as many lines as it
likes; ``lxy`` and ``velxy`` (the GUI's derived arrays) are ignored; several ``xy``
assignments are several strokes; ``%`` starts a comment. Anything else is an error.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from pathlib import Path

from camtool.errors import InputError, UsageError
from camtool.geometry import Contour, Drawing, Line, Point
from camtool.importers import ImportOptions
from camtool.units import LENGTH_UNITS

TEXT_SUFFIXES = (".csv", ".txt", ".xy")
MATLAB_SUFFIX = ".m"
DEFAULT_UNITS = "mm"
"""Unit of text point lists when ``--units`` is not given."""
MATLAB_UNITS = "0.1mm"
"""Unit of Matlab ``xy`` matrices when ``--units`` is not given (seed-002 §3: "resolución ...
de una decima de milímetro")."""
LAYER = "0"
"""Contour.layer of every stroke (point lists have no layers)."""

_SEPARATOR = re.compile(r"\s*[,;\t]\s*|\s+")
_IGNORED_MATLAB = ("lxy", "velxy")


@dataclass(frozen=True)
class _Stroke:
    """Raw points of one stroke in file units and the line number where it starts."""

    xy: tuple[tuple[float, float], ...]
    line: int


def read_points(path: str | Path, options: ImportOptions | None = None) -> Drawing:
    """Read a point list (``.csv``, ``.txt``, ``.xy``) or a Matlab ``xy`` file (``.m``).

    Args:
        path: the file.
        options: ``units`` (a name of :data:`camtool.units.LENGTH_UNITS`; default mm for
            text files, 0.1 mm for ``.m`` files) is used; layers and tolerance do not apply.

    Returns:
        One contour of lines per stroke of 2 or more distinct points, mm, Y up as written;
        warnings for a varying Z and for strokes of a single point (skipped).

    Raises:
        UsageError: ``options.units`` is not a known unit.
        InputError: the file is missing, not text, has a bad row (the message names the
            line), or holds no stroke of two points.
    """
    path = Path(path)
    options = options or ImportOptions()
    matlab = path.suffix.lower() == MATLAB_SUFFIX
    scale = unit_factor(options.units or (MATLAB_UNITS if matlab else DEFAULT_UNITS))
    text = _read_text(path)
    warnings: list[str] = []
    strokes = _matlab_strokes(text, path) if matlab else _text_strokes(text, path, warnings)
    contours: list[Contour] = []
    for k, stroke in enumerate(strokes, start=1):
        pts = [(_scale(x, scale), _scale(y, scale)) for x, y in stroke.xy]
        contour = _contour(pts, f"stroke {k} (line {stroke.line})")
        if contour is None:
            warnings.append(f"{path}: line {stroke.line}: a stroke of one point was skipped")
        else:
            contours.append(contour)
    if not contours:
        raise InputError(f"{path}: no stroke of two or more points")
    return Drawing(tuple(contours), str(path), tuple(warnings))


def unit_factor(unit: str) -> float:
    """Millimetres per ``unit``, a name of :data:`camtool.units.LENGTH_UNITS`.

    Raises:
        UsageError: ``unit`` is not one of them (the message lists them).
    """
    if unit not in LENGTH_UNITS:
        raise UsageError(f"unknown unit {unit!r}; use one of {', '.join(LENGTH_UNITS)}")
    return LENGTH_UNITS[unit]


def _scale(value: float, factor: float) -> float:
    """``value * factor``, dividing by the exact integer for sub-mm units (0.1 mm: ``/ 10``).

    ``151 / 10`` is the float nearest to 15.1 (what ``float("15.1")`` reads), ``151 * 0.1``
    is not.
    """
    if factor < 1.0:
        inverse = round(1.0 / factor)
        if abs(inverse * factor - 1.0) < 1e-12:
            return value / inverse
    return value * factor


def _read_text(path: Path) -> str:
    if not path.is_file():
        raise InputError(f"{path}: no such file")
    try:
        return path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{path}: not a UTF-8 text file ({exc.reason} at byte {exc.start})"
        ) from exc
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc})") from exc


def _contour(pts: list[Point], source: str) -> Contour | None:
    kept = [p for i, p in enumerate(pts) if i == 0 or p != pts[i - 1]]
    if len(kept) < 2:
        return None
    lines = tuple(Line(a, b) for a, b in itertools.pairwise(kept))
    return Contour(lines, kept[-1] == kept[0], LAYER, source)


# ---------------------------------------------------------------------------- text files


def _text_strokes(text: str, path: Path, warnings: list[str]) -> list[_Stroke]:
    strokes: list[_Stroke] = []
    current: list[tuple[float, float]] = []
    start = 0
    columns: int | None = None
    z_range: list[float] = []
    seen_data = False
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if line.startswith("#"):
            continue
        fields = [f for f in _SEPARATOR.split(line) if f] if line else []
        values = _row(fields, path, number, header_allowed=not seen_data)
        if values is None:  # the header
            seen_data = True
            continue
        seen_data = seen_data or bool(fields)
        if not values or all(math.isnan(v) for v in values):
            if current:
                strokes.append(_Stroke(tuple(current), start))
            current = []
            continue
        if columns is None:
            columns = len(values)
        elif len(values) != columns:
            raise InputError(
                f"{path}: line {number}: {len(values)} numbers where the rows above have "
                f"{columns}; every row is X,Y or every row is X,Y,Z"
            )
        if not current:
            start = number
        current.append((values[0], values[1]))
        if columns == 3:
            z_range = (
                [min(z_range[0], values[2]), max(z_range[1], values[2])]
                if z_range
                else [values[2]] * 2
            )
    if current:
        strokes.append(_Stroke(tuple(current), start))
    if z_range and z_range[0] != z_range[1]:
        warnings.append(
            f"{path}: Z varies from {z_range[0]:g} to {z_range[1]:g} (file units); camtool "
            "reads X and Y only (the drawing is 2D; depths come from --depth)"
        )
    return strokes


def _row(fields: list[str], path: Path, number: int, *, header_allowed: bool) -> list[float] | None:
    """The numbers of one row; ``None`` for a header; ``[]`` for a blank row.

    Raises:
        InputError: a field that is not a number (after the header), a partly NaN row,
            infinity, or a count other than 2 or 3.
    """
    if not fields:
        return []
    try:
        values = [float(f) for f in fields]
    except ValueError:
        if header_allowed and not any(_is_number(f) for f in fields):
            return None
        bad = next(f for f in fields if not _is_number(f))
        raise InputError(
            f"{path}: line {number}: {bad!r} is not a number; rows are X,Y or X,Y,Z "
            "separated by a comma, semicolon, tab or spaces (decimal point, not comma)"
        ) from None
    nan = [math.isnan(v) for v in values]
    if any(nan) and not all(nan):
        raise InputError(
            f"{path}: line {number}: NaN in only some columns; a NaN row ends a stroke"
        )
    if len(values) not in (2, 3) and not all(nan):
        raise InputError(f"{path}: line {number}: {len(values)} numbers; rows are X,Y or X,Y,Z")
    if any(math.isinf(v) for v in values):
        raise InputError(f"{path}: line {number}: infinite coordinate")
    return values


def _is_number(field: str) -> bool:
    try:
        float(field)
    except ValueError:
        return False
    return True


# ---------------------------------------------------------------------------- Matlab files


_ASSIGN = re.compile(r"([A-Za-z_]\w*)\s*=\s*")
_MATRIX = re.compile(r"\[([^\]\[]*)\]\s*[;,]?")


def _matlab_strokes(text: str, path: Path) -> list[_Stroke]:
    """Strokes from every ``xy = [ ... ]`` assignment of a Matlab script (seed-002 §3)."""
    code = re.sub(r"%[^\n]*", "", text)  # comments; the file holds no strings
    strokes: list[_Stroke] = []
    pos = 0
    while True:
        while pos < len(code) and code[pos] in " \t\r\n;,":
            pos += 1
        if pos >= len(code):
            break
        line = code.count("\n", 0, pos) + 1
        assign = _ASSIGN.match(code, pos)
        if assign is not None and assign.group(1) not in ("xy", *_IGNORED_MATLAB):
            raise InputError(
                f"{path}: line {line}: unexpected variable {assign.group(1)!r}; camtool "
                "reads 'xy' and ignores 'lxy' and 'velxy'"
            )
        matrix = _MATRIX.match(code, assign.end()) if assign is not None else None
        if assign is None or matrix is None:
            snippet = code[pos:].split("\n", 1)[0].strip()[:40]
            raise InputError(
                f"{path}: line {line}: expected 'xy = [ x ...; y ... ]', got {snippet!r}; "
                "camtool reads the xy matrix of the thesis GUI (seed-002 §3)"
            )
        pos = matrix.end()
        if assign.group(1) == "xy":
            strokes.append(_Stroke(_matrix(matrix.group(1), path, line), line))
    if not strokes:
        raise InputError(f"{path}: no 'xy = [ ... ]' matrix")
    return strokes


def _matrix(body: str, path: Path, line: int) -> tuple[tuple[float, float], ...]:
    """Columns ``(x, y)`` of a 2-row matrix body; rows end at ';' or a line break."""
    rows = [r.split() for r in re.split(r"[;\n]", body.replace(",", " ")) if r.strip()]
    if len(rows) != 2:
        raise InputError(
            f"{path}: line {line}: xy has {len(rows)} rows; it must have 2 (x, then y)"
        )
    if len(rows[0]) != len(rows[1]):
        raise InputError(
            f"{path}: line {line}: xy rows have {len(rows[0])} and {len(rows[1])} numbers; "
            "x and y need one number per point each"
        )
    try:
        xs, ys = ([float(v) for v in row] for row in rows)
    except ValueError:
        bad = next(v for row in rows for v in row if not _is_number(v))
        raise InputError(f"{path}: line {line}: {bad!r} in xy is not a number") from None
    if not all(math.isfinite(v) for v in (*xs, *ys)):
        raise InputError(f"{path}: line {line}: xy holds NaN or infinity")
    return tuple(zip(xs, ys, strict=True))
