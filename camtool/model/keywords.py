"""Keyword checks of the public option classes: unknown names and renamed ones.

The naming rule of the API (docs/api.md#naming): a keyword is the command-line option's
name with ``_`` for ``-`` (``--lead-in`` → ``lead_in``), lengths in mm without a suffix,
and any other unit as a suffix (``feed_mm_min``, ``pocket_angle_deg``, ``dwell_s``). A name
that broke the rule still works for one release as a deprecated alias.
"""

from __future__ import annotations

import dataclasses
import difflib
import functools
import warnings
from typing import TYPE_CHECKING, Any, TypeVar

from camtool.model.errors import UsageError

if TYPE_CHECKING:
    from collections.abc import Callable, Mapping

T = TypeVar("T")


def checked_keywords(renamed: Mapping[str, str] | None = None) -> Callable[[type[T]], type[T]]:
    """Class decorator for a keyword-only dataclass: clear errors, deprecated aliases.

    ``renamed`` maps an old keyword to its new one: the old one is accepted (as a keyword
    and as an attribute) with a :class:`DeprecationWarning`. Any other unknown keyword
    raises :class:`UsageError` naming the valid ones (instead of ``TypeError``).
    """
    aliases = dict(renamed or {})

    def wrap(cls: type[T]) -> type[T]:
        valid = tuple(f.name for f in dataclasses.fields(cls) if f.init)  # type: ignore[arg-type]
        init = cls.__init__

        @functools.wraps(init)
        def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
            for old, new in aliases.items():
                if old in kwargs:
                    if new in kwargs:
                        raise UsageError(
                            f"{cls.__name__}: give {new}, not both {new} and {old} (its old name)"
                        )
                    _warn(cls.__name__, old, new, stacklevel=3)
                    kwargs[new] = kwargs.pop(old)
            unknown = [k for k in kwargs if k not in valid]
            if unknown:
                raise UsageError(_unknown(cls.__name__, unknown, valid))
            init(self, *args, **kwargs)

        cls.__init__ = __init__  # type: ignore[method-assign]
        for old, new in aliases.items():
            setattr(cls, old, _alias(cls.__name__, old, new))
        return cls

    return wrap


def _warn(owner: str, old: str, new: str, stacklevel: int) -> None:
    warnings.warn(
        f"{owner}.{old} is deprecated: it is called {new} (the name of its command-line "
        "option); the old name goes in the next release",
        DeprecationWarning,
        stacklevel=stacklevel,
    )


def _alias(owner: str, old: str, new: str) -> property:
    def get(self: Any) -> Any:
        _warn(owner, old, new, stacklevel=3)
        return getattr(self, new)

    return property(get, doc=f"Deprecated: :attr:`{new}`.")


def _unknown(owner: str, unknown: list[str], valid: tuple[str, ...]) -> str:
    parts = []
    for name in unknown:
        close = difflib.get_close_matches(name, valid, n=1)
        parts.append(f"{name!r}" + (f" (did you mean {close[0]!r}?)" if close else ""))
    return f"{owner}: unknown option(s) {', '.join(parts)}; valid: {', '.join(valid)}"
