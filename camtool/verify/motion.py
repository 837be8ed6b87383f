"""Motion models: what a simulator produces, the pieces a target adds, and name lookup.

Every simulator produces a :class:`StepTrace` (the step simulator of
:mod:`camtool.verify.simulate`, or a target's own), which the measures read.

Design notes: docs/internals.md, ``camtool/verify/motion.py``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, TypeVar

import numpy as np
import numpy.typing as npt

from camtool.model.errors import CamtoolError, InputError
from camtool.model.machine import Machine, Motion
from camtool.model.program import ArcMove, Program
from camtool.model.shapes import Point
from camtool.verify.dda import dda_line
from camtool.verify.interpolators import (
    accumulator_dda_line,
    bresenham_line,
    circular_dda_arc,
    corte_recto_line,
    dsm_arc,
    sagitta_chord_points,
    staircase_arc,
)
from camtool.verify.sources import ALL, Sources
from camtool.verify.steparray import StepArray
from camtool.verify.timing import TimingModel, TrapezoidTiming, timing_from_table

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True, eq=False)
class StepTrace:
    """What the motors and the carriage did, row by row.

    Attributes:
        rows: ``(N, 2) int8`` motor steps per iteration, compensation included.
        compensation: ``(N,) bool``, True for a backlash-compensation row.
        block_of_row: ``(N,) int64``, index of the program move each row belongs to.
        block_start: ``(B + 1,) int64`` row offsets: move ``b`` owns rows
            ``block_start[b]:block_start[b + 1]``.
        carriage_mm: ``(N, 2) float64``, carriage (tool-centre) position after each
            row, mm, machine coordinates.
        start_mm: carriage position before the first row, mm.
        logical_end: ``(B, 2) int64``, the controller's logical position after each
            move, steps.
        block_steps: ``(B, 3) int64``, motor steps (pulses) per move and axis, without
            compensation: ``(x, y, z)``.
        block_dominant: ``(B,) int64``, steps of the dominant axis of each executed line
            (summed over the chords of a chord arc; iterations for a native arc), what
            per-step time models count (Yanez-07 R15).
        block_compensation: ``(B,) int64``, compensation steps inserted in each move.
        reversals: reversals of the commanded X and Y directions.
        compensations: compensation events (axis reversals the controller
            compensated; 0 when the profile compensates nothing).
        block_time_s: ``(B,) float64`` time of each move when the simulation itself
            gives it (a target's own simulator), else ``None`` (the timing model decides).
    """

    rows: StepArray
    compensation: npt.NDArray[np.bool_]
    block_of_row: IntArray
    block_start: IntArray
    carriage_mm: FloatArray
    start_mm: Point
    logical_end: IntArray
    block_steps: IntArray
    block_dominant: IntArray
    block_compensation: IntArray
    reversals: tuple[int, int]
    compensations: int
    block_time_s: FloatArray | None = None

    @property
    def row_count(self) -> int:
        """Rows of the trace (iterations and compensation steps)."""
        return len(self.rows)

    @property
    def iterations(self) -> int:
        """Interpolator iterations: the rows that are not compensation."""
        return int((~self.compensation).sum())

    @property
    def compensation_steps(self) -> tuple[int, int]:
        """Compensation steps per axis ``(x, y)``."""
        rows = self.rows[self.compensation]
        return (int(np.abs(rows[:, 0]).sum()), int(np.abs(rows[:, 1]).sum()))


LineInterpolator = Callable[[int, int], StepArray]
"""``(dx, dy)`` signed steps → step array ``(N, 2) int8``."""
LineFactory = Callable[[Machine], LineInterpolator]
"""A line interpolator made for one machine profile (may read its parameters).

Raises:
    UsageError or InputError: the profile lacks what the interpolator needs.
"""
ArcInterpolator = Callable[[int, int, int, int, int, int, bool], StepArray]
"""``(x0, y0, x1, y1, cx, cy, clockwise)`` absolute steps → step array ending at ``(x1, y1)``."""
ChordRule = Callable[[Point, ArcMove, Motion], "npt.ArrayLike"]
"""``(start_mm, move, motion)`` → chord end points ``(N, 2)`` mm, start excluded.

``motion`` carries the profile's chord parameters (``chord_tolerance_mm``,
``chord_segments``, ``chord_angle_deg``)."""
TimingFactory = Callable[[Mapping[str, Any], "Machine | None", str], TimingModel]
"""``(table, machine, where)`` → timing model; raises InputError naming ``where``."""
Simulator = Callable[[Program, Machine], StepTrace]
"""``(program, machine)`` → the trace the verifier measures (replaces the step simulator)."""

CHORDS = "chords"
"""The ``arc`` name that cuts arcs into chords (by the ``chords`` rule) run as lines."""

T = TypeVar("T")


def _frozen(mapping: Mapping[str, T] | None = None) -> Mapping[str, T]:
    return MappingProxyType(dict(mapping or {}))


@dataclass(frozen=True, kw_only=True)
class MotionHooks:
    """Named pieces a target (or the generic library) adds to the verifier.

    A target's module ``<stem>_motion`` defines ``MOTION = MotionHooks(...)``; a
    profile then names a piece by its key. Every mapping is read-only.

    Attributes:
        lines: ``line`` name → :data:`LineFactory`.
        arcs: ``arc`` name → :data:`ArcInterpolator` (``"chords"`` is reserved).
        chords: ``chords`` name → :data:`ChordRule`.
        timing: ``[machine.timing] model`` name → :data:`TimingFactory`.
        simulators: ``line`` name → :data:`Simulator` run instead of the step
            simulator.
        honours: piece name (a line or a simulator) → the error sources it
            models and can switch off (names of :data:`camtool.verify.sources.SOURCES`);
            it is then called with ``sources=``.
    """

    lines: Mapping[str, LineFactory] = field(default_factory=_frozen)
    arcs: Mapping[str, ArcInterpolator] = field(default_factory=_frozen)
    chords: Mapping[str, ChordRule] = field(default_factory=_frozen)
    timing: Mapping[str, TimingFactory] = field(default_factory=_frozen)
    simulators: Mapping[str, Simulator] = field(default_factory=_frozen)
    honours: Mapping[str, tuple[str, ...]] = field(default_factory=_frozen)

    def __post_init__(self) -> None:
        for name in ("lines", "arcs", "chords", "timing", "simulators", "honours"):
            object.__setattr__(self, name, _frozen(getattr(self, name)))


def fixed_line(line: LineInterpolator) -> LineFactory:
    """A :data:`LineFactory` for an interpolator that needs no profile parameter."""

    def factory(machine: Machine) -> LineInterpolator:
        return line

    return factory


def timing_class(cls: type[Any]) -> TimingFactory:
    """A :data:`TimingFactory` building the parameter dataclass ``cls`` from the table alone.

    See :func:`camtool.verify.timing.timing_from_table` for the accepted keys.
    """

    def factory(table: Mapping[str, Any], machine: Machine | None, where: str) -> TimingModel:
        model: TimingModel = timing_from_table(cls, table, where=where)
        return model

    return factory


def _sagitta(start: Point, move: ArcMove, motion: Motion) -> npt.ArrayLike:
    return sagitta_chord_points(start, move, motion.chord_tolerance_mm)


GENERIC = MotionHooks(
    lines={
        "dda": fixed_line(dda_line),
        "accumulator-dda": fixed_line(accumulator_dda_line),
        "bresenham": fixed_line(bresenham_line),
        "corte-recto": fixed_line(corte_recto_line),
    },
    arcs={"dsm": dsm_arc, "staircase": staircase_arc, "circular-dda": circular_dda_arc},
    chords={"sagitta": _sagitta},
    timing={"trapezoid": timing_class(TrapezoidTiming)},
)
"""The generic library, named by algorithm (:mod:`camtool.verify.interpolators`,
:mod:`camtool.verify.timing`)."""


QUALIFIED = ":"
"""Separates a target's name from its piece's: ``chords = "grbl:grbl"`` names the chord rule
``grbl`` of target ``grbl`` from a profile that is not GRBL's."""


