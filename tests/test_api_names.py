"""The API's keyword names follow one rule, old names are deprecated aliases, values are checked.

The rule (docs/api.md#naming): a keyword is its command-line option's name with ``_`` for
``-``; lengths are mm and carry no suffix, any other unit is a suffix (``feed_mm_min``,
``pocket_angle_deg``). The job file's keys are the option names themselves.
"""

from __future__ import annotations

import dataclasses
import math
import re
import warnings
from pathlib import Path
from typing import Any

import pytest

import camtool
from camtool.importers.options import ImportOptions
from camtool.jobs.job import Operation, Selection, Tool
from camtool.jobs.jobfile import _JOB_KEYS, _OP_PLAN_KEYS
from camtool.model.errors import UsageError
from camtool.toolpath.options import RENAMED, PlanOptions, flag

SAMPLES = Path(__file__).parents[1] / "samples"
UNIT_SUFFIXES = ("_mm_min", "_deg")
NOT_FLAGS = {
    "origin": "the start position: API only",
    "placement": "--origin (origin is the start position, a point)",
    "fit_arcs": "--no-fit-arcs (a negated flag)",
}


def test_every_plan_option_is_its_flag_with_a_unit_suffix_only_when_not_mm() -> None:
    for f in dataclasses.fields(PlanOptions):
        if f.name in NOT_FLAGS:
            continue
        stem = f.name
        for suffix in UNIT_SUFFIXES:
            stem = stem.removesuffix(suffix)
        assert flag(f.name) == "--" + stem.replace("_", "-"), f.name


def test_the_job_file_keys_are_the_option_names() -> None:
    for key, name in {**_JOB_KEYS, **_OP_PLAN_KEYS}.items():
        if name and name != "fit_arcs":
            assert flag(name) == "--" + key.replace("_", "-"), key


def _code(plan: PlanOptions) -> str:
    drawing = camtool.read_drawing(SAMPLES / "logo.dxf")
    return camtool.post_drawing(drawing, camtool.load_target("grbl"), plan).result.code


BASE: dict[str, Any] = {"offset": "outside", "tool_diameter": 0.5, "depth": 1.0}


@pytest.mark.parametrize(
    ("old", "new", "value"),
    [
        ("lead_in_mm", "lead_in", 0.5),
        ("fit_mm", "fit", (20.0, 20.0)),
        ("ramp_angle_deg", "ramp_deg", 10.0),
    ],
)
def test_an_old_plan_name_plans_as_the_new_one_and_warns(old: str, new: str, value: Any) -> None:
    assert RENAMED[old] == new
    with pytest.warns(
        DeprecationWarning, match=f"PlanOptions.{old} is deprecated: it is called {new}"
    ):
        before = PlanOptions(**BASE, **{old: value})
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        after = PlanOptions(**BASE, **{new: value})
    assert before == after and getattr(after, new) == value
    assert _code(before) == _code(after)
    assert _code(after) != _code(PlanOptions(**BASE))  # the option did something
    with pytest.warns(DeprecationWarning):
        assert getattr(after, old) == value  # read under its old name too


@pytest.mark.parametrize(
    ("cls", "given", "old", "new", "value"),
    [
        (ImportOptions, {}, "fit_mm", "fit", (10.0, 10.0)),
        (Selection, {}, "diameter_mm", "diameter", (3.0, 3.0)),
        (Selection, {}, "except_diameter_mm", "except_diameter", (3.0, 3.0)),
        (Operation, {"type": "drill", "tool": 1}, "hole_tolerance_mm", "hole_tolerance", 0.1),
    ],
)
def test_old_names_of_the_other_options_are_aliases(
    cls: Any, given: dict[str, Any], old: str, new: str, value: Any
) -> None:
    with pytest.warns(DeprecationWarning, match=f"{cls.__name__}.{old} is deprecated"):
        before = cls(**given, **{old: value})
    assert before == cls(**given, **{new: value})


def test_a_job_with_an_old_selection_name_cuts_the_same() -> None:
    drawing = camtool.read_drawing(SAMPLES / "part.dxf")
    target = camtool.load_target("linuxcnc")
    tools = (Tool(id=1, type="drill", diameter=3.2),)
    codes = []
    for name in ("diameter_mm", "diameter"):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)
            select = Selection(**{name: (3.1, 3.3)})
        plan = PlanOptions(depth=2.0)
        op = Operation(type="drill", tool=1, select=select, plan=plan)
        job = camtool.Job(tools=tools, operations=(op,))
        codes.append(camtool.run_job(drawing, target, job).result.code)
    assert codes[0] == codes[1]
    assert codes[0].count("G1 Z-2.000") == 4  # the four 3.2 mm holes of samples/part.dxf


