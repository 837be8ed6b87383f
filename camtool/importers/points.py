"""Point-list importer: X,Y(,Z) text files and the thesis GUI's Matlab ``xy`` matrices.

Design notes: docs/internals.md, ``camtool/importers/points.py``.
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass
from pathlib import Path

from camtool.importers.options import ImportOptions
from camtool.importers.textfile import text_lines
from camtool.model.errors import InputError, UsageError, not_a_file, quoted
from camtool.model.shapes import Contour, Drawing, Line, Point
from camtool.model.units import LARGEST_VALUE, LENGTH_UNITS

MATLAB_SUFFIX = ".m"
DEFAULT_UNITS = "mm"
"""Unit of text point lists when ``--units`` is not given."""
MATLAB_UNITS = "0.1mm"
"""Unit of Matlab ``xy`` matrices when ``--units`` is not given (Angel-11 §3: "resolución ...
de una decima de milímetro")."""
LAYER = "0"
"""Contour.layer of every stroke (point lists have no layers)."""

NUMBER = re.compile(r"[+-]?+(?:\d++\.?+\d*+|\.\d++)(?:[eE][+-]?+\d++)?+", re.ASCII)
"""A number as point lists write it: ``12``, ``-1.5``, ``.5``, ``3.``, ``1e-3``.

Its quantifiers are possessive (``++``, ``*+``), here and in the other patterns of point
lists: a hostile row of a million digits or blanks is matched in time linear in its
length, not quadratic (each possessive run is the only one that can match)."""
_FIELD = re.compile(r'"([^"]*)"|[^,;\s]+')
"""A field: what lies between separators (comma, semicolon, tab, spaces), or between
double quotes (a CSV writer quoting every field: ``"1.5","2"``)."""
_DIGIT_COMMA = re.compile(r"\d,\d")
"""A comma between two digits: a decimal comma when the row separates its columns otherwise
(:func:`_decimal_comma` widens it to the number it stands in)."""
_OTHER_SEPARATOR = re.compile(r";|[\d.]\s++[+\-.\d]")
"""A semicolon, or tabs or blanks between two numbers: the separators of a decimal-comma row
(not a row's trailing blanks)."""
_HEADER_UNITS = {
    "mm": "mm", "millimeter": "mm", "millimeters": "mm", "millimetre": "mm",
    "millimetres": "mm", "cm": "cm", "m": "m", "meters": "m", "metres": "m", "in": "in",
    "inch": "in", "inches": "in", "ft": "ft", "feet": "ft", "um": "um", "µm": "um",
    "microns": "um",
}  # fmt: skip
"""Unit words a header may give, by the name ``--units`` takes for them."""
_HEADER_UNIT = re.compile(
    r"[\[(]\s*([a-zµ]+)\s*[\])]|_([a-zµ]+)\b|\b(inch(?:es)?|mil+imet(?:er|re)s?)\b",
    re.IGNORECASE,
)
"""A unit in a header: ``X (in)``, ``x[mm]``, ``x_in``, or a spelt-out inch or millimetre."""
_NAN = "nan"
"""A field that breaks a stroke (any case: ``NaN``, ``nan``), as Matlab writes it."""
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
        options: ``units`` (a name of :data:`camtool.model.units.LENGTH_UNITS`; default mm for
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
    if matlab:
        strokes = _matlab_strokes(text, path, scale)
    else:
        try:
            strokes = _text_strokes(text, path, warnings, scale, options.units)
        except InputError as exc:
            raise _program_error(text, path) or exc from exc
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
    """Millimetres per ``unit``, a name of :data:`camtool.model.units.LENGTH_UNITS`.

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
        raise not_a_file(path)
    from camtool.importers.textfile import decoded

    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc})") from exc
    try:
        return decoded(data)
    except UnicodeDecodeError as exc:
        name = exc.encoding.upper().removesuffix("-SIG")
        raise InputError(
            f"{path}: not a {name} text file ({exc.reason} at byte {exc.start}); save it as "
            "UTF-8 (or plain ASCII) text"
        ) from exc


def _contour(pts: list[Point], source: str) -> Contour | None:
    kept = [p for i, p in enumerate(pts) if i == 0 or p != pts[i - 1]]
    if len(kept) < 2:
        return None
    lines = tuple(Line(a, b) for a, b in itertools.pairwise(kept))
    return Contour(lines, kept[-1] == kept[0], LAYER, source)


# ---------------------------------------------------------------------------- text files


_PROGRAM_BLOCK = re.compile(r"(?:[Nn]\s*\d+\s*)?[GgMm]\s*\d+(?:\.\d+)?(?=$|[\s(;%A-Za-z])")
"""A G-code block: a G or M word first (after a line number), then a word, a blank, a comment
or the end, as no point-list row has (``G1,4`` is a bad row, not a block)."""
_PROGRAM_LOOK = 20
"""How many lines (not blank) are looked at for a block (a program's header comes first)."""


_NUMBER_ROW = re.compile(
    rf"\s*+{NUMBER.pattern}(?:(?:\s*+[,;]\s*+|\s++){NUMBER.pattern}){{1,2}}\s*+[,;]?+\s*+$",
    re.ASCII,
)
"""A row of two or three numbers, as a point list writes them."""
_EXCEL_SEPARATOR = re.compile(r'\s*"?sep=(.?)"?\s*', re.IGNORECASE)
"""Excel's first line naming the column separator (``sep=;``), which it writes for a CSV
to open the same in every locale."""


def holds_rows(text: str) -> bool:
    """Whether ``text``, a ``.txt`` file's first lines, is a point list or a program.

    So it is with a row of 2 or 3 numbers, a first line naming X and Y over a row of
    numbers (a wide table's header), or a G-code block; a note (a README) has none of them.
    """
    lines = [line.strip() for line in text_lines(text) if line.strip()]
    lines = lines[1:] if lines and _EXCEL_SEPARATOR.fullmatch(lines[0]) else lines
    rows = [line for line in lines if not line.startswith("#")]
    if len(rows) > 1 and _under_header(rows[0], rows[1]):
        return True  # a header naming X and Y over a row of numbers
    if rows and lines[0].startswith("#") and _under_header(lines[0][1:], rows[0]):
        return True  # numpy's header comment
    return any(_NUMBER_ROW.match(line) or _PROGRAM_BLOCK.match(line.strip()) for line in lines)


def _under_header(header: str, row: str) -> bool:
    """Whether ``row`` is a row of the table ``header`` heads.

    So it is when the header names X and Y, and the row has as many cells, with numbers in
    the X and Y columns.
    """
    columns = _header_columns(header)
    if columns is None:
        return False
    cells = _cells(row, columns.separator)
    return len(cells) == len(columns.names) and all(
        NUMBER.fullmatch(cells[i][0].strip('"')) for i in (columns.x, columns.y)
    )


def _program_error(text: str, path: Path) -> InputError | None:
    """The error for a G-code program saved with a point list's ending (CamBam's ``.txt``).

    ``None`` when none of the first :data:`_PROGRAM_LOOK` lines that are not blank is a
    G-code block (a ``(10, 20)`` row stays a bad point-list row).
    """
    lines = ((n, raw.strip()) for n, raw in enumerate(text_lines(text), start=1) if raw.strip())
    for number, line in itertools.islice(lines, _PROGRAM_LOOK):
        if _PROGRAM_BLOCK.match(line):
            shown = line if len(line) <= 40 else line[:40] + "…"
            return InputError(
                f"{path}: line {number}: {shown!r} is a G-code block: this is a program, not a "
                f"point list; camtool re-posts a program by its file ending: save it as "
                f"{path.stem}.nc and post that"
            )
    return None


def _header_units(header: str) -> set[str]:
    """The units (names ``--units`` takes) a header row names, e.g. ``{"in"}`` for ``X (in)``."""
    found = set()
    for match in _HEADER_UNIT.finditer(header):
        word = next(w for w in match.groups() if w).lower()
        word = "millimeters" if word.startswith("mil") else word
        if word in _HEADER_UNITS:
            found.add(_HEADER_UNITS[word])
    return found


def _check_header(header: str, where: str, given: str | None, warnings: list[str]) -> None:
    """Refuse a header naming a unit other than the one read (``given``: ``--units``).

    Raises:
        InputError: the header names a unit other than mm and ``--units`` is not given,
            or names two units (the columns are read in one).
    """
    units = _header_units(header)
    where = f"{where}: the header {header.strip()!r}"
    if len(units) > 1:
        raise InputError(
            f"{where} names the units {' and '.join(sorted(units))}; camtool reads every "
            "column in one unit: convert the file to one, and give it with --units"
        )
    if not units or units == {given or DEFAULT_UNITS}:
        return
    (unit,) = units
    if given is None:
        raise InputError(
            f"{where} gives the unit {unit}, and camtool reads a point list in mm unless "
            f"--units says otherwise: give --units {unit} (or --units mm if the header is wrong)"
        )
    warnings.append(f"{where} names {unit}; read in --units {given}, as asked")


_HEADER_NAME = re.compile(r"\s*([A-Za-z]+)\s*(?:[\[(].*|_[A-Za-zµ]+)?")
"""A header field's column name without its unit: ``X (in)``, ``x[mm]``, ``x_mm`` → ``x``."""


@dataclass(frozen=True)
class _Columns:
    """What a header naming X and Y says: their columns (0-based), Z's, every cell's name."""

    x: int
    y: int
    z: int | None
    names: tuple[str | None, ...]
    """Each header cell's column name, lower case (``None``: empty, or not a name)."""
    separator: str | None
    """``,``, ``;`` or a tab, or ``None`` for blanks (which leave no empty cell)."""

    def positional(self, cells: int) -> bool:
        """Whether a row of ``cells`` cells is read by the header's names.

        So it is when it has as many cells as the header, or the header has more than X,
        Y and Z (the other columns are not read).
        """
        return cells == len(self.names) or len(self.names) > 3

    def others(self) -> list[str]:
        """The named columns that are not read."""
        kept = (self.x, self.y, self.z)
        return [name for i, name in enumerate(self.names) if name and i not in kept]


def _header_columns(header: str) -> _Columns | None:
    """The columns a header names X, Y and Z in, when it names X and Y.

    ``None`` when it does not (the columns are then X, Y, Z in that order). A header
    cell left empty is a row number's (pandas writes its index so: ``,x,y``).
    """
    separator = next((s for s in ",;\t" if s in header), None)
    cells = header.strip().split(separator) if separator else header.split()
    names = []
    for cell in cells:
        match = _HEADER_NAME.fullmatch(cell.strip().strip('"').strip())
        names.append(match[1].lower() if match else None)
    if "x" not in names or "y" not in names:
        return None
    ix, iy = names.index("x"), names.index("y")
    if "z" in names:
        iz: int | None = names.index("z")
    else:  # a third column the header does not name at all is Z, as without a header
        iz = 2 if len(names) < 3 and 2 not in (ix, iy) else None
    return _Columns(ix, iy, iz, tuple(names), separator)


def _cells(raw: str, separator: str | None) -> list[tuple[str, int]]:
    """The cells of a row as ``(text, 1-based column)``, empty ones too.

    ``separator``: a comma, semicolon or tab; ``None``: fields as :data:`_FIELD` finds them.
    """
    if separator is None:
        return [
            (m[0] if m[1] is None else m[1].strip(), m.start() + 1) for m in _FIELD.finditer(raw)
        ]
    cells, at = [], 0
    for part in raw.split(separator):
        text = part.strip()
        cells.append((text.strip('"').strip(), at + len(part) - len(part.lstrip()) + 1))
        at += len(part) + 1
    return cells


def _named(raw: str, where: _Where, columns: _Columns) -> list[tuple[str, int]]:
    """The X, Y (and Z) cells of a row read by the header's names, in that order.

    Raises:
        InputError: the row ends before the X or Y column, or one of them is empty.
    """
    cells = _cells(raw, columns.separator)
    if cells == [("", 1)]:
        return []
    picked = []
    for axis, index in zip("XYZ", (columns.x, columns.y, columns.z), strict=True):
        if index is None or (axis == "Z" and (index >= len(cells) or not cells[index][0])):
            continue  # Z is only looked at (whether it varies)
        if index >= len(cells) or not cells[index][0]:
            raise InputError(
                f"{where.path}: line {where.line}: no value in column {index + 1}, which the "
                f"header names {axis}; every row needs its X and Y"
            )
        picked.append(cells[index])
    return picked


def _text_strokes(
    text: str, path: Path, warnings: list[str], scale: float, given: str | None = None
) -> list[_Stroke]:
    """The strokes of a text point list; ``given``: ``--units`` (``None``: not given)."""
    strokes: list[_Stroke] = []
    current: list[tuple[float, float]] = []
    start = 0
    columns: int | None = None
    z_range: list[float] = []
    seen_data = False
    header: _Columns | None = None  # the X, Y, Z columns the header names
    excel = _excel_separator_line(text, path)
    for number, raw in enumerate(text_lines(text), start=1):
        if number == excel:
            continue
        if raw.strip().startswith("#"):
            named_in_comment = _header_columns(raw.strip()[1:])
            if not seen_data and header is None and named_in_comment is not None:
                # numpy's savetxt writes its header so (genfromtxt's names=True reads it)
                _check_header(raw, f"{path}: line {number}", given, warnings)
                header = named_in_comment
            continue
        where = _Where(path, number, scale)
        _refuse_decimal_comma(raw, where)
        named = header is not None and header.positional(len(_cells(raw, header.separator)))
        fields = _named(raw, where, header) if named and header else _cells(raw, None)
        if header is not None and not named and len(fields) > 3:
            raise InputError(
                f"{path}: line {number}: {len(fields)} numbers, but the header names "
                f"{len(header.names)} columns; name every column in the header (x and y the "
                "X and Y ones), and camtool reads those two"
            )
        values = _row(fields, where, header_allowed=not seen_data)
        if values is None:  # the header
            seen_data = True
            _check_header(raw, f"{path}: line {number}", given, warnings)
            header = _header_columns(raw)
            continue
        seen_data = seen_data or bool(fields)
        if not values or all(math.isnan(v) for v in values):
            if current:
                strokes.append(_Stroke(tuple(current), start))
            current = []
            continue
        iz: int | None = 2
        if named:
            ix, iy = 0, 1  # _named gave X, Y (and Z) in that order
        else:
            ix, iy, iz = (header.x, header.y, header.z) if header else (0, 1, 2)
            if columns is None:
                columns = len(values)
            elif len(values) != columns:
                raise InputError(
                    f"{path}: line {number}: {len(values)} numbers where the rows above have "
                    f"{columns}; every row is X,Y or every row is X,Y,Z"
                )
            if max(ix, iy) >= columns:
                raise InputError(
                    f"{path}: line {number}: {columns} numbers, but the header names X and Y "
                    f"columns {ix + 1} and {iy + 1}"
                )
        if not current:
            start = number
        current.append((values[ix], values[iy]))
        if iz is not None and iz < len(values):
            z_range = (
                [min(z_range[0], values[iz]), max(z_range[1], values[iz])]
                if z_range
                else [values[iz]] * 2
            )
    if current:
        strokes.append(_Stroke(tuple(current), start))
    _header_warnings(header, path, warnings)
    if z_range and z_range[0] != z_range[1]:
        warnings.append(
            f"{path}: Z varies from {z_range[0]:g} to {z_range[1]:g} (file units); camtool "
            "reads X and Y only (the drawing is 2D; depths come from --depth)"
        )
    return strokes


def _header_warnings(header: _Columns | None, path: Path, warnings: list[str]) -> None:
    """Say which columns the header's names made X and Y, and which named ones are not read."""
    if header is None:
        return
    if (header.x, header.y) != (0, 1):
        warnings.append(
            f"{path}: X and Y read from columns {header.x + 1} and {header.y + 1}, as the "
            "header names them"
        )
    if header.others():
        warnings.append(
            f"{path}: column(s) {', '.join(repr(n) for n in header.others())} not read "
            "(camtool reads the columns the header names X and Y, and Z)"
        )


def _excel_separator_line(text: str, path: Path) -> int | None:
    """The number of the first line when it is Excel's ``sep=`` line, else ``None``.

    Raises:
        InputError: it names a separator other than a comma, semicolon, tab or blank.
    """
    for number, raw in enumerate(text_lines(text), start=1):
        if not raw.strip():
            continue
        match = _EXCEL_SEPARATOR.fullmatch(raw)
        if match is None:
            return None
        if not match[1] or match[1] not in ",; \t":
            raise InputError(
                f"{path}: line {number}: {raw.strip()!r} names the column separator "
                f"{match[1]!r}; camtool reads columns separated by a comma, semicolon, tab "
                "or spaces: export the file with one of them"
            )
        return number
    return None


def _refuse_decimal_comma(raw: str, where: _Where) -> None:
    """Refuse a comma between two digits in a row separated otherwise (a decimal comma)."""
    comma = _decimal_comma(raw)
    if comma is not None and _OTHER_SEPARATOR.search(raw):
        start, number = comma
        raise where.fail(
            start + 1,
            f"{_quote(number)} has a decimal comma (the row separates its columns by "
            "semicolons, tabs or blanks); camtool reads decimal points: save the file "
            "with '.' decimals (a spreadsheet's export in an English locale)",
        )


def _decimal_comma(raw: str) -> tuple[int, str] | None:
    """The first number of ``raw`` with a comma between two digits, and where it starts.

    The number is the run of digits and points around the first such comma, with a sign
    before it (``-1.5,25``); a scan out from the comma, linear in the row's length.
    """
    found = _DIGIT_COMMA.search(raw)
    if found is None:
        return None
    start, end = found.start(), found.end()
    while start > 0 and (raw[start - 1].isdecimal() or raw[start - 1] == "."):
        start -= 1
    if start > 0 and raw[start - 1] in "+-":
        start -= 1
    while end < len(raw) and (raw[end].isdecimal() or raw[end] == "."):
        end += 1
    return start, raw[start:end]


@dataclass(frozen=True)
class _Where:
    """The file and line being read, and mm per file unit (for the range check)."""

    path: Path
    line: int
    scale: float

    def fail(self, column: int, text: str) -> InputError:
        return InputError(f"{self.path}: line {self.line}, column {column}: {text}")


def _row(
    fields: list[tuple[str, int]], where: _Where, *, header_allowed: bool
) -> list[float] | None:
    """The numbers of one row of ``(text, 1-based column)`` fields.

    Returns ``None`` for a header, ``[]`` for a blank row, NaNs for a stroke break.

    Raises:
        InputError: a field that is not a number (after the header), a partly NaN row,
            a value out of range, or a count other than 2 or 3.
    """
    if not fields:
        return []
    nan = [text.lower() == _NAN for text, _ in fields]
    bad = [(text, col) for (text, col), n in zip(fields, nan, strict=True) if not n]
    bad = [(text, col) for text, col in bad if not NUMBER.fullmatch(text)]
    if bad:
        if header_allowed and not any(_loose_number(text) for text, _ in fields):
            return None
        text, col = bad[0]
        raise where.fail(col, f"{_quote(text)} is not a number; {_why_not(text)}")
    if any(nan) and not all(nan):
        col = fields[nan.index(True)][1]
        raise where.fail(col, "NaN in only some columns; a NaN row ends a stroke")
    if all(nan):
        return [math.nan] * len(fields)
    if len(fields) not in (2, 3):
        raise InputError(
            f"{where.path}: line {where.line}: {len(fields)} numbers; rows are X,Y or X,Y,Z "
            "(more columns need a header naming the X and Y columns: x,y,z,...)"
        )
    return [_in_range(text, col, where) for text, col in fields]


def _in_range(text: str, column: int, where: _Where) -> float:
    """The value of a number field, refused when it is absurd (at least LARGEST_VALUE mm)."""
    value = float(text)
    if not abs(value) * where.scale < LARGEST_VALUE:
        raise where.fail(
            column,
            f"{_quote(text)} is out of range (at most {LARGEST_VALUE:.0e} mm); "
            "the file is damaged or the unit is wrong (--units)",
        )
    return value


def _quote(text: str) -> str:
    return quoted(text, 24)


def _why_not(text: str) -> str:
    """What to do about a field that is not a plain decimal number."""
    if "_" in text and _loose_number(text):
        return "write digits without '_' (1000, not 1_000)"
    if text.lower().lstrip("+-") in ("inf", "infinity"):
        return "infinity is not a coordinate"
    if text.lower().startswith(("0x", "-0x", "+0x")):
        return "write decimal numbers, not hexadecimal"
    return (
        "rows are X,Y or X,Y,Z separated by a comma, semicolon, tab or spaces "
        "(decimal point, not comma)"
    )


def _loose_number(field: str) -> bool:
    """Whether Python's ``float`` takes ``field`` (so it is not a header word)."""
    try:
        float(field)
    except ValueError:
        return False
    return True


# ---------------------------------------------------------------------------- Matlab files


_ASSIGN = re.compile(r"([A-Za-z_]\w*)\s*=\s*")
_MATRIX = re.compile(r"\[([^\]\[]*)\]\s*[;,]?")


def _matlab_strokes(text: str, path: Path, scale: float) -> list[_Stroke]:
    """Strokes from every ``xy = [ ... ]`` assignment of a Matlab script (Angel-11 §3)."""
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
                "camtool reads the xy matrix of the thesis GUI (Angel-11 §3)"
            )
        pos = matrix.end()
        if assign.group(1) == "xy":
            strokes.append(
                _Stroke(_matrix(code, matrix.start(1), matrix.end(1), path, scale), line)
            )
    if not strokes:
        raise InputError(f"{path}: no 'xy = [ ... ]' matrix")
    return strokes


def _matrix(
    code: str, start: int, end: int, path: Path, scale: float
) -> tuple[tuple[float, float], ...]:
    """Columns ``(x, y)`` of the 2-row matrix body ``code[start:end]``.

    Rows end at ';' or a line break; numbers are separated by blanks or commas. Messages
    give the line of the matrix, and the line and column of a bad number in it.
    """
    line = code.count("\n", 0, start) + 1
    rows: list[list[float]] = [[]]
    for m in re.finditer(r"[;\n]|[^\s,;]+", code[start:end]):
        if m[0] in ";\n":
            rows.append([])
            continue
        offset = start + m.start()
        where = _Where(path, code.count("\n", 0, offset) + 1, scale)
        column = offset - code.rfind("\n", 0, offset)
        if not NUMBER.fullmatch(m[0]):
            why = "; NaN and Inf are not coordinates" if m[0].lower() in ("nan", "inf") else ""
            raise where.fail(column, f"{_quote(m[0])} in xy is not a number{why}")
        rows[-1].append(_in_range(m[0], column, where))
    rows = [r for r in rows if r]
    if len(rows) != 2:
        raise InputError(
            f"{path}: line {line}: xy has {len(rows)} rows; it must have 2 (x, then y)"
        )
    if len(rows[0]) != len(rows[1]):
        raise InputError(
            f"{path}: line {line}: xy rows have {len(rows[0])} and {len(rows[1])} numbers; "
            "x and y need one number per point each"
        )
    return tuple(zip(rows[0], rows[1], strict=True))
