"""Before anything is sent: read the program back, check it, frame it, time it.

Design notes: docs/internals.md, ``camtool/link/plan.py``.
"""

from __future__ import annotations

import bisect
from array import array
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, replace
from functools import cached_property
from typing import TYPE_CHECKING, Any

from camtool.link.spec import (
    Joined,
    LinkHooks,
    LinkSpec,
    WireBlock,
    frame_lines,
    link_hooks,
    link_spec,
)
from camtool.model.errors import (
    DialectError,
    InputError,
    LinkError,
    UsageError,
    VerifyLimitError,
)
from camtool.model.program import ArcMove, Dwell, Program
from camtool.model.units import fmt_num

if TYPE_CHECKING:
    from camtool.model.machine import Machine
    from camtool.post.base import Target
    from camtool.verify.verifier import Verification


@dataclass(frozen=True)
class SendPlan:
    """A checked program ready to go on the wire.

    Attributes:
        target: the target name.
        spec: its link.
        hooks: its link hooks.
        source: the program's file name, for messages.
        blocks: the blocks to send, in order: modal restore blocks first
            (``index`` 0) when resuming, then the program's from ``from_line``.
        block_time_s: estimated motion time of each of :attr:`blocks`, s.
        total_blocks: blocks in the whole program.
        skipped: program blocks before ``from_line`` (not sent).
        program: the program as read back (the whole file).
        warnings: what the operator should know before the job starts.
        verification: the verifier's result with ``verify``, else ``None``.
    """

    target: str
    spec: LinkSpec
    hooks: LinkHooks
    source: str
    blocks: Sequence[WireBlock]
    block_time_s: Sequence[float]
    total_blocks: int
    skipped: int
    program: Program
    warnings: tuple[str, ...] = ()
    verification: Verification | None = None

    @cached_property
    def _elapsed(self) -> array[float]:
        """``(n + 1,)``: estimated time of the first ``k`` blocks, wire time included, s."""
        out = array("d", [0.0])
        for block, seconds in zip(self.blocks, self.block_time_s, strict=True):
            out.append(out[-1] + seconds + self.wire_time_s(block))
        return out

    @cached_property
    def total_bytes(self) -> int:
        """Bytes to send (real-time and start-up bytes not counted)."""
        return sum(len(b.data) for b in self.blocks)

    def wire_time_s(self, block: WireBlock) -> float:
        """Seconds ``block`` takes on the wire."""
        return self.spec.wire_time_s(len(block.data))

    @property
    def estimated_time_s(self) -> float:
        """Motion time of the blocks to send plus their wire time, s."""
        return self._elapsed[-1]

    def time_left_s(self, done: int) -> float:
        """Estimated time of the blocks after the first ``done`` of :attr:`blocks`, s."""
        elapsed = self._elapsed
        return elapsed[-1] - elapsed[min(max(done, 0), len(elapsed) - 1)]

    def start_of(self, line: int) -> tuple[tuple[float, float, float] | None, bool]:
        """Where the tool stands before source ``line`` runs, and whether that line holds an arc.

        The position (X, Y, Z in mm, the program's coordinates) is where the
        last move of an earlier line ends (``None``: no move before it, or the
        program was not read with line numbers); Z is the last Z set before it
        (0 when none was).
        """
        program = self.program
        end: tuple[float, float, float] | None = None
        z = 0.0
        arc = False
        for index, move in enumerate(program.moves):
            at = program.line_of(index)
            if at is None:
                return None, False
            if at >= line:
                arc = at == line and isinstance(move, ArcMove)
                break
            z = z if move.z is None else move.z
            end = (move.x, move.y, z)
        return end, arc

    def describe(self) -> list[str]:
        """The protocol plan, one line per item: what ``--dry-run`` prints on stdout."""
        return list(self.describe_lines())

    def describe_lines(self) -> Iterator[str]:
        """:meth:`describe`, one line at a time (a long program is never held as text)."""
        spec = self.spec
        flow = {
            "char-count": f"character counting ({spec.rx_buffer_bytes}-byte receive buffer)",
            "ack": f"one block per answer {spec.ack!r}" if not spec.echo else "echo per block",
            "timed": "one block at a time, no answer: each waits its estimated time",
        }[spec.flow]
        first = next((b.line for b in self.blocks if b.index), 0)
        out = [
            f"target: {self.target} ({spec.source})" if spec.source else f"target: {self.target}",
            f"link: {spec.baud} baud 8N1, blocks end with {spec.block_end!r}, {flow}",
        ]
        if spec.handshake:
            out.append(f"start-up: {spec.handshake.upper()} handshake (modem lines)")
        if spec.startup:
            out.append(f"start-up: send {spec.startup!r}")
        if spec.banner:
            out.append(f"start-up: wait for the banner {spec.banner!r}")
        out += [
            f"blocks: {len(self.blocks)} ({self.total_bytes} bytes) of {self.total_blocks}, "
            f"from line {first}" + (f" ({self.skipped} skipped)" if self.skipped else ""),
            f"estimated time: {duration(self.estimated_time_s)}",
        ]
        yield from out
        for block, seconds in zip(self.blocks, self.block_time_s, strict=True):
            where = f"block {block.index} line {block.line}" if block.index else "restore"
            extra = f", {block.events} feedback events" if block.events else ""
            if block.quiet_end:
                extra = (
                    f", feedback events not known (it starts where the tool stands): done "
                    f"after {spec.quiet_end_s:g} s without one"
                )
            extra += f", answer {block.ack!r}" if block.ack else ""
            text = block.shown.replace("\r", " ")
            text = text if len(text) <= 60 else text[:57] + "..."
            yield f"{where}: {len(block.data)} bytes, {fmt_num(seconds, 3)} s{extra}: {text}"