def test_both_names_at_once_is_refused() -> None:
    with pytest.raises(UsageError, match="give lead_in, not both lead_in and lead_in_mm"):
        PlanOptions(**BASE, lead_in=1.0, lead_in_mm=1.0)


@pytest.mark.parametrize(
    ("cls", "kwargs", "message"),
    [
        (
            PlanOptions,
            {"lead": 1.0},
            "PlanOptions: unknown option(s) 'lead' (did you mean 'lead_in'?); "
            "valid: offset, tool_diameter,",
        ),
        (PlanOptions, {"step_over": 0.5}, "'step_over' (did you mean 'stepover'?)"),
        (Tool, {"id": 1, "diameter": 3.0, "dia": 3.0}, "Tool: unknown option(s) 'dia'"),
        (ImportOptions, {"layer": ("A",)}, "did you mean 'layers'?"),
        (
            Operation,
            {"type": "drill", "tool": 1, "hole_tol": 0.1},
            "did you mean 'hole_tolerance'?",
        ),
    ],
)
def test_an_unknown_keyword_names_the_valid_ones(
    cls: Any, kwargs: dict[str, Any], message: str
) -> None:
    with pytest.raises(UsageError, match=re.escape(message)):
        cls(**kwargs)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: PlanOptions(tool_diameter=-3.0), "--tool-diameter must be ≥ 0 mm, got -3.0"),
        (
            lambda: PlanOptions(pocket_angle_deg=1e300),
            "--pocket-angle is an angle within ±360 degrees from +X, got 1e+300",
        ),
        (
            lambda: PlanOptions(offset="outside", tool_diameter=1e-300),
            "--tool-diameter 1e-300 mm is less than 0.001 mm: no cutter is that narrow",
        ),
        (lambda: PlanOptions(depth=math.nan), "--depth must be a finite number, got nan"),
        (lambda: PlanOptions(feed_mm_min=-1.0), "--feed must be > 0 mm/min"),
        (lambda: PlanOptions(placement="centre"), "unknown --origin 'centre'; choose one of"),
        (
            lambda: PlanOptions(origin="center"),  # type: ignore[arg-type]
            "for the work zero (drawing, lower-left, center: --origin on the command line) "
            "give placement='center'",
        ),
        (lambda: PlanOptions(depth="3"), "PlanOptions depth = '3': give a number (--depth)"),  # type: ignore[arg-type]
        (
            lambda: PlanOptions(offset="outside", tool_diameter=1.0, lead_in=-1.0),
            "--lead-in must be ≥ 0 mm",
        ),
        (lambda: Tool(id=1, diameter=-3.0), "Tool.diameter must be ≥ 0 and ≤ 1000 mm, got -3.0"),
        (lambda: Tool(id=1, diameter=math.nan), "Tool.diameter must be"),
        (lambda: Tool(id=-1, diameter=3.0), "Tool.id must be 0…99999"),
        (lambda: Tool(id=1, diameter=3.0, type="laser"), "unknown Tool.type 'laser'"),
        (lambda: Tool(id=1, diameter=3.0, feed_mm_min=0.0), "Tool.feed_mm_min must be > 0"),
        (
            lambda: Selection(diameter=(5.0, 3.0)),
            "Selection.diameter must be (min, max) with min ≤ max",
        ),
        (lambda: Selection(diameter=(math.inf, 3.0)), "Selection.diameter must be"),
        (lambda: Operation(type="mill", tool=1), "unknown Operation.type 'mill'"),
        (lambda: Operation(type="drill", tool=1, dwell_s=math.nan), "Operation.dwell_s must be"),
        (lambda: Operation(type="profile", tool=1, side="left"), "Operation.side of a profile"),
    ],
)
def test_values_are_checked_when_made(make: Any, message: str) -> None:
    with pytest.raises(UsageError, match=re.escape(message)):
        make()


def test_usage_errors_are_value_errors() -> None:
    assert issubclass(UsageError, ValueError)
