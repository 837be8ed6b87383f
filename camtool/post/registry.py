"""Targets by name: providers of target files, target files, and plugins.

Design notes: docs/internals.md, ``camtool/post/registry.py``.
"""

from __future__ import annotations

import copy
import functools
import importlib
import importlib.util
import itertools
import sys
import tomllib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from importlib import metadata

    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks

from camtool.model.errors import InputError, UsageError
from camtool.model.machine import Machine, load_toml, machine_from_table, merge_tables
from camtool.post.base import PostProcessor, Target

ENTRY_POINT_GROUP = "camtool.postprocessors"
"""Entry-point group of every target provider and plugin (pyproject ``[project.entry-points]``)."""

WORD_ADDRESS = "word-address"
"""The framework's dialect family: a target file declares it wholly in ``[dialect_options]``."""

_DISTRIBUTION = "camtool"
"""Entry points of this distribution are the built-in targets."""

BUILTIN_ENTRY_POINT = "camtool_postprocessors:TARGETS"
"""The object camtool's own entry point names: its built-in targets (pyproject
``[project.entry-points."camtool.postprocessors"]``; tests/test_packaging.py holds the two
equal). The built-in targets are loaded from it directly: finding them through
:mod:`importlib.metadata` cost every command ~0.03 s of imports and a scan of the
installed distributions, and a plugin can never shadow a built-in anyway.
Plugins are still found by their entry points, when a name is not built in."""

_TOP_KEYS = {
    "name",
    "description",
    "source",
    "dialect",
    "dialect_options",
    "default_feed_mm_min",
    "spindle_rpm",
    "machine",
    "link",
}

DialectFactory = Callable[[Mapping[str, Any], str], PostProcessor]
"""Builds a dialect from its ``[dialect_options]`` table and the file's name
(for messages). Raises :class:`InputError` naming the bad key."""


