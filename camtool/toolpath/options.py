"""Planning options: every ``post`` option that shapes a drawing's toolpath, checked once.

Each field maps to one command-line option (``--offset`` → ``offset``, ``--step-down``
→ ``step_down``...). Invalid combinations raise :class:`~camtool.model.errors.UsageError`
naming the option, before any file is read (``batch`` validates once for all files).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING

from camtool.model.errors import UsageError
from camtool.model.keywords import checked_keywords
from camtool.model.shapes import Point

if TYPE_CHECKING:
    from collections.abc import Mapping

    from camtool.model.machine import Machine
    from camtool.toolpath.cuts import Finding

OFFSET_MODES = ("on", "outside", "inside", "pocket")
"""Valid values of ``PlanOptions.offset``."""

DIRECTIONS = ("climb", "conventional")
"""Valid values of ``PlanOptions.direction``."""

POCKET_STYLES = ("concentric", "zigzag")
"""Valid values of ``PlanOptions.pocket``."""

ORDERS = ("travel", "reversals", "mirror")
"""Valid values of ``PlanOptions.order``."""

PLACEMENTS = ("drawing", "lower-left", "center")
"""Valid values of ``PlanOptions.placement`` (the ``--origin`` option): where the work
zero (X0 Y0 of the program) lies: the drawing's own origin, the toolpath's lower-left
corner, or its centre."""

DEFAULT_CLOSE_GAP = 0.02
"""Default ``--close-gap`` (mm): a contour whose own ends lie this close is closed, with a
warning (:func:`camtool.toolpath.chain.close_gaps`)."""

DEFAULT_CHAIN_TOLERANCE = 0.01
"""Default distance (mm) within which entity ends are joined into one contour.

Real CAD files leave gaps of a few µm between entities that should meet (0.002 mm is
common). 0.01 mm is dxf2gcode's ``point_tolerance`` default and FreeCAD Path's default
geometry tolerance; it is far below any tool or machine resolution camtool targets
except pic-mmh's 140 nm step, where a gap of 10 µm is still below the scribed line."""

DEFAULT_CLEARANCE_Z = 5.0
"""Clearance height (mm above the top) when ``--clearance-z`` is not given: the larger of
this and ``--safe-z``."""

_FLAG_NAMES = {
    "plunge_feed_mm_min": "--plunge-feed",
    "ramp_deg": "--ramp",
    "pocket_angle_deg": "--pocket-angle",
    "fit_arcs": "--no-fit-arcs",
    "feed_mm_min": "--feed",
    "placement": "--origin",
    "reverse_open": "--reverse-open",
    "origin": "the start position (PlanOptions.origin)",  # API only: --origin is placement
}


RENAMED = {"lead_in_mm": "lead_in", "fit_mm": "fit", "ramp_angle_deg": "ramp_deg"}
"""Old :class:`PlanOptions` keywords → their names (deprecated aliases for one release)."""


def flag(field_name: str) -> str:
    """The command-line flag of a :class:`PlanOptions` field (``step_down`` → ``--step-down``)."""
    return _FLAG_NAMES.get(field_name, "--" + field_name.replace("_", "-"))


def drawing_only(values: Mapping[str, object]) -> list[str]:
    """Flags of the planning options in ``values`` that differ from their defaults.

    Only :data:`PLAN_FIELDS` count (feed and tolerance apply to re-posted programs
    too), in the order :class:`PlanOptions` declares them. Used to refuse, not
    ignore, toolpath options given for an existing G-code program; ``values`` may be
    a command's raw options (checked before they are validated) or
    :meth:`PlanOptions.given`.
    """
    import dataclasses

    return [
        flag(f.name)
        for f in dataclasses.fields(PlanOptions)
        if f.name in PLAN_FIELDS and f.name in values and values[f.name] != f.default
    ]


