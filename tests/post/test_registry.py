"""Targets by name: built-ins, target files, and third-party plugins (entry points)."""

from __future__ import annotations

import dataclasses
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from camtool.model.errors import InputError, UsageError
from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import (
    ENTRY_POINT_GROUP,
    list_targets,
    load_machine,
    load_target,
    target_names,
)

ROOT = Path(__file__).parents[2]

PLUGIN = '''
from camtool.post.registry import load_machine
from camtool.post.base import PostProcessor, PostResult, Target
from camtool.model.program import Linear, Program, Rapid


class Plotter(PostProcessor):
    """A toy dialect: one 'x,y' line per point, 'U' before a rapid."""

    def emit(self, program, machine, *, fmt=None):
        self.check_format(fmt)
        lines = []
        for move in program.moves:
            lines.append(("U " if isinstance(move, Rapid) else "") + f"{move.x:.3f},{move.y:.3f}")
        return PostResult("\\n".join(lines) + "\\n", len(lines))

    def parse(self, code, *, source="<code>"):
        moves = []
        for line in str(code).splitlines():
            up = line.startswith("U ")
            x, y = (float(v) for v in line.removeprefix("U ").split(","))
            moves.append(Rapid(x, y) if up else Linear(x, y, 100.0))
        return Program(tuple(moves))


def plotter():
    return Target("toy-plotter", "a toy pen plotter", Plotter(), load_machine("grbl"), 100.0)


def broken():
    raise RuntimeError("no serial port driver")


NOT_A_TARGET = 42
'''


@pytest.fixture
def plugins(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    """A distribution on sys.path with a good, a raising and a wrong-typed plugin."""
    (tmp_path / "toy_camtool_plugin.py").write_text(PLUGIN, encoding="utf-8")
    info = tmp_path / "toy_camtool_plugin-1.0.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: toy-camtool-plugin\nVersion: 1.0\n", encoding="utf-8"
    )
    (info / "entry_points.txt").write_text(
        textwrap.dedent(
            f"""\
            [{ENTRY_POINT_GROUP}]
            toy-plotter = toy_camtool_plugin:plotter
            toy-broken = toy_camtool_plugin:broken
            toy-number = toy_camtool_plugin:NOT_A_TARGET
            toy-missing = toy_camtool_plugin_gone:plotter
            pic-mmh = toy_camtool_plugin:plotter
            """
        ),
        encoding="utf-8",
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    return tmp_path


def test_builtin_targets_load_and_are_listed() -> None:
    names = target_names()
    assert "pic-mmh" in names
    entries = {e.name: e for e in list_targets()}
    assert all(entries[n].origin == "builtin" and entries[n].target for n in names)


def test_plugin_target_is_listed_and_usable(plugins: Path) -> None:
    entries = {e.name: e for e in list_targets()}
    toy = entries["toy-plotter"]
    assert toy.target is not None and toy.origin == "plugin toy_camtool_plugin:plotter"
    target = load_target("toy-plotter")
    program = Program((Rapid(1.0, 2.0), Linear(3.0, 4.0, 100.0)))
    code = target.emit(program).code
    assert code == "U 1.000,2.000\n3.000,4.000\n"
    assert target.post.parse(code).moves == program.moves


def test_a_plugin_cannot_shadow_a_builtin(plugins: Path) -> None:
    entries = [e for e in list_targets() if e.name == "pic-mmh"]
    assert len(entries) == 1 and entries[0].origin == "builtin"


@pytest.mark.parametrize(
    ("name", "reason"),
    [
        ("toy-broken", "RuntimeError: no serial port driver"),
        ("toy-number", "it gives int, not a Target"),
        ("toy-missing", "ModuleNotFoundError"),
    ],
)
def test_broken_plugins_are_listed_not_raised(plugins: Path, name: str, reason: str) -> None:
    entry = {e.name: e for e in list_targets()}[name]
    assert entry.target is None and reason in entry.error
    with pytest.raises(InputError, match=f"plugin '{name}'.*is broken"):
        load_target(name)


def test_plugin_machine_override(plugins: Path, tmp_path: Path) -> None:
    override = tmp_path / "measured.toml"
    override.write_text("[machine.backlash]\ntrue_um = [50.0, 40.0, 0.0]\n", encoding="utf-8")
    target = load_target("toy-plotter", machine_file=override)
    assert target.machine.backlash.true_um[:2] == (50.0, 40.0)
    assert target.machine.name == "GRBL 1.1 (defaults)"


def test_unknown_target_lists_builtins_and_plugins(plugins: Path) -> None:
    with pytest.raises(UsageError, match=r"choose one of: .*pic-mmh.*toy-plotter"):
        load_target("nope")


def test_cli_lists_broken_plugin_and_keeps_going(plugins: Path) -> None:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(plugins), str(ROOT)])}
    run = subprocess.run(
        [sys.executable, "-m", "camtool", "targets"], capture_output=True, text=True, env=env
    )
    assert run.returncode == 0, run.stderr
    assert "toy-broken" in run.stdout and "BROKEN: plugin 'toy-broken'" in run.stdout
    toy = next(line for line in run.stdout.splitlines() if line.startswith("toy-plotter "))
    assert toy.endswith(" a toy pen plotter [plugin toy_camtool_plugin:plotter]")
    as_json = subprocess.run(
        [sys.executable, "-m", "camtool", "targets", "--json"],
        capture_output=True,
        text=True,
        env=env,
    )
    rows = {r["name"]: r for r in json.loads(as_json.stdout)}
    assert rows["toy-broken"]["broken"].endswith("RuntimeError: no serial port driver")
    assert rows["pic-mmh"]["formats"] == {"code": ".pic"}
    assert rows["pic-mmh"]["has_z"] is False
    chosen = subprocess.run(
        [sys.executable, "-m", "camtool", "post", "x.dxf", "--target", "toy-broken"],
        capture_output=True,
        text=True,
        env=env,
    )
    assert chosen.returncode == 3 and "Traceback" not in chosen.stderr
    assert "is broken: RuntimeError: no serial port driver" in chosen.stderr