class TargetPackage:
    """A target provider: a package of machines, one file or one folder each.

    A machine that needs no Python is one ``<name>.toml`` (its dialect and its
    machine together). A machine with Python is one folder ``<stem>/`` (``<stem>`` =
    the name with ``-`` → ``_``) holding ``<name>.toml`` and an ``__init__.py`` that
    builds its :class:`Target` as ``TARGET`` (:func:`folder_target`: the dialect
    factory, the verifier's motion model and the link hooks, each named there).
    A folder is imported only when its target is asked for.

    Args:
        package: the import name of the package holding the files, e.g.
            ``"camtool_postprocessors"`` (pyproject: ``[project.entry-points.
            "camtool.postprocessors"] builtin = "camtool_postprocessors:TARGETS"``).
    """

    def __init__(self, package: str) -> None:
        self.package = package

    def __repr__(self) -> str:
        return f"TargetPackage({self.package!r})"

    @functools.cached_property
    def _files(self) -> dict[str, str]:
        """Target name → its ``.toml`` file, relative to the package (``grbl/grbl.toml``)."""
        found: dict[str, str] = {}
        for entry in resources.files(self.package).iterdir():
            if entry.name.endswith(".toml"):
                found[entry.name.removesuffix(".toml")] = entry.name
            elif entry.is_dir() and entry.joinpath("__init__.py").is_file():
                name = entry.name.replace("_", "-")
                if entry.joinpath(f"{name}.toml").is_file():
                    found[name] = f"{entry.name}/{name}.toml"
        return found

    def names(self) -> list[str]:
        """Names of the targets, sorted."""
        return sorted(self._files)

    def table(self, name: str) -> dict[str, Any]:
        """The parsed ``<name>.toml`` of target ``name`` (a fresh copy).

        Raises:
            InputError: the file is not valid TOML.
        """
        return copy.deepcopy(_parse_toml(self.package, self._files[name]))

    def _parsed(self, name: str) -> Mapping[str, Any]:
        """The cached parse of ``<name>.toml``, shared: read it, never modify it."""
        return _parse_toml(self.package, self._files[name])

    def _folder(self, name: str) -> Target | None:
        """The ``TARGET`` its folder's ``__init__.py`` builds, or ``None`` for a TOML-only machine.

        Raises:
            InputError: the folder's module fails to import or gives no :class:`Target`.
        """
        file = self._files[name]
        if "/" not in file:
            return None
        module = f"{self.package}.{file.partition('/')[0]}"
        try:
            target = importlib.import_module(module).TARGET
        except InputError:
            raise
        except Exception as exc:  # a third party's bug must not crash the CLI
            raise InputError(f"{module} is broken: {type(exc).__name__}: {exc}") from exc
        if not isinstance(target, Target):
            raise InputError(f"{module}.TARGET is a {type(target).__name__}, not a Target")
        return target

    def dialect(self, dialect: str) -> DialectFactory | None:
        """The factory of ``dialect`` if a machine folder of this package provides it."""
        for name in self.names():
            if self._parsed(name).get("dialect") == dialect:
                target = self._folder(name)
                if target is not None and target.dialect_factory is not None:
                    return target.dialect_factory
        return None

    def dialects(self) -> set[str]:
        """Names of the dialects the targets of this package declare."""
        return {str(self._parsed(n).get("dialect")) for n in self.names()}

    def profiles(self) -> dict[str, str]:
        """Machine profile name → the target whose ``[machine]`` table declares it."""
        found: dict[str, str] = {}
        for name in self.names():
            machine = self._parsed(name).get("machine")
            if isinstance(machine, Mapping) and isinstance(machine.get("profile"), str):
                found.setdefault(machine["profile"], name)
        return found

    def target(
        self, name: str, *, machine_file: Path | str | None = None, origin: str = "builtin"
    ) -> Target:
        """Target ``name``: its folder's ``TARGET``, or built from its TOML alone.

        Raises:
            InputError: the file, its machine or its dialect options are invalid.
        """
        built = self._folder(name)
        if built is not None and machine_file is None and origin == built.origin:
            return built
        return _target_from_table(
            self.table(name),
            where=f"{name}.toml",
            machine_file=machine_file,
            origin=origin,
            provider=self,
            factory=built.dialect_factory if built else None,
            motion=built.motion_hook if built else None,
            link=built.link_hook if built else None,
        )


def folder_target(
    package: str,
    *,
    dialect: DialectFactory | None = None,
    motion: Callable[[], MotionHooks] | None = None,
    link: Callable[[], LinkHooks] | None = None,
) -> Target:
    """The target of a machine folder, built from its ``<name>.toml`` and the Python it names.

    Args:
        package: the folder's import name (its ``__name__``), e.g.
            ``"camtool_postprocessors.pic_mmh"``; the target file is ``pic-mmh.toml`` in it.
        dialect: builds the dialect its file declares by name (``dialect = "pic-mmh"``),
            when that is not ``word-address``.
        motion: returns the verifier's motion model (imported when first asked for).
        link: returns the link hooks of ``camtool send`` (imported when first asked for).

    Raises:
        InputError: the file, its machine or its dialect options are invalid.
    """
    name = package.rpartition(".")[2].replace("_", "-")
    return _target_from_table(
        copy.deepcopy(_parse_toml(package, f"{name}.toml")),
        where=f"{name}.toml",
        machine_file=None,
        origin="builtin",
        factory=dialect,
        motion=motion,
        link=link,
    )


@functools.cache
def _parse_toml(package: str, file: str) -> dict[str, Any]:
    text = resources.files(package).joinpath(file).read_text("utf-8")
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{file.rpartition('/')[2]}: not valid TOML ({exc})") from exc


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


def _entry_points() -> tuple[tuple[metadata.EntryPoint, ...], tuple[metadata.EntryPoint, ...]]:
    """Entry points of :data:`ENTRY_POINT_GROUP`: (camtool's own, third-party), by name.

    :mod:`importlib.metadata` is imported here, when plugins are asked for (see
    :data:`BUILTIN_ENTRY_POINT`). The installed distributions are scanned once for each
    ``sys.path`` (and discovery function): the verifier asks for the targets' motion models
    at every simulation. A distribution installed on a path already scanned is seen by a
    new process.
    """
    from importlib import metadata

    return _entry_points_on(tuple(sys.path), metadata.entry_points)


