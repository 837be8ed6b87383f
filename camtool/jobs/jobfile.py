"""The job file: a :class:`~camtool.jobs.job.Job` read from TOML (docs/jobs.md), every key checked.

The file format is TOML (docs/jobs.md)::

Design notes: docs/internals.md, ``camtool/jobs/jobfile.py``.
"""

from __future__ import annotations

import dataclasses
import difflib
import math
import re
from collections.abc import Collection, Mapping
from pathlib import Path
from typing import Any

from camtool.jobs.job import (
    MAX_DRAWN_DIAMETER_MM,
    MAX_DWELL_S,
    MAX_JOB_BYTES,
    MAX_RPM,
    MAX_TOOL_NUMBER,
    MAX_TOOLS,
    OPERATION_TYPES,
    PECKS,
    SEQUENCES,
    SETUP_FIELDS,
    SIDES,
    TOOL_TYPES,
    Job,
    Operation,
    Selection,
    Setup,
    Tool,
)
from camtool.model.errors import InputError, UsageError
from camtool.model.tomlfile import as_toml
from camtool.toolpath.options import (
    MAX_TOOL_DIAMETER_MM,
    MIN_TOOL_DIAMETER_MM,
    PLACEMENTS,
    PlanOptions,
    flag,
)

_JOB_KEYS: dict[str, str] = {
    "origin": "placement",
    "translate": "translate",
    "scale": "scale",
    "fit": "fit",
    "clearance_z": "clearance_z",
    "end_position": "end_position",
    "chain_tolerance": "chain_tolerance",
    "close_gap": "close_gap",
    "tolerance": "tolerance",
    "fit_arcs": "fit_arcs",
    "order": "order",
    "safe_z": "safe_z",
    "sequence": "",
}
"""Keys of the ``[job]`` table → :class:`PlanOptions` fields (``sequence`` is the job's)."""

_TOOL_KEYS = ("id", "type", "diameter", "name", "rpm", "feed", "plunge_feed")

_OP_PLAN_KEYS: dict[str, str] = {
    "depth": "depth",
    "step_down": "step_down",
    "safe_z": "safe_z",
    "feed": "feed_mm_min",
    "plunge_feed": "plunge_feed_mm_min",
    "ramp": "ramp_deg",
    "tabs": "tabs",
    "tab_width": "tab_width",
    "tab_height": "tab_height",
    "lead_in": "lead_in",
    "direction": "direction",
    "stepover": "stepover",
    "pocket": "pocket",
    "pocket_angle": "pocket_angle_deg",
    "order": "order",
    "reverse_open": "reverse_open",
    "fit_arcs": "fit_arcs",
}
"""An operation's planning keys → :class:`PlanOptions` fields (the names of ``post``'s
options without ``--``, ``-`` as ``_``)."""

_OP_KEYS = (
    "name",
    "type",
    "tool",
    "layers",
    "colours",
    "closed",
    "diameter",
    "except_diameter",
    "linetypes",
    "points",
    "side",
    "peck",
    "dwell",
    "hole_tolerance",
    *_OP_PLAN_KEYS,
)

_FLAG = re.compile(r"--([a-z][a-z-]*)")


def load_job(path: str | Path, *, overrides: Mapping[str, object] | None = None) -> Job:
    """Read a job file (TOML, docs/jobs.md) into a checked :class:`Job`.

    Args:
        path: the job file.
        overrides: shared planning options given on the command line, by
            :class:`PlanOptions` field (``placement``, ``translate``, ``scale``...); they
            replace the file's ``[job]`` values.

    Raises:
        InputError: the file cannot be read, is not TOML, has an unknown key (with a
            did-you-mean), a value of the wrong type or out of range, an operation whose
            tool is not in the table, or no operation; the message names the file, the
            table and the key.
    """
    from camtool.jobs.inputs import read_small_toml

    name = str(path)
    data = read_small_toml(path, what="job file", limit_bytes=MAX_JOB_BYTES)
    return job_from_dict(data, source=name, overrides=overrides)


