"""Targets by name: built-in TOML files, target files, and plugins.

A target file (``camtool/targets/<name>.toml`` or any ``--target path.toml``)
holds ``name``, ``description``, ``source``, ``dialect`` (a key of
:data:`DIALECTS`), ``default_feed_mm_min``, optional ``spindle_rpm``, a
``[dialect_options]`` table for that dialect and ``machine`` (a built-in
profile name or a ``[machine]`` table, :mod:`camtool.model.machine`). Every field is
documented in docs/targets/index.md and docs/dialects.md.

Third-party Python targets register under the entry-point group
:data:`ENTRY_POINT_GROUP`; the object an entry point names is a
:class:`~camtool.post.base.Target` or a callable returning one. A plugin that
fails to load is listed by :func:`list_targets` as broken with the reason, and
choosing it is a clear error; it never crashes the CLI.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from importlib import metadata, resources
from pathlib import Path
from typing import Any

from camtool.model.errors import InputError, UsageError
from camtool.model.machine import load_toml, machine_from_table, machine_table, merge_tables
from camtool.post.base import PostProcessor, Target

ENTRY_POINT_GROUP = "camtool.postprocessors"
"""Entry-point group of third-party targets (pyproject ``[project.entry-points]``)."""

_TOP_KEYS = {
    "name",
    "description",
    "source",
    "dialect",
    "dialect_options",
    "default_feed_mm_min",
    "spindle_rpm",
    "machine",
}

DialectFactory = Callable[[Mapping[str, Any], str], PostProcessor]
"""Builds a dialect from its ``[dialect_options]`` table and the file's name
(for messages). Raises :class:`InputError` naming the bad key."""


def _class_factory(module: str, cls: str) -> DialectFactory:
    """A factory for a dialect class taking its options as keyword arguments."""

    def build(options: Mapping[str, Any], where: str) -> PostProcessor:
        post_class = getattr(importlib.import_module(module), cls)
        try:
            post: PostProcessor = post_class(**options)
        except (TypeError, ValueError) as exc:
            raise InputError(f"{where}: invalid dialect_options ({exc})") from exc
        return post

    return build


def _spec_factory(module: str, function: str) -> DialectFactory:
    """A factory for a dialect built by ``module.function(options, where)``."""

    def build(options: Mapping[str, Any], where: str) -> PostProcessor:
        post: PostProcessor = getattr(importlib.import_module(module), function)(options, where)
        return post

    return build


DIALECTS: dict[str, DialectFactory] = {
    "pic-mmh": _class_factory("camtool.post.pic_mmh", "PicMmhPost"),
    "matlab-router": _class_factory("camtool.post.matlab_router", "MatlabRouterPost"),
    "i8751": _class_factory("camtool.post.i8751", "I8751Post"),
    "word-address": _spec_factory("camtool.post.wordaddress", "word_address_dialect"),
}
"""Dialects by the name a target file gives in ``dialect``. Modules are imported
only when a target uses them."""


@dataclass(frozen=True)
class TargetEntry:
    """One row of ``camtool targets``.

    Attributes:
        name: the name given to ``--target``.
        origin: "builtin" or "plugin" (``module:object`` of the entry point).
        target: the loaded target, or ``None`` when it is broken.
        error: why a broken target could not be loaded ("" when it loaded).
    """

    name: str
    origin: str
    target: Target | None
    error: str = ""


def target_names() -> list[str]:
    """Names of the built-in targets, sorted."""
    files = resources.files("camtool.targets").iterdir()
    return sorted(f.name.removesuffix(".toml") for f in files if f.name.endswith(".toml"))


def _plugins() -> dict[str, metadata.EntryPoint]:
    """Entry points of :data:`ENTRY_POINT_GROUP` by name (built-in names win)."""
    builtin = set(target_names())
    found = metadata.entry_points(group=ENTRY_POINT_GROUP)
    return {ep.name: ep for ep in found if ep.name not in builtin}


def _load_plugin(ep: metadata.EntryPoint) -> Target:
    """The target a plugin entry point provides.

    Raises:
        InputError: the plugin cannot be imported, raises, or gives no Target.
    """
    where = f"plugin {ep.name!r} ({ep.value})"
    try:
        obj = ep.load()
        target = obj() if callable(obj) and not isinstance(obj, Target) else obj
    except Exception as exc:  # a third party's bug must not crash the CLI
        raise InputError(f"{where} is broken: {type(exc).__name__}: {exc}") from exc
    if not isinstance(target, Target):
        raise InputError(f"{where} is broken: it gives {type(target).__name__}, not a Target")
    if not isinstance(target.post, PostProcessor):
        raise InputError(f"{where} is broken: its post is not a PostProcessor")
    return replace(target, origin=f"plugin {ep.value}")


def list_targets() -> list[TargetEntry]:
    """Every target camtool knows: built-ins, then plugins (broken ones included), by name."""
    entries = [TargetEntry(name, "builtin", load_target(name)) for name in target_names()]
    for name, ep in sorted(_plugins().items()):
        try:
            entries.append(TargetEntry(name, f"plugin {ep.value}", _load_plugin(ep)))
        except InputError as exc:
            entries.append(TargetEntry(name, f"plugin {ep.value}", None, str(exc)))
    return entries


def load_target(name: str, *, machine_file: Path | str | None = None) -> Target:
    """The target called ``name`` (or the target file at path ``name``).

    Args:
        name: a built-in target name, a plugin's name, or a path to a target
            ``.toml`` file.
        machine_file: a TOML file (or built-in profile name) whose ``[machine]``
            table is laid over the target's machine profile, key by key
            (:func:`camtool.model.machine.merge_tables`).

    Raises:
        UsageError: no such target (the message lists the valid names).
        InputError: a target or machine file is unreadable or invalid, or the
            plugin is broken.
    """
    if name.endswith(".toml"):
        path = Path(name)
        return _target_from_table(
            load_toml(path), where=str(path), machine_file=machine_file, origin=str(path)
        )
    if name in target_names():
        return _target_from_table(
            _builtin(name), where=f"{name}.toml", machine_file=machine_file, origin="builtin"
        )
    plugins = _plugins()
    if name in plugins:
        target = _load_plugin(plugins[name])
        if machine_file is not None:
            override, where_override = machine_table(str(machine_file))
            base = target.machine.table
            machine = machine_from_table(merge_tables(base, override), where=where_override)
            target = replace(target, machine=machine)
        return target
    names = [*target_names(), *sorted(plugins)]
    raise UsageError(
        f"unknown target {name!r}; choose one of: {', '.join(names)} (or a target .toml file)"
    )


def _builtin(name: str) -> dict[str, Any]:
    import tomllib

    text = resources.files("camtool.targets").joinpath(f"{name}.toml").read_text("utf-8")
    return tomllib.loads(text)


def _target_from_table(
    table: Mapping[str, Any],
    *,
    where: str,
    machine_file: Path | str | None,
    origin: str,
) -> Target:
    unknown = sorted(set(table) - _TOP_KEYS)
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; known: {sorted(_TOP_KEYS)}")
    dialect = table.get("dialect")
    options = table.get("dialect_options", {})
    if dialect not in DIALECTS:
        raise InputError(f"{where}: unknown dialect {dialect!r}; known: {sorted(DIALECTS)}")
    if not isinstance(options, Mapping):
        raise InputError(f"{where}: dialect_options must be a table")
    machine = table.get("machine", {})
    where_machine = where
    if isinstance(machine, str):
        machine, where_machine = machine_table(machine)
    if machine_file is not None:
        override, where_override = machine_table(str(machine_file))
        machine = merge_tables(machine, override)
        where_machine = f"{where_override} (over {where_machine})"
    post = DIALECTS[dialect](options, where)
    return Target(
        name=str(table.get("name", Path(where).stem)),
        description=str(table.get("description", "")),
        post=post,
        machine=machine_from_table(machine, where=where_machine),
        default_feed_mm_min=_number(table, "default_feed_mm_min", where, 100.0),
        source=str(table.get("source", "")),
        spindle_rpm=_number(table, "spindle_rpm", where, None),
        origin=origin,
    )


def _number(table: Mapping[str, Any], key: str, where: str, default: Any) -> Any:
    value = table.get(key, default)
    if value is default:
        return value
    if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
        raise InputError(f"{where}: {key} must be a positive number, not {value!r}")
    return float(value)


def motion_hooks() -> list[tuple[str, Any]]:
    """The ``MOTION`` object of every target that declares one, as ``(target name, MOTION)``.

    A target's motion model for the verifier (interpolators, chord rules, timing
    models, simulators it adds to :mod:`camtool.verify`'s generic library) is the
    ``MOTION`` attribute of its module ``<package>.<stem>_motion`` (or, for a
    one-module plugin, of ``<package>.<stem>``). Modules are imported on the
    first call only (the verifier asks; listing targets does not).
    """
    found: list[tuple[str, Any]] = []
    for name in target_names():
        stem = name.replace("-", "_")
        for module in (f"camtool_postprocessors.{stem}_motion", f"camtool_postprocessors.{stem}"):
            try:
                hooks = getattr(importlib.import_module(module), "MOTION", None)
            except ModuleNotFoundError:
                continue
            if hooks is not None:
                found.append((name, hooks))
                break
    return found