@checked_keywords(RENAMED)
@dataclass(frozen=True, kw_only=True)
class PlanOptions:
    """How to turn a drawing into a toolpath.

    The fields are declared in the order of ``camtool post --help`` (the batch
    report lists them so), ``origin`` last.

    Attributes:
        offset: one of :data:`OFFSET_MODES` (see :mod:`camtool.toolpath.plan`).
        tool_diameter: tool diameter, mm (needed for every offset but ``on``).
        feed_mm_min: cutting feed, mm/min (> 0); ``None``: the target's default,
            filled in by :func:`camtool.jobs.pipeline.plan_options` before planning
            (:attr:`feed` refuses to plan without one).
        tolerance: curve tolerance, mm (> 0): fitted arcs, offsets and chords stay
            this close to what they replace. Chaining uses ``chain_tolerance``
            (``--chain-tolerance``), not this.
        close_gap: contours whose ends are further apart than ``chain_tolerance`` but
            at most this far (mm), and less than a tenth of their length, are
            closed with a warning; 0 closes nothing.
        origin: tool position before the program, mm.
        scale: uniform scale applied to the drawing about its origin (> 0).
        fit: ``(width, height)``: scale the drawing uniformly, about the
            lower-left corner of its bounding box, to the largest size that fits
            this box. Excludes ``scale``.
        direction: ``climb`` or ``conventional`` for closed contours with a
            material side (a clockwise M03 spindle: climb keeps the material on
            the right of travel). ``None``: climb when compensating, the drawn
            direction for ``offset="on"``.
        stepover: pocket step-over as a fraction of the tool diameter, (0, 1].
        pocket: pocket style, one of :data:`POCKET_STYLES`.
        pocket_angle_deg: zigzag line angle, degrees CCW from +X.
        depth: final cut depth below the top (Z = 0), mm (> 0); ``None`` writes
            no Z (2D program).
        step_down: depth of each pass, mm (> 0); ``None``: one pass at ``depth``.
        safe_z: height of every rapid when a depth is given, mm (> 0).
        plunge_feed_mm_min: feed of Z moves into the material (and, on a Z machine
            without ``depth``, down to Z 0), mm/min; ``None``: half of ``feed_mm_min``.
        ramp_deg: enter each pass along the path descending at this angle
            from the horizontal, degrees in (0, 90); ``None`` plunges straight.
        tabs: number of holding tabs on each outside profile (0 = none).
        tab_width: tab length along the part edge, mm.
        tab_height: tab height above the final depth, mm (< ``depth``).
        order: cutting order, one of :data:`ORDERS`.
        lead_in: radius of tangent lead-in/lead-out arcs on closed profiles,
            mm (0 = none).
        fit_arcs: fit arcs to dense polylines within ``tolerance``.
        placement: where the work zero lies, one of :data:`PLACEMENTS` (``--origin``):
            ``drawing`` keeps the drawing's coordinates, ``lower-left``/``center`` move
            the program so that the lower-left corner / the centre of the toolpath's
            extent (tool radius, lead-ins and tabs included) is X0 Y0.
        translate: ``(dx, dy)`` mm added to every position after ``placement``.
            Order: ``scale``/``fit`` on the drawing, then planning, then
            ``placement``, then ``translate``.
        chain_tolerance: entity ends closer than this (mm) are joined into one
            contour (:data:`DEFAULT_CHAIN_TOLERANCE`).
        clearance_z: height (mm above the top) of the first and last moves and of
            travel between parts; ``None``: the larger of :data:`DEFAULT_CLEARANCE_Z`
            and ``safe_z``. Must be ≥ ``safe_z``.
        end_position: ``(x, y)`` mm to rapid to at clearance height at the end of the
            program; ``None`` stays above the last cut.
        reverse_open: let the ordering cut open contours backwards (default: open
            contours are cut in their drawn direction).
    """

    offset: str = "on"
    tool_diameter: float = 0.0
    direction: str | None = None
    stepover: float = 0.4
    pocket: str = "concentric"
    pocket_angle_deg: float = 0.0
    depth: float | None = None
    step_down: float | None = None
    safe_z: float = 2.0
    plunge_feed_mm_min: float | None = None
    ramp_deg: float | None = None
    tabs: int = 0
    tab_width: float = 2.0
    tab_height: float = 0.5
    order: str = "travel"
    lead_in: float = 0.0
    close_gap: float = DEFAULT_CLOSE_GAP
    fit_arcs: bool = True
    feed_mm_min: float | None = None
    tolerance: float = 0.001
    scale: float = 1.0
    fit: tuple[float, float] | None = None
    placement: str = "drawing"
    translate: tuple[float, float] = (0.0, 0.0)
    chain_tolerance: float = DEFAULT_CHAIN_TOLERANCE
    clearance_z: float | None = None
    end_position: tuple[float, float] | None = None
    reverse_open: bool = False
    origin: Point = (0.0, 0.0)

    def __post_init__(self) -> None:
        _check_types(self)
        self._check_numbers()
        self._check_choices()
        self._check_tool()
        self._check_placement()
        self._check_depth()
        self._check_tabs()

    @property
    def clearance(self) -> float:
        """Clearance height, mm above the top (see ``clearance_z``)."""
        if self.clearance_z is None:
            return max(DEFAULT_CLEARANCE_Z, self.safe_z)
        return self.clearance_z

    @property
    def radius(self) -> float:
        """Tool radius, mm."""
        return self.tool_diameter / 2.0

    @property
    def feed(self) -> float:
        """Cutting feed, mm/min.

        Raises:
            UsageError: ``feed_mm_min`` is ``None`` (no target filled in its default).
        """
        if self.feed_mm_min is None:
            raise UsageError(
                "no cutting feed: give --feed MM_PER_MIN (camtool.jobs.pipeline.plan_options "
                "fills in the target's default)"
            )
        return self.feed_mm_min

    @property
    def plunge_feed(self) -> float:
        """Feed of Z moves into the material, mm/min."""
        if self.plunge_feed_mm_min is None:
            return self.feed / 2.0
        return self.plunge_feed_mm_min

    def given(self) -> dict[str, object]:
        """Every field by name (for :func:`drawing_only`)."""
        return {name: getattr(self, name) for name in type(self).__dataclass_fields__}

    def _check_numbers(self) -> None:
        """Every number finite and of a sane magnitude, named by its flag (NaN fails ``x <= 0``)."""
        for name, value in _numbers(self):
            if not math.isfinite(value):
                raise UsageError(f"{flag(name)} must be a finite number, got {value!r}")
            limit = MAX_SCALE if name == "scale" else MAX_LENGTH_MM
            if name.endswith("_deg") or name == "stepover":
                continue  # checked against their own ranges below
            if name == "origin":
                # a point of the drawing's own frame (a job's tool between operations),
                # not a length: a site plan in metres lies 1e6 mm and more from 0
                continue
            if abs(value) > limit:
                unit = "" if name in ("scale", "tabs") else " mm"  # a factor, a count
                raise UsageError(
                    f"{flag(name)} {value:g} is beyond ±{limit:g}{unit}: no machine camtool "
                    "writes for is that large; check the value and its unit"
                )
        if self.scale < 1.0 / MAX_SCALE:
            raise UsageError(f"--scale must be at least {1.0 / MAX_SCALE:g}, got {self.scale!r}")
        if self.depth is not None and self.step_down is not None and self.step_down > 0:
            passes = self.depth / self.step_down
            if passes > MAX_PASSES:
                count = f"{passes:.0f}" if passes < 1e9 else f"{passes:.3g}"
                raise UsageError(
                    f"--depth {self.depth:g} with --step-down {self.step_down:g} mm makes "
                    f"{count} passes, more than the limit of {MAX_PASSES}; give a larger "
                    "--step-down"
                )

    def _check_choices(self) -> None:
        for name, value, choices in (
            ("--offset", self.offset, OFFSET_MODES),
            ("--pocket", self.pocket, POCKET_STYLES),
            ("--order", self.order, ORDERS),
            ("--origin", self.placement, PLACEMENTS),
        ):
            if value not in choices:
                raise UsageError(f"unknown {name} {value!r}; choose one of {', '.join(choices)}")
        if self.direction is not None and self.direction not in DIRECTIONS:
            raise UsageError(
                f"unknown --direction {self.direction!r}; choose one of {', '.join(DIRECTIONS)}"
            )

    def _check_tool(self) -> None:
        if self.tool_diameter < 0:
            raise UsageError(f"--tool-diameter must be ≥ 0 mm, got {self.tool_diameter!r}")
        if self.tool_diameter > MAX_TOOL_DIAMETER_MM:
            raise UsageError(
                f"--tool-diameter {self.tool_diameter:g} mm is more than "
                f"{MAX_TOOL_DIAMETER_MM:g} mm: no cutter is that wide; check the value and its unit"
            )
        if 0 < self.tool_diameter < MIN_TOOL_DIAMETER_MM:
            raise UsageError(
                f"--tool-diameter {self.tool_diameter:g} mm is less than "
                f"{MIN_TOOL_DIAMETER_MM:g} mm: no cutter is that narrow; check the value and "
                "its unit (0 means no tool: its centre follows the drawing)"
            )
        if self.offset != "on" and self.tool_diameter <= 0:
            raise UsageError(f"--offset {self.offset} needs --tool-diameter MM (> 0)")
        if self.feed_mm_min is not None and self.feed_mm_min <= 0:
            raise UsageError(f"--feed must be > 0 mm/min, got {self.feed_mm_min!r}")
        if self.tolerance < MIN_TOLERANCE_MM:
            raise UsageError(
                f"--tolerance must be at least {MIN_TOLERANCE_MM:g} mm (1 nm, below every "
                f"machine step camtool writes for), got {self.tolerance!r}"
            )
        if self.tolerance > MAX_TOLERANCE_MM:
            raise UsageError(
                f"--tolerance must be at most {MAX_TOLERANCE_MM:g} mm (the fitted arcs and "
                f"lines may lie that far from the drawing), got {self.tolerance!r}"
            )
        if self.close_gap < 0:
            raise UsageError(f"--close-gap must be ≥ 0 mm, got {self.close_gap!r}")
        if not 0 < self.stepover <= 1:
            raise UsageError(
                f"--stepover is a fraction of the tool diameter in (0, 1], got {self.stepover!r}"
            )
        if abs(self.pocket_angle_deg) > 360:
            # 1e300 % 180 is a number, but not one the user chose
            raise UsageError(
                f"--pocket-angle is an angle within ±360 degrees from +X, got "
                f"{self.pocket_angle_deg!r}"
            )
        if self.lead_in < 0:
            raise UsageError(f"--lead-in must be ≥ 0 mm, got {self.lead_in!r}")
        if self.lead_in > 0 and self.offset in ("on", "pocket"):
            raise UsageError(
                "--lead-in needs a side to approach from: use --offset outside or inside"
            )

    def _check_placement(self) -> None:
        if self.chain_tolerance < 0:
            raise UsageError(f"--chain-tolerance must be ≥ 0 mm, got {self.chain_tolerance!r}")
        if self.scale <= 0:
            raise UsageError(f"--scale must be > 0, got {self.scale!r}")
        if self.fit is not None:
            if self.scale != 1.0:
                raise UsageError("give either --scale or --fit, not both")
            if min(self.fit) <= 0:
                raise UsageError(f"--fit needs a width and height > 0 mm, got {self.fit!r}")

    def _check_depth(self) -> None:
        if self.safe_z <= 0:
            raise UsageError(f"--safe-z must be above the top (> 0 mm), got {self.safe_z!r}")
        if self.clearance_z is not None and self.clearance_z < self.safe_z:
            raise UsageError(
                f"--clearance-z {self.clearance_z:g} mm is below --safe-z {self.safe_z:g} mm: "
                "clearance is the higher of the two (start, end and between parts); raise it "
                "or lower --safe-z"
            )
        if self.depth is None:
            given = [
                flag
                for flag, value in (
                    ("--step-down", self.step_down),
                    ("--ramp", self.ramp_deg),
                )
                if value is not None
            ]
            if given:
                raise UsageError(f"{', '.join(given)} need(s) --depth MM")
            return
        if self.depth <= 0:
            raise UsageError(
                f"--depth is measured down from the top: give a value > 0 mm, got {self.depth!r}"
            )
        if self.step_down is not None and self.step_down <= 0:
            raise UsageError(f"--step-down must be > 0 mm, got {self.step_down!r}")
        if self.plunge_feed_mm_min is not None and self.plunge_feed_mm_min <= 0:
            raise UsageError(f"--plunge-feed must be > 0 mm/min, got {self.plunge_feed_mm_min!r}")
        if self.ramp_deg is not None and not 0 < self.ramp_deg < 90:
            raise UsageError(
                f"--ramp is an angle in (0, 90) degrees from the horizontal, got {self.ramp_deg!r}"
            )

    def _check_tabs(self) -> None:
        if self.tabs < 0:
            raise UsageError(f"--tabs must be ≥ 0, got {self.tabs!r}")
        if self.tabs == 0:
            return
        if self.depth is None:
            raise UsageError("--tabs need --depth MM: a tab is material left above the depth")
        if self.offset != "outside":
            raise UsageError("--tabs go on outside profiles: use --offset outside")
        if self.tab_width <= 0 or self.tab_height <= 0:
            raise UsageError(
                f"--tab-width and --tab-height must be > 0 mm, got {self.tab_width!r}, "
                f"{self.tab_height!r}"
            )
        if self.tab_height >= self.depth:
            raise UsageError(
                f"--tab-height {self.tab_height:g} mm must be below --depth {self.depth:g} mm"
            )

    def ineffective(self) -> list[Finding]:
        """Options given that have no effect in this combination, as ``option`` findings.

        Each says why, so a user who expected an effect knows what to add or drop.
        """
        from camtool.toolpath.cuts import Finding

        notes: list[str] = []
        if self.offset == "on" and self.tool_diameter > 0:
            notes.append(
                f"--tool-diameter {self.tool_diameter:g} has no effect with --offset on (the "
                "tool centre follows the drawn line); add --offset outside, inside or pocket "
                "to compensate for the tool"
            )
        pocket_only = self._changed("stepover", "pocket", "pocket_angle_deg")
        if self.offset != "pocket" and pocket_only:
            verb = "only applies" if len(pocket_only) == 1 else "only apply"
            notes.append(f"{', '.join(pocket_only)} {verb} to --offset pocket: no effect here")
        tab_only = self._changed("tab_width", "tab_height")
        if self.tabs == 0 and tab_only:
            verb = "has" if len(tab_only) == 1 else "have"
            notes.append(f"{', '.join(tab_only)} {verb} no effect without --tabs N")
        return [Finding("option", note) for note in notes]

    def _changed(self, *names: str) -> list[str]:
        """Flags of the fields among ``names`` that differ from their defaults."""
        fields = type(self).__dataclass_fields__
        return [flag(n) for n in names if getattr(self, n) != fields[n].default]

    def z_options(self) -> list[str]:
        """The depth options given, as flags (for the 2D-target error)."""
        flags = [("--depth", self.depth is not None), ("--tabs", self.tabs > 0)]
        return [flag for flag, given in flags if given]

    def check_machine(self, machine: Machine, name: str) -> None:
        """Refuse depth options for a machine without Z (``name``: the target, for the message).

        Raises:
            UsageError: a depth option was given and ``machine.has_z`` is false.
        """
        if self.z_options() and not machine.has_z:
            raise UsageError(
                f"{', '.join(self.z_options())}: {name} has no programmable Z axis "
                f"({machine.name} is 2D); set the depth by hand on the machine and "
                "leave these options out"
            )