def job_from_dict(
    data: Mapping[str, Any], *, source: str, overrides: Mapping[str, object] | None = None
) -> Job:
    """A :class:`Job` from a job file's parsed TOML (see :func:`load_job`).

    Raises:
        InputError: as :func:`load_job`.
    """
    _known(data, ("job", "tools", "operations"), source, "the file")
    setup = _setup(_table(data.get("job", {}), source, "[job]"), source, overrides or {})
    tools = _tools(data.get("tools"), source)
    operations = _operations(data.get("operations"), tools, setup, source)
    return Job(tools=tools, operations=operations, setup=setup, source=Path(source).name)


def _setup(table: Mapping[str, Any], source: str, overrides: Mapping[str, object]) -> Setup:
    _known(table, tuple(_JOB_KEYS), source, "[job]")
    values: dict[str, object] = {}
    for key, value in table.items():
        if key != "sequence":
            values[_JOB_KEYS[key]] = _value(value, _JOB_KEYS[key], source, f"[job] {key}")
    if overrides.keys() & {"scale", "fit"}:  # one choice, the drawing's size: theirs
        values.pop("scale", None)
        values.pop("fit", None)
    values.update(overrides)
    sequence = table.get("sequence", "file")
    if sequence not in SEQUENCES:
        raise InputError(
            f"{source}: [job] sequence = {as_toml(sequence)}; choose one of {', '.join(SEQUENCES)}"
        )
    plan = _plan(values, source, "[job]")
    return Setup(plan=plan, sequence=sequence)


def _tools(rows: Any, source: str) -> tuple[Tool, ...]:
    if rows is None:
        raise InputError(
            f"{source}: no [[tools]]: a job needs a tool table (id, type, diameter of each tool)"
        )
    rows = _array(rows, source, "[[tools]]")
    if len(rows) > MAX_TOOLS:
        raise InputError(
            f"{source}: {len(rows)} [[tools]], more than the {MAX_TOOLS} a job may hold; "
            "list the tools its operations use (one part, one job)"
        )
    tools: dict[int, Tool] = {}
    for n, row in enumerate(rows, start=1):
        where = f"[[tools]] {n}"
        row = _table(row, source, where)
        _known(row, _TOOL_KEYS, source, where)
        number = _int(row.get("id"), source, f"{where} id", 0, MAX_TOOL_NUMBER, required=True)
        where = f"tool {number}"
        if number in tools:
            raise InputError(f"{source}: two tools with id {number}; give each tool its own id")
        kind = _choice(row.get("type", "end-mill"), TOOL_TYPES, source, f"{where} type")
        diameter = _number(row.get("diameter"), source, f"{where} diameter", required=True)
        if not MIN_TOOL_DIAMETER_MM <= diameter <= MAX_TOOL_DIAMETER_MM:
            raise InputError(
                f"{source}: {where} diameter = {diameter:g} mm; give the tool's cutting "
                f"diameter in mm ({MIN_TOOL_DIAMETER_MM:g}…{MAX_TOOL_DIAMETER_MM:g})"
            )
        tools[number] = Tool(
            id=number,
            type=kind,
            diameter=diameter,
            name=_text(row.get("name", ""), source, f"{where} name"),
            rpm=_positive(row.get("rpm"), source, f"{where} rpm", "rev/min"),
            feed_mm_min=_positive(row.get("feed"), source, f"{where} feed", "mm/min"),
            plunge_feed_mm_min=_positive(
                row.get("plunge_feed"), source, f"{where} plunge_feed", "mm/min"
            ),
        )
    if not tools:
        raise InputError(f"{source}: [[tools]] is empty; a job needs at least one tool")
    return tuple(tools.values())


def _operations(
    rows: Any, tools: tuple[Tool, ...], setup: Setup, source: str
) -> tuple[Operation, ...]:
    if rows is None:
        raise InputError(f"{source}: no [[operations]]: a job needs at least one operation")
    rows = _array(rows, source, "[[operations]]")
    by_id = {t.id: t for t in tools}
    out = [
        _operation(_table(row, source, f"operation {n}"), n, by_id, setup, source)
        for n, row in enumerate(rows, start=1)
    ]
    if not out:
        raise InputError(f"{source}: [[operations]] is empty; a job needs at least one operation")
    return tuple(out)


