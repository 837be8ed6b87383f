"""Many inputs, one or more targets: post every file in a process pool or on Dask; summarise.

Design notes: docs/internals.md, ``camtool/jobs/batch.py``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import os
import re
import signal
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camtool.importers.options import ImportOptions
from camtool.jobs.batch_plan import BatchInterrupted, BatchPlan, BatchResult, BatchRow, BatchTask
from camtool.jobs.batch_report import batch_report
from camtool.jobs.batch_report import summary_table as summary_table  # camtool.batch API
from camtool.jobs.batch_stop import Interrupts, Terminated, kill_pool, worker_init
from camtool.jobs.by_hand import earlier_pieces
from camtool.jobs.inputs import BatchInput, expand_inputs
from camtool.jobs.pipeline import OutputOptions
from camtool.model.errors import CamtoolError, InputError, UsageError, unexpected
from camtool.model.version import __version__
from camtool.toolpath.options import PlanOptions

if TYPE_CHECKING:
    from concurrent.futures import Future

    from camtool.jobs.job import Job
    from camtool.jobs.pipeline import PostJob
    from camtool.post.base import Target
    from camtool.verify.verifier import Verification

PREVIEW_FORMATS = ("png", "svg")
"""Preview picture formats (``--preview``)."""
STATUSES = ("ok", "error", "over-limit")
"""Values of :attr:`BatchRow.status`."""
SHOWN_EXISTING = 5
"""Existing outputs named in the refusal to overwrite (the rest are counted)."""

Progress = Callable[[int, int, "BatchRow"], None]
"""``progress(done, total, row)``: called in the calling process as each file finishes."""


@dataclass(frozen=True, kw_only=True)
class BatchOptions:
    """What every file of a batch is posted with (the ``post`` options) and what is kept.

    Attributes:
        target: a target name or target ``.toml`` path (see ``camtool targets``), or
            several (a sequence, kept as a tuple; one alone is kept as a string): each
            file is posted for each, below ``output_dir/<target name>``.
        output_dir: where the outputs go (created when missing).
        machine_file: machine profile laid over the target's (file or built-in name).
        plan: the planning options (``offset``, ``tool_diameter``, ``feed_mm_min`` —
            ``None``: the target's default —, ``tolerance`` (also the importers'
            curve-fit tolerance; chaining uses ``chain_tolerance``), ``scale``,
            ``depth``, ``order``...).
        output: the output format and spindle (``fmt``, ``spindle_rpm``,
            ``spindle_dwell_s``).
        job: the operations and tools of every drawing (``batch --job``); ``None``:
            ``plan`` is the one operation.
        layers: layers to keep (``None``: all).
        units: unit of unitless inputs (point lists).
        hatch_boundaries: use DXF HATCH boundaries as contours.
        max_entities: most entities a drawing may expand to (``None``: the importers'
            default, :data:`camtool.importers.options.MAX_ENTITIES`).
        verify: verify each file and write its report (``OUT/<name>.json``).
        preview: ``"png"`` or ``"svg"``: draw each file (``OUT/<name>.png``): the
            program, and when verified the simulated trace and its worst point.
        max_error_um: predicted error limit, µm: a file over it is ``over-limit``
            (implies ``verify``).
        strict: ``max_error_um`` also judges the features the planner reported it
            cannot cut as drawn with this tool (``--strict``).
        force: overwrite existing outputs.
        jobs: worker processes; ``None``: ``os.cpu_count()``; 1: in this process.
        scheduler: run on Dask instead (:mod:`camtool.jobs.batch_dask`): a scheduler's
            address (``tcp://HOST:8786``) or ``local:N`` (a cluster of N worker
            processes on this machine); ``None``: the process pool.
        report: the batch report's path, checked like an output and written by
            :func:`run_batch` before it releases the output folder (``"-"``: stdout,
            left to the caller).

    Raises:
        UsageError: ``preview`` is not one of :data:`PREVIEW_FORMATS`, ``jobs`` < 1,
            ``max_error_um`` < 0, no target or one named twice, a ``scheduler`` that
            is neither an address nor ``local:N``, or both ``jobs`` and ``scheduler``.
    """

    target: str | tuple[str, ...]
    output_dir: Path
    machine_file: Path | None = None
    plan: PlanOptions = field(default_factory=PlanOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    job: Job | None = None
    layers: tuple[str, ...] | None = None
    units: str | None = None
    hatch_boundaries: bool = False
    max_entities: int | None = None
    verify: bool = False
    preview: str | None = None
    max_error_um: float | None = None
    strict: bool = False
    force: bool = False
    jobs: int | None = None
    scheduler: str | None = None
    report: str | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "target", _targets(self.target))
        if self.preview is not None and self.preview not in PREVIEW_FORMATS:
            raise UsageError(
                f"unknown preview format {self.preview!r}; choose one of "
                f"{', '.join(PREVIEW_FORMATS)}"
            )
        if self.jobs is not None and self.jobs < 1:
            raise UsageError(f"--jobs must be at least 1, got {self.jobs}")
        if self.max_error_um is not None and self.max_error_um < 0:
            raise UsageError(f"--max-error-um must be >= 0, got {self.max_error_um:g}")
        if self.scheduler is not None:
            from camtool.jobs.batch_dask import check_scheduler

            check_scheduler(self.scheduler)
            if self.jobs is not None:
                raise UsageError(
                    f"--jobs {self.jobs} and --scheduler {self.scheduler} both say where "
                    "files are posted; give one of them"
                )

    @property
    def targets(self) -> tuple[str, ...]:
        """The targets, in the order given (one or more)."""
        return (self.target,) if isinstance(self.target, str) else self.target

    @property
    def verifying(self) -> bool:
        """True when each file is verified (``verify``, or implied by ``max_error_um``)."""
        return self.verify or self.max_error_um is not None

    def import_options(self) -> ImportOptions:
        """The importer options of every drawing."""
        options = ImportOptions(
            layers=self.layers,
            tolerance=self.plan.tolerance,
            units=self.units,
            hatch_boundaries=self.hatch_boundaries,
        )
        if self.max_entities is None:
            return options
        return dataclasses.replace(options, max_entities=self.max_entities)


def _targets(target: str | Sequence[str]) -> str | tuple[str, ...]:
    """``target`` as :class:`BatchOptions` keeps it: one name a string, several a tuple.

    Raises:
        UsageError: no target, or one named twice.
    """
    names = (target,) if isinstance(target, str) else tuple(target)
    if not names:
        raise UsageError("no --target given; name at least one (see `camtool targets`)")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise UsageError(f"--target {twice[0]} is given twice; name each target once")
    return names[0] if len(names) == 1 else names


def plan_batch(inputs: Sequence[str], options: BatchOptions) -> BatchPlan:
    """Expand ``inputs`` and check the whole batch before any work starts.

    Raises:
        UsageError: unknown target or format (for any of the targets), invalid post
            options, an output that would land outside the output folder (inputs
            named through ``..`` or a symlink), two files writing the same output
            (two target files of one name, too), an output that is an input (even
            with ``force``), existing outputs without ``force`` (the first
            :data:`SHOWN_EXISTING` named), or a ``scheduler`` without Dask installed.
        InputError: an input matches nothing, or a target/machine file is invalid.
    """
    if options.scheduler is not None:
        from camtool.jobs.batch_dask import require_dask

        require_dask()
    several = len(options.targets) > 1
    layouts = {name: _layout(name, options, several) for name in options.targets}
    if options.output_dir.exists() and not options.output_dir.is_dir():
        raise UsageError(f"{options.output_dir}: exists and is not a directory (-o OUTDIR)")
    items = expand_inputs(inputs, exclude=options.output_dir)
    tasks = tuple(
        _task(item, options, suffix, (name, folder) if several else None, tools)
        for name, (folder, suffix, tools) in layouts.items()
        for item in items
    )
    _check_outputs(items, tasks, options)
    return BatchPlan(options, tasks)


def _layout(name: str, options: BatchOptions, several: bool) -> tuple[str, str, tuple[int, ...]]:
    """The target ``name`` checked with the options: its folder, ending and per-tool programs.

    The last is the T numbers of a job's programs on a target that cannot change tools
    (one program per tool), empty otherwise.

    Raises:
        UsageError: as :func:`plan_batch`; a target whose name cannot be a folder
            (with several targets).
    """
    from camtool.jobs.pipeline import load_target_checked
    from camtool.jobs.run import plan_options

    target = load_target_checked(name, machine_file=options.machine_file)
    fmt = target.post.check_format(options.output.fmt)
    plan_options(target, options.plan)  # checks the options for the target once, before any file
    if several and (target.name in ("", ".", "..") or Path(target.name).name != target.name):
        raise UsageError(
            f"target {name}: its name {target.name!r} cannot name a folder of -o; "
            "give it a plain name (name = ... in its .toml)"
        )
    tools: tuple[int, ...] = ()
    if options.job is not None and target.post.tool_changes == "none":
        order = [op.tool for op in options.job.sequenced()]  # a change where the tool differs
        used = tuple(t for k, t in enumerate(order) if k == 0 or t != order[k - 1])
        tools = used if len(used) > 1 else ()
    return target.name, target.post.formats[fmt], tools


def _task(
    item: BatchInput,
    options: BatchOptions,
    suffix: str,
    of: tuple[str, str] | None,
    tools: tuple[int, ...] = (),
) -> BatchTask:
    """One file's task: for the batch's only target (``of`` None), or for one of several.

    ``of`` is ``(target as given, its folder below -o)``.
    """
    base = options.output_dir / (of[1] if of else "") / item.relative
    return BatchTask(
        file=str(item.path),
        code_path=str(base.with_suffix(suffix)),
        report_path=str(base.with_suffix(".json")) if options.verifying else None,
        preview_path=str(base.with_suffix(f".{options.preview}")) if options.preview else None,
        target=of[0] if of else None,
        tools=tools,
    )


def _check_outputs(
    items: Sequence[BatchInput], tasks: Sequence[BatchTask], options: BatchOptions
) -> None:
    """Every output inside ``-o``, none an input or another output, none existing unless forced.

    Raises:
        UsageError: as :func:`plan_batch` says.
    """
    from camtool.jobs.output import Named, check_outputs, definition_inputs

    _check_inside(tasks, options.output_dir)
    inputs: list[Named] = [("the input", i.path) for i in items]
    for name in options.targets:
        inputs += definition_inputs(name, options.machine_file)
    outputs: list[Named] = [("--report", options.report)]
    outputs += [(f"{task.file} →", out) for task in tasks for out in task.outputs]
    check_outputs(inputs, outputs, hint="post them in separate batches or rename one")
    if not options.force:
        _refuse_existing(tasks, options)


def _check_inside(tasks: Sequence[BatchTask], output_dir: Path) -> None:
    """Every output resolves (symlinks and ``..`` followed) to a path inside ``output_dir``."""
    root = os.path.realpath(output_dir)
    for task in tasks:
        for out in task.outputs:
            real = os.path.realpath(out)
            if real != root and not real.startswith(root.rstrip(os.sep) + os.sep):
                raise UsageError(
                    f"{task.file} → {out} would be written outside -o {output_dir} "
                    f"(it resolves to {real}); remove the symlink that leads out of the "
                    "output folder, or name the inputs without '..'"
                )


def _refuse_existing(tasks: Sequence[BatchTask], options: BatchOptions) -> None:
    """Without ``force``, outputs of a previous run (the first few named) are refused.

    Besides each task's planned outputs, the programs per tool a previous run wrote for
    its code (``part.T2.gcode``, ``part.start.gcode``, ``part.1.T1.gcode``): a re-posted
    program's are known only once it is read.
    """
    named = [t for t in (options.report,) if t is not None and t != "-"]
    named += [out for task in tasks for out in task.outputs]
    pieces: dict[str, dict[tuple[str, str], list[str]]] = {}  # by folder, by stem and ending
    for task in tasks:
        base = Path(task.code_path)
        folder = str(base.parent)
        if folder not in pieces:
            pieces[folder] = _pieces_in(folder)
        named += [str(base.parent / n) for n in pieces[folder].get((base.stem, base.suffix), [])]
    existing = sorted({out for out in named if os.path.lexists(out)})
    if existing:
        shown = ", ".join(existing[:SHOWN_EXISTING])
        more = len(existing) - SHOWN_EXISTING
        rest = f" and {more} more" if more > 0 else ""
        raise UsageError(
            f"{len(existing)} output(s) exist already: {shown}{rest}; "
            "use --force to overwrite them, or another -o"
        )


_PIECE = re.compile(r"(.+?)\.(?:(\d+)\.)?(?:T\d+|start)(\.[^.]+)?")
"""A program per tool's name (:func:`camtool.jobs.by_hand.program_path`): stem, number, ending."""


