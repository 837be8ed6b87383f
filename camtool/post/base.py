"""The dialect framework: PostProcessor (``emit`` and ``parse``), WriterState, Target.

- :class:`PostProcessor` — a dialect: writes a program, reads its own code back;
- :class:`WriterState` — what every dialect writer keeps while it writes one
  program (the blocks, where it is, the warnings and the counted notes);
- :class:`ContourCounter` — the contour-numbering rule of every reader;
- :class:`Target` — one machine: a dialect bound to a machine profile.
"""

from __future__ import annotations

import dataclasses
from abc import ABC, abstractmethod
from collections import Counter
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, ClassVar, Generic, TypeVar, get_args

from camtool.model.errors import DialectError, InputError, UsageError
from camtool.model.machine import Machine
from camtool.model.program import (
    Command,
    DrillCycle,
    Home,
    LengthOffset,
    Linear,
    Move,
    PlaneArc,
    Program,
    Rapid,
    Stop,
    ToolChange,
    WorkOffset,
    plane_arcs_as_chords,
    segment_of,
)
from camtool.model.shapes import Point, bbox_union
from camtool.model.units import fmt_num
from camtool.toolpath.placement import (
    EPS_MM,
    check_travel,
    check_z_travel,
    moved_remedy,
    outside_text,
    place_remedy,
    too_large,
    toolpath_extent,
)

if TYPE_CHECKING:
    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks


def check_work_area(
    start: Point,
    move: Move,
    machine: Machine,
    where: str,
    program: Program,
    *,
    reposted: bool = False,
) -> None:
    """Machine coordinates: refuse a move (an arc by its extremes) outside the work area.

    A machine in work coordinates (``machine.coordinates == "work"``) runs any
    position: there only the program's size counts (:func:`check_placement`).

    Args:
        start: where the move starts, mm.
        move: the move.
        machine: the machine profile (``work_area_mm``, ``coordinates``).
        where: the contour and block for the message ("contour 3, block 12").
        program: the whole program, for the remedy (by how much to move it).
        reposted: ``program`` is a re-posted one (G-code another program wrote), which
            camtool does not move: the remedy is to move it where it was written.

    Raises:
        DialectError: the move reaches outside the work area, naming ``where``,
            the move's extent, the work area and options that move the program in.
    """
    if machine.coordinates == "work":
        return
    box = segment_of(start, move).bbox()
    if machine.outside_work_area(box, EPS_MM):
        whole = toolpath_extent(program) or box
        too_large(whole, machine, None)
        extent = bbox_union([whole, box])
        remedy = moved_remedy(extent, machine) if reposted else place_remedy(extent, machine, None)
        raise DialectError(
            f"{where}: reaches X {fmt_num(box[0])}…{fmt_num(box[2])}, Y {fmt_num(box[1])}…"
            f"{fmt_num(box[3])} mm, {outside_text(machine)}; {remedy}"
        )


def check_written_z(requested: float, written: float, where: str) -> None:
    """Refuse a height above the stock that the dialect's rounding writes at its top.

    A move the program puts above the top (Z > 0: a rapid, a retract) written at or
    below Z0 would travel at the surface. A depth rounded to Z0 is refused earlier,
    by the option that asked for it (:func:`camtool.jobs.heights.check_heights`); a
    re-posted program's own depths are written as the dialect rounds them.

    Args:
        requested: the Z the program asks for, mm.
        written: the Z the code says, read back, mm.
        where: the block, for the message.

    Raises:
        DialectError: ``requested`` above 1 µm written at or below 0.
    """
    if requested < 1e-6 or written > 0:
        return
    raise DialectError(
        f"{where}: Z{requested:g} mm above the stock is written as Z{written:g}, at its "
        "top: moves there would run at the surface; raise the height to the dialect's "
        "resolution or more"
    )