def _operation(
    row: Mapping[str, Any], n: int, tools: Mapping[int, Tool], setup: Setup, source: str
) -> Operation:
    name = _text(row.get("name", ""), source, f"operation {n} name")
    where = f"operation {n}" + (f" ({name!r})" if name else "")
    _known(row, _OP_KEYS, source, where)
    kind = _choice(row.get("type"), OPERATION_TYPES, source, f"{where} type", required=True)
    number = _int(row.get("tool"), source, f"{where} tool", 0, MAX_TOOL_NUMBER, required=True)
    tool = tools.get(number)
    if tool is None:
        known = ", ".join(str(t) for t in sorted(tools))
        raise InputError(
            f"{source}: {where} uses tool {number}, which [[tools]] does not define "
            f"(its tools: {known})"
        )
    side = ""
    if kind == "profile":
        side = _choice(row.get("side", "outside"), SIDES, source, f"{where} side")
    elif "side" in row:
        raise InputError(f"{source}: {where}: side is for profile operations, not {kind}")
    tab_keys = [k for k in ("tabs", "tab_width", "tab_height") if k in row]
    if tab_keys and kind != "drill" and side != "outside":
        article = "an" if kind == "engrave" else "a"
        what = f"a profile with side = {as_toml(side)}" if side else f"{article} {kind} operation"
        raise InputError(
            f"{source}: {where}: {', '.join(tab_keys)}: tabs hold a part on an outside "
            f"profile only, and this is {what}; remove "
            f"{'it' if len(tab_keys) == 1 else 'them'} here"
        )
    plan = _operation_plan(row, kind, side, tool, setup, source, where)
    select = _selection(row, kind, source, where)
    drill_keys = [k for k in ("peck", "dwell", "hole_tolerance") if k in row]
    if kind != "drill" and drill_keys:
        raise InputError(
            f"{source}: {where}: {', '.join(drill_keys)}: only a drill operation takes "
            f"{'this key; remove it' if len(drill_keys) == 1 else 'these keys; remove them'} here"
        )
    if kind == "drill" and tool.type not in ("drill", "end-mill"):
        raise InputError(
            f"{source}: {where} drills with tool {number}, a {tool.type}; drill with a drill "
            "(or an end mill)"
        )
    return Operation(
        type=kind,
        tool=number,
        select=select,
        plan=plan,
        name=name,
        side=side,
        peck=_choice(row.get("peck", "retract"), PECKS, source, f"{where} peck"),
        dwell_s=_number(row.get("dwell", 0.0), source, f"{where} dwell", low=0.0, high=MAX_DWELL_S),
        hole_tolerance=_number(
            row.get("hole_tolerance", 0.05), source, f"{where} hole_tolerance", low=0.0, high=100.0
        ),
    )


def _operation_plan(
    row: Mapping[str, Any],
    kind: str,
    side: str,
    tool: Tool,
    setup: Setup,
    source: str,
    where: str,
) -> PlanOptions:
    values: dict[str, object] = {f: getattr(setup.plan, f) for f in (*SETUP_FIELDS, "safe_z")}
    values["tool_diameter"] = tool.diameter
    values["offset"] = {"pocket": "pocket", "profile": side}.get(kind, "on")
    if tool.feed_mm_min is not None:
        values["feed_mm_min"] = tool.feed_mm_min
    if tool.plunge_feed_mm_min is not None:
        values["plunge_feed_mm_min"] = tool.plunge_feed_mm_min
    for key, fieldname in _OP_PLAN_KEYS.items():
        if key in row:
            values[fieldname] = _value(row[key], fieldname, source, f"{where} {key}")
    if kind in ("drill", "engrave") and values["offset"] == "on":
        values["tool_diameter"] = 0.0  # on the line: no compensation, no "no effect" note
    if kind == "drill":
        for key in (
            *("tabs", "tab_width", "tab_height", "ramp", "lead_in", "stepover"),
            *("pocket", "pocket_angle", "direction"),
        ):
            if key in row:
                raise InputError(f"{source}: {where}: {key} does not apply to drilling")
        if values.get("depth") is None:
            raise InputError(f"{source}: {where}: a drill operation needs a depth (mm)")
    if kind in ("engrave", "profile"):
        for key in ("stepover", "pocket", "pocket_angle"):
            if key in row:  # read for nothing: a slip, or an operation meant as a pocket
                raise InputError(
                    f"{source}: {where}: {key} applies to a pocket operation, not to this "
                    f"{kind} operation; remove it here"
                )
    return _plan(values, source, where)