def _pieces_in(folder: str) -> dict[tuple[str, str], list[str]]:
    """The names in ``folder`` of programs per tool, by the stem and ending of their ``-o``."""
    found: dict[tuple[str, str], list[str]] = {}
    with contextlib.suppress(OSError):
        for name in os.listdir(folder):
            m = _PIECE.fullmatch(name)
            if m is None:
                continue
            ending = m[3] or ""
            found.setdefault((m[1], ending), []).append(name)
            if m[2] is not None:  # "a.1.T1.nc" may also be "a.1"'s own T1 program
                found.setdefault((f"{m[1]}.{m[2]}", ending), []).append(name)
    return found


def run(
    inputs: str | Sequence[str],
    *,
    targets: str | Sequence[str],
    output_dir: str | Path,
    client: Any = None,
    progress: Progress | None = None,
    **options: Any,
) -> BatchResult:
    """Plan and run a batch in one call: ``camtool.batch.run`` (docs/api.md, docs/batch.md).

    :func:`plan_batch` then :func:`run_batch`. A pipeline that already has a Dask
    client passes it in; the files are then posted on its cluster::

        from dask.distributed import Client
        import camtool

        with Client("tcp://scheduler:8786") as client:
            result = camtool.batch.run(["drawings"], targets=["grbl", "pic-mmh"],
                                       output_dir="out", client=client, verify=True)

    Args:
        inputs: files, directories and globs (one as a string, or several).
        targets: a target name (or target ``.toml`` path), or several.
        output_dir: where the outputs go.
        client: a ``dask.distributed.Client`` to post on (``None``: ``scheduler``, else
            the process pool).
        progress: called as each file finishes (see :data:`Progress`).
        **options: any other field of :class:`BatchOptions` (``verify``, ``preview``,
            ``max_error_um``, ``plan``, ``jobs``, ``scheduler``, ``force``, ``report``...).

    Returns:
        The finished batch; its ``exit_code`` is what ``camtool batch`` exits with.

    Raises:
        UsageError, InputError, CamtoolError: as :func:`plan_batch` and :func:`run_batch`.
    """
    names = [inputs] if isinstance(inputs, str) else list(inputs)
    opts = BatchOptions(target=_targets(targets), output_dir=Path(output_dir), **options)
    return run_batch(plan_batch(names, opts), progress=progress, client=client)


