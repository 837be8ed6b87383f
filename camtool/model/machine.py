"""Machine profile: what a target's machine can do and how it moves.

Loaded from the ``[machine]`` table of a target's TOML file and overridable,
key by key, with ``--machine FILE.toml`` (see :func:`merge_tables`). Lengths in
mm unless the name says otherwise. The verifier (:mod:`camtool.verify`) reads
everything below; the post-processors read the work area, Z and step rate.

Design notes: docs/internals.md, ``camtool/model/machine.py``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from types import MappingProxyType
from typing import Any

from camtool.model.errors import InputError
from camtool.model.shapes import BBox
from camtool.model.tomlfile import SMALL_TOML_BYTES, as_toml, read_toml_file

ROUNDINGS = ("half_even", "half_up", "floor", "trunc")
"""mm → steps rounding rules (:func:`camtool.verify.quantize.steps_from_mm`)."""

AXES = ("x", "y", "z")

COORDINATES: dict[str, str] = {
    "work": "the controller runs programs relative to a work zero the operator sets "
    "(G54 or zeroing at the current position): only the program's size must fit the travel",
    "machine": "the controller runs programs relative to its home: every position must lie "
    "inside work_area_mm",
}
"""What the numbers of a program mean on a machine (``coordinates`` key of a profile)."""


@dataclass(frozen=True, kw_only=True)
class Motion:
    """How the controller turns blocks into motor steps.

    The names are open: the verifier looks each up in its generic library, then in
    every installed target's motion model (:mod:`camtool.verify.motion`), and an
    unknown name is an error there, listing the valid ones.

    Attributes:
        line: line interpolator name (e.g. ``"dda"``, ``"bresenham"``), or the name
            of a whole simulator a target brings.
        arc: arc interpolator name (e.g. ``"dsm"``), or ``"chords"``: chords run
            by the line interpolator.
        chords: chord rule name (e.g. ``"sagitta"``; used when ``arc == "chords"``).
        chord_tolerance_mm: largest chord sagitta, mm (``sagitta``, ``grbl``).
        chord_segments: chords per arc (``flashcut``; the thesis does not say).
        chord_angle_deg: chord angle β, degrees (``valcnc``; not given).
        rounding: mm → steps rounding of the controller, one of :data:`ROUNDINGS`.
            Positions are converted absolutely (no drift), Yanez-07 §4.5.
    """

    line: str = "dda"
    arc: str = "dsm"
    chords: str = "sagitta"
    chord_tolerance_mm: float = 0.002
    chord_segments: int = 16
    chord_angle_deg: float = 5.0
    rounding: str = "half_up"


@dataclass(frozen=True, kw_only=True)
class BacklashRegion:
    """True backlash of one axis inside a rectangle of the work area (UNAM-GMM Tabla 13).

    Attributes:
        axis: ``"x"`` or ``"y"``.
        x_mm: ``(lo, hi)`` extent in X, mm.
        y_mm: ``(lo, hi)`` extent in Y, mm.
        true_um: true backlash of ``axis`` there, µm.
    """

    axis: str
    x_mm: tuple[float, float]
    y_mm: tuple[float, float]
    true_um: float

    def contains(self, x_mm: float, y_mm: float) -> bool:
        """True when ``(x_mm, y_mm)`` lies in the rectangle (edges included)."""
        return self.x_mm[0] <= x_mm <= self.x_mm[1] and self.y_mm[0] <= y_mm <= self.y_mm[1]


@dataclass(frozen=True, kw_only=True)
class Backlash:
    """Mechanical backlash and the controller's compensation (UNAM-GMM §5, Yanez-07 §5).

    A reversal of an axis takes up the true backlash before the carriage moves;
    the controller adds ``compensation_um`` (as whole steps, rounded) in the new
    direction on every reversal, not counted in its logical position.

    Attributes:
        true_um: true backlash per axis ``(x, y, z)``, µm.
        compensation_um: compensation per axis ``(x, y, z)``, µm (0 = none).
        regions: where the true backlash differs from ``true_um``; the first
            region of the axis containing the carriage at the reversal applies.
    """

    true_um: tuple[float, float, float] = (0.0, 0.0, 0.0)
    compensation_um: tuple[float, float, float] = (0.0, 0.0, 0.0)
    regions: tuple[BacklashRegion, ...] = ()

    def true_at(self, axis: int, x_mm: float, y_mm: float) -> float:
        """True backlash of ``axis`` (0 = x, 1 = y, 2 = z) at ``(x_mm, y_mm)``, µm."""
        name = AXES[axis]
        for region in self.regions:
            if region.axis == name and region.contains(x_mm, y_mm):
                return region.true_um
        return self.true_um[axis]


@dataclass(frozen=True, kw_only=True)
class Machine:
    """A machine profile.

    Attributes:
        name: profile name, e.g. ``"MMH-1 (GMM)"``.
        profile: the short name a built-in profile is chosen by (``--machine
            mmh-gmm``, a target file's ``machine = "mmh-gmm"``); "" for others.
        steps_per_mm: motor steps per mm per axis ``(x, y, z)`` as the controller
            assumes them (nominal).
        work_area_mm: ``(xmin, ymin, xmax, ymax)`` reachable by the tool, mm. In
            work coordinates only its size (the travel) matters.
        coordinates: ``"work"`` or ``"machine"`` (:data:`COORDINATES`): whether a
            program's X0 Y0 is a work zero the operator sets (GRBL/LinuxCNC G54, the
            thesis controllers that store a part zero or start from where the tool
            stands) or the machine's home.
        has_z: whether programs may move Z.
        z_travel_mm: the Z travel, mm: the most a program's Z may span, from its highest
            position to its lowest (GRBL's ``$132``); 0 when not known (not checked).
        max_step_rate_hz: highest step frequency the controller sustains, Hz
            (0 = no limit known).
        source: where the numbers come from (a thesis section).
        true_steps_per_mm: steps per mm the mechanics really make (Yanez-07 R14:
            1.9 µm assumed, 1.88 µm real); ``None`` means the nominal values.
        motion: interpolators and arc handling.
        backlash: true backlash and compensation.
        timing: the ``[machine.timing]`` table as written: ``model`` (a timing model
            name) and its parameters; the verifier looks it up and checks it
            (:func:`camtool.verify.motion.timing_model_from_table`).
        steps_per_mm_settings: how the operator sets the controller's steps/mm per
            axis ``(x, y, z)``: a template with ``{}`` where the value goes (GRBL:
            ``"$100={}"``); empty when the profile's ``steps_per_mm`` is the setting
            (compiled into the firmware). Printed by ``camtool calibrate fit``.
        table: the ``[machine]`` table it was built from (empty when built in
            code), so that ``--machine`` can be laid over any profile.
    """

    name: str
    steps_per_mm: tuple[float, float, float]
    work_area_mm: BBox
    coordinates: str = "work"
    has_z: bool = True
    z_travel_mm: float = 0.0
    max_step_rate_hz: float = 0.0
    source: str = ""
    true_steps_per_mm: tuple[float, float, float] | None = None
    profile: str = ""
    motion: Motion = field(default_factory=Motion)
    backlash: Backlash = field(default_factory=Backlash)
    timing: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    steps_per_mm_settings: tuple[str, ...] = ()
    table: Mapping[str, Any] = field(
        default_factory=lambda: MappingProxyType({}), compare=False, repr=False
    )

    @property
    def real_steps_per_mm(self) -> tuple[float, float, float]:
        """Steps per mm the mechanics make: ``true_steps_per_mm`` or the nominal ones."""
        return self.true_steps_per_mm or self.steps_per_mm

    def step_rate_hz(self, feed_mm_min: float) -> float:
        """Step frequency of the fastest axis moving alone at ``feed_mm_min``, Hz.

        UNAM-GMM Eq. 3.1: f = d · F / 60 with d in steps/mm and F in mm/min.
        """
        return max(self.steps_per_mm[:2]) * feed_mm_min / 60.0

    @property
    def travel_mm(self) -> tuple[float, float]:
        """Travel ``(x, y)`` of the work area, mm."""
        x0, y0, x1, y1 = self.work_area_mm
        return (x1 - x0, y1 - y0)

    def outside_work_area(self, box: BBox, eps_mm: float = 1e-9) -> bool:
        """True when ``box`` reaches beyond the work area by more than ``eps_mm``."""
        x0, y0, x1, y1 = self.work_area_mm
        return (
            box[0] < x0 - eps_mm
            or box[1] < y0 - eps_mm
            or box[2] > x1 + eps_mm
            or box[3] > y1 + eps_mm
        )


RANGES: dict[str, tuple[float, float, str]] = {
    "steps_per_mm": (1e-3, 1e6, "steps/mm"),
    "true_steps_per_mm": (1e-3, 1e6, "steps/mm"),
    "max_step_rate_hz": (1e-3, 1e7, "Hz"),
    "work_area_mm": (0.0, 1e6, "mm"),
    "z_travel_mm": (0.0, 1e6, "mm"),
    "chord_tolerance_mm": (1e-5, 10.0, "mm"),
    "chord_segments": (1, 10_000, "chords per arc"),
    "chord_angle_deg": (1e-2, 180.0, "degrees"),
    "true_um": (0.0, 1e5, "µm"),
    "compensation_um": (0.0, 1e5, "µm"),
}
"""The physical range of each number of a ``[machine]`` table (its magnitude; 0 means
"none" where a key allows it): a hostile or mistyped value (``steps_per_mm = 1e300``,
``chord_tolerance_mm = 1e-300``, ``chord_segments = 1e15``) is refused naming the key,
the range and the unit, before it can hang a simulation or fill memory."""


def machine_from_table(table: Mapping[str, Any], *, where: str) -> Machine:
    """Build a :class:`Machine` from a TOML ``[machine]`` table.

    Raises:
        InputError: an unknown key or a value of the wrong type or shape, naming
            ``where`` and the key (``machine.backlash.true_um``).
    """
    r = _Reader(table, "machine", where)
    x0, y0, x1, y1 = r.floats("work_area_mm", 4, required=True)
    if not (x0 < x1 and y0 < y1):
        raise r._fail(
            "work_area_mm",
            "[xmin, ymin, xmax, ymax] with xmin < xmax and ymin < ymax",
            [x0, y0, x1, y1],
        )
    true_steps = r.triple("true_steps_per_mm", positive=True)
    machine = Machine(
        name=r.text("name", required=True),
        steps_per_mm=r.triple("steps_per_mm", required=True, positive=True),
        work_area_mm=(x0, y0, x1, y1),
        coordinates=r.choice("coordinates", COORDINATES, "work"),
        has_z=r.flag("has_z", True),
        z_travel_mm=r.number("z_travel_mm", 0.0, nonnegative=True),
        max_step_rate_hz=r.number("max_step_rate_hz", 0.0, nonnegative=True),
        source=r.text("source"),
        true_steps_per_mm=true_steps if "true_steps_per_mm" in table else None,
        profile=r.text("profile"),
        motion=_motion(r.table("motion")),
        backlash=_backlash(r.table("backlash")),
        timing=r.raw_table("timing"),
        steps_per_mm_settings=r.templates("steps_per_mm_settings", 3),
        table=MappingProxyType(dict(table)),
    )
    r.done()
    return machine


def _motion(r: _Reader) -> Motion:
    d = Motion()
    motion = Motion(
        line=r.name("line", d.line),
        arc=r.name("arc", d.arc),
        chords=r.name("chords", d.chords),
        chord_tolerance_mm=r.number("chord_tolerance_mm", d.chord_tolerance_mm, positive=True),
        chord_segments=r.whole("chord_segments", d.chord_segments),
        chord_angle_deg=r.number("chord_angle_deg", d.chord_angle_deg, positive=True),
        rounding=r.choice("rounding", dict.fromkeys(ROUNDINGS, ""), d.rounding),
    )
    r.done()
    return motion


def _backlash(r: _Reader) -> Backlash:
    regions = []
    for sub in r.tables("regions"):
        regions.append(
            BacklashRegion(
                axis=sub.choice("axis", {"x": "", "y": ""}, None),
                x_mm=sub.pair("x_mm"),
                y_mm=sub.pair("y_mm"),
                true_um=sub.number("true_um", None, nonnegative=True),
            )
        )
        sub.done()
    backlash = Backlash(
        true_um=r.triple("true_um", nonnegative=True),
        compensation_um=r.triple("compensation_um", nonnegative=True),
        regions=tuple(regions),
    )
    r.done()
    return backlash


class _Reader:
    """Strict reader of one TOML table: every key read once, unknown keys an error."""

    def __init__(self, table: Mapping[str, Any], path: str, where: str) -> None:
        if not isinstance(table, Mapping):
            raise InputError(f"{where}: {path} must be a table, got {as_toml(table)}")
        self.data, self.path, self.where = table, path, where
        self.seen: set[str] = set()

    def _fail(self, key: str, want: str, value: Any) -> InputError:
        return InputError(f"{self.where}: {self.path}.{key} must be {want}, got {as_toml(value)}")

    def _get(self, key: str, required: bool) -> Any:
        self.seen.add(key)
        if key not in self.data:
            if required:
                raise InputError(f"{self.where}: {self.path}.{key} is missing")
            return None
        return self.data[key]

    def text(self, key: str, *, required: bool = False) -> str:
        value = self._get(key, required)
        if value is None:
            return ""
        if not isinstance(value, str):
            raise self._fail(key, "a string", value)
        return value

    def templates(self, key: str, count: int) -> tuple[str, ...]:
        """``count`` short printable-ASCII templates, each with one ``{}``, or ``()``."""
        value = self._get(key, False)
        if value is None:
            return ()
        want = f'a list of {count} strings, each with one {{}} for the value ("$100={{}}")'
        if not isinstance(value, list) or len(value) != count:
            raise self._fail(key, want, value)
        for item in value:
            if (
                not isinstance(item, str)
                or len(item) > 80
                or not (item.isascii() and item.isprintable())
                or item.count("{}") != 1
                or item.replace("{}", "").count("{") + item.replace("{}", "").count("}")
            ):
                raise self._fail(key, want, value)
        return tuple(value)

    def name(self, key: str, default: str) -> str:
        """A non-empty name (checked where it is used, e.g. an interpolator's)."""
        value = self._get(key, False)
        if value is None:
            return default
        if not isinstance(value, str) or not value:
            raise self._fail(key, "a name (a non-empty string)", value)
        return value

    def choice(self, key: str, choices: Mapping[str, object], default: str | None) -> str:
        value = self._get(key, default is None)
        if value is None:
            return str(default)
        if not isinstance(value, str) or value not in choices:  # a list is not hashable
            raise self._fail(key, f"one of {sorted(choices)}", value)
        return str(value)

    def flag(self, key: str, default: bool) -> bool:
        value = self._get(key, False)
        if value is None:
            return default
        if not isinstance(value, bool):
            raise self._fail(key, "true or false", value)
        return value

    def number(
        self,
        key: str,
        default: float | None,
        *,
        positive: bool = False,
        nonnegative: bool = False,
    ) -> float:
        value = self._get(key, default is None)
        if value is None:
            return float(default)  # type: ignore[arg-type]
        return self._check(key, value, positive, nonnegative)

    def whole(self, key: str, default: int) -> int:
        """A whole number in :data:`RANGES` (``chord_segments``)."""
        value = self._get(key, False)
        if value is None:
            return default
        number = self._check(key, value, True, False)
        if number != int(number):
            raise self._fail(key, "a whole number", value)
        return int(number)

    def _check(self, key: str, value: Any, positive: bool, nonnegative: bool) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self._fail(key, "a number", value)
        number = float(value)
        if not math.isfinite(number) or (positive and number <= 0) or (nonnegative and number < 0):
            want = "a positive number" if positive else "a number >= 0" if nonnegative else "finite"
            raise self._fail(key, want, value)
        span = RANGES.get(key)
        if span is not None and number != 0 and not span[0] <= abs(number) <= span[1]:
            low, high, unit = span
            if positive or nonnegative:
                want = f"between {low:g} and {high:g} {unit}"
            elif low == 0:  # a signed number (work_area_mm): its size is bounded
                want = f"from -{high:g} to {high:g} {unit}"
            else:
                want = f"of magnitude {low:g} to {high:g} {unit}"
            raise self._fail(key, f"{want} (a physical machine)", value)
        return number

    def floats(
        self,
        key: str,
        count: int,
        *,
        required: bool = False,
        positive: bool = False,
        nonnegative: bool = False,
    ) -> tuple[float, ...]:
        value = self._get(key, required)
        if value is None:
            return (0.0,) * count
        if not isinstance(value, list) or len(value) != count:
            raise self._fail(key, f"a list of {count} numbers", value)
        return tuple(self._check(key, v, positive, nonnegative) for v in value)

    def pair(self, key: str) -> tuple[float, float]:
        lo, hi = self.floats(key, 2, required=True)
        if lo > hi:
            raise self._fail(key, "[lo, hi] with lo <= hi", [lo, hi])
        return (lo, hi)

    def triple(
        self,
        key: str,
        *,
        required: bool = False,
        positive: bool = False,
        nonnegative: bool = False,
    ) -> tuple[float, float, float]:
        x, y, z = self.floats(key, 3, required=required, positive=positive, nonnegative=nonnegative)
        return (x, y, z)

    def table(self, key: str) -> _Reader:
        value = self._get(key, False)
        return _Reader({} if value is None else value, f"{self.path}.{key}", self.where)

    def raw_table(self, key: str) -> Mapping[str, Any]:
        value = self._get(key, False)
        if value is None:
            return MappingProxyType({})
        if not isinstance(value, Mapping):
            raise self._fail(key, "a table", value)
        return MappingProxyType(dict(value))

    def tables(self, key: str) -> list[_Reader]:
        value = self._get(key, False)
        if value is None:
            return []
        if not isinstance(value, list):
            raise self._fail(key, "an array of tables ([[...]])", value)
        return [_Reader(v, f"{self.path}.{key}[{i}]", self.where) for i, v in enumerate(value)]

    def done(self, hint: str = "") -> None:
        unknown = sorted(set(self.data) - self.seen)
        if unknown:
            known = hint or f"known: {sorted(self.seen)}"
            raise InputError(f"{self.where}: unknown key(s) {unknown} in [{self.path}]; {known}")


def merge_tables(base: Mapping[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    """``override`` laid over ``base``, sub-tables merged key by key.

    How ``--machine FILE`` changes a target's profile: a file that only says
    ``[machine.backlash] true_um = [...]`` keeps every other value of the target.
    Arrays (including arrays of tables) are replaced, not merged.
    """
    merged = dict(base)
    for key, value in override.items():
        if isinstance(value, Mapping) and isinstance(merged.get(key), Mapping):
            merged[key] = merge_tables(merged[key], value)
        else:
            merged[key] = value
    return merged


def load_toml(path: Path, what: str = "TOML file") -> dict[str, Any]:
    """Read a machine or target TOML file (:func:`camtool.model.tomlfile.read_toml_file`).

    Raises:
        InputError: the file is missing, not a regular file, over
            :data:`~camtool.model.tomlfile.SMALL_TOML_BYTES`, not UTF-8 or not valid TOML.
    """
    return read_toml_file(path, what=what, limit_bytes=SMALL_TOML_BYTES)