def _selection(row: Mapping[str, Any], kind: str, source: str, where: str) -> Selection:
    layers = row.get("layers")
    if isinstance(layers, str):
        layers = [layers]
    colours = row.get("colours")
    if isinstance(colours, str | int):
        colours = [colours]
    linetypes = row.get("linetypes")
    if isinstance(linetypes, str):
        linetypes = [linetypes]
    closed = row.get("closed")
    if closed is not None and not isinstance(closed, bool):
        raise InputError(f"{source}: {where} closed = {as_toml(closed)}; give true or false")
    # a drill drills the points unless it selects by a contour's shape (only the circles of
    # a diameter, say: `camtool job init` gives one drill per hole size), which no point has
    shaped = any(row.get(key) is not None for key in ("diameter", "closed", "linetypes"))
    points = row.get("points", kind == "drill" and not shaped)
    alone = points == "only"  # the points, no contour: where they share a layer with outlines
    if not (isinstance(points, bool) or alone):
        raise InputError(
            f'{source}: {where} points = {as_toml(points)}; give true, false or "only" (the points '
            "alone, no contour)"
        )
    given = [key for key in ("diameter", "except_diameter", "closed", "linetypes") if key in row]
    if alone and given:
        raise InputError(
            f'{source}: {where} points = "only" selects no contour, so {given[0]} has nothing '
            f"to choose from; leave it out, or give points = true"
        )
    return Selection(
        layers=None if layers is None else _names(layers, source, f"{where} layers"),
        colours=None if colours is None else tuple(_colour(c, source, where) for c in colours),
        closed=closed,
        diameter=_diameters(row.get("diameter"), source, where),
        except_diameter=_diameters(
            row.get("except_diameter"), source, where, key="except_diameter"
        ),
        linetypes=None
        if linetypes is None
        else tuple(n.upper() for n in _names(linetypes, source, f"{where} linetypes")),
        points=alone or points,
        contours=not alone,
    )


def _diameters(
    value: Any, source: str, where: str, *, key: str = "diameter"
) -> tuple[float, float] | None:
    if value is None:
        return None
    if isinstance(value, list):
        if len(value) != 2:
            raise InputError(
                f"{source}: {where} {key} = {as_toml(value)}; give one diameter or [min, max] in mm"
            )
        lo = _number(value[0], source, f"{where} {key}", low=0.0, high=MAX_DRAWN_DIAMETER_MM)
        hi = _number(value[1], source, f"{where} {key}", low=0.0, high=MAX_DRAWN_DIAMETER_MM)
        if lo > hi:
            raise InputError(f"{source}: {where} {key} = [{lo:g}, {hi:g}]: min above max")
        return (lo, hi)
    d = _number(value, source, f"{where} {key}", low=0.0, high=MAX_DRAWN_DIAMETER_MM)
    return (d, d)


def _colour(value: Any, source: str, where: str) -> str:
    """A colour as ``#rrggbb``: an ACI number (DXF), a CSS name or ``#rrggbb``."""
    if isinstance(value, bool):
        raise InputError(f"{source}: {where} colours: {as_toml(value)} is not a colour")
    if isinstance(value, int):
        if not 1 <= value <= 255:
            raise InputError(
                f"{source}: {where} colours: {value} is not a DXF colour number (1–255)"
            )
        from ezdxf.colors import aci2rgb

        r, g, b = aci2rgb(value)
        return f"#{r:02x}{g:02x}{b:02x}"
    if isinstance(value, str):
        rgb = _css_colour(value.strip())
        if rgb is not None:
            return rgb
    raise InputError(
        f"{source}: {where} colours: {as_toml(value)} is not a colour; give a DXF colour number "
        "(1 red, 2 yellow, 3 green, 4 cyan, 5 blue, 6 magenta, 7 white), a name or #rrggbb"
    )


_HEX = re.compile(r"#(?:[0-9a-fA-F]{3}|[0-9a-fA-F]{6})")
_RGB = re.compile(r"rgb\(\s*[0-9.]+%?\s*,\s*[0-9.]+%?\s*,\s*[0-9.]+%?\s*\)", re.IGNORECASE)