def run_batch(
    plan: BatchPlan, *, progress: Progress | None = None, client: Any = None
) -> BatchResult:
    """Post every file of ``plan``; one file's failure never stops the others.

    The output folder is claimed for the whole run
    (:func:`camtool.jobs.output.lock_directory`), so two batches never write into one
    folder at once; under the claim, outputs that appeared since :func:`plan_batch`
    are refused again (unless ``force``), stale temporary files of killed runs are
    removed, and at the end the batch report is written (when ``options.report``
    names a file; ``"-"`` is left to the caller).

    Where the files are posted: on the Dask cluster of ``client`` when one is given
    (the report's ``scheduler`` is its address), on ``options.scheduler``'s
    (:func:`camtool.jobs.batch_dask.connect`), else in a process pool of
    ``options.jobs`` (in this process for 1).

    Args:
        plan: from :func:`plan_batch`.
        progress: called in this process as each file finishes, in finishing order.
        client: a ``dask.distributed.Client`` to post on (``None``: see above).

    Ctrl-C (SIGINT) and SIGTERM, in the main thread, stop the batch at once
    (:class:`Interrupts`): the pool's workers are killed (a file being posted is lost,
    never half written), Dask's tasks cancelled (a ``local:N`` cluster closed), the
    claim released, and :class:`BatchInterrupted` raised with the files finished and
    those not written. No batch report is written then.

    Returns:
        The rows in the plan's (sorted input) order.

    Raises:
        CamtoolError: another run holds the output folder, the batch report cannot be
            written, or the Dask scheduler cannot be reached or has no worker.
        UsageError: outputs appeared since the plan was checked (without ``force``);
            a ``client`` with ``jobs`` or ``scheduler``.
        BatchInterrupted: Ctrl-C or SIGTERM (or a ``KeyboardInterrupt`` raised by the
            caller's own handler) stopped it.
    """
    options = plan.options if client is None else _with_client(plan.options, client)
    rows: dict[int, BatchRow] = {}
    with Interrupts() as interrupts:
        try:
            return _run_claimed(plan.tasks, options, client, progress, rows, interrupts)
        except KeyboardInterrupt as exc:
            done = tuple(rows[i] for i in sorted(rows))
            left = tuple(t for i, t in enumerate(plan.tasks) if i not in rows)
            signum = signal.SIGTERM if isinstance(exc, Terminated) else signal.SIGINT
            raise BatchInterrupted(BatchResult(options, done), left, signum) from None


