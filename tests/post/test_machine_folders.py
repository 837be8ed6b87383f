"""A machine is one folder: its ``__init__.py`` builds one typed Target; names stay its own.

The registry finds a machine's Python only where its folder's ``__init__.py`` names it
(no sibling module found by a file-name suffix), and a profile's interpolators, chord rule
and timing model are looked up in its own target's motion model, not across every
installed target.
"""

from __future__ import annotations

import dataclasses
import importlib
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from camtool.link.spec import LinkHooks
from camtool.model.errors import InputError
from camtool.model.machine import machine_from_table
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import TargetPackage, load_machine, load_target, target_names
from camtool.verify.motion import GENERIC, QUALIFIED, MotionHooks, library
from camtool.verify.verifier import verify_program

ROOT = Path(__file__).resolve().parents[2]

WORD_ADDRESS_TOML = """\
name = "{name}"
description = "a test machine"
dialect = "word-address"
default_feed_mm_min = 100.0

[dialect_options]
motion_codes = {{ rapid = "G0", linear = "G1", cw = "G2", ccw = "G3" }}
z_moves = "own-block"
[dialect_options.words.XYZIJ]
decimals = 3
[dialect_options.words.F]
decimals = 0

[machine]
name = "test"
profile = "{name}"
steps_per_mm = [100.0, 100.0, 100.0]
work_area_mm = [0.0, 0.0, 100.0, 100.0]
"""


def test_every_builtin_with_python_is_one_folder_whose_init_builds_its_target() -> None:
    folders = {p.parent.name for p in (ROOT / "postprocessors").glob("*/__init__.py")}
    assert {name.replace("-", "_") for name in target_names()} == folders
    assert [p.name for p in (ROOT / "postprocessors").glob("*.py")] == ["__init__.py"]
    for name in target_names():
        module = importlib.import_module(f"camtool_postprocessors.{name.replace('-', '_')}")
        assert load_target(name) is module.TARGET
        assert isinstance(module.TARGET.motion, MotionHooks)
        assert module.TARGET.link is None or isinstance(module.TARGET.link, LinkHooks)


