"""The program header: the job in a few comment lines, and the warnings every job shares.

What a machinist reads before running the program: the input, target and camtool
version, where work zero is, the heights, and for a job file its tools and each
operation in order with its tool, depths and time. Nothing in it varies between two runs
of the same job (no date, no absolute path), so programs stay byte-for-byte reproducible.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.model.units import LARGEST_VALUE
from camtool.toolpath.options import (
    DEFAULT_CHAIN_TOLERANCE,
    DEFAULT_CLOSE_GAP,
    MAX_LENGTH_MM,
    MAX_SCALE,
    MAX_TOOL_DIAMETER_MM,
    MIN_TOOL_DIAMETER_MM,
)

if TYPE_CHECKING:
    from camtool.jobs.job import Job
    from camtool.jobs.run import OperationRun
    from camtool.post.base import Target
    from camtool.toolpath.options import PlanOptions


NO_DEPTH_WARNING = (
    "no --depth: cutting at Z 0, the top of the stock — a pen, a drag knife or an engraving "
    "at the surface; give --depth MM to cut into it"
)
"""What a plan without ``--depth`` for a machine with Z says (rapids stay at safe Z)."""


def surface_warnings(runs: Sequence[OperationRun], target: Target) -> tuple[str, ...]:
    """:data:`NO_DEPTH_WARNING` when ``target`` has Z and an operation no depth."""
    if not target.machine.has_z:
        return ()
    bare = [r for r in runs if r.operation.plan.depth is None]
    if not bare:
        return ()
    if len(runs) == 1:
        return (NO_DEPTH_WARNING,)
    return (f"{', '.join(r.label for r in bare)}: {NO_DEPTH_WARNING}",)


def job_notes(
    source: str,
    target: Target,
    plan: PlanOptions | None = None,
    job: Job | None = None,
    runs: Sequence[OperationRun] = (),
    placement: tuple[float, float, float] = (1.0, 0.0, 0.0),
    carried: tuple[str, ...] = (),
) -> tuple[str, ...]:
    """The job, in a few lines for the top of the program (comments where the dialect has them).

    Input file name (without its folder), target, camtool version, and for a
    planned drawing the tool, offset, depth and heights, mm; for a job file its tools
    and each operation in order with its tool, depths and time. Nothing varies
    between two runs of the same job (no date, no absolute path).

    Args:
        source: the input's file name (``""`` or ``"-"``: standard input).
        target: the target the program is for.
        plan: the planning options of ``post``'s one operation (``None``: a re-posted
            program, or a job file's: ``job`` and ``runs``).
        job: a job file's job.
        runs: what each of its operations made, in order.
        placement: ``(k, dx, dy)``: a drawing point ``p`` is the program's ``k·p + (dx,
            dy)`` mm (``--scale``/``--fit``, ``--origin``, ``--translate``); written as
            ``placement: scale K, shift XdX YdY mm`` unless it is the identity, so that
            ``verify --against`` can place the drawing again (:func:`read_placement`).
        carried: for a re-posted program, the notes of the input's camtool header
            (:func:`carried_notes`), written after the line that says it is re-posted.
    """
    from camtool.model.version import __version__

    name = Path(source).name if source and source != "-" else "stdin"
    notes = [f"camtool {__version__}: {name} for {target.name}"]
    setup = plan if plan is not None else job.setup.plan if job is not None else None
    notes.extend(_placement_lines(placement, setup))
    if job is not None and plan is None:
        return (*notes, *_job_lines(job, runs, target))
    if plan is None:
        return (*notes, REPOSTED, *carried)
    tool = f"tool diameter {plan.tool_diameter:g} mm, offset {plan.offset}"
    if plan.offset == "on":
        tool = "offset on: the tool centre follows the drawing"
        if plan.tool_diameter > 0:
            tool += f" (tool diameter {plan.tool_diameter:g} mm)"
    elif plan.offset == "pocket":
        tool += f" ({plan.pocket}, stepover {plan.stepover:g})"
    notes.append(tool)
    layers = job.operations[0].select.layers if job is not None and job.operations else None
    if layers:  # --layers: what verify --against compares (read_layers)
        notes.append(f"layers: {', '.join(layers)}")
    if (plan.chain_tolerance, plan.close_gap) != (DEFAULT_CHAIN_TOLERANCE, DEFAULT_CLOSE_GAP):
        notes.append(  # which contours closed, so cut by a side (read_chaining)
            f"chaining: ends within {plan.chain_tolerance:.12g} mm joined, gaps up to "
            f"{plan.close_gap:.12g} mm closed"
        )
    notes.append(_work_zero(plan))
    if not target.machine.has_z:
        notes.append("no Z axis: set the depth by hand")
        return tuple(notes)
    if plan.depth is None:
        depth = "depth none: cuts at Z 0, the top of the stock"
    else:
        step = "" if plan.step_down is None else f" in passes of {plan.step_down:g} mm"
        depth = f"depth {plan.depth:g} mm{step}"
    notes.append(depth)
    notes.append(f"safe Z {plan.safe_z:g} mm, clearance Z {plan.clearance:g} mm above the top")
    return tuple(notes)


def _job_lines(job: Job, runs: Sequence[OperationRun], target: Target) -> list[str]:
    """The header lines of a job file's program: setup, tools, operations in order.

    Each line stays short (GRBL's line buffer holds 79 characters, comment included).
    """
    setup = job.setup.plan
    lines = [f"job {job.source}: {_count(len(runs), 'operation')}"]
    lines.append(_work_zero(setup))
    if target.machine.has_z:
        safe = sorted({r.operation.plan.safe_z for r in runs})
        lines.append(
            f"safe Z {', '.join(f'{z:g}' for z in safe)} mm, clearance Z {setup.clearance:g} "
            "mm above the top"
        )
    used = dict.fromkeys(r.tool.id for r in runs)
    lines.extend(f"T{t}: {job.tool(t).describe()}" for t in used)
    lines.extend(_operation_line(run, target) for run in runs)
    total = sum(r.time_s for r in runs)
    lines.append(f"about {_minutes(total)} at the programmed feeds")
    return lines


def _operation_line(run: OperationRun, target: Target) -> str:
    """``"3. pocket 'floor' T1: 2 deep, passes of 1; 2.3 min"``."""
    op = run.operation
    name = f" {op.name!r}" if op.name else ""
    plan = op.plan
    head = f"{run.number}. {op.kind}{name} T{run.tool.id}"
    if run.moves[0] == run.moves[1] and op.type != "drill":
        return f"{head}: nothing left to cut (its paths cut before)"
    if op.type == "drill":
        what = f"{_count(run.holes, 'hole')}, {plan.depth:g} deep"
        if plan.step_down is not None and plan.depth is not None and plan.step_down < plan.depth:
            what += f", pecks of {plan.step_down:g}"
    elif not target.machine.has_z:
        what = "no Z"
    elif plan.depth is None:
        what = "at Z 0"
    else:
        what = f"{plan.depth:g} deep"
        if plan.step_down is not None and plan.step_down < plan.depth:
            what += f", passes of {plan.step_down:g}"
        if plan.tabs:
            what += f", {_count(plan.tabs, 'tab')}"
    return f"{head}: {what}; {_minutes(run.time_s)}"


def _count(n: int, noun: str) -> str:
    return f"{n} {noun}" if n == 1 else f"{n} {noun}s"


def _minutes(seconds: float) -> str:
    if seconds < 60:
        return f"{seconds:.0f} s"
    return f"{seconds / 60:.1f} min"


PLACEMENT = re.compile(
    r"placement: scale (?P<k>[-+0-9.eE]+), shift X(?P<dx>[-+0-9.eE]+) Y(?P<dy>[-+0-9.eE]+) mm"
)
"""The header line :func:`job_notes` writes for a drawing scaled or moved (any comment style)."""
_CAMTOOL = re.compile(r"camtool \S+: (?:.* for \S+|.*\.\.\.)")
"""camtool's first line, ``camtool VERSION: NAME for TARGET``, or cut short with ``...`` at
the dialect's line limit (a long file name: GRBL's 80 bytes)."""


def _placement_lines(placement: tuple[float, float, float], plan: PlanOptions | None) -> list[str]:
    k, dx, dy = placement
    if (k, dx, dy) == (1.0, 0.0, 0.0):
        return []
    lines = [f"placement: scale {k:.12g}, shift X{dx:.12g} Y{dy:.12g} mm"]
    if plan is not None and plan.fit is not None and k != 1.0:
        w, h = plan.fit
        lines.append(f"--fit {w:g} x {h:g} mm: the drawing at {100 * k:.4g} % of its size")
    elif k != 1.0:
        lines.append(f"--scale {k:g}: the drawing at {100 * k:.4g} % of its size")
    return lines


REPOSTED = "re-posted program: moves as the input gives them"
"""The note that says a program is re-posted, after camtool's first line."""
CARRIED_FROM = "its header: "
"""Before the input's first line among a re-posted program's notes."""