def _run_claimed(
    tasks: Sequence[BatchTask],
    options: BatchOptions,
    client: Any,
    progress: Progress | None,
    rows: dict[int, BatchRow],
    interrupts: Interrupts,
) -> BatchResult:
    """:func:`run_batch` once the signals are taken: ``rows`` fills up as files finish."""
    from camtool.jobs.output import lock_directory

    with contextlib.ExitStack() as stack:
        if client is None and options.scheduler is not None:
            from camtool.jobs.batch_dask import connect

            # before -o is touched; local:N starts no more workers than files, as --jobs
            client = stack.enter_context(connect(options.scheduler, most_workers=len(tasks)))
        with lock_directory(options.output_dir):
            if not options.force:
                _refuse_existing(tasks, options)
            _remove_stale_temps(tasks)
            if client is not None:
                _run_dask(tasks, options, client, progress, rows, interrupts)
            else:
                _run_here(tasks, options, progress, rows, interrupts)
            result = BatchResult(options, tuple(rows[i] for i in range(len(tasks))))
            if options.report is not None and options.report != "-":
                _write_report(result, options.report)
    return result


def _with_client(options: BatchOptions, client: Any) -> BatchOptions:
    """``options`` with ``scheduler`` the address of ``client``'s scheduler (for the report).

    Raises:
        UsageError: ``options`` names ``jobs`` or a ``scheduler`` too.
    """
    if options.jobs is not None or options.scheduler is not None:
        given = "jobs" if options.jobs is not None else "scheduler"
        raise UsageError(f"a Dask client and {given} both say where files are posted; give one")
    return dataclasses.replace(options, scheduler=str(client.scheduler.address))