@functools.lru_cache(maxsize=4)
def _entry_points_on(
    path: tuple[str, ...], scan: Callable[..., metadata.EntryPoints]
) -> tuple[tuple[metadata.EntryPoint, ...], tuple[metadata.EntryPoint, ...]]:
    """:func:`_entry_points` as ``scan`` finds them on the search path ``path`` (the key)."""
    found = sorted(scan(group=ENTRY_POINT_GROUP), key=lambda ep: ep.name)
    own = tuple(ep for ep in found if ep.dist is not None and ep.dist.name == _DISTRIBUTION)
    return own, tuple(ep for ep in found if ep not in own)


@functools.cache
def _builtin_providers() -> tuple[TargetPackage, ...]:
    """The providers camtool itself registers: :data:`BUILTIN_ENTRY_POINT`'s, loaded directly.

    Raises:
        InputError: the ``camtool_postprocessors`` package is missing or gives no
            provider (camtool is installed incompletely: reinstall it).
    """
    module, _, name = BUILTIN_ENTRY_POINT.partition(":")
    try:
        provider = getattr(importlib.import_module(module), name)
    except (ImportError, AttributeError) as exc:
        raise InputError(
            f"camtool's built-in targets cannot be loaded ({BUILTIN_ENTRY_POINT}: {exc}); "
            "reinstall camtool (pip install -e .)"
        ) from exc
    if not isinstance(provider, TargetPackage):
        raise InputError(
            f"camtool's built-in targets cannot be loaded ({BUILTIN_ENTRY_POINT} is a "
            f"{type(provider).__name__}); reinstall camtool (pip install -e .)"
        )
    return (provider,)


def _builtin(name: str) -> TargetPackage | None:
    """The built-in provider of target ``name``, if any."""
    return next((p for p in _builtin_providers() if name in p.names()), None)


def target_names() -> list[str]:
    """Names of the built-in targets, sorted."""
    return sorted({n for p in _builtin_providers() for n in p.names()})


def _load_entry(ep: metadata.EntryPoint) -> TargetPackage | Target:
    """What a plugin entry point names: a provider, or the single target it gives.

    Raises:
        InputError: the plugin cannot be imported, raises, or gives neither.
    """
    where = f"plugin {ep.name!r} ({ep.value})"
    try:
        obj = ep.load()
        if isinstance(obj, TargetPackage):
            return obj
        target = obj() if callable(obj) and not isinstance(obj, Target) else obj
    except Exception as exc:  # a third party's bug must not crash the CLI
        raise InputError(f"{where} is broken: {type(exc).__name__}: {exc}") from exc
    if not isinstance(target, Target):
        raise InputError(f"{where} is broken: it gives {type(target).__name__}, not a Target")
    if not isinstance(target.post, PostProcessor):
        raise InputError(f"{where} is broken: its post is not a PostProcessor")
    return replace(target, origin=f"plugin {ep.value}")


def _plugin_providers() -> Iterator[tuple[metadata.EntryPoint, TargetPackage]]:
    """Third-party providers that load (broken plugins are skipped here)."""
    for ep in _entry_points()[1]:
        try:
            loaded = _load_entry(ep)
        except InputError:
            continue
        if isinstance(loaded, TargetPackage):
            yield ep, loaded