@dataclass(frozen=True)
class Library:
    """The pieces a profile may name: the generic library, then its own target's ``MOTION``.

    A name ``"<target>:<piece>"`` is looked up in that target's ``MOTION`` alone.

    Attributes:
        sources: :data:`GENERIC` first, then the hooks of the target the profile belongs
            to; the first source that has a name wins.
    """

    sources: tuple[MotionHooks, ...]

    def _sources(self, name: str) -> tuple[tuple[MotionHooks, ...], str]:
        """Where ``name`` is looked up, and the piece's name there."""
        target, qualified, piece = name.partition(QUALIFIED)
        if not qualified:
            return self.sources, name
        from camtool.post.registry import target_motion

        try:
            hooks = target_motion(target)
        except CamtoolError:
            return (), piece
        return ((hooks,) if hooks is not None else ()), piece

    def _find(
        self, pick: Callable[[MotionHooks], Mapping[str, T]], name: str, what: str, where: str
    ) -> T:
        sources, piece = self._sources(name)
        for hooks in sources:
            table = pick(hooks)
            if piece in table:
                return table[piece]
        raise InputError(f"{where}: unknown {what} {name!r}; {self.valid(pick)}")

    def names(self, pick: Callable[[MotionHooks], Mapping[str, Any]]) -> list[str]:
        """Every name of one kind of piece, in lookup order (``pick`` selects the kind)."""
        return list(dict.fromkeys(key for hooks in self.sources for key in pick(hooks)))

    def valid(self, pick: Callable[[MotionHooks], Mapping[str, Any]], *extra: str) -> str:
        """The valid names for an error message, and how to name another target's."""
        names = ", ".join([*self.names(pick), *extra])
        return f"valid: {names} (or <target>{QUALIFIED}<name> for another target's)"

    def simulator(self, line: str) -> Simulator | None:
        """The whole simulator a ``line`` name selects, or ``None`` for the step simulator."""
        sources, piece = self._sources(line)
        for hooks in sources:
            if piece in hooks.simulators:
                return hooks.simulators[piece]
        return None

    def honours(self, name: str) -> tuple[str, ...]:
        """The error sources the piece ``name`` (a line or a simulator) models itself."""
        sources, piece = self._sources(name)
        for hooks in sources:
            if piece in hooks.lines or piece in hooks.simulators:
                return tuple(hooks.honours.get(piece, ()))
        return ()

    def line(self, machine: Machine, *, sources: Sources = ALL) -> LineInterpolator:
        """The line interpolator of ``machine``'s ``[machine.motion] line``.

        ``sources`` reach a factory that honours some (``MotionHooks.honours``).

        Raises:
            InputError: an unknown name (the message lists the valid ones).
            UsageError: the profile lacks a parameter the interpolator needs.
        """
        found, piece = self._sources(machine.motion.line)
        for hooks in found:
            if piece in hooks.lines:
                if piece in hooks.honours:
                    return hooks.lines[piece](machine, sources=sources)  # type: ignore[call-arg]
                return hooks.lines[piece](machine)
        valid = self.valid(lambda h: {**h.lines, **h.simulators})
        raise InputError(
            f"{_where(machine, 'motion')}: unknown line interpolator {machine.motion.line!r}; "
            f"{valid}"
        )

    def arc(self, machine: Machine) -> ArcInterpolator | None:
        """The arc interpolator of ``machine``, or ``None`` for ``arc = "chords"``.

        Raises:
            InputError: an unknown name (the message lists the valid ones).
        """
        if machine.motion.arc == CHORDS:
            return None
        found, piece = self._sources(machine.motion.arc)
        for hooks in found:
            if piece in hooks.arcs:
                return hooks.arcs[piece]
        raise InputError(
            f"{_where(machine, 'motion')}: unknown arc interpolator {machine.motion.arc!r}; "
            f"{self.valid(lambda h: h.arcs, CHORDS)}"
        )

    def chord_rule(self, machine: Machine) -> ChordRule:
        """The chord rule of ``machine``'s ``[machine.motion] chords``.

        Raises:
            InputError: an unknown name (the message lists the valid ones).
        """
        where = _where(machine, "motion")
        return self._find(lambda h: h.chords, machine.motion.chords, "chord rule", where)

    def timing(
        self, table: Mapping[str, Any], *, where: str, machine: Machine | None = None
    ) -> TimingModel:
        """The timing model a ``[machine.timing]`` table names, with its parameters.

        Raises:
            InputError: an unknown model or key, or a bad value, naming ``where``.
        """
        name = table.get("model")
        if not isinstance(name, str):
            valid = self.valid(lambda h: h.timing)
            raise InputError(f"{where}: unknown timing model {name!r}; {valid}")
        factory = self._find(lambda h: h.timing, name, "timing model", where)
        return factory(table, machine, where)

    def check(self, machine: Machine) -> None:
        """Resolve every name ``machine`` uses, and build its timing table's model if any.

        Raises:
            InputError: the first unknown name, listing the valid ones, or a timing
                value of the wrong type or out of range.
        """
        if self.simulator(machine.motion.line) is None:
            self.line(machine)
        if self.arc(machine) is None:
            self.chord_rule(machine)
        if machine.timing:  # its rates time a program's header too, verified or not
            self.timing(machine.timing, where=_where(machine, "timing"), machine=machine)


