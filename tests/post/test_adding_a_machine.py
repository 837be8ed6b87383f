"""docs/dialects.md "Adding a machine": its example TOML is a whole target (file or provider)."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

from camtool.model.program import Linear, Program, Rapid
from camtool.post.registry import TargetPackage, load_target

ROOT = Path(__file__).parents[2]


def example_toml() -> str:
    """The ```toml block of the section "Adding a machine" in docs/dialects.md."""
    text = (ROOT / "docs" / "dialects.md").read_text("utf-8")
    section = text.split("## Adding a machine", 1)[1].split("\n## ", 1)[0]
    found = re.search(r"```toml\n(.*?)```", section, re.S)
    assert found, "docs/dialects.md: no ```toml example under ## Adding a machine"
    return found.group(1)


SQUARE = Program(
    (
        Rapid(10.0, 10.0),
        Linear(10.0, 10.0, 1200.0, z=0.0),
        Linear(30.0, 10.0, 1200.0),
        Linear(30.0, 30.0, 1200.0),
        Linear(10.0, 30.0, 1200.0),
        Linear(10.0, 10.0, 1200.0),
        Rapid(10.0, 10.0, z=5.0),
    )
)

BLOCKS = [
    "G21 G90",
    "G0 X10.00 Y10.00",
    "G1 Z0.00 F1200",
    "G1 X30.00 Y10.00",
    "G1 X30.00 Y30.00",
    "G1 X10.00 Y30.00",
    "G1 X10.00 Y10.00",
    "G0 Z5.00",
    "M2",
]


def check(target_text: str, code: str) -> None:
    assert target_text  # the example was found
    assert code.splitlines() == BLOCKS


def test_the_example_is_a_target_file(tmp_path: Path) -> None:
    path = tmp_path / "pen-plotter.toml"
    path.write_text(example_toml(), encoding="utf-8")
    target = load_target(str(path))
    assert target.machine.name == "A4 pen plotter" and target.machine.profile == "pen-plotter"
    result = target.emit(SQUARE)
    check(example_toml(), str(result.code))
    back = target.parse(result.code)
    assert [(m.x, m.y) for m in back.moves][-2:] == [(10.0, 10.0), (10.0, 10.0)]


def test_the_example_is_one_file_in_a_provider_package(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    package = tmp_path / "my_machines"
    package.mkdir()
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "pen-plotter.toml").write_text(example_toml(), encoding="utf-8")
    monkeypatch.syspath_prepend(str(tmp_path))
    provider = TargetPackage("my_machines")
    assert provider.names() == ["pen-plotter"]
    assert provider.profiles() == {"pen-plotter": "pen-plotter"}
    target = provider.target("pen-plotter", origin="plugin my_machines:TARGETS")
    assert target.motion is None  # no module: no motion model of its own
    check(example_toml(), str(target.emit(SQUARE).code))
    sys.modules.pop("my_machines", None)