def _css_colour(text: str) -> str | None:
    """``text`` as ``#rrggbb``: ``#rgb``, ``#rrggbb``, ``rgb(…)`` or a CSS keyword; else None.

    svgelements' own parser reads any other word (a typo, ``""``) as black and a string of
    digits as a number, so it is asked only about what has a colour's form, and a keyword
    only counts when it is one (the one keyword whose colour is black is ``black``).
    """
    import svgelements as se

    name = text.replace(" ", "").lower()
    if not (_HEX.fullmatch(text) or _RGB.fullmatch(text) or name.isalpha()):
        return None
    c = se.Color(text)
    black = se.Color.rgb_to_int(0, 0, 0)
    if (
        c.value is None
        or c.alpha != 255
        or (name.isalpha() and c.value == black and name != "black")
    ):
        return None
    return f"#{c.red:02x}{c.green:02x}{c.blue:02x}"


# ------------------------------------------------------------------------ values


def _plan(values: Mapping[str, object], source: str, where: str) -> PlanOptions:
    try:
        return PlanOptions(**values)  # type: ignore[arg-type]
    except UsageError as exc:
        raise InputError(f"{source}: {where}: {as_keys(str(exc))}") from None


_OFFSET = re.compile(
    r"--offset ((?:outside|inside|on|pocket)(?:(?:, | or )(?:outside|inside|on|pocket))*)"
)
"""``post``'s ``--offset`` with its values: a profile's ``side`` or a pocket operation in a job."""


def as_keys(message: str) -> str:
    """``message`` with ``post``'s flags named as job file keys (``step_down``).

    ``--offset outside or inside`` becomes ``side = "outside" or "inside"`` (a job's
    profile has a side; ``--offset pocket`` is a pocket operation).
    """
    return _FLAG.sub(lambda m: _key_of(m.group(1)), _OFFSET.sub(_sides, message))


def _sides(match: re.Match[str]) -> str:
    """``--offset`` and its values as a job says them (:func:`as_keys`)."""
    words = re.split(r", | or ", match.group(1))
    sides = [f'"{w}"' for w in words if w != "pocket"]
    out = f"side = {' or '.join(sides)}" if sides else ""
    if "pocket" in words:
        out += (", or " if out else "") + "a pocket operation"
    return out


def _key_of(flag_name: str) -> str:
    """The job file's key for ``post``'s option ``--flag-name``."""
    if flag_name == "origin":
        return "origin"
    return flag_name.replace("-", "_")


def _value(value: Any, fieldname: str, source: str, where: str) -> object:
    """A TOML value for the :class:`PlanOptions` field ``fieldname``, its type checked."""
    default = PlanOptions.__dataclass_fields__[fieldname].default
    if fieldname in ("translate", "end_position", "fit"):
        if not (isinstance(value, list) and len(value) == 2):
            raise InputError(
                f"{source}: {where} = {as_toml(value)}; give two numbers, [x, y] in mm"
            )
        return (_number(value[0], source, where), _number(value[1], source, where))
    if fieldname in ("fit_arcs", "reverse_open"):
        if not isinstance(value, bool):
            raise InputError(f"{source}: {where} = {as_toml(value)}; give true or false")
        return value
    if fieldname == "tabs":
        return _int(value, source, where, 0, 1000)
    if isinstance(default, str) or fieldname in ("direction",):
        choices = _CHOICES.get(fieldname)
        if choices is not None:
            return _choice(value, choices, source, where)
        return _text(value, source, where)
    return _number(value, source, where)


def _choices() -> dict[str, tuple[str, ...]]:
    from camtool.toolpath.options import DIRECTIONS, ORDERS, POCKET_STYLES

    return {
        "placement": PLACEMENTS,
        "direction": DIRECTIONS,
        "pocket": POCKET_STYLES,
        "order": ORDERS,
    }


_CHOICES = _choices()


def _number(
    value: Any,
    source: str,
    where: str,
    *,
    low: float = -math.inf,
    high: float = math.inf,
    required: bool = False,
) -> float:
    if value is None and required:
        raise InputError(f"{source}: {where} is missing; give a number")
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InputError(f"{source}: {where} = {as_toml(value)}; give a number")
    number = float(value)
    if not math.isfinite(number):
        raise InputError(f"{source}: {where} = {as_toml(value)}; give a finite number")
    if not low <= number <= high:
        raise InputError(f"{source}: {where} = {number:g} is outside {low:g}…{high:g}")
    return number


