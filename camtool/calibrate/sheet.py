"""The measurement sheet: what to measure on the coupon, where, and the column to fill in.

Two forms of the same rows: ``coupon.md`` (Markdown, to print and read at the comparator) and
``coupon.csv`` (the template to fill in and give to ``camtool calibrate fit``). CSV columns:

Design notes: docs/internals.md, ``camtool/calibrate/sheet.py``.
"""

from __future__ import annotations

import csv
import io
import math
import re
from pathlib import Path

from camtool.calibrate.coupon import Coupon, Measure
from camtool.calibrate.fitdata import Observation
from camtool.model.errors import InputError, quoted
from camtool.model.machine import Machine
from camtool.model.tomlfile import read_small_text
from camtool.model.units import LARGEST_VALUE, fmt_num

SHEET_BYTES = 1 << 20
"""The largest sheet read, bytes (a coupon's filled-in sheet is under 20 KB)."""
NUMBER = re.compile(r"[+-]?+(\d++\.?+\d*+|\.\d++)([eE][+-]?+\d++)?+", re.ASCII)
"""A plain ASCII decimal (``12``, ``12.5``, ``.5``, ``1.2e-3``): what a sheet's number may be.
Python's ``float`` also takes ``1_5``, full-width and Arabic-Indic digits, ``inf`` and ``nan``."""

COLUMNS = (
    "id",
    "what",
    "x_mm",
    "y_mm",
    "nominal_mm",
    "measured_mm",
    "compensation_x_um",
    "compensation_y_um",
)


def _n(value: float, decimals: int = 4) -> str:
    text = fmt_num(value, decimals)
    return text.rstrip("0").rstrip(".") if "." in text else text


def sheet_csv(coupon: Coupon, machine: Machine) -> str:
    """The CSV template of ``coupon``'s measures (``measured_mm`` empty)."""
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS)
    comp = machine.backlash.compensation_um
    for m in coupon.measures:
        writer.writerow(
            [
                m.id,
                m.what,
                _n(m.at_mm[0]),
                _n(m.at_mm[1]),
                _n(m.nominal_mm, 6),
                "",
                _n(comp[0], 3),
                _n(comp[1], 3),
            ]
        )
    return out.getvalue()


def sheet_markdown(
    coupon: Coupon, machine: Machine, *, code: str = "the coupon program", csv: str = "coupon.csv"
) -> str:
    """The printable sheet: how to cut, then one table per feature."""
    comp = machine.backlash.compensation_um
    lines = [
        f"# Calibration coupon for {coupon.target}",
        "",
        f"Cut {code} on the machine as it is set up (work zero where the program's X0 Y0 "
        f"is; backlash compensation X {_n(comp[0], 1)} µm, Y {_n(comp[1], 1)} µm as in the "
        "profile, or write the values you used in the CSV's compensation columns). Each feature "
        "starts with a short approach cut that takes up the play: it is not measured.",
        "",
        "Measure each row (a profile projector or a measuring microscope for small parts, a "
        "vernier for large ones), write the value in mm in the `measured_mm` column of the CSV "
        "template and run `camtool calibrate fit -t "
        f"{coupon.target} {csv} -o my-machine.toml`. Leave a row empty if you did not "
        "measure it.",
        "",
    ]
    if coupon.scale:
        lines += [
            f"Scale {coupon.scale:g} of UNAM-GMM's coupon (U 2.5/1.2 mm, squares 2.5 mm, "
            "circles ø6/4/2 mm), to fit the travel.",
            "",
        ]
    for feature in coupon.features:
        title = f"## {feature.id}: {feature.title}"
        lines += [title, ""]
        if feature.region:
            lines += [f"Backlash region: {feature.region}.", ""]
        lines += [
            "| id | what to measure | where (X, Y) mm | nominal mm | measured mm |",
            "|---|---|---|---|---|",
        ]
        for m in feature.measures:
            lines.append(
                f"| {m.id} | {m.what} | {_n(m.at_mm[0])}, {_n(m.at_mm[1])} | "
                f"{_n(m.nominal_mm, 6)} | |"
            )
        lines.append("")
    return "\n".join(lines)


def read_sheet(path: str | Path) -> str:
    """The text of a filled-in sheet file: a regular file of at most :data:`SHEET_BYTES`, UTF-8.

    Raises:
        InputError: missing or unreadable, not a regular file (a FIFO or a device is
            refused before it is opened for reading), too large or not UTF-8.
    """
    return read_small_text(path, what="measurement sheet", limit_bytes=SHEET_BYTES)