def _run_here(
    tasks: Sequence[BatchTask],
    options: BatchOptions,
    progress: Progress | None,
    rows: dict[int, BatchRow],
    interrupts: Interrupts,
) -> None:
    """Post ``tasks`` on this machine, into ``rows``: a process pool, or this process for 1."""
    jobs = min(options.jobs or os.cpu_count() or 1, len(tasks))
    if jobs > 1:
        _run_pool(tasks, options, jobs, progress, rows, interrupts)
        return
    if len(tasks) > 1:
        _offsets_here(options)
    for done, task in enumerate(tasks, start=1):
        row, files = _posted(task, options)
        with interrupts.held():
            rows[done - 1] = _publish(task, row, files)
        if progress is not None:
            progress(done, len(tasks), rows[done - 1])


def _offsets_here(options: BatchOptions) -> None:
    """Load OpenCASCADE here once when every file will be offset in this process, one by one."""
    from camtool.toolpath.compensate import makes_offsets
    from camtool.toolpath.offset import load_here

    if makes_offsets(options.plan):
        load_here()


def _run_dask(
    tasks: Sequence[BatchTask],
    options: BatchOptions,
    client: Any,
    progress: Progress | None,
    rows: dict[int, BatchRow],
    interrupts: Interrupts,
) -> None:
    """Post ``tasks`` on ``client``'s cluster, into ``rows``; the files written here.

    Each task travels with the input's bytes (read here, as it is submitted) and the
    target loaded here (so a target or ``--machine`` file need not exist on the
    workers); each worker returns the row and the outputs' bytes
    (:func:`post_data`), written here as for the pool (:func:`_write`). A task that
    failed on the cluster (its workers kept dying) is that file's error row.
    """
    from camtool.jobs.batch_dask import map_unordered
    from camtool.jobs.pipeline import load_target_checked

    loaded = {n: load_target_checked(n, machine_file=options.machine_file) for n in options.targets}

    def arguments(i: int) -> tuple[Any, ...]:
        task = tasks[i]
        return task, options, loaded[task.target or options.targets[0]], _read(task.file)

    for done, (i, value, error) in enumerate(
        map_unordered(client, post_data, len(tasks), arguments), start=1
    ):
        with interrupts.held():
            rows[i] = _written(tasks[i], value, error)
        if progress is not None:
            progress(done, len(tasks), rows[i])