def list_targets() -> list[TargetEntry]:
    """Every target camtool knows: built-ins, then plugins (broken ones included), by name."""
    builtin = target_names()
    entries = [TargetEntry(name, "builtin", load_target(name)) for name in builtin]
    plugins: list[TargetEntry] = []
    for ep in _entry_points()[1]:
        origin = f"plugin {ep.value}"
        try:
            loaded = _load_entry(ep)
        except InputError as exc:
            if ep.name not in builtin:
                plugins.append(TargetEntry(ep.name, origin, None, str(exc)))
            continue
        if isinstance(loaded, Target):
            if ep.name not in builtin:
                plugins.append(TargetEntry(ep.name, origin, loaded))
            continue
        for name in loaded.names():
            if name in builtin:
                continue
            try:
                plugins.append(TargetEntry(name, origin, loaded.target(name, origin=origin)))
            except InputError as exc:
                plugins.append(TargetEntry(name, origin, None, f"{origin}: {exc}"))
    return entries + sorted(plugins, key=lambda e: e.name)


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
            load_toml(path, "target file"),
            where=str(path),
            machine_file=machine_file,
            origin=str(path),
        )
    provider = _builtin(name)
    if provider is not None:
        return provider.target(name, machine_file=machine_file)
    others = _entry_points()[1]
    for ep in others:
        if ep.name == name:
            loaded = _load_entry(ep)
            if isinstance(loaded, Target):
                return _with_machine_file(loaded, machine_file)
    names = [*target_names(), *(ep.name for ep in others)]
    for ep, plugin in _plugin_providers():
        if name in plugin.names():
            return plugin.target(name, machine_file=machine_file, origin=f"plugin {ep.value}")
        names += plugin.names()
    known = sorted(set(names) - set(target_names()), key=names.index)
    raise UsageError(
        f"unknown target {name!r}; choose one of: {', '.join([*target_names(), *known])} "
        "(or a target .toml file)"
    )


def _with_machine_file(target: Target, machine_file: Path | str | None) -> Target:
    """``target`` with the ``[machine]`` table of ``machine_file`` laid over its machine."""
    if machine_file is None:
        return target
    table, where = _machine_over(target.machine.table, target.origin, machine_file)
    return replace(target, machine=machine_from_table(table, where=where))


def _machine_over(
    machine: Mapping[str, Any], where: str, machine_file: Path | str | None
) -> tuple[Mapping[str, Any], str]:
    """``machine`` (a ``[machine]`` table from ``where``) with ``machine_file`` laid over it.

    Returns the table and where it comes from, for messages: ``where`` alone without
    a machine file, else ``"<machine file> (over <where>)"``.

    Raises:
        InputError: the machine file is unknown, unreadable or not valid TOML.
    """
    if machine_file is None:
        return machine, where
    override, where_override = machine_table(str(machine_file))
    merged = _pieces_kept(machine, override, merge_tables(machine, override))
    return merged, f"{where_override} (over {where})"


_PIECES = (
    ("motion", "line", lambda h: {**h.lines, **h.simulators}),
    ("motion", "arc", lambda h: h.arcs),
    ("motion", "chords", lambda h: h.chords),
    ("timing", "model", lambda h: h.timing),
)
"""The keys of a ``[machine]`` table that name a motion piece, and where it is found."""


def _pieces_kept(
    base: Mapping[str, Any], override: Mapping[str, Any], merged: dict[str, Any]
) -> dict[str, Any]:
    """``merged`` with the base's own motion pieces kept when ``override`` renames the profile.

    The profile names the target whose ``MOTION`` an unqualified piece name is looked
    up in (:func:`camtool.verify.motion.library`). A machine file that renames it (a
    user naming their machine ``profile = "shapeoko"``) keeps the pieces the base named
    from its built-in target's ``MOTION`` and did not set itself: they are qualified with
    that target (``chords = "grbl"`` becomes ``"grbl:grbl"``). A name of the generic library
    stays as it is (no built-in target gives a piece a generic name; a test keeps it so).
    """
    old, new = base.get("profile"), override.get("profile")
    if not isinstance(old, str) or not old or new == old:
        return merged
    target = next((p.profiles()[old] for p in _builtin_providers() if old in p.profiles()), None)
    hooks = profile_motion(old)
    if target is None or hooks is None:
        return merged
    for table, key, pick in _PIECES:
        section = merged.get(table)
        own = override.get(table)
        if not isinstance(section, Mapping) or (isinstance(own, Mapping) and key in own):
            continue
        name = section.get(key)
        if isinstance(name, str) and name in pick(hooks):
            merged[table] = {**section, key: f"{target}:{name}"}
    return merged


