"""A job: the tools and the operations that make a part, as one typed value.

Design notes: docs/internals.md, ``camtool/jobs/job.py``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from camtool.model.errors import UsageError
from camtool.model.keywords import checked_keywords
from camtool.toolpath.options import MAX_TOOL_DIAMETER_MM, MIN_TOOL_DIAMETER_MM, PlanOptions

TOOL_TYPES = ("end-mill", "drill", "v-bit", "engraver")
"""Valid values of ``Tool.type``."""

OPERATION_TYPES = ("drill", "pocket", "profile", "engrave")
"""Valid values of ``Operation.type``."""

SIDES = ("outside", "inside", "on")
"""Valid values of a profile's ``side``."""

PECKS = ("retract", "chip-break")
"""How a drill pecks when it has a ``step_down``: ``retract`` leaves the hole after each
peck (G83), ``chip-break`` backs off a little (G73)."""

SEQUENCES = ("file", "auto")
"""``file``: operations run in the file's order; ``auto``: drill, engrave, pocket, inside
profiles, outside profiles last, grouped by tool within each (:meth:`Job.sequenced`)."""

MAX_TOOL_NUMBER = 99_999
"""Largest T number a job may give (LinuxCNC's tool table takes any int; pic-mmh takes 99)."""

MAX_JOB_BYTES = 1_000_000
"""Largest job file read (a job of a thousand operations is a few hundred kB)."""
MAX_RPM = 1e6
"""Largest spindle speed a tool or ``--spindle-rpm`` may give, rev/min: beyond any spindle
(a larger one is a typo, and fixed-width dialects have no room for it)."""
MAX_DWELL_S = 3600.0
"""Longest wait a drill's ``dwell`` or ``--spindle-dwell`` may give, s."""
MAX_TOOLS = 1000
"""Most tools a job's tool table may hold: more than a tool changer holds. Each program
a job writes lists them (and its operations) in its header, and a machine without a tool
changer gets one program per tool, so what a job writes grows as the square of it."""
MAX_DRAWN_DIAMETER_MM = 1e6
"""Largest circle diameter a selection names, mm as drawn: a drawing in metres (a site plan,
scaled down by ``fit``) has circles of metres, which ``camtool job init`` names as they are."""


@checked_keywords()
@dataclass(frozen=True, kw_only=True)
class Tool:
    """A tool of the job's tool table.

    Attributes:
        id: the T number (≥ 0).
        type: one of :data:`TOOL_TYPES`.
        diameter: cutting diameter, mm: 0 (no tool: its centre on the drawing) or
            ``MIN_TOOL_DIAMETER_MM``…``MAX_TOOL_DIAMETER_MM``.
        name: what the operator loads, for comments (``""``: from type and diameter).
        rpm: spindle speed, rev/min (``None``: the target's).
        feed_mm_min: cutting feed, mm/min (``None``: the target's).
        plunge_feed_mm_min: feed into the material, mm/min (``None``: half the feed).
    """

    id: int
    type: str = "end-mill"
    diameter: float
    name: str = ""
    rpm: float | None = None
    feed_mm_min: float | None = None
    plunge_feed_mm_min: float | None = None

    def __post_init__(self) -> None:
        if isinstance(self.id, bool) or not isinstance(self.id, int):
            raise UsageError(f"Tool.id must be a whole number, got {self.id!r}")
        if not 0 <= self.id <= MAX_TOOL_NUMBER:
            raise UsageError(f"Tool.id must be 0…{MAX_TOOL_NUMBER}, got {self.id!r}")
        if self.type not in TOOL_TYPES:
            raise UsageError(
                f"unknown Tool.type {self.type!r}; choose one of {', '.join(TOOL_TYPES)}"
            )
        _check_number("Tool.diameter", self.diameter, "mm", low=0.0, high=MAX_TOOL_DIAMETER_MM)
        if 0 < self.diameter < MIN_TOOL_DIAMETER_MM:
            raise UsageError(
                f"Tool.diameter {self.diameter:g} mm is less than {MIN_TOOL_DIAMETER_MM:g} mm: "
                "no cutter is that narrow (0: no tool, its centre on the drawing)"
            )
        for name in ("rpm", "feed_mm_min", "plunge_feed_mm_min"):
            value = getattr(self, name)
            if value is not None:
                _check_number(f"Tool.{name}", value, "", low=0.0, high=MAX_RPM, above=True)

    def describe(self) -> str:
        """``"drill 3 mm"`` (or the tool's name): what the operator is asked to load."""
        return self.name or f"{self.type} {self.diameter:g} mm"