def _read(file: str) -> bytes | CamtoolError:
    """The bytes of the input ``file``, or the error reading it (that file's error row)."""
    from camtool.jobs.output import reason

    try:
        return Path(file).read_bytes()
    except FileNotFoundError:
        return InputError(f"{file}: no such file")
    except OSError as exc:
        return InputError(f"{file}: cannot read ({reason(exc)})")


Files = tuple[tuple[str, "str | bytes"], ...]
"""A file's outputs, ``(path, text or bytes)``, in the order they are written."""
Written = tuple["BatchRow", Files, str]
"""What a Dask worker returns (:func:`post_data`): the row, the outputs, its camtool version."""


def _written(task: BatchTask, value: Written | None, error: BaseException | None) -> BatchRow:
    """The row of a Dask task, once its outputs are written here (or why not)."""
    if error is not None or value is None:
        return _error_row(task, 1, f"worker failed: {type(error).__name__}: {error}")
    row, files, version = value
    if version != __version__:
        return _error_row(
            task,
            1,
            f"the Dask worker runs camtool {version}, this camtool is {__version__}; "
            "install the same camtool on every worker",
        )
    return _publish(task, row, files)


def _publish(task: BatchTask, row: BatchRow, files: Files) -> BatchRow:
    """Write a posted file's outputs (each atomically); its row, or why they cannot be written."""
    try:
        for path, data in files:
            _write(path, data)
    except CamtoolError as exc:
        return _error_row(task, exc.exit_code, str(exc))
    return row


def _remove_stale_temps(tasks: Sequence[BatchTask]) -> None:
    """Temporary files left by killed runs, in every folder this batch writes into."""
    from camtool.jobs.output import reason, remove_stale_temps

    for folder in sorted({Path(out).parent for task in tasks for out in task.outputs}):
        try:
            remove_stale_temps(folder)
        except OSError as exc:
            raise CamtoolError(f"{folder}: cannot write ({reason(exc)})") from exc