def _dialect(dialect: Any, where: str, provider: TargetPackage | None) -> DialectFactory:
    """The factory of ``dialect``: the framework's word-address family, or a provider's.

    The provider of the target file itself is asked first, then camtool's own
    targets, then third-party providers.

    Raises:
        InputError: no provider offers ``dialect`` (the message lists the known ones).
    """
    if dialect == WORD_ADDRESS:
        from camtool.post.wordaddress import word_address_dialect

        return word_address_dialect
    if isinstance(dialect, str):
        providers = [*([provider] if provider else []), *_builtin_providers()]
        for p in itertools.chain(providers, (p for _, p in _plugin_providers())):
            if factory := p.dialect(dialect):
                return factory
    known = {WORD_ADDRESS} | {d for p in _builtin_providers() for d in p.dialects()}
    raise InputError(f"{where}: unknown dialect {dialect!r}; known: {sorted(known)}")


def _target_from_table(
    table: Mapping[str, Any],
    *,
    where: str,
    machine_file: Path | str | None,
    origin: str,
    provider: TargetPackage | None = None,
    factory: DialectFactory | None = None,
    motion: Callable[[], MotionHooks | None] | None = None,
    link: Callable[[], LinkHooks | None] | None = None,
) -> Target:
    unknown = sorted(set(table) - _TOP_KEYS)
    if unknown:
        raise InputError(f"{where}: unknown key(s) {unknown}; known: {sorted(_TOP_KEYS)}")
    options = table.get("dialect_options", {})
    if factory is None:
        factory = _dialect(table.get("dialect"), where, provider)
    elif table.get("dialect") in (None, WORD_ADDRESS):
        raise InputError(f"{where}: a folder's dialect factory needs the dialect's name in dialect")
    if not isinstance(options, Mapping):
        raise InputError(f"{where}: dialect_options must be a table")
    machine = table.get("machine", {})
    where_machine = where
    if isinstance(machine, str):
        machine, where_machine = machine_table(machine)
    machine, where_machine = _machine_over(machine, where_machine, machine_file)
    post = factory(options, where)
    link_table = table.get("link", {})
    if not isinstance(link_table, Mapping):
        raise InputError(f"{where}: [link] must be a table")
    built = machine_from_table(machine, where=where_machine)
    _check_z_word(post, built, where, where_machine)
    return Target(
        name=_text(table, "name", where, Path(where).stem),
        description=_text(table, "description", where, ""),
        post=post,
        machine=built,
        default_feed_mm_min=_number(table, "default_feed_mm_min", where, 100.0),
        source=_text(table, "source", where, ""),
        spindle_rpm=_number(table, "spindle_rpm", where, None),
        origin=origin,
        motion_hook=motion,
        link_table=MappingProxyType(dict(link_table)),
        link_hook=link,
        dialect_factory=factory if table.get("dialect") != WORD_ADDRESS else None,
    )


def _check_z_word(post: PostProcessor, machine: Machine, where: str, where_machine: str) -> None:
    """Refuse a machine with a Z axis whose dialect writes no Z word.

    Every depth, safe height and plunge of such a target would be refused block by block
    as the program is written (or, re-posting, dropped): the file is what to change.

    Raises:
        InputError: naming both files' keys to change.
    """
    if not machine.has_z or not isinstance(post, PostProcessor):
        return
    if post.for_machine(machine).written_z(1.0, machine) is not None:
        return
    machine_at = "" if where_machine == where else f" ({where_machine})"
    raise InputError(
        f"{where}: the machine has a Z axis (has_z = true{machine_at}) but the dialect "
        "writes no Z word: give the dialect a Z word (z_moves and a Z in [dialect_options."
        "words]) or set has_z = false for a machine whose depth is set by hand"
    )