def check_dropped_homes(program: Program, homes: tuple[str, ...], target: str) -> None:
    """Refuse a return of Z to a machine position the dialect cannot write, with moves after it.

    A program read from code that runs ``G91 G28 Z0`` (or G30, or ``G53 G0 Z0``) leaves
    its tool at that height (the top, on most machines); its next moves give X and Y only, and
    written without the return they would run at the height the tool had before it:
    a rapid at cutting depth. A next move that gives Z and X, Y would run from that
    height on a slant, through what it cut. Such a program is refused, not written.
    A return at the end of the program, or followed by a move of Z alone, costs
    nothing when dropped; neither does one in a program that never gives Z (a
    plotter's, a laser's).

    Args:
        program: the program to write.
        homes: the codes of the returns the dialect writes (``()``: none).
        target: the target's name, for the message.

    Raises:
        DialectError: a dropped return on Z followed by a move at an unknown height,
            naming its source line (or move) and the height the tool would stay at.
    """
    dropped = [
        (i, c)
        for i, c in program.commands
        if isinstance(c, Home) and "Z" in c.axes and c.code not in homes
    ]
    moves = program.moves
    if not dropped or all(m.z is None for m in moves):
        return
    for index, home in dropped:
        if index >= len(moves):
            continue
        move = moves[index]
        start = (moves[index - 1].x, moves[index - 1].y) if index else (0.0, 0.0)
        if move.z is not None and isinstance(move, Rapid | Linear) and (move.x, move.y) == start:
            continue  # Z alone: from whatever height, it goes where the program says
        before = next((m.z for m in reversed(moves[:index]) if m.z is not None), None)
        line = program.lines[index] if index < len(program.lines) else None
        where = f"line {line}" if line else f"move {index + 1}"
        left = f"Z{before:g}" if before is not None else "wherever it was left"
        how = "gives no Z" if move.z is None else "moves X or Y with Z"
        raise DialectError(
            f"{where}: the move after the program's {home.code} return on Z {how}, and "
            f"{target} cannot write that return: written without it, the move would run "
            f"from the height the tool had before it ({left}), not from the {home.code} "
            "position; give a move of Z alone (G0 Z at the clearance height) right after "
            f"the {home.code}, or post for a target that writes it (grbl, linuxcnc)"
        )


def input_line(program: Program, index: int, *, move: bool) -> str:
    """Where an item of ``program`` read from code comes from, for messages.

    ``index``: the move's index in ``program.moves``, or for a command the index of the move
    it stands before (``len(program.moves)``: after the last). ``"input line N"`` for a
    move, ``"before input line N"`` / ``"after input line N"`` for a command; empty when the
    program was not read from code.
    """
    if move:
        line, where = program.line_of(index), "input line"
    elif index < len(program.moves):
        line, where = program.line_of(index), "before input line"
    else:
        line, where = program.line_of(index - 1), "after input line"
    return "" if line is None else f"{where} {line}"


def check_placement(
    program: Program, machine: Machine, *, reposted: bool | None = None
) -> tuple[str, ...]:
    """The work-coordinate rule for a program about to be written (or verified).

    The toolpath must be no larger than the machine's travel; where its work zero
    needs care the returned warnings say so (see
    :func:`camtool.toolpath.placement.check_travel`). A machine in machine
    coordinates is checked move by move instead (:func:`check_work_area`, which
    names the block).

    Its Z must span no more than the machine's Z travel, when the profile gives it
    (:func:`~camtool.toolpath.placement.check_z_travel`), in either coordinates.
    ``reposted``: G-code camtool did not plan (remedies name the program that wrote it);
    ``None``: whether ``program`` was read from code (:attr:`Program.from_code`), as a
    writer's is. A verification says which, as its code is always read back.

    Raises:
        DialectError: the toolpath is larger than the travel (both sizes named), or its
            Z spans more than the Z travel.
    """
    if reposted is None:
        reposted = program.from_code
    check_z_travel(program, machine, reposted=reposted)
    if machine.coordinates == "machine":
        return ()
    return check_travel(program, machine, planned=not reposted)


class ContourCounter:
    """The contour-numbering rule of every dialect reader (word-address, pic-mmh, i8751, ...).

    Contour 1 from the start; a rapid after a cut starts the next contour (a run
    of rapids starts one). Writers start a contour where the planner's toolpath
    does, with the rapid to its start; read-back programs number their moves the
    same way.
    """

    def __init__(self) -> None:
        self.contour = 1
        self.cut = False

    def next(self, rapid: bool) -> int:
        """The contour of the next move (``rapid``: whether it is a rapid)."""
        if rapid:
            if self.cut:
                self.contour += 1
            self.cut = False
        else:
            self.cut = True
        return self.contour