def duration(seconds: float) -> str:
    """``"1 h 02 min"``, ``"3 min 12 s"`` or ``"4.2 s"``."""
    if seconds < 60:
        return f"{seconds:.1f} s"
    minutes, secs = divmod(round(seconds), 60)
    if minutes < 60:
        return f"{minutes} min {secs:02d} s"
    return f"{minutes // 60} h {minutes % 60:02d} min"


def prepare_send(
    code: str | bytes,
    target: Target,
    *,
    source: str = "<code>",
    from_line: int | None = None,
    verify: bool = False,
    max_error_um: float | None = None,
    max_depth_mm: float | None = None,
) -> SendPlan:
    """Read ``code`` back, check it and frame it for ``target``'s link.

    Args:
        code: the program file's contents (text is sent as UTF-8).
        target: the target whose link and reader to use.
        source: the file name for messages.
        from_line: resume at this 1-based source line (it must start a block).
        verify: run the verifier and keep its result.
        max_error_um: with ``verify``, refuse a predicted error above it, µm.
        max_depth_mm: deepest Z below 0 allowed, mm (default: the link's).

    Raises:
        LinkError: the target has no link camtool can speak.
        ParseError: the code is not the target's (named by line).
        DialectError: a move outside the machine's area, or deeper than allowed,
            or a block whose end the sender could not tell (the ``expect`` hook).
        UsageError: ``from_line`` is outside the program or inside a block,
            or ``max_error_um`` without ``verify``.
        InputError: a line the controller would refuse (the link's ``check``
            hook: GRBL's own word and code rules), naming it.
        VerifyLimitError: the predicted error exceeds ``max_error_um``.
    """
    spec, hooks = link_spec(target), link_hooks(target)
    data = code.encode("utf-8") if isinstance(code, str) else code
    if not data:
        raise InputError(f"{source}: empty; nothing to send")
    if max_error_um is not None and not verify:
        raise UsageError("--max-error-um needs --verify")
    program = _read_back(data, target, source)
    from camtool.verify.report import check_area

    warnings = [*program.warnings, *spec.warnings, *check_area(program, target.machine, source)]
    _check_depth(program, max_depth_mm if max_depth_mm is not None else spec.max_depth_mm, source)
    frame = hooks.frame or frame_lines
    blocks = frame(data, spec, source)
    if hooks.expect is not None:
        blocks = hooks.expect(blocks, program, target)
    first = _first_block(blocks, from_line, source)
    if first and hooks.feedback is not None:
        blocks = _quiet_first_motion(blocks, first)
    restore: list[WireBlock] = []
    if first and hooks.resume is not None:
        restore = hooks.resume(blocks[:first], blocks[first], spec)
    sent: Sequence[WireBlock] = Joined(restore, blocks, first) if first or restore else blocks
    if hooks.check is not None:  # before the timing, which simulates every step
        try:
            hooks.check(sent, source)
        except InputError as exc:
            raise InputError(f"{exc}; nothing was sent") from None
    verification, move_times = _times(program, target, verify, max_error_um)
    times = _block_times(blocks, program, _with_z(program, target, move_times))
    sent_times = array("d", [0.0] * len(restore))
    sent_times.extend(times[first:])
    return SendPlan(
        target=target.name,
        spec=spec,
        hooks=hooks,
        source=source,
        blocks=sent,
        block_time_s=sent_times,
        total_blocks=len(blocks),
        skipped=first,
        program=program,
        warnings=tuple(dict.fromkeys(warnings)),
        verification=verification,
    )