MAX_LENGTH_MM = 1e6
"""Largest length (mm) any option may give: 1 km, beyond every machine camtool targets."""

MAX_SCALE = 1e6
"""Largest ``--scale`` factor (and 1/this the smallest)."""

MAX_TOOL_DIAMETER_MM = 1000.0
"""Largest tool diameter (mm) an option or a job's tool may give: wider than any cutter."""

MIN_TOOL_DIAMETER_MM = 0.001
"""Smallest tool diameter (mm) an option or a job's tool may give, 0 (no tool) aside: 1 µm,
narrower than any cutter; far below it the offset kernels lose a half-diameter in the
coordinates' float precision and call a region narrower than the tool."""

MIN_TOLERANCE_MM = 1e-6
"""Smallest ``--tolerance`` (mm): chords and fitted arcs finer than 1 nm only cost time."""

MAX_TOLERANCE_MM = 1.0
"""Largest ``--tolerance`` (mm): the toolpath may lie this far from the drawing, already
coarser than any part is cut to; a larger value is a slip (10 for 0.010)."""

MAX_PASSES = 10_000
"""Most depth passes a plan may have (``--depth`` / ``--step-down``)."""


_KINDS: dict[str, str] = {
    "offset": "choice",
    "tool_diameter": "number",
    "direction": "choice?",
    "stepover": "number",
    "pocket": "choice",
    "pocket_angle_deg": "number",
    "depth": "number?",
    "step_down": "number?",
    "safe_z": "number",
    "plunge_feed_mm_min": "number?",
    "ramp_deg": "number?",
    "tabs": "int",
    "tab_width": "number",
    "tab_height": "number",
    "order": "choice",
    "lead_in": "number",
    "close_gap": "number",
    "fit_arcs": "bool",
    "feed_mm_min": "number?",
    "tolerance": "number",
    "scale": "number",
    "fit": "pair?",
    "placement": "choice",
    "translate": "pair",
    "chain_tolerance": "number",
    "clearance_z": "number?",
    "end_position": "pair?",
    "reverse_open": "bool",
    "origin": "pair",
}
"""The kind of value each :class:`PlanOptions` field takes (``?``: or ``None``)."""

