"""A plugin target brings its own interpolator and timing model: no edit in camtool/.

The plugin (tests/plugins/xy_then.py and xy-then.toml) is registered by
monkeypatching :func:`camtool.post.registry.motion_hooks`, the one place the
verifier asks for installed targets' motion models.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

import camtool.post.registry as registry
from camtool.model.errors import InputError
from camtool.model.machine import Machine, machine_from_table
from camtool.model.program import Linear, Program
from camtool.verify.verifier import verify_program
from tests.plugins import xy_then

TOML = Path(__file__).with_name("xy-then.toml")
PROGRAM = Program((Linear(1.0, 2.0, 100.0), Linear(0.0, 0.0, 100.0)))


def plugin_machine() -> Machine:
    table = tomllib.loads(TOML.read_text(encoding="utf-8"))["machine"]
    return machine_from_table(table, where=TOML.name)


@pytest.fixture
def installed(monkeypatch: pytest.MonkeyPatch) -> None:
    builtin = registry.motion_hooks
    monkeypatch.setattr(registry, "motion_hooks", lambda: [*builtin(), ("xy-then", xy_then.MOTION)])


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