def test_a_sibling_module_is_not_found_by_its_suffix(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``<stem>_motion.py`` beside a TOML-only machine is not its motion model any more."""
    package = tmp_path / "suffix_machines"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "mill.toml").write_text(WORD_ADDRESS_TOML.format(name="mill"), encoding="utf-8")
    (package / "mill_motion.py").write_text(
        "from camtool.verify.motion import MotionHooks\nMOTION = MotionHooks()\n",
        encoding="utf-8",
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        target = TargetPackage("suffix_machines").target("mill")
        assert target.motion is None and target.link is None
    finally:
        sys.modules.pop("suffix_machines", None)


def test_a_folder_names_its_python_and_a_machine_file_keeps_it(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = tmp_path / "folder_machines"
    (package / "saw").mkdir(parents=True)
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "saw" / "saw.toml").write_text(WORD_ADDRESS_TOML.format(name="saw"), "utf-8")
    (package / "saw" / "__init__.py").write_text(
        textwrap.dedent(
            """
            from camtool.post.registry import folder_target
            from camtool.verify.motion import MotionHooks

            HOOKS = MotionHooks()
            TARGET = folder_target(__name__, motion=lambda: HOOKS)
            """
        ),
        encoding="utf-8",
    )
    over = tmp_path / "over.toml"
    over.write_text("[machine]\nmax_step_rate_hz = 5000.0\n", encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    try:
        provider = TargetPackage("folder_machines")
        assert provider.names() == ["saw"]
        hooks = importlib.import_module("folder_machines.saw").HOOKS
        assert provider.target("saw").motion is hooks
        overlaid = provider.target("saw", machine_file=over)
        assert overlaid.machine.max_step_rate_hz == 5000.0 and overlaid.motion is hooks
    finally:
        for module in ("folder_machines", "folder_machines.saw"):
            sys.modules.pop(module, None)


def _grbl_table_without_profile(**motion: str) -> dict[str, object]:
    table = dict(load_target("grbl").machine.table)
    table.pop("profile")
    table["motion"] = {**table["motion"], **motion}
    return table


def test_a_profile_names_only_its_own_targets_pieces_unqualified() -> None:
    """GRBL's chord rule is GRBL's: a profile of another name must qualify it."""
    grbl = load_machine("grbl")
    assert library(grbl).chord_rule(grbl) is load_target("grbl").motion.chords["grbl"]
    valcnc_chords = dataclasses.replace(
        grbl, motion=dataclasses.replace(grbl.motion, chords="valcnc")
    )
    with pytest.raises(InputError, match="unknown chord rule 'valcnc'; valid: sagitta, grbl"):
        library(valcnc_chords).check(valcnc_chords)
    mine = machine_from_table(_grbl_table_without_profile(), where="mine.toml")
    with pytest.raises(InputError, match=r"unknown chord rule 'grbl'.*<target>:<name>"):
        library(mine).check(mine)


def test_a_qualified_name_borrows_another_targets_piece_exactly() -> None:
    """``chords = "grbl:grbl"`` in a profile of its own cuts arcs as GRBL's profile does."""
    table = _grbl_table_without_profile(chords="grbl:grbl")
    table["timing"] = {**table["timing"], "model": "grbl:grbl"}
    mine = machine_from_table(table, where="mine.toml")
    grbl = load_machine("grbl")
    arc = Program((Linear(10.0, 0.0, 300.0), ArcMove(0.0, 10.0, 0.0, 0.0, False, 300.0)))
    ours, theirs = verify_program(arc, mine), verify_program(arc, grbl)
    assert ours.trace.row_count == theirs.trace.row_count > 1000
    assert np.array_equal(np.asarray(ours.trace.rows), np.asarray(theirs.trace.rows))
    assert np.array_equal(ours.block_time_s, theirs.block_time_s)
    with pytest.raises(InputError, match="unknown chord rule 'nosuch:grbl'"):
        bad = dataclasses.replace(
            mine, motion=dataclasses.replace(mine.motion, chords="nosuch:grbl")
        )
        library(bad).check(bad)


def test_a_machine_file_that_renames_the_profile_keeps_the_targets_own_pieces(
    tmp_path: Path,
) -> None:
    """``--machine`` laying ``profile = "shapeoko"`` over GRBL names the user's machine; the
    chord rule, line and timing GRBL's profile names stay GRBL's (a rename changes no step),
    and a piece the file sets itself is its own."""
    grbl = load_target("grbl")
    renamed = tmp_path / "shapeoko.toml"
    renamed.write_text('[machine]\nprofile = "shapeoko"\nname = "Shapeoko 3"\n')
    mine = load_target("grbl", machine_file=renamed).machine
    assert mine.profile == "shapeoko" and mine.motion.chords == f"grbl{QUALIFIED}grbl"
    arc = Program((Linear(10.0, 0.0, 300.0), ArcMove(0.0, 10.0, 0.0, 0.0, False, 300.0)))
    ours, theirs = verify_program(arc, mine), verify_program(arc, grbl.machine)
    assert ours.trace.row_count == theirs.trace.row_count > 1000
    assert np.array_equal(np.asarray(ours.trace.rows), np.asarray(theirs.trace.rows))
    assert np.array_equal(ours.block_time_s, theirs.block_time_s)
    # GRBL's writer knows its chord rule under either name: an arc of radius <= $12 / 2,
    # which GRBL's mc_arc cannot divide into chords, is written as a line
    tiny = Program((Rapid(0.0, 0.0), ArcMove(0.0015, 0.0, 0.00075, 0.0, True, 300.0)))
    written = load_target("grbl", machine_file=renamed).emit(tiny).code
    assert str(written) == str(grbl.emit(tiny).code)
    assert not any(line.startswith("G2 ") for line in str(written).splitlines())
    # a piece the target declares is never one of the generic library's: qualifying it
    # cannot swap a generic piece for the target's
    for name in target_names():
        hooks = load_target(name).motion
        for kind in ("lines", "arcs", "chords", "timing", "simulators"):
            assert not set(getattr(hooks, kind)) & set(getattr(GENERIC, kind)), (name, kind)
    own = tmp_path / "own.toml"
    own.write_text('[machine]\nprofile = "shapeoko"\n[machine.motion]\nchords = "sagitta"\n')
    machine = load_target("grbl", machine_file=own).machine
    assert machine.motion.chords == "sagitta"
    assert library(machine).chord_rule(machine) is library().chord_rule(machine)


def test_a_qualified_name_names_an_installed_target_not_a_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """``"<target>:<piece>"`` never reads a target file given as a path."""
    import camtool.post.registry as registry

    read: list[object] = []
    load_toml = registry.load_toml
    monkeypatch.setattr(registry, "load_toml", lambda *a: read.append(a) or load_toml(*a))
    grbl = load_machine("grbl")
    target_file = tmp_path / "other.toml"
    target_file.write_text((ROOT / "postprocessors" / "grbl" / "grbl.toml").read_text("utf-8"))
    for name in (f"{target_file}:grbl", "../grbl.toml:grbl", "grbl.toml:grbl"):
        asked = dataclasses.replace(grbl, motion=dataclasses.replace(grbl.motion, chords=name))
        with pytest.raises(InputError, match="unknown chord rule"):
            library(asked).check(asked)
    assert read == []
