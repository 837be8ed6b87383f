"""Options and helpers every ``camtool`` command shares (post, verify, preview, batch).

Click options are defined once here so that the same option reads the same in
every command; the helpers keep stdout for data and stderr for messages.
"""

from __future__ import annotations

import functools
import math
import os
import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import TYPE_CHECKING, Any, ParamSpec, TypeVar

import click

from camtool.model.errors import CamtoolError, VerifyLimitError
from camtool.toolpath.options import (
    DEFAULT_CHAIN_TOLERANCE,
    DIRECTIONS,
    OFFSET_MODES,
    ORDERS,
    PLACEMENTS,
    POCKET_STYLES,
    PlanOptions,
)

if TYPE_CHECKING:
    from camtool.importers.options import ImportOptions
    from camtool.jobs.job import Job
    from camtool.jobs.output import Staged
    from camtool.jobs.pipeline import OutputOptions


class FiniteFloat(click.FloatRange):
    """A float option that refuses NaN and ±inf, within an optional range.

    click's float takes both, and ``x <= 0`` is false for NaN, so a range check alone
    lets NaN through. Every numeric option of every command uses it (:data:`NUMBER`,
    :func:`number_range`), so a non-finite value is refused at the boundary, naming
    the option.
    """

    name = "number"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The value as a finite float in range, or a usage error naming the option."""
        if isinstance(value, str) and not plain_digits(value):
            self.fail(f"{value!r} is not a number", param, ctx)
        rv = super().convert(value, param, ctx)
        if not math.isfinite(rv):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        return rv

    def _describe_range(self) -> str:
        """The range for ``--help`` ("" without bounds: click would print ``x<=None``)."""
        if self.min is None and self.max is None:
            return ""
        return super()._describe_range()


def plain_digits(text: str) -> bool:
    """Whether ``text`` is in ASCII without ``_``, as G-code and machine panels write numbers.

    Python's ``float`` and ``int`` also read ``1_5`` (15, where ``1.5`` was meant) and the
    digits of other scripts (``١``, full-width ``１``): such a value is refused, naming the
    option, rather than read as a number the user may not have meant.
    """
    return text.isascii() and "_" not in text


class WholeNumber(click.IntRange):
    """An integer option of ASCII digits (:func:`plain_digits`), within an optional range."""

    name = "integer"

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """The value as an int in range, or a usage error naming the option."""
        if isinstance(value, str) and not plain_digits(value):
            self.fail(f"{value!r} is not a whole number", param, ctx)
        return super().convert(value, param, ctx)


NUMBER = FiniteFloat()
"""Any finite float (see :class:`FiniteFloat`)."""


def number_range(
    min: float | None = None,
    max: float | None = None,
    *,
    min_open: bool = False,
) -> FiniteFloat:
    """A finite float in ``[min, max]`` (``min_open``: excluding ``min``)."""
    return FiniteFloat(min=min, max=max, min_open=min_open)


def warn(messages: tuple[str, ...] | list[str]) -> None:
    """Each message to stderr as ``camtool: warning: …``."""
    for message in messages:
        click.echo(f"camtool: warning: {message}", err=True)


P = ParamSpec("P")
R = TypeVar("R")
_STAGED: ContextVar[tuple[Staged, list[str | bytes], list[str]] | None] = ContextVar(
    "staged", default=None
)


def publishes(command: Callable[P, R]) -> Callable[P, R]:
    """Run ``command`` with its outputs published together, at its end, or not at all.

    Inside, :func:`write_output` stages each file (:class:`camtool.jobs.output.Staged`)
    and keeps what goes to stdout, and :func:`say_written` keeps its lines; when the
    command returns, every file is renamed into place, stdout written, then the lines
    said (a file that cannot be placed is never reported as written). When it raises (a
    report that cannot be written; a verification over its limit is not an error of
    writing: the limit check runs after), the temporaries are removed and nothing of the
    run is published.
    """

    @functools.wraps(command)
    def run(*args: P.args, **kwargs: P.kwargs) -> R:
        from camtool.jobs.output import Staged

        staged: tuple[Staged, list[str | bytes], list[str]] = (Staged(), [], [])
        token = _STAGED.set(staged)
        try:
            result = command(*args, **kwargs)
        except BaseException as exc:
            if isinstance(exc, VerifyLimitError):
                _publish(*staged)  # the files are right; the limit decides the exit code
            else:
                staged[0].discard()
            raise
        finally:
            _STAGED.reset(token)
        _publish(*staged)
        return result

    return run


def _publish(files: Staged, stdout: list[str | bytes], said: list[str]) -> None:
    files.publish()
    for data in stdout:
        _write_stdout(data)
    for line in said:
        click.echo(line, err=True)


def say_written(line: str) -> None:
    """Say ``line`` (``camtool: wrote …``) on stderr once the outputs are in place.

    Inside a command run by :func:`publishes`, after its files are published (not at
    all when that fails); elsewhere, now.
    """
    staged = _STAGED.get()
    if staged is None:
        click.echo(line, err=True)
    else:
        staged[2].append(line)


def write_output(data: str | bytes, out: str) -> None:
    """``data`` to the file ``out`` (:func:`camtool.jobs.output.write_file`), or stdout for ``-``.

    Inside a command run by :func:`publishes`, the file is staged and published with
    the command's other outputs when it ends.

    Raises:
        CamtoolError: the file cannot be written, naming it and why (``x.pic: cannot
            write (no space left on device)``); for stdout ``stdout: no space left on
            device`` (or ``broken pipe``), after which stdout is silenced so that
            Python's own flush at exit does not fail again.
    """
    from camtool.jobs.output import write_file

    staged = _STAGED.get()
    if staged is not None:
        if out == "-":
            staged[1].append(data)
        else:
            staged[0].stage(out, data)
        return
    if out == "-":
        _write_stdout(data)
        return
    write_file(out, data)


def _write_stdout(data: str | bytes) -> None:
    """``data`` to stdout, every byte; a failed write or flush is a :class:`CamtoolError`.

    Written to the file descriptor with ``os.write`` until all is taken
    (:func:`camtool.accel.cores.write_all`), text encoded as stdout encodes it. Python's
    buffered stream can report a large write as done when a pipe's reader left during it:
    on the development VM, ``write(2)`` took 64 KiB of a 5.3 MB program, the process got
    the SIGPIPE Python ignores, and ``sys.stdout.write`` returned without an error, so
    ``camtool post -o - | sender`` said nothing (exit 0) of a program cut short. A stdout
    without a file descriptor (a test's capture) is written by click, as before.
    """
    from camtool.accel.cores import write_all
    from camtool.jobs.output import reason

    try:
        fd: int | None = sys.stdout.fileno()
    except (OSError, ValueError, AttributeError):  # io.UnsupportedOperation: no descriptor
        fd = None
    try:
        if fd is not None:
            stream = sys.stdout
            payload = (
                data
                if isinstance(data, bytes)
                else data.encode(stream.encoding or "utf-8", stream.errors or "strict")
            )
            stream.flush()
            write_all(fd, payload)
        elif isinstance(data, bytes):
            sys.stdout.flush()
            sys.stdout.buffer.write(data)
            sys.stdout.buffer.flush()
        else:
            click.echo(data, nl=False)  # flushes
    except OSError as exc:
        _silence_stdout()
        raise CamtoolError(f"stdout: {reason(exc)}") from exc


def _silence_stdout() -> None:
    """Point file descriptor 1 at /dev/null: what could not be written is dropped at exit."""
    try:
        fd = sys.stdout.fileno()
    except (OSError, ValueError):  # not a real file (a test's capture): nothing to silence
        return
    null = os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, fd)
    os.close(null)


@contextmanager
def picture_ahead(preview: str | None) -> Iterator[Callable[[], None]]:
    """Within it, a PNG preview is drawn by a child started now (:mod:`camtool.preview.ahead`).

    For a command that ends by drawing ``preview`` (a file name; ``-`` is an SVG on
    stdout). It gives the call that tells the child to import matplotlib
    (:func:`~camtool.preview.ahead.load_ahead`): the command makes it where it leaves a
    core idle. The child then draws the scene :func:`~camtool.preview.render_preview`
    sends it: ~0.3 s of imports off the end of the benchmark part. An SVG, or no
    preview, starts nothing and imports nothing (a re-post loads no numpy); leaving ends
    the child if it was not used. Only the time depends on it: the PNG is the same bytes.
    A command enters it with ``click.get_current_context().with_resource``, so it is left
    however the command ends.
    """
    if preview is None or preview == "-":
        yield lambda: None
        return
    from camtool.preview import preview_format

    if preview_format(preview) != ".png":
        yield lambda: None
        return
    from camtool.preview.ahead import load_ahead, start_ahead, stop_ahead

    start_ahead()
    try:
        yield load_ahead
    finally:
        stop_ahead()


JOB = click.option(
    "--job",
    "job_file",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    metavar="JOB.toml",
    help="The operations and tools that make the part (docs/jobs.md; `camtool job init` "
    "writes a first one). Without it the planning options are one operation.",
)
"""``--job``: a job file, the same for ``post`` and ``batch``."""


def read_job(path: Path, plan: PlanOptions) -> Job:
    """The job file at ``path``, with the shared options given on the command line.

    The per-operation options are refused before ``plan`` is made
    (:func:`refuse_operation_flags`).

    Raises:
        InputError: the job file is invalid (:func:`camtool.jobs.jobfile.load_job`).
    """
    from camtool.jobs.jobfile import load_job, shared_overrides

    return load_job(path, overrides=shared_overrides(plan, given_options()))


def refuse_operation_flags(job_file: Path | None) -> None:
    """With ``--job``, refuse the per-operation options given, before they are checked.

    Checked together as one operation first, ``--offset inside`` would be refused for
    wanting a ``--tool-diameter`` rather than for belonging in the job file.

    Raises:
        UsageError: ``--offset``, ``--depth``... with ``--job``.
    """
    if job_file is None:
        return
    from camtool.jobs.jobfile import operation_flags
    from camtool.jobs.run import refuse_operation_options

    refuse_operation_options(operation_flags(given_options()))


def given_options() -> frozenset[str]:
    """The parameters of the running command that its command line (or environment) set.

    An option given with its default value is given: ``--origin drawing`` must replace a
    job file's ``origin`` as ``--origin center`` does.
    """
    ctx = click.get_current_context(silent=True)
    if ctx is None:
        return frozenset()
    told = (click.core.ParameterSource.COMMANDLINE, click.core.ParameterSource.ENVIRONMENT)
    return frozenset(name for name in ctx.params if ctx.get_parameter_source(name) in told)


MACHINE = click.option(
    "--machine",
    "machine_file",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    metavar="FILE|NAME",
    help="Machine profile (a TOML file or a built-in name) laid over the target's, key by "
    "key, e.g. a measured backlash.",
)


def import_options(command: Callable[..., None]) -> Callable[..., None]:
    """Options of the importers: --layers, --units, --hatch-boundaries, --max-entities."""
    from camtool.model.units import LENGTH_UNITS

    command = click.option(
        "--max-entities",
        type=WholeNumber(min=1),
        default=None,
        metavar="N",
        help="Refuse a drawing that expands to more than N entities (DXF blocks and "
        "MINSERT grids, SVG <use> clones, counted before expanding) [default: 5000000, "
        "of which blocks and clones may add 250000 to the entities the file holds].",
    )(command)
    command = click.option(
        "--hatch-boundaries",
        is_flag=True,
        help="Use DXF HATCH boundary paths as contours (skipped otherwise).",
    )(command)
    command = click.option(
        "--units",
        type=click.Choice(list(LENGTH_UNITS)),
        default=None,
        help="Unit of a drawing that declares none: point lists (default mm, Matlab xy "
        "files 0.1mm), a DXF without $INSUNITS, an SVG without width/height (default px). "
        "Refused for a drawing that declares another unit.",
    )(command)
    return click.option(
        "--layers",
        default=None,
        metavar="A,B",
        help="Only these layers (DXF layers, Inkscape layers), comma-separated.",
    )(command)


def import_settings(options: dict[str, Any]) -> ImportOptions:
    """Pop the importer options out of a command's keyword options."""
    from camtool.importers.options import ImportOptions

    layers = options.pop("layers", None)
    names = tuple(n.strip() for n in layers.split(",") if n.strip()) if layers else None
    return ImportOptions(
        layers=names,
        tolerance=options.get("tolerance", 0.001),
        units=options.pop("units", None),
        hatch_boundaries=options.pop("hatch_boundaries", False),
        **_given(max_entities=options.pop("max_entities", None)),
    )


def plan_settings(options: dict[str, Any]) -> PlanOptions:
    """Pop the planning options out of a command's keyword options, checked.

    Raises:
        UsageError: invalid planning options (:class:`~camtool.toolpath.options.PlanOptions`).
    """
    fields = PlanOptions.__dataclass_fields__
    return PlanOptions(**{k: options.pop(k) for k in list(options) if k in fields})


def output_settings(options: dict[str, Any]) -> OutputOptions:
    """Pop the output options (``--format``, ``--spindle-rpm``, ``--spindle-dwell``)."""
    from camtool.jobs.pipeline import OutputOptions

    fields = OutputOptions.__dataclass_fields__
    return OutputOptions(**{k: options.pop(k) for k in list(options) if k in fields})


def _given(**values: Any) -> dict[str, Any]:
    """The keyword options that were given (not ``None``), so defaults stay in one place."""
    return {k: v for k, v in values.items() if v is not None}


chain_tolerance_option = click.option(
    "--chain-tolerance",
    type=number_range(min=0),
    default=DEFAULT_CHAIN_TOLERANCE,
    show_default=True,
    metavar="MM",
    help="Entity ends closer than this are joined into one contour (real CAD files "
    "leave gaps of a few µm).",
)
"""``--chain-tolerance``, the same for ``post``/``batch`` (planning) and ``inspect``."""


def post_options(command: Callable[..., None]) -> Callable[..., None]:
    """The options that shape how a drawing is posted (``post`` and ``batch``)."""
    for decorator in reversed(_POST_OPTIONS):
        command = decorator(command)
    return command


_POST_OPTIONS = (
    click.option(
        "--offset",
        type=click.Choice(OFFSET_MODES),
        default="on",
        show_default=True,
        help="Tool-centre side: 'on' follows the drawing (scribing point); 'outside'/"
        "'inside' compensate by half the tool diameter (holes to their correct side); "
        "'pocket' clears the inside of closed contours around their islands.",
    ),
    click.option(
        "--tool-diameter",
        type=number_range(min=0),
        default=0.0,
        metavar="MM",
        help="Tool diameter in mm (needed by every --offset but 'on').",
    ),
    click.option(
        "--direction",
        type=click.Choice(DIRECTIONS),
        default=None,
        help="Cutting direction of closed contours for a clockwise (M03) spindle "
        "[default: climb when compensating; the drawn direction with --offset on].",
    ),
    click.option(
        "--stepover",
        type=NUMBER,
        default=0.4,
        show_default=True,
        metavar="FRACTION",
        help="Pocket step-over as a fraction of the tool diameter.",
    ),
    click.option(
        "--pocket",
        type=click.Choice(POCKET_STYLES),
        default="concentric",
        show_default=True,
        help="Pocket style: concentric offsets (wall first, innermost last) or zigzag lines.",
    ),
    click.option(
        "--pocket-angle",
        "pocket_angle_deg",
        type=NUMBER,
        default=0.0,
        show_default=True,
        metavar="DEG",
        help="Angle of the zigzag lines, degrees counter-clockwise from +X.",
    ),
    click.option(
        "--depth",
        type=NUMBER,
        default=None,
        metavar="MM",
        help="Cut depth below the top (Z 0), mm; Z targets only. Without it no Z is written.",
    ),
    click.option(
        "--step-down",
        type=NUMBER,
        default=None,
        metavar="MM",
        help="Depth of each pass, mm [default: one pass at --depth].",
    ),
    click.option(
        "--safe-z",
        type=NUMBER,
        default=2.0,
        show_default=True,
        metavar="MM",
        help="Height of every rapid when --depth is given, mm above the top.",
    ),
    click.option(
        "--plunge-feed",
        "plunge_feed_mm_min",
        type=NUMBER,
        default=None,
        metavar="MM_PER_MIN",
        help="Feed of Z moves into the material [default: half the cutting feed].",
    ),
    click.option(
        "--ramp",
        "ramp_deg",
        type=NUMBER,
        default=None,
        metavar="DEG",
        help="Enter each pass descending along the path at DEG from the horizontal, "
        "instead of plunging (targets that move X, Y and Z together).",
    ),
    click.option(
        "--tabs",
        type=WholeNumber(min=0),
        default=0,
        show_default=True,
        metavar="N",
        help="Holding tabs per outside profile (needs --depth and --offset outside).",
    ),
    click.option(
        "--tab-width",
        type=NUMBER,
        default=2.0,
        show_default=True,
        metavar="MM",
        help="Tab length along the part edge, mm.",
    ),
    click.option(
        "--tab-height",
        type=NUMBER,
        default=0.5,
        show_default=True,
        metavar="MM",
        help="Tab height above the final depth, mm.",
    ),
    click.option(
        "--order",
        type=click.Choice(ORDERS),
        default="travel",
        show_default=True,
        help="Cutting order (holes always before the contour around them): 'travel' "
        "shortens rapids; 'reversals' minimises axis reversals weighted by the machine's "
        "backlash; 'mirror' cuts a symmetric part half by half from one shared point.",
    ),
    click.option(
        "--lead-in",
        "lead_in",
        type=NUMBER,
        default=0.0,
        show_default=True,
        metavar="MM",
        help="Radius of tangent lead-in/lead-out arcs on closed profiles (targets with arcs).",
    ),
    click.option(
        "--close-gap",
        type=NUMBER,
        default=0.02,
        show_default=True,
        metavar="MM",
        help="Close contours whose ends are at most this far apart (with a warning); 0: never.",
    ),
    click.option(
        "--fit-arcs/--no-fit-arcs",
        default=True,
        show_default=True,
        help="Fit arcs to dense polylines within --tolerance (G02/G03 instead of many G01).",
    ),
    click.option(
        "--feed",
        "feed_mm_min",
        type=NUMBER,
        default=None,
        metavar="MM_PER_MIN",
        help="Cutting feed in mm/min [default: the target's, 0.8 for pic-mmh].",
    ),
    click.option(
        "--tolerance",
        type=NUMBER,
        default=0.001,
        show_default=True,
        metavar="MM",
        help="Curve tolerance (mm, at most 1): fitted arcs, flattened curves and chords stay "
        "this close to what they replace (chaining uses --chain-tolerance).",
    ),
    click.option(
        "--scale",
        type=NUMBER,
        default=1.0,
        show_default=True,
        metavar="K",
        help="Scale the drawing by K about its origin (unitless factor).",
    ),
    click.option(
        "--fit",
        "fit",
        type=(NUMBER, NUMBER),
        default=None,
        metavar="W H",
        help="Scale the drawing uniformly so that what is cut fits W x H mm (construction, "
        "such as centre lines or a sheet's border, left out), about its lower-left corner.",
    ),
    click.option(
        "--origin",
        "placement",
        type=click.Choice(PLACEMENTS),
        default="drawing",
        show_default=True,
        help="Where the work zero (X0 Y0) lies: 'drawing' keeps the drawing's coordinates; "
        "'lower-left'/'center' put it at the toolpath's lower-left corner / centre "
        "(tool radius, lead-ins and tabs included). Applied after --scale/--fit.",
    ),
    click.option(
        "--translate",
        type=(NUMBER, NUMBER),
        default=(0.0, 0.0),
        metavar="DX DY",
        help="Move the program by DX DY mm, after --origin.",
    ),
    chain_tolerance_option,
    click.option(
        "--clearance-z",
        type=NUMBER,
        default=None,
        metavar="MM",
        help="Height of the first and last moves and of travel between parts, mm above "
        "the top [default: the larger of 5 mm and --safe-z]. Z targets only.",
    ),
    click.option(
        "--end-position",
        type=(NUMBER, NUMBER),
        default=None,
        metavar="X Y",
        help="Rapid to X Y at clearance height at the end of the program.",
    ),
    click.option(
        "--reverse-open",
        is_flag=True,
        help="Let the cutting order cut open contours backwards (default: as drawn).",
    ),
    click.option(
        "--spindle-dwell",
        "spindle_dwell_s",
        type=number_range(min=0),
        default=0.0,
        show_default=True,
        metavar="S",
        help="Wait S seconds (at most 3600) after starting the spindle, before the first move "
        "(G4).",
    ),
    click.option(
        "--format",
        "fmt",
        default=None,
        metavar="NAME",
        help="Output format of the target's dialect (e.g. matlab-router 'wire', i8751 'dump'); "
        "see `camtool targets`.",
    ),
    click.option(
        "--spindle-rpm",
        type=number_range(min=0),
        default=None,
        metavar="RPM",
        help="Spindle on (M03) at RPM (at most 1000000) before the first move and off (M05) "
        "after the last; 0 writes no spindle commands [default: the target's].",
    ),
)