B = TypeVar("B")
"""What a writer emits one of: a text line, a binary record, a job."""

COMMAND_KINDS = frozenset(kind.__name__ for kind in get_args(Command))
"""The kinds of :data:`~camtool.model.program.Command` by class name (``"Spindle"``, ...)."""

FAR_FROM_ZERO = (
    ": the toolpath lies that far from work zero; place the drawing at work zero with "
    "--origin lower-left, or move it with --translate X Y"
)
"""Said after a coordinate too long for its word: the drawing, not the machine, is far off
(:func:`far_from_zero` says so only where the toolpath is small enough to fit)."""
FAR_FROM_ZERO_CODE = (
    ": the toolpath lies that far from work zero; move it nearer in the program that wrote "
    "it (its work zero): camtool re-posts a program where it is"
)
""":data:`FAR_FROM_ZERO` for a re-posted program (``--origin`` and ``--translate`` are for
drawings)."""


def far_from_zero(program: Program, letter: str, reach_mm: float | None) -> str:
    """What to do about an X or Y value too long for its word, said after the error.

    :data:`FAR_FROM_ZERO_CODE` for a re-posted program. For a drawing's toolpath:
    :data:`FAR_FROM_ZERO` when its width and height fit the word from work zero;
    ``--origin center`` when only their halves do (the words write ± values); else that
    the part itself is larger than the words can hold: scale it or cut it in parts.

    Args:
        program: the program being written.
        letter: ``"X"`` or ``"Y"``.
        reach_mm: about the largest magnitude the word writes, mm
            (:meth:`~camtool.post.numfmt.NumberFormat.reach_mm`; ``None``: unknown).
    """
    if program.from_code:
        return FAR_FROM_ZERO_CODE
    box = toolpath_extent(program)
    if reach_mm is None or box is None:
        return FAR_FROM_ZERO
    w, h = box[2] - box[0], box[3] - box[1]
    if max(w, h) <= reach_mm:
        return FAR_FROM_ZERO
    size = f": the toolpath is {fmt_num(w)} × {fmt_num(h)} mm"
    if max(w, h) <= 2.0 * reach_mm:
        return (
            f"{size}, more than the {letter} word holds from work zero one way "
            f"({fmt_num(reach_mm)} mm): put work zero at its centre with --origin center"
        )
    return (
        f"{size}, more than the {letter} word holds either way from work zero "
        f"(±{fmt_num(reach_mm)} mm): scale it down (--fit W H or --scale) or cut it in parts"
    )


