"""Estimated machining time of a simulated program: the machine's timing model per block.

Builds the per-block :class:`~camtool.verify.timing.BlockKinematics` from a
:class:`~camtool.verify.motion.StepTrace` and hands it to the model named in
the profile's ``[machine.timing]`` table (looked up by
:meth:`camtool.verify.motion.Library.timing`: the generic library, then the
targets' ``MOTION``; the model may complete the table from the profile).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from camtool.model.errors import InputError
from camtool.model.machine import Machine
from camtool.model.program import PlaneArc, Program, Rapid, SourceLines
from camtool.verify.motion import StepTrace, timing_model_from_table
from camtool.verify.timing import BlockKinematics, TimingModel


def block_kinematics(trace: StepTrace, program: Program) -> BlockKinematics:
    """Per-block quantities of a simulated program (see :class:`BlockKinematics`)."""
    moves = program.moves
    steps = trace.block_steps
    rows = np.diff(trace.block_start) if len(trace.block_start) else np.zeros(0, np.int64)
    return BlockKinematics.build(
        dominant_steps=trace.block_dominant,
        is_rapid=np.fromiter((isinstance(m, Rapid) for m in moves), np.bool_, len(moves)),
        feed_mm_min=np.fromiter(
            (0.0 if isinstance(m, Rapid) else m.feed_mm_min for m in moves), np.float64, len(moves)
        ),
        length_mm=program.path_lengths(),
        iterations=rows - trace.block_compensation,
        steps=steps,
        compensation_steps=trace.block_compensation,
    )


def block_times_s(trace: StepTrace, program: Program, machine: Machine) -> npt.NDArray[np.float64]:
    """Seconds each move takes on ``machine``, ``(B,)`` float64.

    A profile without a ``[machine.timing]`` table is timed at the programmed
    feed (rapids at the fastest feed of the program), which is what a controller
    with ideal acceleration would do.

    Raises:
        InputError: the ``[machine.timing]`` table names an unknown model or key,
            or there is no table and a cutting move has no feed to be timed at.
    """
    if trace.block_time_s is not None:
        return np.asarray(trace.block_time_s, dtype=np.float64)
    if not machine.timing:
        return _at_feed(program, machine)
    model = _timing_model(machine)
    blocks = block_kinematics(trace, program)
    times = np.array(model.block_time_s(blocks), dtype=np.float64)
    spans = _plane_arc_spans(program)
    if spans:
        arcs = np.asarray(model.block_time_s(_joined(blocks, spans)), dtype=np.float64)
        lengths = blocks.length_mm
        for (start, stop), seconds in zip(spans, arcs, strict=True):
            share = lengths[start:stop] / max(float(lengths[start:stop].sum()), 1e-300)
            times[start:stop] = seconds * share
    return times


def _timing_model(machine: Machine) -> TimingModel:
    """The model of ``machine``'s ``[machine.timing]`` table (which must not be empty).

    Raises:
        InputError: the table names an unknown model or key.
    """
    where = f"machine {machine.name!r} [machine.timing]"
    return timing_model_from_table(machine.timing, where=where, machine=machine)


def time_assumption(trace: StepTrace, machine: Machine) -> str:
    """What :func:`block_times_s` assumed that a reader of the estimate should know, or ``""``.

    The timing model's ``assumes`` (the rest-to-rest trapezoid: an upper bound); nothing
    for a target simulator's own times or a profile without a timing table.
    """
    if trace.block_time_s is not None or not machine.timing:
        return ""
    model = _timing_model(machine)
    return str(getattr(model, "assumes", ""))


def _plane_arc_spans(program: Program) -> list[tuple[int, int]]:
    """``[start, stop)`` move ranges that are the chords of a G18/G19 arc the code holds.

    The controller runs such an arc as one block (GRBL's ``mc_arc`` and LinuxCNC's
    planner blend its segments as they do an XY arc's), so it is timed as one.
    """
    return [
        (index, index + command.moves)
        for index, command in program.commands
        if isinstance(command, PlaneArc)
        and command.moves > 1
        and program.has_chords_of(index, command)
    ]


def _joined(blocks: BlockKinematics, spans: list[tuple[int, int]]) -> BlockKinematics:
    """One block per span of ``blocks``: counts and lengths summed, the first block's feed."""

    def total(values: npt.NDArray[np.generic]) -> npt.NDArray[np.generic]:
        return np.array([values[a:b].sum(axis=0) for a, b in spans])

    first = np.array([a for a, _ in spans], dtype=np.int64)
    return BlockKinematics.build(
        dominant_steps=total(blocks.dominant_steps),
        is_rapid=blocks.is_rapid[first],
        feed_mm_min=blocks.feed_mm_min[first],
        length_mm=total(blocks.length_mm),
        iterations=total(blocks.iterations),
        steps=total(blocks.steps).reshape(len(spans), 3),
        compensation_steps=total(blocks.compensation_steps),
        block_bytes=total(blocks.block_bytes),
    )


def timing_warnings(trace: StepTrace, program: Program, machine: Machine) -> list[str]:
    """Warnings for the limits the timing model applied (``capped_blocks``), by code line.

    A model that caps a move (a step rate over the controller's limit, a feed over
    the maximum rate) says which blocks in ``capped_blocks``
    (:data:`camtool.verify.timing.CappedBlocks`); blocks with the same reason are
    named together (the first 8 lines, then how many more).

    Raises:
        InputError: the ``[machine.timing]`` table is invalid.
    """
    if trace.block_time_s is not None or not machine.timing:
        return []
    model = _timing_model(machine)
    capped = getattr(model, "capped_blocks", None)
    if capped is None:
        return []
    known = len(program.lines)
    source = program.lines if isinstance(program.lines, SourceLines) else SourceLines(program.lines)
    lines = np.frombuffer(source.view(), dtype=np.int64)
    out = []
    for blocks, reason in capped(block_kinematics(trace, program)):
        word, numbers = "line", lines[blocks] if int(blocks[-1]) < known else None
        if numbers is None:
            word, numbers = "move", blocks + 1
        # the chords of one arc share its line: each number once, in the order first met
        numbers = numbers[np.sort(np.unique(numbers, return_index=True)[1])]
        more = len(numbers) - 8
        shown = ", ".join(str(int(n)) for n in numbers[:8]) + (
            f" and {more} more" if more > 0 else ""
        )
        out.append(f"{word}{'s' if len(numbers) > 1 else ''} {shown}: {reason}")
    return out


def _at_feed(program: Program, machine: Machine) -> npt.NDArray[np.float64]:
    feeds = [m.feed_mm_min for m in program.moves if not isinstance(m, Rapid)]
    if any(not feed > 0 for feed in feeds):
        raise InputError(
            f"machine {machine.name!r} has no [machine.timing] table and the program has "
            "cutting moves without a feed (a dialect without an F word): name a timing model "
            "in [machine.timing] to time it"
        )
    rapid = max(feeds, default=1.0)
    out = [
        length / ((rapid if isinstance(move, Rapid) else move.feed_mm_min) / 60.0)
        for move, length in zip(program.moves, program.path_lengths(), strict=True)
    ]
    return np.asarray(out, dtype=np.float64)