def carried_notes(code: str) -> tuple[str, ...]:
    """The notes of camtool's header at the top of ``code``, for a program re-posted from it.

    Re-posting moves nothing, so what the header says of the cut (its placement, tool and
    offset, layers, job, work zero, depths) still holds for the re-posted program, and
    ``verify --against`` reads it there as in the program it came from. The header is the
    run of whole-line comments (``(…)`` or ``; …``) at the top (blank and ``%`` lines
    skipped) when its first is camtool's own (``camtool VERSION: NAME for TARGET``),
    which is carried as ``its header: …``; a re-posted program's own first two lines are
    left out and the rest carried as they are. ``()`` for any other program: another
    tool's comments are never taken.
    """
    texts: list[str] = []
    for line in _head_lines(code.lstrip("\ufeff")):
        text = _comment_of(line)
        if text is None:
            if line.strip() in ("", "%"):
                continue
            break
        texts.append(text)
    if not texts or not _CAMTOOL.fullmatch(texts[0]):
        return ()
    if texts[1:2] == [REPOSTED]:
        return tuple(texts[2:])
    return (CARRIED_FROM + texts[0], *texts[1:])


def _comment_of(line: str) -> str | None:
    """The text of ``line`` when it is one whole comment, ``(…)`` or ``; …``, else ``None``."""
    text = line.strip()
    if text.startswith("(") and text.endswith(")") and ")" not in text[1:-1]:
        return text[1:-1].strip()
    if text.startswith(";"):
        return text[1:].strip()
    return None