def controller_refusal(code: str | bytes, target: Target, source: str) -> str | None:
    """The first line of ``code`` that ``target``'s controller refuses, in its link's words.

    What :func:`prepare_send` refuses before the first byte (the link's ``check`` hook:
    GRBL's own word and code rules), for ``camtool verify`` to say. ``None`` for a program
    the check accepts, and for a target without a link or a check.
    """
    try:
        spec, hooks = link_spec(target), link_hooks(target)
    except (LinkError, InputError):  # no link, or a [link] table only send reads
        return None
    if hooks.check is None:
        return None
    data = code.encode("utf-8") if isinstance(code, str) else code
    try:
        hooks.check((hooks.frame or frame_lines)(data, spec, source), source)
    except (InputError, DialectError) as exc:  # GRBL's check raises the first, a plugin's may
        return str(exc)
    return None


def _quiet_first_motion(blocks: Sequence[WireBlock], first: int) -> Sequence[WireBlock]:
    """``blocks`` with the first motion from ``first`` on ending on silence (``quiet_end``).

    A resumed job starts where the stopped one left the tool, not where line N-1 ends:
    the steps of its first block that moves (feedback events) are not known; the blocks
    after it start where it ends, as predicted.
    """
    moving = next((k for k in range(first, len(blocks)) if blocks[k].events), None)
    if moving is None:
        return blocks
    out = list(blocks)
    out[moving] = replace(out[moving], quiet_end=True)
    return out


def _read_back(data: bytes, target: Target, source: str) -> Program:
    if target.post.binary:
        return target.parse(data, source=source)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{source}: byte {exc.start} is not UTF-8 text") from exc
    return target.parse(text, source=source)


def _check_depth(program: Program, max_depth_mm: float | None, source: str) -> None:
    """Refuse a Z below ``-max_depth_mm`` (S004-R20), naming the line."""
    if max_depth_mm is None:
        return
    for index, move in enumerate(program.moves):
        if move.z is not None and move.z < -max_depth_mm - 1e-9:
            line = program.line_of(index)
            where = f"line {line}" if line is not None else f"move {index + 1}"
            raise DialectError(
                f"{source}, {where}: Z {move.z:g} mm is deeper than the "
                f"{max_depth_mm:g} mm this link allows (Munoz-22 S004-R20); "
                "give --max-depth MM if the machine and tool can take it"
            )


def _times(
    program: Program, target: Target, verify: bool, max_error_um: float | None
) -> tuple[Verification | None, Sequence[float]]:
    """The verifier's result (with ``verify``) and each move's estimated time, s."""
    from camtool.verify.report import block_times
    from camtool.verify.trace_sources import simulate
    from camtool.verify.verifier import verify_program

    if not program.moves:
        return None, []
    if verify:
        v = verify_program(program, target.machine, name=target.name)
        if max_error_um is not None:
            over = v.over_limit(max_error_um)
            if over:
                raise VerifyLimitError(f"not sent: {over}")
        return v, [float(t) for t in v.block_time_s]
    return None, _chunk_times(program, target.machine, simulate, block_times)


CHUNK_MOVES = 2000
"""Most moves timed at once (see :data:`CHUNK_ROWS`)."""
CHUNK_ROWS = 200_000
"""About how many step rows a chunk may make: the step simulation behind the timing model
holds every row of the moves it is given (a 1 MB program of 2 mm moves made 15 M rows,
600 MB), so a long program is timed in chunks and only the seconds are kept."""


