"""``camtool batch``: post many drawings for one target, in parallel, with a summary.

A thin click wrapper over :mod:`camtool.jobs.batch` (see docs/batch.md). Progress
goes to stderr — a bar on a terminal, one plain line per finished file
otherwise — then the summary table; stdout carries only ``--report -``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from camtool.cli.common import (
    JOB,
    MACHINE,
    WholeNumber,
    import_options,
    number_range,
    output_settings,
    plan_settings,
    post_options,
    read_job,
    refuse_operation_flags,
    write_output,
)
from camtool.model.errors import CamtoolError, InputError, UsageError, VerifyLimitError

if TYPE_CHECKING:
    from collections.abc import Callable

    from camtool.jobs.batch_plan import BatchPlan, BatchResult, BatchRow

_PREVIEW_FORMATS = ("png", "svg")  # camtool.jobs.batch.PREVIEW_FORMATS, validated there too
_ERRORS: dict[int, type[CamtoolError]] = {2: UsageError, 3: InputError, 4: VerifyLimitError}
"""The error a failed batch exits with, by its exit code (others: CamtoolError, 1)."""


def _post_options(command: Callable[..., None]) -> Callable[..., None]:
    """The options of ``camtool post`` that shape each file (machine and importers too)."""
    return post_options(MACHINE(import_options(command)))


@click.command()
@click.argument("inputs", nargs=-1, required=True, metavar="INPUTS...")
@click.option(
    "--target",
    "-t",
    required=True,
    multiple=True,
    metavar="NAME",
    help="See `camtool targets`. Repeat for several: each writes below OUTDIR/<NAME>/.",
)
@click.option(
    "-o",
    "--output-dir",
    required=True,
    type=click.Path(file_okay=False, path_type=Path),
    metavar="OUTDIR",
    help="Where the outputs go, keeping each file's path below its input.",
)
@click.option(
    "--jobs",
    "-j",
    type=WholeNumber(min=1),
    default=None,
    metavar="N",
    help="Worker processes [default: all cores]; 1 runs in this process.",
)
@click.option(
    "--scheduler",
    default=None,
    metavar="ADDRESS",
    help="Post on a Dask cluster instead: its scheduler (tcp://HOST:8786), or local:N to "
    "start N workers here. Needs pip install 'camtool[cluster]'; not with --jobs.",
)
@click.option("--verify", "verify_too", is_flag=True, help="Verify each file; write its report.")
@click.option(
    "--preview",
    type=click.Choice(_PREVIEW_FORMATS),
    default=None,
    help="Draw each file (with --verify: its simulated cut and worst point too).",
)
@click.option(
    "--max-error-um",
    type=number_range(min=0),
    default=None,
    metavar="N",
    help="A file whose predicted error exceeds N µm is over the limit: exit code 4 "
    "(implies --verify).",
)
@click.option(
    "--strict",
    is_flag=True,
    help="--max-error-um also counts the features the planner reported it cannot cut "
    "as drawn with this tool (tight corners, regions narrower than the tool).",
)
@click.option("--report", default=None, metavar="BATCH.json", help="Batch report ('-': stdout).")
@click.option("--force", is_flag=True, help="Overwrite existing outputs.")
@JOB
@_post_options
def batch(inputs: tuple[str, ...], layers: str | None, verify_too: bool, **options: Any) -> None:
    """Post every drawing of INPUTS (files, directories, quoted globs with **) for a target.

    Each file is posted as `camtool post` would, in parallel (on this machine, or on a
    Dask cluster with --scheduler); one bad file never stops the others. Outputs keep
    the path below their input (drawings/a/b.dxf → OUTDIR/a/b.<ending>, .json when
    verified, .png/.svg with --preview; OUTDIR/<target>/a/b.<ending> with several
    targets) and are never overwritten without --force. Exit code: 0 all ok, else the
    smallest per-file code (1 error, 2 usage, 3 unreadable input, 4 over --max-error-um).
    Ctrl-C or SIGTERM stops it at once, keeping the files finished, with a summary of what
    was and was not written (exit code 130, 143 for SIGTERM).
    """
    from camtool.jobs.batch import BatchOptions, plan_batch
    from camtool.jobs.batch_plan import BatchInterrupted
    from camtool.jobs.batch_report import batch_report, failure_line, summary_table, unwritten_lines

    names = tuple(n.strip() for n in layers.split(",") if n.strip()) if layers else None
    job_file = options.pop("job_file")
    refuse_operation_flags(job_file)
    planning, output = plan_settings(options), output_settings(options)
    job = None if job_file is None else read_job(job_file, planning)
    settings = BatchOptions(
        layers=names, verify=verify_too, plan=planning, output=output, job=job, **options
    )
    plan = plan_batch(inputs, settings)
    try:
        result = _run(plan)
    except BatchInterrupted as stop:
        click.echo("", err=True)  # off the line ^C was echoed on
        table = summary_table(stop.result) if stop.result.rows else ""
        click.echo(table + unwritten_lines(stop), err=True, nl=False)
        raise
    click.echo(summary_table(result), err=True, nl=False)
    if options["report"] == "-":  # a report file is written by run_batch, in its claim
        text = json.dumps(batch_report(result), indent=2, ensure_ascii=False)
        write_output(text + "\n", "-")
    if result.exit_code:
        raise _ERRORS.get(result.exit_code, CamtoolError)(failure_line(result))


def _run(plan: BatchPlan) -> BatchResult:
    """Run the batch with progress on stderr: a bar on a terminal, else a line per file."""
    from camtool.jobs.batch import run_batch
    from camtool.jobs.batch_report import progress_line

    if not sys.stderr.isatty():
        return run_batch(
            plan, progress=lambda done, n, row: click.echo(progress_line(done, n, row), err=True)
        )
    with click.progressbar(
        length=len(plan.tasks),
        label="camtool batch",
        file=sys.stderr,
        item_show_func=_row_name,
    ) as bar:
        return run_batch(plan, progress=lambda _done, _n, row: bar.update(1, row))


def _row_name(row: BatchRow | None) -> str | None:
    return row.file if row is not None else None