def read_placement(code: str) -> tuple[float, float, float] | None:
    """The placement a camtool header in ``code`` records, or ``None``.

    Only the first lines are read, and only with camtool's own first line among them
    (``camtool VERSION: NAME for TARGET``): another tool's comment is never taken. Nor
    is a value ``post`` never writes (a scale beyond its ``--scale`` range, a shift of
    :data:`~camtool.model.units.LARGEST_VALUE` mm or more, NaN): an edited or damaged
    header, read as none. So for the tool and the chaining (the options' own ranges).
    """
    for line in _header(code):
        found = PLACEMENT.search(line)
        if found is not None:
            try:
                k, dx, dy = (float(found[g]) for g in ("k", "dx", "dy"))
            except ValueError:
                return None
            if 1.0 / MAX_SCALE <= k <= MAX_SCALE and max(abs(dx), abs(dy)) < LARGEST_VALUE:
                return (k, dx, dy)
    return None


def read_tool_diameter(code: str) -> float | None:
    """The tool diameter (mm) of an offset cut a camtool header in ``code`` records, or None."""
    found = read_offset(code)
    return None if found is None else found[1]


def read_offset(code: str) -> tuple[str, float] | None:
    """``(side, tool diameter mm)`` of an offset cut a camtool header in ``code`` records.

    ``side`` is ``outside``, ``inside`` or ``pocket``. ``None`` for a program of a cut on
    the line, of a job of several operations, or without camtool's header.
    """
    for line in _header(code):
        found = _TOOL.search(line)
        if found is not None:
            try:
                value = float(found[1])
            except ValueError:
                return None
            fits = MIN_TOOL_DIAMETER_MM <= value <= MAX_TOOL_DIAMETER_MM
            return (found[2], value) if fits else None
    return None


