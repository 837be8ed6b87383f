"""A batch's plan: the tasks (file, target, output), the plan of them all, a row of the report."""

from __future__ import annotations

import signal
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.jobs.batch_report import summary_table as summary_table  # camtool.batch API
from camtool.jobs.by_hand import needs_numbers, program_path
from camtool.model.errors import CamtoolError

if TYPE_CHECKING:
    from camtool.jobs.batch import BatchOptions


@dataclass(frozen=True)
class BatchTask:
    """One file's work, given to a worker (picklable).

    Attributes:
        file: the input file, as the user will see it named.
        code_path: where its code goes.
        report_path: where its verify report goes (``None``: not verified).
        preview_path: where its preview goes (``None``: no preview).
        target: the target it is posted for when the batch has several (``None``:
            the batch's only target).
        tools: for a job on a target that cannot change tools, the T numbers of its
            programs in the order they run, one per tool change (``code_path`` then names
            none of them: each is :func:`~camtool.jobs.by_hand.program_path`'s
            ``<name>.T<n><ending>``); empty: one program at ``code_path``.
    """

    file: str
    code_path: str
    report_path: str | None = None
    preview_path: str | None = None
    target: str | None = None
    tools: tuple[int, ...] = ()

    @property
    def outputs(self) -> tuple[str, ...]:
        """Every path this task writes."""
        base = Path(self.code_path)
        numbered = needs_numbers(self.tools)
        codes = [program_path(base, k, t, numbered) for k, t in enumerate(self.tools, 1)]
        paths = (*(codes or [self.code_path]), self.report_path, self.preview_path)
        return tuple(p for p in paths if p is not None)


@dataclass(frozen=True)
class BatchPlan:
    """A checked batch, ready to run: its options and one task per file, in order."""

    options: BatchOptions
    tasks: tuple[BatchTask, ...]


@dataclass(frozen=True, kw_only=True)
class BatchRow:
    """What became of one file (picklable).

    Attributes:
        file: the input file.
        target: the target it was posted for when the batch has several (``None``:
            the batch's only target).
        status: one of :data:`STATUSES`.
        exit_code: the code ``camtool post`` would have exited with for it (0 ok).
        blocks: blocks written (``None`` when posting failed).
        max_error_um: predicted error, µm (``None`` when not verified).
        time_s: machining time, s: predicted by the verifier when ``verified``,
            else the cutting moves at their programmed feeds (rapids excluded).
        verified: whether the file was verified.
        code_path, report_path, preview_path: the files written (``None``: not written).
        warnings: warnings of every stage, without repeats.
        error: why the file failed or is over the limit ("" when ok).
    """

    file: str
    status: str
    exit_code: int
    target: str | None = None
    blocks: int | None = None
    max_error_um: float | None = None
    time_s: float | None = None
    verified: bool = False
    code_path: str | None = None
    report_path: str | None = None
    preview_path: str | None = None
    warnings: tuple[str, ...] = ()
    error: str = ""


@dataclass(frozen=True)
class BatchResult:
    """A finished batch: its options and one row per file, in input order."""

    options: BatchOptions
    rows: tuple[BatchRow, ...]

    @property
    def exit_code(self) -> int:
        """The batch's exit code (see :func:`batch_exit_code`)."""
        return batch_exit_code(self.rows)


class BatchInterrupted(CamtoolError):
    """A batch stopped by Ctrl-C (SIGINT) or SIGTERM before every file was posted.

    Exit code 128 + the signal's number: 130 for SIGINT, 143 for SIGTERM (as a shell
    reports a process the signal ended).

    Attributes:
        result: the files finished before the signal, in input order: their outputs are
            written whole (``ok``, ``over-limit``) or not at all (``error``).
        unwritten: the files not finished, in input order: none of their outputs is
            written (an output of a previous run, with ``force``, is left as it was).
        signal_name: ``"SIGINT"`` or ``"SIGTERM"``.
    """

    def __init__(self, result: BatchResult, unwritten: tuple[BatchTask, ...], signum: int) -> None:
        self.result = result
        self.unwritten = unwritten
        self.signal_name = signal.Signals(signum).name
        self.exit_code = 128 + signum
        rows = result.rows
        written = sum(r.status != "error" for r in rows)
        reported = result.options.report is not None
        super().__init__(
            f"stopped by {self.signal_name} after {len(rows)} of {len(rows) + len(unwritten)} "
            f"file(s): {written} written, {len(rows) - written} failed, {len(unwritten)} not "
            "posted (nothing of them written)"
            + ("; the batch report is not written" if reported else "")
        )


def batch_exit_code(rows: Sequence[BatchRow]) -> int:
    """0 when every row is ok, else the smallest non-zero per-file exit code.

    The order 1 < 2 < 3 < 4 ranks a general error above a bad option, a bad
    input and an accuracy limit (see the module docstring).
    """
    codes = [row.exit_code for row in rows if row.exit_code]
    return min(codes) if codes else 0
