"""X, Y and Z words coarser than the tolerance: the user is told how far positions moved.

Expected values by analysis: a word of ``decimals = 0`` writes 10.3 as 10 and 15.7 as 16
(0.3 mm each way) and 20.2 as 20 (0.2 mm); an inch word of 4 decimals steps 0.00254 mm, so
it moves a position 0.00127 mm at most, under half the 0.0125 mm step of 80 steps/mm.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import ezdxf

from camtool.model.machine import Machine
from camtool.model.program import Linear, Program, Rapid
from camtool.post.wordaddress import word_address_dialect

WHOLE_MM: dict[str, Any] = {"words": {"XYIJ": {"decimals": 0}, "F": {"decimals": 0}}}
"""A dialect writing X, Y, I and J in whole millimetres."""

ROUTER = Machine(name="router", steps_per_mm=(80.0,) * 3, work_area_mm=(0, 0, 300, 300))
"""80 steps/mm: a step of 0.0125 mm."""


def warnings_of(
    options: dict[str, Any],
    *moves: Any,
    tolerance: float = 0.001,
    kind: str = "writes X and Y",
    machine: Machine = ROUTER,
) -> list[str]:
    program = Program(tuple(moves), tolerance_mm=tolerance)
    result = word_address_dialect(options, "toy.toml").emit(program, machine)
    return [w for w in result.warnings if kind in w]


def test_whole_millimetres_say_how_far_the_positions_moved() -> None:
    said = warnings_of(WHOLE_MM, Rapid(10.3, 20.2), Linear(15.7, 20.2, 300.0))
    assert len(said) == 1
    assert "toy writes X and Y to 1 mm: positions written up to 0.3000 mm" in said[0]
    assert "more than the 0.001 mm tolerance (--tolerance)" in said[0]


def test_positions_on_the_step_or_within_the_tolerance_are_not_warned_of() -> None:
    assert not warnings_of(WHOLE_MM, Rapid(10.0, 20.0), Linear(16.0, 20.0, 300.0))
    moves = (Rapid(10.3, 20.2), Linear(15.7, 20.2, 300.0))
    assert not warnings_of(WHOLE_MM, *moves, tolerance=0.5)


def test_a_step_under_half_a_motor_step_is_not_warned_of() -> None:
    # 0.40005 in (10.16127 mm) is written 0.4001 in: 0.00127 mm more, over the 0.001 mm
    # tolerance but under half the router's 0.0125 mm step; a machine of 1000 steps/mm
    # (half a step 0.0005 mm) stands nearer, so there it is said
    inch = 1.0 / 25.4
    options = {"words": {"XYIJ": {"decimals": 4, "scale": inch}, "F": {"decimals": 1}}}
    moves = (Rapid(10.0, 20.0), Linear(0.40005 * 25.4, 20.0, 300.0))
    assert not warnings_of(options, *moves)
    fine = Machine(name="fine", steps_per_mm=(1000.0,) * 3, work_area_mm=(0, 0, 300, 300))
    said = warnings_of(options, *moves, machine=fine)
    assert len(said) == 1 and "positions written up to 0.0013 mm" in said[0]


def test_a_depth_written_deeper_is_said_with_the_depth_asked() -> None:
    # 1.5 mm rounds half away from zero: Z-2, half a millimetre deeper than planned
    options = {"words": {"XYZIJ": {"decimals": 0}, "F": {"decimals": 0}}}
    moves = (Rapid(10.0, 20.0, 5.0), Linear(10.0, 20.0, 100.0, z=-1.5), Linear(16, 20, 300.0))
    said = warnings_of(options, *moves, kind="writes Z")
    assert said == [
        "toy writes Z to 1 mm: heights written up to 0.5000 mm from those planned (Z-1.5 as "
        "Z-2), more than the 0.001 mm tolerance; give depths and heights in steps of 1 mm "
        "(--depth, --step-down, --safe-z), or its Z word more decimals"
    ]
    whole = (Rapid(10.0, 20.0, 5.0), Linear(10.0, 20.0, 100.0, z=-2.0), Linear(16, 20, 300.0))
    assert not warnings_of(options, *whole, kind="writes Z")
    # -2.5 is a tie too: written half away from zero, Z-3, as the word writes it (not Z-2)
    tie = (Rapid(10.0, 20.0, 5.0), Linear(10.0, 20.0, 100.0, z=-2.5), Linear(16, 20, 300.0))
    assert "(Z-2.5 as Z-3)" in warnings_of(options, *tie, kind="writes Z")[0]


def test_post_with_a_target_file_of_whole_millimetres_warns(tmp_path: Path, run: Any) -> None:
    target = tmp_path / "coarse.toml"
    target.write_text(
        'name = "coarse"\ndescription = "whole millimetres"\ndialect = "word-address"\n'
        "[dialect_options.words.XYZIJ]\ndecimals = 0\n"
        '[machine]\nprofile = "coarse"\nname = "coarse"\nsteps_per_mm = [80.0, 80.0, 80.0]\n'
        "work_area_mm = [0.0, 0.0, 300.0, 300.0]\n",
        encoding="utf-8",
    )
    doc = ezdxf.new()
    doc.units = ezdxf.units.MM
    doc.modelspace().add_lwpolyline([(10.3, 20.2), (15.7, 20.2), (15.7, 25.4)])
    drawing = tmp_path / "part.dxf"
    doc.saveas(drawing)
    out = tmp_path / "part.nc"
    code, err = run("post", str(drawing), "-t", str(target), "-o", str(out))
    assert code == 0
    assert "coarse writes X and Y to 1 mm: positions written up to 0.4000 mm" in err
    assert "X10 Y20" in out.read_text(encoding="utf-8")