def _where(machine: Machine, table: str) -> str:
    return f"machine {machine.name!r} [machine.{table}]"


def library(machine: Machine | None = None) -> Library:
    """The generic library, then the ``MOTION`` of the target ``machine``'s profile belongs to.

    The profile is ``machine.profile`` (``profile = "grbl"`` in ``grbl.toml``'s
    ``[machine]`` table; :func:`camtool.post.registry.profile_motion`). A machine with
    no such profile names the generic library, or another target's pieces qualified
    (``"grbl:grbl"``). The target's modules are imported on the first call.
    """
    from camtool.post.registry import profile_motion

    hooks = profile_motion(machine.profile) if machine is not None else None
    return Library((GENERIC, hooks) if hooks is not None else (GENERIC,))


def timing_model_from_table(
    table: Mapping[str, Any], *, where: str, machine: Machine | None = None
) -> TimingModel:
    """Build the timing model a TOML ``[timing]`` table names (:meth:`Library.timing`).

    The table holds ``model`` (a name of the generic library or of a target's
    ``MOTION.timing``) and that model's parameters, e.g. ``model = "trapezoid"``
    and ``acceleration_mm_s2 = 500``. ``machine``, when given, lets the model take
    defaults from the profile.

    Raises:
        InputError: An unknown model or key, or a value of the wrong type or
            out of range, naming ``where`` and the valid choices.
    """
    return library(machine).timing(table, where=where, machine=machine)
