"""The wheel ships every package: pyproject's explicit list equals the folders on disk."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_package_is_listed_in_pyproject() -> None:
    config = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["tool"]["setuptools"]
    listed = set(config["packages"])
    on_disk = {
        ".".join(p.parent.relative_to(ROOT).parts) for p in (ROOT / "camtool").rglob("__init__.py")
    }
    on_disk |= {
        ".".join(("camtool_postprocessors", *p.parent.relative_to(ROOT / "postprocessors").parts))
        for p in (ROOT / "postprocessors").rglob("__init__.py")
    }
    assert config["package-dir"] == {"camtool_postprocessors": "postprocessors"}
    assert (ROOT / "postprocessors" / "__init__.py").is_file()
    assert listed == on_disk


def test_the_builtin_targets_are_the_entry_point_camtool_registers() -> None:
    """The registry loads its built-ins from the object camtool's entry point names."""
    from camtool.post.registry import BUILTIN_ENTRY_POINT, ENTRY_POINT_GROUP

    config = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["project"]
    assert list(config["entry-points"][ENTRY_POINT_GROUP].values()) == [BUILTIN_ENTRY_POINT]
