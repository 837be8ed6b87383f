"""Plain frozen dataclasses: objects that may be built without their ``__init__``.

The planner and the G-code reader build moves and segments by the hundred thousand; a
frozen dataclass's ``__init__`` stores each field through ``object.__setattr__``, which
costs more than the rest of the work. For a *plain* one (the test below) an object whose
``__dict__`` is filled with the fields, in declaration order, is the object ``__init__``
makes: equal, with the same hash, ``repr`` and pickle. The fast builders check a class
here once, at import, and fall back to the constructor otherwise.
"""

from __future__ import annotations


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
