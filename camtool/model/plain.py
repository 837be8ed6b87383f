"""Plain frozen dataclasses: objects that may be built without their ``__init__``.

Two kinds: dataclasses whose fields live in a ``__dict__`` (:func:`plain_fields`) and
slotted ones (``slots=True``: no ``__dict__``, ~100 bytes less an object;
:func:`slot_setters`).

Design notes: docs/internals.md, ``camtool/model/plain.py``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def plain_fields(cls: type) -> tuple[str, ...] | None:
    """The field names of ``cls``, in order, when it is a plain dataclass; else ``None``.

    Plain: a dataclass with its own generated ``__init__``, no ``__post_init__`` (nothing
    checked or derived at construction) and no ``__slots__`` (its fields live in its
    ``__dict__``).
    """
    fields = getattr(cls, "__dataclass_fields__", None)
    if not fields or hasattr(cls, "__post_init__") or "__slots__" in vars(cls):
        return None
    return tuple(fields) if "__init__" in vars(cls) else None


def share_keys(cls: type, names: tuple[str, ...]) -> None:
    """Make room for ``names`` in the ``__dict__`` of every later instance of ``cls``.

    A memory measure with no effect on behaviour. CPython (3.11+) keeps the attributes of a
    class's instances in *split* dicts: the keys once per class, the values per instance
    in an array sized, when the instance is made, for the keys the class has learned so
    far. Values kept later on an instance (:class:`~camtool.model.shapes.cached_property`,
    an arc's axis signs) that do not fit turn its dict into an ordinary one, ~170 bytes
    more per object. This makes a first instance holding ``names`` (the fields first, in
    order, then what is kept later), so the class learns them all; the instance is
    thrown away. Call it right after the class is defined, before any instance is made.

    Args:
        cls: a class whose instances have a ``__dict__``.
        names: every attribute its instances may hold, fields first, in order.
    """
    first: object = object.__new__(cls)
    values = first.__dict__
    for name in names:
        values[name] = None


def slot_setters(cls: type) -> tuple[Callable[[Any, Any], None], ...] | None:
    """The setters of a slotted dataclass's fields, in order, when it is plain; else ``None``.

    Plain here: a dataclass with ``__slots__`` (``slots=True``) holding exactly its fields,
    its own generated ``__init__`` and no ``__post_init__``. ``object.__new__(cls)`` then each
    setter called with the instance and a field's value, in order, makes the object its
    ``__init__`` makes (equal, same hash, ``repr`` and pickle) without the frozen
    ``__setattr__`` detour, which costs more than the rest of the work per move.
    """
    fields = getattr(cls, "__dataclass_fields__", None)
    slots = vars(cls).get("__slots__")
    if not fields or hasattr(cls, "__post_init__") or "__init__" not in vars(cls):
        return None
    if slots is None or tuple(slots) != tuple(fields):
        return None
    return tuple(vars(cls)[name].__set__ for name in fields)