class WriterState(Generic[B]):
    """What a dialect writer keeps while it writes one program (one ``emit`` call).

    Every writer (word-address, pic-mmh, i8751, matlab-router) subclasses it
    with its own dialect state (modal words, step positions, feed codes...);
    this holds what they share. Messages name the place with :meth:`where`;
    conversions are counted while writing and worded once at the end (one
    warning per kind, "12 arc(s) written as 80 chords").

    Args:
        blocks: blocks already written (e.g. a fixed preamble).
        here: where the program starts, mm (``Program.origin``).

    Attributes:
        blocks: what has been emitted, in order: text lines, binary records or
            jobs, the dialect's unit of :attr:`PostResult.blocks`; the next
            one is block ``len(blocks) + 1``.
        warnings: messages already worded, in order.
        counts: conversions and drops counted by kind (the writer's own kinds;
            commands not written under their class name, :meth:`drop`).
        notes: the first message of each kind counted by :meth:`note`, in the
            order the kinds first occurred.
        here: where the program has reached, mm (the end of the last move
            written).
        contour: the contour of the move being written (0: the moves have none).
        source: the line of the program read from code that the item being written
            comes from (:func:`input_line`; empty: none).
        arcs: arcs written as chords.
        chords: chords written for them.
        chord_error_mm: largest chord error (sagitta) of those chords, mm.
        feeds: programmed feeds the dialect cannot write, mm/min.
    """

    def __init__(self, blocks: Iterable[B] = (), *, here: Point = (0.0, 0.0)) -> None:
        self.blocks: list[B] = list(blocks)
        self.warnings: list[str] = []
        self.counts: Counter[str] = Counter()
        self.notes: dict[str, str] = {}
        self.here: Point = here
        self.contour = 0
        self.source = ""
        self.arcs = 0
        self.chords = 0
        self.chord_error_mm = 0.0
        self.feeds: set[float] = set()

    def where(self, contour: int | None = None, block: int | None = None) -> str:
        """The place for a message: ``"contour C, block B"``, or ``"block B"`` without a contour.

        A program read from code adds the line it comes from (:attr:`source`):
        ``"block 4 (input line 3)"``.

        Args:
            contour: the contour (``None``: :attr:`contour`; 0: none).
            block: the 1-based block (``None``: the one about to be written).
        """
        contour = self.contour if contour is None else contour
        block = len(self.blocks) + 1 if block is None else block
        place = f"contour {contour}, block {block}" if contour else f"block {block}"
        return f"{place} ({self.source})" if self.source else place

    def warn(self, message: str) -> None:
        """Add ``message`` to :attr:`warnings` unless it is there already."""
        if message not in self.warnings:
            self.warnings.append(message)

    def note(self, kind: str, message: str) -> None:
        """Count one conversion of ``kind``; the first message of a kind is kept."""
        self.notes.setdefault(kind, message)
        self.counts[kind] += 1

    def noted(self) -> list[str]:
        """The :meth:`note` messages, one per kind, with ``" (N times)"`` when N > 1."""
        return [
            message + (f" ({self.counts[kind]} times)" if self.counts[kind] > 1 else "")
            for kind, message in self.notes.items()
        ]

    def drop(self, command: Command) -> None:
        """Count ``command`` as not written (under its class name, e.g. ``"Dwell"``).

        A drilling cycle or an arc in another plane is written as the moves that follow
        it (the cycle's moves, the arc's chords): nothing is lost. A tool
        change or a program stop is never dropped (a wrong tool or an unattended change
        ruins the part): the program is refused.

        Raises:
            DialectError: ``command`` is a tool change or a stop.
        """
        if isinstance(command, DrillCycle | PlaneArc):
            return
        if isinstance(command, WorkOffset):  # read only for a dialect that writes them
            raise DialectError(
                f"{self.where()}: this dialect cannot select the work offset {command.code}, "
                "and the program's coordinates are in it: post for a target that has it"
            )
        if isinstance(command, LengthOffset):  # read only for a dialect that writes them
            what = "G49" if command.tool is None else f"G43 H{command.tool}"
            raise DialectError(
                f"{self.where()}: this dialect cannot write the tool length offset {what}, "
                "and the program's Z is measured with it: post for a target that has one"
            )
        if isinstance(command, ToolChange | Stop):
            what = (
                f"a tool change to T{command.tool}"
                if isinstance(command, ToolChange)
                else "a program stop" + (f" ({command.message})" if command.message else "")
            )
            raise DialectError(
                f"{self.where()}: this dialect cannot write {what}, and camtool never drops "
                "one; post one program per tool (a job does so for such a target), or a "
                "target that changes tools or stops"
            )
        self.counts[type(command).__name__] += 1

    def dropped(self) -> list[tuple[str, int]]:
        """The commands not written: ``(class name, count)`` sorted by name."""
        return sorted((kind, n) for kind, n in self.counts.items() if kind in COMMAND_KINDS)

    def chorded(self, chords: int, error_mm: float = 0.0) -> None:
        """Count one arc written as ``chords`` chords whose largest error is ``error_mm``."""
        self.arcs += 1
        self.chords += chords
        self.chord_error_mm = max(self.chord_error_mm, error_mm)


@dataclass(frozen=True)
class PostResult:
    """Emitted code and what the post-processor had to say.

    Attributes:
        code: the program in the dialect (``str`` for text formats, ``bytes``
            for binary ones).
        blocks: number of blocks (lines, packets, jobs) written.
        warnings: messages for the user (rounded feeds, rate limits...).
        format: the output format written (a key of ``PostProcessor.formats``).
    """

    code: str | bytes
    blocks: int
    warnings: tuple[str, ...] = ()
    format: str = "code"