def _write_report(result: BatchResult, path: str) -> None:
    """The batch report (:func:`batch_report`) as UTF-8 JSON."""
    text = json.dumps(batch_report(result), indent=2, ensure_ascii=False) + "\n"
    _write(path, text)


def _run_pool(
    tasks: Sequence[BatchTask],
    options: BatchOptions,
    jobs: int,
    progress: Progress | None,
    rows: dict[int, BatchRow],
    interrupts: Interrupts,
) -> None:
    """Post ``tasks`` in a pool of ``jobs`` processes, into ``rows``; the files written here.

    The workers post (:func:`_posted`) and this process writes (:func:`_publish`), so
    a worker killed mid-file leaves nothing behind. They die with this process
    (:func:`worker_init`), so killing a batch (even with ``kill -9``) leaves no
    worker running or holding its pipes; and when the loop ends early (Ctrl-C, a
    failing progress callback) they are killed at once (:func:`_kill_pool`) rather
    than left to finish the files they hold.
    """
    from concurrent.futures import ProcessPoolExecutor, as_completed

    pool = ProcessPoolExecutor(max_workers=jobs, initializer=worker_init, initargs=(os.getpid(),))
    try:
        futures = {pool.submit(_posted, task, options): i for i, task in enumerate(tasks)}
        for done, future in enumerate(as_completed(futures), start=1):
            index = futures[future]
            with interrupts.held():
                rows[index] = _collect(future, tasks[index])
            if progress is not None:
                progress(done, len(tasks), rows[index])
    except BaseException:
        kill_pool(pool)
        raise
    pool.shutdown()


def _collect(future: Future[tuple[BatchRow, Files]], task: BatchTask) -> BatchRow:
    """The row of a worker's file once its outputs are written here, or why they are not."""
    try:
        row, files = future.result()
    except Exception as exc:  # e.g. a worker killed (BrokenProcessPool): that file's error
        return _error_row(task, 1, f"worker failed: {type(exc).__name__}: {exc}")
    return _publish(task, row, files)


def post_one(task: BatchTask, options: BatchOptions) -> BatchRow:
    """Post (and verify, and draw) one file and write its outputs.

    Never raises for the file's own problems: a :class:`CamtoolError` becomes an
    ``error`` row with its exit code, any other exception an ``error`` row with
    exit code 1 ("internal error").
    """
    return _publish(task, *_posted(task, options))


def _posted(task: BatchTask, options: BatchOptions) -> tuple[BatchRow, Files]:
    """One file posted (and verified, and drawn), its outputs in memory: the pool's worker.

    Touches no output; errors become rows as in :func:`post_one` (with no outputs).
    """
    try:
        return _outputs(task, options, _post_job(task.file, _for(task, options)))
    except CamtoolError as exc:
        return _error_row(task, exc.exit_code, str(exc)), ()
    except Exception as exc:  # a bug on one file (or no memory left) must not stop the batch
        return _error_row(task, 1, unexpected(exc)), ()


def post_data(
    task: BatchTask, options: BatchOptions, target: Target, data: bytes | CamtoolError
) -> Written:
    """Post (and verify, and draw) one file given as bytes: the Dask worker of a batch.

    Touches no file: ``data`` is the input's bytes (or the error reading it, which
    becomes the row), ``target`` the target loaded by the batch; the outputs come
    back as ``(path, text or bytes)`` for the batch to write, with this worker's
    camtool version (a batch refuses results of another version). Errors become
    rows as in :func:`post_one`.
    """
    from camtool.jobs.pipeline import post_bytes

    try:
        if isinstance(data, CamtoolError):
            raise data
        job = post_bytes(
            data,
            task.file,
            target,
            options.plan,
            options.output,
            import_options=options.import_options(),
            job=options.job,
        )
        row, files = _outputs(task, options, job)
        return row, files, __version__
    except CamtoolError as exc:
        return _error_row(task, exc.exit_code, str(exc)), (), __version__
    except Exception as exc:  # a bug on one file (or no memory left) must not stop the batch
        return _error_row(task, 1, unexpected(exc)), (), __version__


