"""Program: moves plus non-motion commands, and how the pipeline keeps them."""

from __future__ import annotations

import pytest

from camtool.jobs.pipeline import OutputOptions, post_program
from camtool.model.program import Dwell, Home, Linear, Program, Rapid, Spindle, ToolChange
from camtool.post.registry import load_target

MOVES = (Rapid(1.0, 1.0), Linear(2.0, 1.0, 0.8), Rapid(3.0, 3.0), Linear(4.0, 3.0, 0.8))


def test_items_interleave_commands_in_program_order() -> None:
    program = Program(
        MOVES,
        commands=((0, ToolChange(2)), (0, Spindle("cw", 1200)), (2, Dwell(1.5)), (4, Home("XY"))),
    )
    assert list(program.items()) == [
        ToolChange(2),
        Spindle("cw", 1200),
        MOVES[0],
        MOVES[1],
        Dwell(1.5),
        MOVES[2],
        MOVES[3],
        Home("XY"),
    ]
    assert program.commands_before(2) == (Dwell(1.5),)
    assert program.commands_before(1) == ()


@pytest.mark.parametrize("commands", [((5, Dwell(1.0)),), ((2, Dwell(1.0)), (1, Dwell(1.0)))])
def test_command_indices_must_be_sorted_and_in_range(
    commands: tuple[tuple[int, Dwell], ...],
) -> None:
    with pytest.raises(ValueError, match=r"sorted within 0\.\.4"):
        Program(MOVES, commands=commands)


def test_with_spindle_wraps_the_moves() -> None:
    program = Program(MOVES, commands=((2, Dwell(1.0)),)).with_spindle(9000, "ccw")
    assert program.commands == (
        (0, Spindle("ccw", 9000)),
        (2, Dwell(1.0)),
        (4, Spindle("off")),
    )
    with pytest.raises(ValueError, match="spindle speed must be > 0"):
        Program(MOVES).with_spindle(0)


def test_with_moves_drops_commands_that_no_longer_fit() -> None:
    program = Program(MOVES).with_spindle(1000)
    assert program.with_moves(MOVES[:2]).commands == ()


def test_flattening_for_a_2d_target_moves_commands_with_their_moves() -> None:
    """pic-mmh has no Z (UNAM-GMM S000-08): Z-only moves go, commands stay in place."""
    moves = (
        Rapid(1.0, 1.0, z=2.0),
        Linear(1.0, 1.0, 50.0, z=-0.1),  # Z-only: dropped
        Linear(2.0, 1.0, 0.8),
        Rapid(2.0, 1.0, z=2.0),  # Z-only: dropped
    )
    program = Program(moves, commands=((1, Dwell(2.0)), (3, Spindle("off")), (4, Home("XY"))))
    job = post_program(program, load_target("pic-mmh"))
    assert len(job.program.moves) == 2
    assert job.program.commands == ((1, Dwell(2.0)), (2, Spindle("off")), (2, Home("XY")))


def test_post_program_adds_the_spindle_only_when_asked_and_absent() -> None:
    target = load_target("pic-mmh")
    program = Program(MOVES[:2])
    assert post_program(program, target).program.commands == ()
    wrapped = post_program(program, target, OutputOptions(spindle_rpm=1000)).program
    assert wrapped.commands == ((0, Spindle("cw", 1000)), (2, Spindle("off")))
    own = Program(MOVES[:2], commands=((0, Spindle("ccw", 500)),))
    assert (
        post_program(own, target, OutputOptions(spindle_rpm=1000)).program.commands == own.commands
    )
