"""What a batch tells: its JSON report, the summary table and the progress lines.

Pure functions of a :class:`~camtool.jobs.batch_plan.BatchResult` (or a row) returning data or
text; the CLI decides where they go.

Design notes: docs/internals.md, ``camtool/jobs/batch_report.py``.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camtool.model.version import __version__
from camtool.toolpath.options import PLAN_FIELDS

if TYPE_CHECKING:
    from camtool.jobs.batch import BatchOptions
    from camtool.jobs.batch_plan import BatchInterrupted, BatchResult, BatchRow

SHOWN_UNWRITTEN = 10
"""Files not posted named in an interrupted batch's summary (the rest are counted)."""

FILE_COLUMN_MAX = 48
"""Widest file column of the summary table; longer names keep their end."""
_NOT_OPTIONS = ("jobs", "force", "report")
_NOT_PLAN_OPTIONS = ("origin",)
"""Planning fields that are no option of ``batch`` (the tool's position before the program)."""


def batch_report(result: BatchResult) -> dict[str, Any]:
    """The batch report (keys in the module docstring), JSON-ready."""
    return {
        "camtool": __version__,
        "options": _options(result.options),
        "files": [row_dict(row) for row in result.rows],
        "totals": totals(result.rows),
        "exit_code": result.exit_code,
    }


def _options(options: BatchOptions) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for f in dataclasses.fields(options):
        if f.name in _NOT_OPTIONS:
            continue
        value = getattr(options, f.name)
        if f.name == "plan":
            out["feed_mm_min"] = value.feed_mm_min
            out["tolerance"] = value.tolerance
            out["plan"] = {
                k: _json(getattr(value, k))
                for k in type(value).__dataclass_fields__
                if k in PLAN_FIELDS and k not in _NOT_PLAN_OPTIONS
            }
        elif f.name == "output":
            out.update(dataclasses.asdict(value))
        elif f.name == "job":  # ``--job``: the job file's name, as the headers say it
            out["job"] = (value.source or None) if value is not None else None
        else:
            out[f.name] = _json(value)
    out["verify"] = options.verifying  # also when implied by preview or max_error_um
    return out


def _json(value: Any) -> Any:
    """An option's value as JSON: paths POSIX, tuples lists."""
    if isinstance(value, Path):
        return value.as_posix()
    if isinstance(value, tuple):
        return list(value)
    return value


def row_dict(row: BatchRow) -> dict[str, Any]:
    """One file of the report (its ``target`` only in a batch of several targets)."""
    named = {"target": row.target} if row.target is not None else {}
    return {
        "file": row.file,
        **named,
        "status": row.status,
        "exit_code": row.exit_code,
        "blocks": row.blocks,
        "max_error_um": None if row.max_error_um is None else round(row.max_error_um, 4),
        "time_s": None if row.time_s is None else round(row.time_s, 3),
        "verified": row.verified,
        "outputs": {"code": row.code_path, "report": row.report_path, "preview": row.preview_path},
        "warnings": list(row.warnings),
        "error": row.error,
    }


def totals(rows: tuple[BatchRow, ...]) -> dict[str, Any]:
    """Counts by status and sums over the files that posted (see the module docstring)."""
    errors = [r.max_error_um for r in rows if r.max_error_um is not None]
    return {
        "files": len(rows),
        "ok": sum(r.status == "ok" for r in rows),
        "error": sum(r.status == "error" for r in rows),
        "over_limit": sum(r.status == "over-limit" for r in rows),
        "blocks": sum(r.blocks or 0 for r in rows),
        "time_s": round(sum(r.time_s or 0.0 for r in rows), 3),
        "max_error_um": round(max(errors), 4) if errors else None,
    }


def summary_table(result: BatchResult) -> str:
    """The end-of-batch table: one line per file and a totals line (plain text).

    Columns: file, target (only in a batch of several targets), status, blocks,
    predicted max error (µm, ``-`` when not verified), machining time (s; verified
    time, else at programmed feeds), and a note (the error, or the number of warnings). Each
    line ends with a newline.
    """
    width = min(max([len("file")] + [len(r.file) for r in result.rows]), FILE_COLUMN_MAX)
    named = [r.target for r in result.rows if r.target is not None]
    tw = max([len("target"), *map(len, named)]) if named else 0

    def target(text: str | None) -> str:
        return f"{text or '':<{tw}}  " if tw else ""

    lines = [
        f"{'file':<{width}}  {target('target')}{'status':<10}  {'blocks':>6}  {'max µm':>9}  "
        f"{'machining s':>11}  note"
    ]
    for row in result.rows:
        note = message(row) if row.error else _warning_count(row)
        lines.append(
            f"{_shorten(row.file, width):<{width}}  {target(row.target)}{row.status:<10}  "
            f"{_int(row.blocks):>6}  {_fixed(row.max_error_um, 2):>9}  "
            f"{_fixed(row.time_s, 1):>11}  {note}".rstrip()
        )
    lines.append(totals_line(result))
    return "\n".join(lines) + "\n"


