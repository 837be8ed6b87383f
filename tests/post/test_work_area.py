"""The ``coordinates`` profile key and the work-area rule of the post-processors."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

from camtool.model.errors import DialectError, InputError
from camtool.model.machine import machine_from_table
from camtool.model.program import Linear, Program, Rapid
from camtool.post.base import check_placement
from camtool.post.registry import load_machine, machine_names

BASE = {"name": "bench", "steps_per_mm": [100, 100, 100], "work_area_mm": [0, 0, 100, 50]}


def test_every_thesis_controller_with_a_work_zero_is_work_and_the_router_machine() -> None:
    # Angel-11: every job homes and starts from its first point's offset from home (R1, R6).
    kinds = {name: load_machine(name).coordinates for name in machine_names()}
    assert kinds.pop("router-2011") == "machine"
    assert set(kinds.values()) == {"work"}


def test_coordinates_default_to_work_and_are_read_strictly() -> None:
    assert machine_from_table(BASE, where="t").coordinates == "work"
    table = {**BASE, "coordinates": "machine"}
    assert machine_from_table(table, where="t").coordinates == "machine"
    with pytest.raises(InputError, match=r"t: machine.coordinates must be one of .*'work'"):
        machine_from_table({**BASE, "coordinates": "absolute"}, where="t")


def test_an_empty_or_inverted_work_area_is_refused() -> None:
    with pytest.raises(InputError, match=r"machine.work_area_mm must be \[xmin, ymin"):
        machine_from_table({**BASE, "work_area_mm": [0, 0, -10, 50]}, where="t")


def test_work_coordinates_check_only_the_size() -> None:
    machine = machine_from_table(BASE, where="t")
    inside = Program((Rapid(-80, -40), Linear(20, 10, 100)))  # 100 × 50 mm, all negative
    # code written elsewhere chose its own work zero: it fits, so nothing to say
    assert check_placement(inside, machine) == ()
    # planned here from a drawing as drawn, the same extent is worth a warning
    from camtool.toolpath.placement import Placing, check_travel

    assert check_travel(inside, machine, Placing()) == (
        "the toolpath spans X -80…20, Y -40…10 mm, on both sides of work zero (X0 Y0): set "
        "work zero so that this fits the 100 × 50 mm travel of bench, or use "
        "--origin lower-left",
    )
    assert check_placement(Program((Rapid(0, 0), Linear(100, 50, 100))), machine) == ()
    with pytest.raises(DialectError, match=r"100.5 × 50 mm, larger than the 100 × 50 mm travel"):
        check_placement(Program((Rapid(0, 0), Linear(100.5, 50, 100))), machine)


def test_a_toolpath_far_from_work_zero_is_warned_about() -> None:
    machine = machine_from_table(BASE, where="t")
    (warning,) = check_placement(Program((Rapid(60, 0), Linear(120, 0, 100))), machine)
    assert warning.startswith("the toolpath spans X 60…120 mm, so work zero (X0 Y0) lies 120 mm")
    assert "more than the 100 mm X travel of bench" in warning


def test_a_suggested_translation_is_not_rounded_up_by_float_noise() -> None:
    # A FreeCAD part reached Y -7.0000000001 after offsetting; 7, not 7.001, brings it in.
    from camtool.toolpath.placement import Placing, place_remedy

    machine = load_machine("router-2011")
    box = (-1.5, -7.0000000001, 41.5, 30.344)
    assert place_remedy(box, machine, Placing()).endswith("--translate 1.5 7")


@pytest.mark.parametrize("target", ["pic-mmh", "flashcut"])
def test_a_reposted_coordinate_too_long_for_its_word_is_moved_where_it_was_written(
    run: Any, tmp_path: Path, target: str
) -> None:
    """pic-mmh writes at most 99.99999 mm (5 integer digits of µm), flashcut 4 integer
    digits of mm: a re-posted program that far out is moved in the program that wrote it
    (``--origin`` and ``--translate`` are refused for G-code)."""
    machine = tmp_path / "wide.toml"
    machine.write_text("[machine]\nwork_area_mm = [0, 0, 900000, 900000]\n")
    far = 150.0 if target == "pic-mmh" else 15000.0
    program = tmp_path / "far.ngc"
    program.write_text(f"G21 G90\nG0 Z5\nG0 X{far} Y1\nG1 Z-1 F100\nG1 X{far + 5} Y1\nG0 Z5\nM2\n")
    out = tmp_path / "out.txt"
    code, err = run("post", str(program), "-t", target, "--machine", str(machine), "-o", str(out))
    assert code != 0 and not out.exists()
    assert "integer digits" in err and "(input line 3)" in err
    assert "move it nearer in the program that wrote it (its work zero)" in err
    assert "--origin" not in err and "--translate" not in err