def _for(task: BatchTask, options: BatchOptions) -> BatchOptions:
    """The options ``task`` is posted with: the batch's, for the task's own target."""
    if task.target is None or task.target == options.target:
        return options
    return dataclasses.replace(options, target=task.target)


def _error_row(task: BatchTask, code: int, message: str) -> BatchRow:
    return BatchRow(
        file=task.file, target=task.target, status="error", exit_code=code, error=message
    )


def _outputs(task: BatchTask, options: BatchOptions, job: PostJob) -> tuple[BatchRow, Files]:
    """The row of a posted file and its outputs ``(path, data)``, verified and drawn as asked."""
    files: list[tuple[str, str | bytes]] = [(task.code_path, job.result.code)]
    if job.pieces:  # a target that cannot change tools: one program per tool
        files = [(piece.path(task.code_path), piece.result.code) for piece in job.pieces]
    written = [path for path, _ in files]  # without --force, any earlier one was refused
    earlier = earlier_pieces(task.code_path, written) if options.force else None
    warnings = job.warnings + ((earlier,) if earlier else ())
    error_um: float | None = None
    # at programmed feeds, where the machine runs them; else known only by simulating
    time_s = job.program.cutting_time_s() if job.target.post.writes_feeds else None
    v = None
    if options.verifying:
        from camtool.jobs.pipeline import report_json, verify_job

        v = verify_job(job)
        error_um, time_s = v.max_error_um, v.time_s
        warnings = tuple(dict.fromkeys(warnings + v.warnings))
        if task.report_path is not None:
            files.append((task.report_path, report_json(v, job.plan)))
    if task.preview_path is not None:
        files.append((task.preview_path, preview_bytes(job, v, task.preview_path, task.file)))
    problem = None
    if v is not None and options.max_error_um is not None:
        problem = v.over_limit(options.max_error_um, strict=options.strict)
    over = problem is not None
    row = BatchRow(
        file=task.file,
        target=task.target,
        status="over-limit" if over else "ok",
        exit_code=4 if over else 0,
        blocks=job.result.blocks,
        max_error_um=error_um,
        time_s=time_s,
        verified=options.verifying,
        code_path=task.code_path,
        report_path=task.report_path,
        preview_path=task.preview_path,
        warnings=warnings,
        error=problem or "",
    )
    return row, tuple(files)


def _post_job(file: str, options: BatchOptions) -> PostJob:
    """Import and post one file for ``options.target``: a drawing planned, a program re-posted."""
    from camtool.jobs.pipeline import post_file

    (target,) = options.targets  # one: see _for
    return post_file(
        file,
        target,
        options.plan,
        options.output,
        machine_file=options.machine_file,
        import_options=options.import_options(),
        job=options.job,
    )


def preview_bytes(job: PostJob, v: Verification | None, path: str, title: str) -> bytes:
    """The preview of one file, PNG or SVG by ``path``'s ending (the one place a batch draws).

    The program over the drawing as placed, the tool width of an offset cut and
    the target's work area; with a verification ``v`` also the simulated trace
    coloured by its deviation and the worst point (:func:`camtool.preview.render_preview`).

    Raises:
        UsageError: the ending is neither ``.png`` nor ``.svg``.
    """
    from camtool.preview import render_preview

    return render_preview(
        path,
        program=job.program,
        drawing=job.placed,
        verification=v,
        target=job.target,
        edge_radius_mm=job.edge_radius_mm,
        title=title,
        sections=[(run.label, *run.moves) for run in job.operations] or None,
    )


def _write(path: str, data: str | bytes) -> None:
    """Write one output atomically, creating its directory."""
    from camtool.jobs.output import reason, write_atomic

    try:
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        write_atomic(path, data)
    except OSError as exc:
        raise CamtoolError(f"{path}: cannot write ({reason(exc)})") from exc