def test_target_file_rejects_bad_numbers(tmp_path: Path) -> None:
    path = tmp_path / "t.toml"
    path.write_text('dialect = "pic-mmh"\nmachine = "mmh-gmm"\nspindle_rpm = -5\n', "utf-8")
    with pytest.raises(InputError, match=r"t.toml: spindle_rpm must be a number from 1 to 1e\+06"):
        load_target(str(path))


def test_unknown_format_is_a_usage_error() -> None:
    target = load_target("pic-mmh")
    with pytest.raises(UsageError, match="unknown format 'wire'; this target writes: code"):
        target.emit(Program((Linear(1.0, 1.0, 0.8),)), fmt="wire")


def test_a_target_whose_machine_has_z_and_its_dialect_no_z_word_is_refused_at_load(
    tmp_path: Path,
) -> None:
    """Not block by block when the program is written: the file names what to change."""
    valcnc = (
        Path(__file__).resolve().parents[2] / "postprocessors" / "valcnc" / "valcnc.toml"
    ).read_text()
    text = valcnc.replace('name = "valcnc"', 'name = "noz"').replace("words.XYZIJ", "words.XYIJ")
    text = text.replace('z_moves = "with-xy"', 'z_moves = "none"')
    (tmp_path / "noz.toml").write_text(text)
    with pytest.raises(InputError, match=r"noz\.toml: the machine has a Z axis .*has_z = false"):
        load_target(str(tmp_path / "noz.toml"))
    (tmp_path / "noz.toml").write_text(text.replace("has_z = true", "has_z = false"))
    assert not load_target(str(tmp_path / "noz.toml")).machine.has_z


def test_a_z_axis_given_to_a_machine_without_z_word_is_refused(tmp_path: Path) -> None:
    """A --machine overlay that gives pic-mmh (no Z word) a Z axis."""
    (tmp_path / "z.toml").write_text("has_z = true\n")
    with pytest.raises(InputError, match=r"has_z = true .*z\.toml"):
        load_target("pic-mmh", machine_file=tmp_path / "z.toml")


def test_the_installed_plugins_are_scanned_once_per_search_path(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The verifier asks for the motion models at every simulation: a dry run of a 1 MB program
    scanned the installed distributions 2 124 times (11 of its 33 s of CPU)."""
    import importlib.metadata

    from camtool.verify.motion import library

    scans: list[object] = []
    discover = importlib.metadata.entry_points

    def counting(**params: object) -> importlib.metadata.EntryPoints:
        scans.append(params.get("group"))
        return discover(**params)  # type: ignore[arg-type]

    monkeypatch.setattr(importlib.metadata, "entry_points", counting)
    grbl = load_machine("grbl")
    for _ in range(10):
        library(grbl)  # a built-in profile: its own target's motion, no scan
    assert scans == []
    unknown = dataclasses.replace(grbl, profile="not-installed")
    for _ in range(10):
        library(unknown)  # a profile no built-in declares: the plugins are asked, once
    assert scans == [ENTRY_POINT_GROUP]
    monkeypatch.syspath_prepend(str(tmp_path))  # another search path: scanned again
    library(unknown)
    assert scans == [ENTRY_POINT_GROUP, ENTRY_POINT_GROUP]