@checked_keywords({"diameter_mm": "diameter", "except_diameter_mm": "except_diameter"})
@dataclass(frozen=True, kw_only=True)
class Selection:
    """Which of the drawing an operation cuts: every condition given must hold.

    Attributes:
        layers: layer names (case-insensitive); ``None``: every layer. Naming a layer
            selects its construction geometry too (centre lines, a construction layer).
        colours: colours as ``#rrggbb``; ``None``: any.
        closed: only closed (``True``) or only open (``False``) contours; ``None``: both.
        diameter: ``(min, max)``: only circles whose diameter lies in it, mm.
        except_diameter: ``(min, max)``: not the circles whose diameter lies in it (the
            holes a drill operation drills), mm.
        linetypes: linetype names (upper case): only these; naming one selects it even
            when it is construction (CENTER, DASHED...). ``None``: any continuous one.
        points: the drawing's points (DXF POINTs, SVG dots) too (drill operations).
        contours: ``False``: no contour at all, the points alone (``points = "only"``).
    """

    layers: tuple[str, ...] | None = None
    colours: tuple[str, ...] | None = None
    closed: bool | None = None
    diameter: tuple[float, float] | None = None
    except_diameter: tuple[float, float] | None = None
    linetypes: tuple[str, ...] | None = None
    points: bool = False
    contours: bool = True

    def __post_init__(self) -> None:
        for name in ("diameter", "except_diameter"):
            span = getattr(self, name)
            if span is None:
                continue
            if not isinstance(span, tuple) or len(span) != 2:
                raise UsageError(f"Selection.{name} must be (min, max) in mm, got {span!r}")
            for value in span:
                _check_number(f"Selection.{name}", value, "mm", low=0.0, high=MAX_DRAWN_DIAMETER_MM)
            if span[0] > span[1]:
                raise UsageError(
                    f"Selection.{name} must be (min, max) with min ≤ max, got {span!r}"
                )

    def describe(self) -> str:
        """The selection in a few words for messages and the program header."""
        parts = []
        if self.layers is not None:
            parts.append("layer" + ("s " if len(self.layers) > 1 else " ") + ", ".join(self.layers))
        if self.colours is not None:
            parts.append("colour " + ", ".join(self.colours))
        if self.closed is not None:
            parts.append("closed contours" if self.closed else "open contours")
        if self.diameter is not None:
            lo, hi = self.diameter
            parts.append(f"circles of {lo:g}" + (f"–{hi:g}" if hi != lo else "") + " mm")
        if self.except_diameter is not None:
            lo, hi = self.except_diameter
            parts.append(f"not circles of {lo:g}" + (f"–{hi:g}" if hi != lo else "") + " mm")
        if self.linetypes is not None:
            parts.append("linetype " + ", ".join(self.linetypes))
        return "; ".join(parts) or "the whole drawing"


@checked_keywords({"hole_tolerance_mm": "hole_tolerance"})
@dataclass(frozen=True, kw_only=True)
class Operation:
    """One operation: what to cut (its selection), with which tool, and how.

    Attributes:
        type: one of :data:`OPERATION_TYPES`.
        tool: the T number of a tool of the job's table.
        select: what of the drawing it cuts.
        plan: its planning options (offset, depth, passes, tabs, feeds...); for a drill
            operation ``depth``, ``step_down`` (the peck), ``safe_z`` (the R plane) and the
            feed (into the material) are used.
        name: how messages and the header name it (``""``: its number).
        side: for a profile, one of :data:`SIDES`; else ``""``.
        peck: for a drill with a ``step_down``, one of :data:`PECKS`.
        dwell_s: for a drill, the wait at the bottom, s (G82).
        hole_tolerance: for a drill, how far a circle's diameter may differ from the
            drill's, mm.
    """

    type: str
    tool: int
    select: Selection = field(default_factory=Selection)
    plan: PlanOptions = field(default_factory=PlanOptions)
    name: str = ""
    side: str = ""
    peck: str = "retract"
    dwell_s: float = 0.0
    hole_tolerance: float = 0.05

    def __post_init__(self) -> None:
        if self.type not in OPERATION_TYPES:
            raise UsageError(
                f"unknown Operation.type {self.type!r}; choose one of {', '.join(OPERATION_TYPES)}"
            )
        if self.type == "profile" and self.side not in SIDES:
            raise UsageError(f"Operation.side of a profile must be one of {', '.join(SIDES)}")
        if self.peck not in PECKS:
            raise UsageError(
                f"unknown Operation.peck {self.peck!r}; choose one of {', '.join(PECKS)}"
            )
        _check_number("Operation.dwell_s", self.dwell_s, "s", low=0.0, high=MAX_DWELL_S)
        _check_number("Operation.hole_tolerance", self.hole_tolerance, "mm", low=0.0, high=1000.0)

    @property
    def kind(self) -> str:
        """``"drill"``, ``"engrave"``, ``"pocket"``, or ``"profile "`` and the side."""
        return f"profile {self.side}" if self.type == "profile" else self.type