def totals_line(result: BatchResult) -> str:
    """``3 files: 1 ok, 1 over the limit, 1 error; 50 blocks; max 14.07 µm; 6804.2 s machining``."""
    t = totals(result.rows)
    text = (
        f"{t['files']} file(s): {t['ok']} ok, {t['over_limit']} over the limit, "
        f"{t['error']} error(s); {t['blocks']} blocks"
    )
    if t["max_error_um"] is not None:
        text += f"; max {t['max_error_um']:.2f} µm"
    untimed = sum(r.time_s is None and r.status != "error" for r in result.rows)
    but = f" ({untimed} written without a time: --verify times them)" if untimed else ""
    return f"{text}; {sum(r.time_s or 0.0 for r in result.rows):.1f} s machining{but}"


def progress_line(done: int, total: int, row: BatchRow) -> str:
    """One finished file, for a log (its machining time, not how long it took to post).

    ``[3/12] ok  a.dxf → out/a.pic  41 blocks  12.3 µm  2.1 s machining``. An error shows
    its message instead of the outputs; an over-limit file shows both. In a batch of
    several targets the file is followed by ``for <target>``.
    """
    head = f"[{done}/{total}] {row.status}  {row.file}"
    if row.target is not None:
        head += f" for {row.target}"
    if row.code_path is None:
        return f"{head}: {message(row) or 'failed'}"
    text = f"{head} → {row.code_path}  {row.blocks} blocks"
    if row.max_error_um is not None:
        text += f"  {row.max_error_um:.1f} µm"
    if row.time_s is not None:
        text += f"  {row.time_s:.1f} s machining"
    return f"{text}: {row.error}" if row.error else text


def message(row: BatchRow) -> str:
    """The first line of ``row``'s error, without a leading ``<file>: `` (shown beside it)."""
    first = row.error.splitlines()[0] if row.error else ""
    return first.removeprefix(f"{row.file}: ")


def unwritten_lines(stop: BatchInterrupted) -> str:
    """The files an interrupted batch did not post (the first :data:`SHOWN_UNWRITTEN` named).

    ``not posted (stopped by SIGINT): 3 file(s)`` then one indented line per file
    (``for <target>`` in a batch of several targets) and ``... and N more``; each line
    ends with a newline. Empty when every file was posted.
    """
    if not stop.unwritten:
        return ""
    lines = [f"not posted (stopped by {stop.signal_name}): {len(stop.unwritten)} file(s)"]
    for task in stop.unwritten[:SHOWN_UNWRITTEN]:
        lines.append(f"  {task.file}" + (f" for {task.target}" if task.target else ""))
    more = len(stop.unwritten) - SHOWN_UNWRITTEN
    if more > 0:
        lines.append(f"  ... and {more} more")
    return "\n".join(lines) + "\n"


def failure_line(result: BatchResult) -> str:
    """Why a batch failed, for its last line: ``1 of 3 file(s) failed, 1 over the limit``."""
    t = totals(result.rows)
    parts = [f"{t['error']} of {t['files']} file(s) failed"] if t["error"] else []
    if t["over_limit"]:
        parts.append(f"{t['over_limit']} of {t['files']} over the limit")
    return ", ".join(parts) + " (see the table above)"


def _warning_count(row: BatchRow) -> str:
    n = len(row.warnings)
    return "" if n == 0 else f"{n} warning{'s' if n > 1 else ''}"


def _shorten(text: str, width: int) -> str:
    return text if len(text) <= width else "…" + text[-(width - 1) :]


def _int(value: int | None) -> str:
    return "-" if value is None else str(value)


def _fixed(value: float | None, decimals: int) -> str:
    return "-" if value is None else f"{value:.{decimals}f}"