def read_measurements(text: str, coupon: Coupon, *, source: str) -> list[Observation]:
    """The filled-in rows of a sheet CSV as observations of ``coupon``'s measures.

    Raises:
        InputError: a missing column, an unknown or repeated id, a value that is not a finite
            number in range, or a nominal that is not the coupon's (the sheet of another
            coupon); each names ``source``, the line and the column.
    """
    measures = {m.id: m for m in coupon.measures}
    reader = csv.reader(io.StringIO(text))
    try:
        header = next(reader)
    except StopIteration:
        raise InputError(
            f"{source}: empty file; expected a CSV with columns {', '.join(COLUMNS)}"
        ) from None
    names = [h.strip().lower() for h in header]
    for required in ("id", "measured_mm"):
        if required not in names:
            split = next((d for d in (";", "\t") if len(names) == 1 and d in names[0]), None)
            hint = (
                f" (the columns are separated by {split!r}, as a spreadsheet set to a language "
                "with decimal commas saves them: save it as CSV with commas between the "
                "columns and points in the numbers)"
                if split
                else ""
            )
            raise InputError(
                f"{source}: line 1: no '{required}' column (columns: {', '.join(names)}); "
                f"expected {', '.join(COLUMNS)}{hint}"
            )
    out: list[Observation] = []
    seen: dict[str, int] = {}
    try:
        rows = list(reader)
    except csv.Error as exc:
        raise InputError(f"{source}: line {reader.line_num}: not valid CSV ({exc})") from exc
    for offset, row in enumerate(rows, start=2):
        if not any(cell.strip() for cell in row):
            continue
        cells = dict(zip(names, (c.strip() for c in row), strict=False))
        mid = cells.get("id", "")
        if mid not in measures:
            raise InputError(
                f"{source}: line {offset}, column 'id': unknown measure {mid!r}; this "
                f"coupon of {coupon.target} has {len(measures)} measures ({_some(measures)})"
            )
        if mid in seen:
            raise InputError(
                f"{source}: line {offset}, column 'id': {mid!r} repeats line {seen[mid]}"
            )
        seen[mid] = offset
        measure = measures[mid]
        _check_nominal(cells, measure, source, offset)
        value = _number(cells, "measured_mm", source, offset, positive=True)
        if value is None:
            continue
        cx = _number(cells, "compensation_x_um", source, offset)
        cy = _number(cells, "compensation_y_um", source, offset)
        comp = None if cx is None and cy is None else (cx or 0.0, cy or 0.0)
        out.append(Observation(measure, value, comp, offset))
    return out


def _some(measures: dict[str, Measure]) -> str:
    ids = list(measures)
    return ", ".join(ids[:6]) + (", ..." if len(ids) > 6 else "")


def _check_nominal(cells: dict[str, str], measure: Measure, source: str, line: int) -> None:
    nominal = _number(cells, "nominal_mm", source, line)
    if nominal is not None and abs(nominal - measure.nominal_mm) > 1e-6 * max(1.0, nominal):
        raise InputError(
            f"{source}: line {line}, column 'nominal_mm': {measure.id} is "
            f"{_n(measure.nominal_mm, 6)} mm on this coupon, the sheet says {_n(nominal, 6)}: "
            "the sheet is of another coupon; give the fit the same -t and --machine as the coupon"
        )


def _number(
    cells: dict[str, str], column: str, source: str, line: int, *, positive: bool = False
) -> float | None:
    text = cells.get(column, "")
    if not text:
        return None
    if NUMBER.fullmatch(text) is None:
        comma = NUMBER.fullmatch(text.replace(",", ".", 1)) is not None
        hint = f"; a decimal comma? write {text.replace(',', '.', 1)}" if comma else ""
        raise InputError(
            f"{source}: line {line}, column '{column}': {quoted(text)} is not a number (plain "
            "ASCII digits with a decimal point, e.g. 12.345; mm or µm as the column's name "
            f"says{hint})"
        )
    value = float(text)
    if (
        not math.isfinite(value)
        or abs(value) >= LARGEST_VALUE
        or value < 0
        or (positive and value == 0)
    ):
        want = "> 0" if positive else ">= 0"
        raise InputError(
            f"{source}: line {line}, column '{column}': {quoted(text)} must be a finite number "
            f"{want} and under {LARGEST_VALUE:g}"
        )
    return value