def _text(table: Mapping[str, Any], key: str, where: str, default: str) -> str:
    """A target file's ``name``, ``description`` or ``source``: one printable line of text.

    Raises:
        InputError: not a string (``name = 1e308`` was written as ``1e+308``), or a control
            character in it (a line break would end the message that names the target).
    """
    value = table.get(key, default)
    if not isinstance(value, str) or not value.isprintable() or (key == "name" and not value):
        raise InputError(
            f"{where}: {key} must be one line of printable text in quotes, not {value!r}"
        )
    return value


def _number(table: Mapping[str, Any], key: str, where: str, default: Any) -> Any:
    value = table.get(key, default)
    if value is default:
        return value
    low, high = _LIMITS.get(key, (0.0, 1e6))
    if (
        isinstance(value, bool)
        or not isinstance(value, int | float)
        or not (value > 0 and low <= value <= high)
    ):
        raise InputError(
            f"{where}: {key} must be a number from {low:g} to {high:g} (a physical machine), "
            f"not {value!r}"
        )
    return float(value)


_LIMITS = {"spindle_rpm": (1.0, 1e6), "default_feed_mm_min": (1e-3, 1e6)}
"""Range of a target file's top-level numbers (rev/min, mm/min); nan is refused. A spindle
below 1 rev/min does not turn (``M3 S0``)."""


def machine_names() -> list[str]:
    """Names of the built-in machine profiles (``profile`` of built-in targets), sorted."""
    return sorted({m for p in _builtin_providers() for m in p.profiles()})


def machine_table(name: str) -> tuple[dict[str, Any], str]:
    """The profile table called ``name`` (built in) or at path ``name`` (``.toml``).

    A profile file holds the machine keys at its top level or in a ``[machine]``
    table. A built-in profile is the ``[machine]`` table of the built-in target
    that declares it (``profile = "mmh-gmm"`` in ``postprocessors/pic_mmh/pic-mmh.toml``).
    Returns the table and the name to use in messages.

    Raises:
        InputError: no such profile or file, or not valid TOML.
    """
    if name.endswith(".toml") or Path(name).is_file():
        table = load_toml(Path(name), "machine file")
        where = name
    else:
        for provider in _builtin_providers():
            target = provider.profiles().get(name)
            if target is not None:
                table, where = provider.table(target), f"{target}.toml"
                break
        else:
            raise InputError(
                f"unknown machine profile {name!r}; give a .toml file or one of: "
                f"{', '.join(machine_names())}"
            )
    inner = table.get("machine", table)
    if not isinstance(inner, Mapping):
        raise InputError(f"{where}: [machine] must be a table")
    return dict(inner), where


def load_machine(name: str) -> Machine:
    """The machine profile called ``name`` or at path ``name`` (see :func:`machine_table`).

    Raises:
        InputError: no such profile, or an invalid one.
    """
    table, where = machine_table(name)
    return machine_from_table(table, where=where)


def profile_motion(profile: str) -> MotionHooks | None:
    """The motion model of the target whose ``[machine]`` table declares ``profile``.

    A machine profile names its interpolators, chord rule and timing model in the
    generic library or in the ``MOTION`` of the target it belongs to
    (:func:`camtool.verify.motion.library`). Built-in targets are asked first, then
    plugins (a broken plugin is skipped). ``None`` when no target declares the profile
    or it has no motion model.
    """
    if not profile:
        return None
    for provider in _builtin_providers():
        if (name := provider.profiles().get(profile)) is not None:
            return provider.target(name).motion
    for ep, plugin in _plugin_providers():
        if (name := plugin.profiles().get(profile)) is not None:
            try:
                return plugin.target(name, origin=f"plugin {ep.value}").motion
            except InputError:
                return None
    return None


def target_motion(name: str) -> MotionHooks | None:
    """The motion model of target ``name`` (for a qualified piece name ``"grbl:grbl"``).

    Only an installed target's name: a target file's path is not read for a piece's name.

    Raises:
        UsageError: no such target, or a path.
        InputError: the target is broken.
    """
    if name.endswith(".toml") or "/" in name:
        raise UsageError(f"{name!r} is a path, not the name of an installed target")
    return load_target(name).motion