_KIND_NAMES = {
    "number": "a number",
    "int": "a whole number",
    "bool": "True or False",
    "pair": "two numbers (x, y)",
    "choice": "a name",
}


def _check_types(options: PlanOptions) -> None:
    """Refuse a value of the wrong kind, naming the field and what it takes.

    Raises:
        UsageError: e.g. ``PlanOptions(origin="center")``: the start position is two
            numbers (the work zero is ``placement``, ``--origin`` on the command line).
    """
    for name, kind in _KINDS.items():
        value = getattr(options, name)
        base = kind.rstrip("?")
        if value is None and kind.endswith("?"):
            continue
        if _of_kind(value, base):
            if isinstance(value, list):  # a pair given as a list: kept as the tuple it is
                object.__setattr__(options, name, tuple(value))
            continue
        hint = ""
        if name == "origin" and isinstance(value, str):
            hint = (
                f"; origin is where the tool stands before the program; for the work zero "
                f"({', '.join(PLACEMENTS)}: --origin on the command line) give "
                f"placement={value!r}"
            )
        raise UsageError(
            f"PlanOptions {name} = {value!r}: give {_KIND_NAMES[base]} ({flag(name)}){hint}"
        )


def _of_kind(value: object, kind: str) -> bool:
    if kind == "bool":
        return isinstance(value, bool)
    if kind == "choice":
        return isinstance(value, str)
    if kind == "int":
        return isinstance(value, int) and not isinstance(value, bool)
    if kind == "number":
        return isinstance(value, int | float) and not isinstance(value, bool)
    return (
        isinstance(value, tuple | list)
        and len(value) == 2
        and all(_of_kind(v, "number") for v in value)
    )


def _numbers(options: PlanOptions) -> list[tuple[str, float]]:
    """Every number of ``options`` with its field name (pairs give two entries)."""
    import dataclasses

    out: list[tuple[str, float]] = []
    for f in dataclasses.fields(options):
        value = getattr(options, f.name)
        if isinstance(value, bool) or value is None or isinstance(value, str):
            continue
        if isinstance(value, tuple):
            out.extend((f.name, float(v)) for v in value)
        elif isinstance(value, int | float):
            out.append((f.name, float(value)))
    return out


PLAN_FIELDS = frozenset(
    f for f in PlanOptions.__dataclass_fields__ if f not in ("feed_mm_min", "tolerance")
)
"""Planning options other than feed and tolerance (which re-posted programs use too)."""