def _chunk_times(
    program: Program,
    machine: Machine,
    simulate: Callable[[Program, Machine], Any],
    block_times: Callable[[Any, Program, Machine], Any],
) -> array[float]:
    """Each move's time, s, by the timing model (through the verifier), in chunks of moves.

    A chunk ends after :data:`CHUNK_MOVES` moves or about :data:`CHUNK_ROWS`
    steps along the longest axis; it starts where the move before it ends, so
    each move is timed from the point it starts at. A backlash take-up at a
    chunk's first move may be timed differently than in one run (the play is not
    carried over): an estimate for pacing and bounds, not the verifier's figure.
    """
    moves = program.moves
    out = array("d")
    first = 0
    for last in _chunk_ends(program, machine):
        origin = program.origin if not first else (moves[first - 1].x, moves[first - 1].y)
        chunk = Program(
            moves=moves[first:last], origin=origin, lines=tuple(program.lines[first:last])
        )
        out.extend(float(t) for t in block_times(simulate(chunk, machine), chunk, machine))
        first = last
    return out


def _chunk_ends(program: Program, machine: Machine) -> Iterator[int]:
    """Where each chunk of :func:`_chunk_times` ends (exclusive move indices)."""
    spm = max(machine.steps_per_mm[0], machine.steps_per_mm[1])
    rows, count = 0.0, 0
    for index, (_, segment) in enumerate(program.segments()):
        rows += segment.length * spm + 1
        count += 1
        if rows >= CHUNK_ROWS or count >= CHUNK_MOVES:
            yield index + 1
            rows, count = 0.0, 0
    if count:
        yield len(program.moves)


def _with_z(program: Program, target: Target, move_times: Sequence[float]) -> Sequence[float]:
    """Each move's time with its Z travel added at the machine's step rate, s.

    The verifier simulates XY; a timed link must not send the next block while
    Z still moves. Adding Z at ``max_step_rate_hz`` (when the profile has one)
    is the conservative reading: it assumes Z moves after XY, not with it (for
    ValCNC the thesis does not say, Munoz-22 open question 5). Z starts at 0.
    """
    machine = target.machine
    if not machine.max_step_rate_hz > 0:
        return move_times
    out, z = array("d"), 0.0
    for move, seconds in zip(program.moves, move_times, strict=False):
        dz = 0.0 if move.z is None else abs(move.z - z)
        z = z if move.z is None else move.z
        out.append(seconds + dz * machine.steps_per_mm[2] / machine.max_step_rate_hz)
    return out


def _block_times(
    blocks: Sequence[WireBlock], program: Program, move_times: Sequence[float]
) -> array[float]:
    """Each block's time: the moves (and dwells) whose source line it holds, s."""
    times = array("d", [0.0]) * len(blocks)
    if not blocks:
        return times
    starts = array("q", (b.line for b in blocks))

    def block_of(move: int) -> int:
        line = program.line_of(move)
        if line is None:
            return len(blocks) - 1
        return max(0, bisect.bisect_right(starts, line) - 1)

    for move, seconds in enumerate(move_times):
        times[block_of(move)] += seconds
    for index, command in program.commands:
        if isinstance(command, Dwell):
            times[_dwell_block(index, program, blocks, block_of)] += command.seconds
    return times


def _dwell_block(
    index: int, program: Program, blocks: Sequence[WireBlock], block_of: Callable[[int], int]
) -> int:
    """The block that holds a dwell run before ``moves[index]`` (after the last: ``len``).

    A command carries no source line, but it was written after the move before it and
    before the move after it: the last block between those two moves' blocks holds it.
    Without a block between them (both in one block) it is the next move's block.
    """
    count = len(program.moves)
    after = block_of(index - 1) + 1 if 0 < index <= count else 0
    following = block_of(index) if index < count else len(blocks)
    if following > after:
        return following - 1
    return min(following, len(blocks) - 1)


def _first_block(blocks: Sequence[WireBlock], from_line: int | None, source: str) -> int:
    """Index of the block that starts at ``from_line`` (0 without one)."""
    if from_line is None:
        return 0
    last = blocks[-1].last_line
    if not 1 <= from_line <= last:
        raise UsageError(f"--from-line {from_line}: {source} has lines 1 to {last}")
    for k, block in enumerate(blocks):
        if block.line == from_line:
            return k
        if block.line < from_line <= block.last_line:
            raise UsageError(
                f"--from-line {from_line} is inside block {block.index} (lines {block.line}–"
                f"{block.last_line}); a block is sent whole: resume at line {block.line}"
            )
    raise UsageError(f"--from-line {from_line}: no block starts there")  # pragma: no cover