POSITIVE_MAX = MAX_RPM
"""The largest feed or speed a job file may give (in its unit): 10⁶ mm/min or rev/min, far
beyond any machine; a larger one is a typo."""


def _positive(value: Any, source: str, where: str, unit: str) -> float | None:
    if value is None:
        return None
    number = _number(value, source, where)
    if not 0 < number <= POSITIVE_MAX:
        raise InputError(
            f"{source}: {where} = {number:g} {unit}; give a value > 0 and at most {POSITIVE_MAX:g}"
        )
    return number


def _int(
    value: Any, source: str, where: str, low: int, high: int, *, required: bool = False
) -> int:
    if value is None and required:
        raise InputError(f"{source}: {where} is missing; give a whole number")
    if isinstance(value, bool) or not isinstance(value, int):
        raise InputError(f"{source}: {where} = {as_toml(value)}; give a whole number")
    if not low <= value <= high:
        raise InputError(f"{source}: {where} = {value} is outside {low}…{high}")
    return value


def _text(value: Any, source: str, where: str) -> str:
    if not isinstance(value, str):
        raise InputError(f"{source}: {where} = {as_toml(value)}; give a text in quotes")
    if len(value) > 200 or any(not c.isprintable() for c in value):
        raise InputError(f"{source}: {where}: give a short text on one line")
    return value


def _names(values: Any, source: str, where: str) -> tuple[str, ...]:
    if not isinstance(values, list) or not values:
        raise InputError(f"{source}: {where} = {as_toml(values)}; give a list of names")
    return tuple(_text(v, source, where) for v in values)


def _choice(
    value: Any, choices: tuple[str, ...], source: str, where: str, *, required: bool = False
) -> str:
    if value is None and required:
        raise InputError(f"{source}: {where} is missing; choose one of {', '.join(choices)}")
    if value not in choices:
        hint = difflib.get_close_matches(str(value), choices, n=1)
        mean = f" (did you mean {as_toml(hint[0])}?)" if hint else ""
        raise InputError(
            f"{source}: {where} = {as_toml(value)}{mean}; choose one of {', '.join(choices)}"
        )
    return str(value)


def _table(value: Any, source: str, where: str) -> Mapping[str, Any]:
    if not isinstance(value, dict):
        raise InputError(f"{source}: {where} is not a table of keys")
    return value


def _array(value: Any, source: str, where: str) -> list[Any]:
    if not isinstance(value, list):
        raise InputError(f"{source}: {where} must be an array of tables ({where} repeated)")
    return value


def _known(table: Mapping[str, Any], keys: tuple[str, ...], source: str, where: str) -> None:
    """Refuse a key of ``table`` that is not in ``keys``, suggesting the nearest."""
    for key in table:
        if key not in keys:
            hint = difflib.get_close_matches(str(key), keys, n=1, cutoff=0.6)
            mean = f"; did you mean {hint[0]!r}?" if hint else ""
            raise InputError(
                f"{source}: {where}: unknown key {key!r}{mean} (known keys: {', '.join(keys)})"
            )


def shared_overrides(plan: PlanOptions, given: Collection[str] = ()) -> dict[str, object]:
    """The shared (``[job]``) options of ``plan`` given on the command line.

    For ``post --job`` with ``--origin``, ``--translate``, ``--scale``... on the command
    line: they replace the job file's values. ``given``: the fields the command line
    named (its default value too: ``--origin drawing`` replaces a file's ``lower-left``);
    a field that differs from its default counts as given as well.
    """
    fields = PlanOptions.__dataclass_fields__
    return {
        name: getattr(plan, name)
        for name in SETUP_FIELDS
        if name in given or getattr(plan, name) != fields[name].default
    }


def operation_flags(given: Collection[str]) -> list[str]:
    """The per-operation options among ``given`` (their flags), as :func:`shared_overrides`.

    With ``--job`` these belong in the job file's operations: ``post`` refuses them.
    """
    shared = {*SETUP_FIELDS, "origin"}
    return [
        flag(f.name)
        for f in dataclasses.fields(PlanOptions)
        if f.name not in shared and f.name in given
    ]