@checked_keywords()
@dataclass(frozen=True, kw_only=True)
class Setup:
    """What every operation of a job shares: where work zero is, the size, the heights.

    Attributes:
        plan: the shared planning options (``scale``/``fit``, ``placement`` and
            ``translate``, ``clearance_z``, ``end_position``, ``chain_tolerance``,
            ``close_gap``, ``tolerance``, the default ``safe_z``).
        sequence: one of :data:`SEQUENCES`.
    """

    plan: PlanOptions = field(default_factory=PlanOptions)
    sequence: str = "file"


SETUP_FIELDS = (
    "scale",
    "fit",
    "placement",
    "translate",
    "clearance_z",
    "end_position",
    "chain_tolerance",
    "close_gap",
    "tolerance",
    "fit_arcs",
    "order",
)
"""The :class:`PlanOptions` fields a job shares (the rest belong to each operation)."""


@checked_keywords()
@dataclass(frozen=True, kw_only=True)
class Job:
    """Tools, operations and the setup they share (see the module docstring).

    Attributes:
        tools: the tool table, by T number.
        operations: in the order they run (:meth:`sequenced` orders them).
        setup: the shared settings.
        source: the job file's name (``""``: the command-line shorthand).
        shorthand: a one-operation job made of ``post``'s options (:meth:`single`): it
            writes no tool change, and its header is the one ``post`` always wrote.
    """

    tools: tuple[Tool, ...]
    operations: tuple[Operation, ...]
    setup: Setup = field(default_factory=Setup)
    source: str = ""
    shorthand: bool = False

    @classmethod
    def single(cls, plan: PlanOptions, layers: tuple[str, ...] | None = None) -> Job:
        """The one-operation job of ``post``'s options (``layers``: ``--layers``)."""
        kind = {"pocket": "pocket"}.get(plan.offset, "profile")
        op = Operation(
            type=kind,
            tool=0,
            select=Selection(layers=layers),
            plan=plan,
            side="" if kind == "pocket" else plan.offset,
        )
        tool = Tool(id=0, diameter=plan.tool_diameter or 0.0)
        return cls(tools=(tool,), operations=(op,), setup=Setup(plan=plan), shorthand=True)

    def tool(self, number: int) -> Tool:
        """The tool numbered ``number``.

        Raises:
            KeyError: no such tool (a loaded job has checked every operation's).
        """
        for t in self.tools:
            if t.id == number:
                return t
        raise KeyError(number)

    def sequenced(self) -> tuple[Operation, ...]:
        """The operations in the order they run.

        ``file``: as given. ``auto``: drill, engrave, pocket, inside (and on-line) profiles,
        outside profiles last (they free the part, so they hold tabs), and within each
        stage grouped by tool in the order the tools first appear, so a tool is loaded once
        per stage; the file's order is kept otherwise.
        """
        if self.setup.sequence == "file":
            return self.operations
        first_use: dict[int, int] = {}
        for op in self.operations:
            first_use.setdefault(op.tool, len(first_use))

        def key(item: tuple[int, Operation]) -> tuple[int, int, int]:
            index, op = item
            return (_STAGE[op.kind], first_use[op.tool], index)

        return tuple(op for _, op in sorted(enumerate(self.operations), key=key))


def check_spindle(rpm: float | None, dwell_s: float) -> None:
    """Refuse a ``--spindle-rpm`` or ``--spindle-dwell`` outside what a machine runs.

    Raises:
        UsageError: ``rpm`` (``None``: the target's) is not within 0…:data:`MAX_RPM`,
            or ``dwell_s`` not within 0…:data:`MAX_DWELL_S` (NaN included).
    """
    if rpm is not None:
        _check_number("--spindle-rpm", rpm, "rev/min", low=0.0, high=MAX_RPM)
    _check_number("--spindle-dwell", dwell_s, "s", low=0.0, high=MAX_DWELL_S)


def _check_number(
    name: str, value: object, unit: str, *, low: float, high: float, above: bool = False
) -> None:
    """``value`` a finite number in ``[low, high]`` (``(low, high]`` when ``above``)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise UsageError(f"{name} must be a number, got {value!r}")
    unit = f" {unit}" if unit else ""
    if not math.isfinite(value) or value < low or (above and value == low) or value > high:
        side = ">" if above else "≥"
        raise UsageError(f"{name} must be {side} {low:g} and ≤ {high:g}{unit}, got {value!r}")


_STAGE = {
    "drill": 0,
    "engrave": 1,
    "pocket": 2,
    "profile inside": 3,
    "profile on": 3,
    "profile outside": 4,
}
