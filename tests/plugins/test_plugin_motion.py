"""A plugin target brings its own interpolator and timing model: no edit in camtool/.

The plugin is a package of targets like camtool's built-ins (tests/plugins/xythen_plugin/:
``TARGETS = TargetPackage(__name__)``; its folder ``xy_then/`` holds ``xy-then.toml``,
``motion.py`` with its ``MOTION`` and the ``__init__.py`` naming it). It is registered the
way an installed distribution registers one: an entry point
``xythen = "tests.plugins.xythen_plugin:TARGETS"`` of the group ``camtool.postprocessors``.
Only the entry-point discovery is patched (:func:`importlib.metadata.entry_points`, which
:mod:`camtool.post.registry` asks); every other step is camtool's own, up to the CLI as a
user runs it.
"""

from __future__ import annotations

import importlib.metadata
import json
import tomllib
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camtool.cli.main import main
from camtool.model.errors import InputError
from camtool.model.machine import Machine, machine_from_table
from camtool.model.program import Linear, Program
from camtool.post.registry import ENTRY_POINT_GROUP
from camtool.verify.verifier import verify_program
from tests.shapes import rectangle_dxf

ROOT = Path(__file__).parents[2]
TOML = Path(__file__).parent / "xythen_plugin" / "xy_then" / "xy-then.toml"
PROGRAM = Program((Linear(1.0, 2.0, 100.0), Linear(0.0, 0.0, 100.0)))
ENTRY_POINT = importlib.metadata.EntryPoint(
    name="xythen", value="tests.plugins.xythen_plugin:TARGETS", group=ENTRY_POINT_GROUP
)
PLUGIN_NAMES = ("xy-then", "xythen", "xy_then", "x-then-y", "fixed-block")
"""The plugin's target, package, module, interpolator and timing model names."""


def plugin_machine() -> Machine:
    table = tomllib.loads(TOML.read_text(encoding="utf-8"))["machine"]
    return machine_from_table(table, where=TOML.name)


@pytest.fixture
def installed(monkeypatch: pytest.MonkeyPatch) -> None:
    """The plugin's entry point is found beside the installed ones (nothing else patched)."""
    discover = importlib.metadata.entry_points

    def entry_points(**params: Any) -> importlib.metadata.EntryPoints:
        found = discover(**params)
        if params.get("group") != ENTRY_POINT_GROUP:
            return found
        return importlib.metadata.EntryPoints((*found, ENTRY_POINT))

    monkeypatch.setattr(importlib.metadata, "entry_points", entry_points)


def test_the_plugin_interpolator_and_timing_are_used(installed: None) -> None:
    v = verify_program(PROGRAM, plugin_machine(), name="xy-then")
    rows = v.trace.rows
    # (1, 2) mm at 10 steps/mm: 10 X rows, then 20 Y rows; back: 10 -X, then 20 -Y
    expected = [[1, 0]] * 10 + [[0, 1]] * 20 + [[-1, 0]] * 10 + [[0, -1]] * 20
    assert rows.tolist() == expected
    assert v.trace.block_start.tolist() == [0, 30, 60]
    # the plugin's timing: one second per block, two blocks
    assert np.array_equal(v.block_time_s, [1.0, 1.0])
    assert v.time_s == 2.0
    # the step path visits the corner (1, 0) mm, 2 mm from the straight line's end
    assert v.deviation.max_um > 800.0


def test_without_the_plugin_its_names_are_unknown() -> None:
    with pytest.raises(InputError, match="unknown line interpolator 'x-then-y'; valid: dda"):
        verify_program(PROGRAM, plugin_machine())


def test_a_plugin_timing_parameter_is_checked(installed: None) -> None:
    table = tomllib.loads(TOML.read_text(encoding="utf-8"))["machine"]
    table["timing"]["seconds_per_block"] = 0.0
    machine = machine_from_table(table, where=TOML.name)
    with pytest.raises(InputError, match="seconds_per_block"):
        verify_program(PROGRAM, machine)


def test_the_plugin_through_the_cli(
    installed: None,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(["targets"]) == 0
    listed = [line for line in capsys.readouterr().out.splitlines() if line.startswith("xy-then")]
    assert listed and "plugin tests.plugins.xythen_plugin:TARGETS" in listed[0]
    assert "BROKEN" not in listed[0]

    square = rectangle_dxf(tmp_path / "square.dxf", 10.0, 10.0)  # (1, 1) to (11, 11) mm
    assert main(["post", str(square), "-t", "xy-then", "-o", "square.xyt"]) == 0
    code = Path("square.xyt").read_text(encoding="utf-8").splitlines()
    assert code[0] == "G21 G90" and code[-1] == "M2"  # the plugin's own dialect options
    assert "G0 X1.0 Y1.0" in code and "G1 X11.0 Y1.0 F100" in code
    capsys.readouterr()

    assert main(["verify", "square.xyt", "-t", "xy-then", "--report", "r.json"]) == 0
    report = json.loads(Path("r.json").read_text(encoding="utf-8"))
    assert report["target"] == "xy-then" and report["machine"] == "XY-then test machine"
    # 9 moves: Z up, the rapid to (1, 1), Z down twice, the 4 sides, Z up
    assert report["blocks"] == 9
    # X: 10 steps to x = 1 mm, then 100 + 100 along the sides (10 steps/mm); Y the same
    assert report["steps"]["x"] == 210 and report["steps"]["y"] == 210
    # the plugin's interpolator moves one axis per row: the diagonal rapid takes 10 + 10 rows
    assert report["iterations"] == 210 + 210
    # the plugin's timing: one second per block, whatever the block does
    assert report["time_s"] == 9.0

    # the same code with the generic DDA (UNAM-GMM A.3: floor(hypot) + 1 iterations a move):
    # 101 per side, 15 for the diagonal rapid (10, 10) steps
    Path("dda.toml").write_text('[machine.motion]\nline = "dda"\n', encoding="utf-8")
    args = ["verify", "square.xyt", "-t", "xy-then", "--machine", "dda.toml"]
    assert main([*args, "--report", "dda.json"]) == 0
    dda = json.loads(Path("dda.json").read_text(encoding="utf-8"))
    assert dda["steps"] == report["steps"] and dda["iterations"] == 4 * 101 + 15


def test_no_file_under_camtool_names_the_plugin() -> None:
    for path in sorted((ROOT / "camtool").rglob("*")):
        if path.is_file() and "__pycache__" not in path.parts:
            text = path.read_bytes().decode("utf-8", errors="replace")
            named = [name for name in PLUGIN_NAMES if name in text]
            assert not named, f"{path.relative_to(ROOT)} names the plugin: {named}"