_TOOL = re.compile(r"tool diameter ([0-9.eE+-]+) mm, offset (outside|inside|pocket)")


def read_chaining(code: str) -> tuple[float, float] | None:
    """``(--chain-tolerance, --close-gap)``, mm, a camtool header in ``code`` records.

    Written only when either is not the default: ``None`` then (the defaults hold), for
    a value outside ``post``'s range (0 to :data:`~camtool.toolpath.options.MAX_LENGTH_MM`),
    and without camtool's header.
    """
    for line in _header(code):
        found = _CHAINING.search(line)
        if found is not None:
            try:
                values = float(found["t"]), float(found["g"])
            except ValueError:
                return None
            return values if all(0 <= v <= MAX_LENGTH_MM for v in values) else None
    return None


_CHAINING = re.compile(
    r"chaining: ends within (?P<t>[0-9.eE+-]+) mm joined, gaps up to (?P<g>[0-9.eE+-]+) mm closed"
)


def read_job(code: str) -> tuple[str, int] | None:
    """``(job file, operations)`` a camtool header in ``code`` records for a job, or ``None``.

    The line :func:`job_notes` writes for a job file's program (``job part.toml: 3
    operations``); ``None`` for a program of ``post``'s own options, or without camtool's
    header (another tool's comment is never taken).
    """
    for line in _header(code):
        found = _JOB.search(line)
        if found is not None:
            return found["name"], int(found["n"])
    return None


def read_layers(code: str) -> tuple[str, ...] | None:
    """The layers ``post --layers`` cut, as a camtool header in ``code`` records them.

    ``None`` without such a line (every layer but construction was cut), or without
    camtool's header. The names are as the dialect's comments hold them (``(``, ``)`` and
    characters outside printable ASCII replaced, a long line cut short): a name the
    drawing does not have is the caller's to refuse.
    """
    for line in _header(code):
        found = _LAYERS.search(line)
        if found is not None:
            return tuple(n.strip() for n in found[1].split(", ") if n.strip())
    return None


def read_single(code: str) -> bool:
    """Whether ``code`` is a program camtool planned from a drawing with ``post``'s options.

    Its header (camtool's first line, then the tool line :func:`job_notes` writes for one
    operation): not a job file's program, nor a re-posted one.
    """
    return any(_TOOL.search(line) or _ON.search(line) for line in _header(code))


def _header(code: str) -> list[str]:
    """The first :data:`HEADER_LINES` lines of ``code`` when camtool's own header is among them.

    Else none: another tool's comment is never taken. Only the start of the text is split
    (a program of millions of lines is not).
    """
    head = _head_lines(code)
    return head if any(_CAMTOOL.search(line) for line in head) else []


def _head_lines(code: str) -> list[str]:
    """The first :data:`HEADER_LINES` lines of ``code``, of its first :data:`HEADER_CHARS`."""
    return code[:HEADER_CHARS].splitlines()[:HEADER_LINES]


HEADER_LINES = 60
"""Lines of a program the header readers look at (camtool's notes come first)."""

HEADER_CHARS = 1 << 16
"""Characters of a program split into lines for them: :data:`HEADER_LINES` lines and more."""


_LAYERS = re.compile(r"\blayers: (.*?)\)?$")
_ON = re.compile(r"offset on: the tool centre follows the drawing")
_JOB = re.compile(r"\bjob (?P<name>.*): (?P<n>[0-9]+) operations?\b")


def _work_zero(plan: PlanOptions) -> str:
    """Where X0 Y0 of the program lies, for the job notes (``--origin``, ``--translate``)."""
    where = {
        "drawing": "the drawing's origin",
        "lower-left": "the toolpath's lower-left corner",
        "center": "the toolpath's centre",
    }[plan.placement]
    dx, dy = plan.translate
    moved = f", moved by X{dx:g} Y{dy:g} mm" if (dx, dy) != (0.0, 0.0) else ""
    return f"work zero X0 Y0: {where}{moved}"