class PostProcessor(ABC):
    """A dialect: writes a :class:`Program` and reads its own code back.

    The reader exists so that the verifier simulates exactly what was emitted;
    ``parse(emit(p).code)`` gives the moves of ``p`` within the dialect's
    resolution.
    """

    formats: ClassVar[Mapping[str, str]] = MappingProxyType({"code": ".nc"})
    """Output formats this dialect writes (``--format``), each with its file
    ending; the first is the default. ``parse`` reads every one of them."""

    binary: ClassVar[bool] = False
    """True when code files are read as bytes (``parse`` gets ``bytes``)."""

    arcs: ClassVar[bool] = True
    """True when the dialect writes arcs as arcs (G02/G03); False when every arc
    becomes chords in the code (matlab-router, i8751)."""

    @property
    def z_with_xy(self) -> bool:
        """True when one block may move X, Y and Z together (a ramp or a helix)."""
        return False

    def written_z(self, z: float, machine: Machine) -> float | None:
        """The Z (mm) the code says for a requested ``z``, as the controller reads it back.

        Rounding to the dialect's resolution (decimals, a step grid, motor steps) can
        turn a shallow depth into the top of the stock or a low safe height into the
        surface: :func:`camtool.jobs.run.check_heights` refuses such options by it.
        ``None``: the dialect writes no Z.
        """
        return None

    @property
    def writes_feeds(self) -> bool:
        """True when the dialect writes a feed the machine runs at (an F word).

        False where every move runs at the machine's own speed whatever the program
        asks (valcnc, the 8751, the Matlab router): a program's time at its programmed
        feeds is then no estimate of the machine's; ``verify`` simulates that one.
        """
        return True

    @property
    def tool_changes(self) -> str:
        """How the dialect changes tools: ``"code"``, ``"stop"`` or ``"none"``.

        ``code``: a tool change code (LinuxCNC's ``T2 M6``); ``stop``: by hand, a program
        stop with a comment naming the tool (GRBL 1.1); ``none``: it cannot, and a job of
        several tools is written as one program per tool (:func:`camtool.jobs.by_hand.per_tool`).
        """
        return "none"

    @property
    def stops(self) -> bool:
        """True when the dialect writes a program stop (``M0``; ``M1`` too if it has one).

        A dialect without one refuses a stop (:meth:`WriterState.drop`), save the
        stop right after a tool change, which a dialect changing tools by code needs not
        (:func:`camtool.jobs.pipeline.post_program`).
        """
        return False

    @property
    def length_offsets(self) -> bool:
        """True when the dialect applies the tool table's length offset after each tool change.

        LinuxCNC's ``G43 H2`` after ``T2 M6``: the program's Z is the tool tip's with the
        offset on. A program read for such a target must have its offsets where the
        dialect writes them (:func:`camtool.importers.gcode.parse_gcode`).
        """
        return False

    @property
    def work_offsets(self) -> tuple[str, ...]:
        """The work offset codes (``G54`` …) the dialect writes for a program that chose one.

        A program read for such a target keeps its own (:func:`camtool.importers.gcode.
        parse_gcode`); ``()``: coordinates are the part zero's, the offset the user has active.
        """
        return ()

    @property
    def path_controls(self) -> tuple[str, ...]:
        """The path control codes (``G61``, ``G61.1``, ``G64``) the dialect writes.

        A program read for such a target keeps its own (:class:`~camtool.model.program.
        PathControl`); ``()``: the machine's own mode applies.
        """
        return ()

    @property
    def homes(self) -> tuple[str, ...]:
        """The returns to machine positions (``"G28"``, ``"G30"``, ``"G53"``) the dialect writes.

        Any other :class:`~camtool.model.program.Home` is dropped with a warning, or
        refused where a move after it needs its height (:func:`check_dropped_homes`).
        """
        return ()

    @property
    def helix(self) -> bool:
        """True when an arc may move Z (a helical arc)."""
        return False

    def resolution_mm(self) -> float | None:
        """The smallest XY step the code can write, mm; ``None``: the dialect does not say."""
        return None

    @property
    def planes(self) -> bool:
        """True when the dialect writes arcs in the ZX and YZ planes (G18, G19).

        A dialect without them never sees a :class:`~camtool.model.program.PlaneArc`:
        :meth:`Target.emit` writes such arcs as chords first (:func:`plane_chords`).
        """
        return False

    @property
    def suffix(self) -> str:
        """File name ending of the default format."""
        return next(iter(self.formats.values()))

    def check_format(self, fmt: str | None) -> str:
        """``fmt`` (``None``: the default format) checked against :attr:`formats`.

        Raises:
            UsageError: this dialect has no such format (the message lists them).
        """
        if fmt is None:
            return next(iter(self.formats))
        if fmt not in self.formats:
            known = ", ".join(self.formats)
            raise UsageError(f"unknown format {fmt!r}; this target writes: {known}")
        return fmt

    @abstractmethod
    def emit(self, program: Program, machine: Machine, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` for ``machine`` in format ``fmt`` (default: the first).

        Raises:
            DialectError: something the dialect or the machine cannot express,
                naming the contour and block.
            UsageError: ``fmt`` is not one of :attr:`formats`.
        """

    def for_machine(self, machine: Machine) -> PostProcessor:
        """This dialect bound to ``machine`` (every :class:`Target` binds its own).

        A dialect whose code is in machine units (motor steps) needs the
        machine's steps/mm to read code back; the default returns ``self``.
        """
        return self

    @abstractmethod
    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read code in this dialect (any of its formats) back into a program.

        Raises:
            ParseError: a block does not follow the dialect, naming ``source``
                and the line (or byte offset).
        """


def from_options(
    post_class: Callable[..., PostProcessor], options: Mapping[str, Any], where: str
) -> PostProcessor:
    """A dialect class built from a target file's ``[dialect_options]`` (keyword arguments).

    What a target module's ``post_processor(options, where)`` factory usually
    returns (see :class:`camtool.post.registry.TargetPackage`).

    Raises:
        InputError: an unknown option or a bad value, naming ``where``.
    """
    try:
        return post_class(**options)
    except (TypeError, ValueError) as exc:
        raise InputError(f"{where}: invalid dialect_options ({exc})") from exc


def program_tolerance(program: Program, machine: Machine) -> float:
    """How far a written position may stray from ``program``'s, mm.

    The program's ``tolerance_mm`` (``--tolerance``), else the machine's
    ``motion.chord_tolerance_mm`` (:class:`~camtool.model.program.Program`).
    """
    if program.tolerance_mm is not None:
        return program.tolerance_mm
    return machine.motion.chord_tolerance_mm


def plane_chords(
    program: Program, target: Target, tolerance_mm: float | None = None
) -> tuple[Program, str]:
    """``program`` with its ZX/YZ arcs as chords when ``target`` cannot write them, and why.

    A target writes them when its dialect has planes (:attr:`PostProcessor.planes`) and
    its machine a Z axis; otherwise each :class:`~camtool.model.program.PlaneArc`
    becomes equal chords within ``tolerance_mm`` (``None``: the program's
    ``tolerance_mm``, else the machine's ``motion.chord_tolerance_mm``), ends exact
    (:func:`~camtool.model.program.plane_arcs_as_chords`); for a dialect that moves Z
    in blocks of its own (:attr:`PostProcessor.z_with_xy` False) no chord is longer
    than the tolerance, so its Z-then-XY staircase stays within it too. The warning (``""``: nothing
    done) says how many arcs, chords and the largest chord error.

    Raises:
        UsageError: the tolerance is not > 0, or an arc would need too many chords.
    """
    if target.post.planes and target.machine.has_z:
        return program, ""
    if tolerance_mm is None:
        tolerance_mm = program_tolerance(program, target.machine)
    # a chord's Z and XY in two blocks: a staircase (a machine without Z drops Z anyway)
    apart = target.machine.has_z and not target.post.z_with_xy
    out, done = plane_arcs_as_chords(program, tolerance_mm, tolerance_mm if apart else None)
    if not done.arcs:
        return out, ""
    how = (
        f"no longer than {tolerance_mm:g} mm, each as a Z block and an XY block (the "
        f"staircase strays at most {done.error_mm * 1000:.2f} µm)"
        if apart
        else f"within {tolerance_mm:g} mm (largest chord error {done.error_mm * 1000:.2f} µm)"
    )
    return out, (
        f"{target.name} has no arcs in the ZX and YZ planes (G18/G19): {done.arcs} such "
        f"arc(s) written as {done.chords} straight chords {how}"
    )


@dataclass(frozen=True)
class Target:
    """One machine: its dialect (write and read back), its machine profile, its motion model.

    Built from a ``<name>.toml`` alone or by a machine folder's ``__init__.py``
    (:class:`camtool.post.registry.TargetPackage`), or given whole by a plugin; listed
    by ``camtool targets``.

    Attributes:
        name: the name given to ``--target``.
        description: one line for listings.
        post: the dialect.
        machine: the machine profile.
        default_feed_mm_min: feed used when ``--feed`` is not given, mm/min.
        source: the thesis section the target comes from.
        spindle_rpm: spindle speed programmed when ``--spindle-rpm`` is not
            given, rev/min; ``None`` programs no spindle commands.
        origin: where the target was found: "builtin", "plugin" or a file path.
        motion_hook: returns the target's motion model for the verifier (its folder's
            ``motion.MOTION``, or ``None``); called only when :attr:`motion` is read, so
            listing targets imports no verifier code.
        link_table: the target file's ``[link]`` table as written (read and
            checked by :mod:`camtool.link` when a program is sent; empty: the
            target declares no link).
        link_hook: returns the target's link hooks for ``camtool send`` (its folder's
            ``link.LINK``, or ``None``); called only when :attr:`link` is read.
        dialect_factory: builds this target's dialect from a ``[dialect_options]`` table,
            for target files that name the dialect (``dialect = "pic-mmh"``); ``None``
            for a word-address dialect.
    """

    name: str
    description: str
    post: PostProcessor
    machine: Machine
    default_feed_mm_min: float
    source: str = ""
    spindle_rpm: float | None = None
    origin: str = "builtin"
    motion_hook: Callable[[], MotionHooks | None] | None = field(
        default=None, compare=False, repr=False
    )
    link_table: Mapping[str, Any] = field(
        default_factory=lambda: MappingProxyType({}), compare=False, repr=False
    )
    link_hook: Callable[[], LinkHooks | None] | None = field(
        default=None, compare=False, repr=False
    )
    dialect_factory: Callable[[Mapping[str, Any], str], PostProcessor] | None = field(
        default=None, compare=False, repr=False
    )

    def __post_init__(self) -> None:
        if isinstance(self.post, PostProcessor):  # a broken plugin's is reported later
            object.__setattr__(self, "post", self.post.for_machine(self.machine))

    def emit(self, program: Program, *, fmt: str | None = None) -> PostResult:
        """Write ``program`` in this target's dialect for its machine (format ``fmt``).

        Arcs in the ZX and YZ planes are written as chords (:func:`plane_chords`) unless
        the dialect writes them (:attr:`PostProcessor.planes`) and the machine has Z.
        """
        program, warning = plane_chords(program, self)
        check_dropped_homes(program, self.post.homes, self.name)
        result = self.post.emit(program, self.machine, fmt=fmt)
        if warning:
            result = dataclasses.replace(result, warnings=(*result.warnings, warning))
        return result

    def parse(self, code: str | bytes, *, source: str = "<code>") -> Program:
        """Read code of this target back into a program (see :meth:`PostProcessor.parse`)."""
        return self.post.parse(code, source=source)

    @property
    def motion(self) -> MotionHooks | None:
        """The target's motion model for the verifier, or ``None``; imported on first use."""
        return self.motion_hook() if self.motion_hook is not None else None

    @property
    def link(self) -> LinkHooks | None:
        """The target's link hooks for ``camtool send``, or ``None``; imported on first use."""
        return self.link_hook() if self.link_hook is not None else None
