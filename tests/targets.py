"""The built-in targets and their default file endings, from the registry (not a copy)."""

from __future__ import annotations

from camtool.post.registry import list_targets

_BUILTIN = [e for e in list_targets() if e.origin == "builtin" and e.target is not None]

TARGETS: tuple[str, ...] = tuple(e.name for e in _BUILTIN)
"""Every built-in target name, in `camtool targets` order."""

EXTENSIONS: dict[str, str] = {e.name: e.target.post.suffix for e in _BUILTIN if e.target}
"""The default output format's file ending of each built-in target."""
