"""Targets by name: the built-in TOML files of :mod:`camtool.targets`.

A target file holds ``name``, ``description``, ``source``, ``dialect`` (the
name of a dialect class), ``default_feed_mm_min``, a ``[dialect]`` table of
options for that class, and a ``[machine]`` table (:mod:`camtool.machine`).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from importlib import resources
from pathlib import Path
from typing import Any

from camtool.errors import InputError, UsageError
from camtool.machine import load_toml, machine_from_table, machine_table, merge_tables
from camtool.post.base import PostProcessor, Target

_TOP_KEYS = {"name", "description", "source", "dialect", "default_feed_mm_min", "machine"}


def _pic_mmh(options: Mapping[str, Any]) -> PostProcessor:
    from camtool.post.pic_mmh import PicMmhPost

    return PicMmhPost(**options)


DIALECTS: dict[str, Callable[[Mapping[str, Any]], PostProcessor]] = {"pic-mmh": _pic_mmh}
"""Dialect classes by the name a target file gives in ``dialect``."""


def target_names() -> list[str]:
    """Names of the built-in targets, sorted."""
    files = resources.files("camtool.targets").iterdir()
    return sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml"))


def load_target(name: str, *, machine_file: Path | None = None) -> Target:
    """The target called ``name`` (or the target file at path ``name``).

    Args:
        name: a built-in target name, or a path to a target ``.toml`` file.
        machine_file: a TOML file whose ``[machine]`` table (or top level) is
            laid over the target's machine profile, key by key
            (:func:`camtool.machine.merge_tables`).

    Raises:
        UsageError: no such target (the message lists the valid names).
        InputError: a target or machine file is unreadable or invalid.
    """
    if name.endswith(".toml"):
        path = Path(name)
        table = load_toml(path)
    elif name in target_names():
        path = Path(f"{name}.toml")
        table = _builtin(name)
    else:
        raise UsageError(f"unknown target {name!r}; choose one of: {', '.join(target_names())}")
    return _target_from_table(table, where=str(path), machine_file=machine_file)


def _builtin(name: str) -> dict[str, Any]:
    import tomllib

    text = resources.files("camtool.targets").joinpath(f"{name}.toml").read_text("utf-8")
    return tomllib.loads(text)


def _target_from_table(
    table: Mapping[str, Any], *, where: str, machine_file: Path | None
) -> Target:
    unknown = sorted(set(table) - _TOP_KEYS - {"dialect_options"})
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; known: {sorted(_TOP_KEYS)}")
    dialect = table.get("dialect")
    options = table.get("dialect_options", {})
    if dialect not in DIALECTS:
        raise InputError(f"{where}: unknown dialect {dialect!r}; known: {sorted(DIALECTS)}")
    machine = table.get("machine", {})
    where_machine = where
    if isinstance(machine, str):
        machine, where_machine = machine_table(machine)
    if machine_file is not None:
        override, where_override = machine_table(str(machine_file))
        machine = merge_tables(machine, override)
        where_machine = f"{where_override} (over {where_machine})"
    try:
        post = DIALECTS[dialect](options)
    except TypeError as exc:
        raise InputError(f"{where}: invalid dialect_options ({exc})") from exc
    return Target(
        name=str(table.get("name", Path(where).stem)),
        description=str(table.get("description", "")),
        post=post,
        machine=machine_from_table(machine, where=where_machine),
        default_feed_mm_min=float(table.get("default_feed_mm_min", 100.0)),
        source=str(table.get("source", "")),
    )
