"""A drawing's SPLINEs fitted at once on the machine's cores: the same fits, read in order.

A DXF of many long splines (dxf2gcode's ``DRAAK.dxf``: 1 186 of them) spends most of its
import fitting them with biarcs (:func:`~camtool.importers.dxf_entities.spline_segments`),
one after the other. Each fit is a function of its entity and the tolerance, so the model
space's splines are fitted first in forked workers (:func:`camtool.accel.pool.map_forked`:
off with ``CAMTOOL_ACCEL=0``, on one core and inside a batch's worker) and the reader takes
each one's segments when it comes to the entity (:func:`fitted_ahead`). A fit that fails in a
worker is done again where it is read, which raises what it raises there; blocks' splines
(transformed copies made as they are read) are fitted as they are read.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from camtool.accel.cores import default_jobs
from camtool.accel.pool import map_forked
from camtool.model.shapes import Arc, Line, Segment

MIN_SPLINES = 64
"""Splines from which they are fitted ahead (a pool costs ~10 ms a worker; a long spline's
fit ~1-3 ms)."""

CHUNK = 16
"""Splines a worker fits per task (pickling and the balance between workers)."""

Fitted = tuple[list[Segment], bool]
"""What :func:`~camtool.importers.dxf_entities.spline_segments` gives: segments, closed."""

_Packed = tuple[tuple[tuple[Any, ...], ...], bool]

_TASK: list[Any] = []
"""``[entities, tolerance, check]`` while a pool fits them: the forked workers inherit it."""


def fit_ahead(
    entities: Sequence[Any],
    tolerance: float,
    fit: Callable[[Any, float], Fitted],
    check: Callable[[Any], None],
    jobs: int | None = None,
) -> dict[int, Fitted]:
    """``fit(e, tolerance)`` of every entity, on forked workers, by ``id(e)``; ``{}`` without.

    Args:
        entities: the model space's SPLINEs on the layers read (kept alive by the caller
            while the answers are used: they are keyed by ``id``).
        tolerance: drawing units (> 0).
        fit: the fit (:func:`~camtool.importers.dxf_entities.spline_segments`).
        check: run before ``fit`` in the worker (the numbers' check the reader runs first);
            what it raises leaves the entity out.
        jobs: worker processes; ``None``: the CPUs this process may use.

    Returns:
        Each entity fitted in a worker without an error; empty when no pool runs (fewer
        than :data:`MIN_SPLINES`, one worker, ``CAMTOOL_ACCEL=0``, ...).
    """
    workers = min(default_jobs() if jobs is None else jobs, -(-len(entities) // CHUNK))
    if len(entities) < MIN_SPLINES or workers < 2:
        return {}
    tasks = [(i, min(i + CHUNK, len(entities))) for i in range(0, len(entities), CHUNK)]
    _TASK[:] = [entities, tolerance, fit, check]
    try:
        results = map_forked(_fit_chunk, tasks, workers)
    finally:
        _TASK.clear()
    if results is None:
        return {}
    out: dict[int, Fitted] = {}
    for (start, _), packed in zip(tasks, results, strict=True):
        for k, one in enumerate(packed, start=start):
            if one is not None:
                out[id(entities[k])] = ([_segment(p) for p in one[0]], one[1])
    return out


def _fit_chunk(task: tuple[int, int]) -> list[_Packed | None]:
    """In a worker: the packed fits of entities ``start`` to ``stop`` of :data:`_TASK`."""
    entities, tolerance, fit, check = _TASK
    out: list[_Packed | None] = []
    for entity in entities[task[0] : task[1]]:
        try:
            check(entity)
            segs, closed = fit(entity, tolerance)
        except Exception:  # done again where it is read, which raises it there
            out.append(None)
            continue
        out.append((tuple(_packed(s) for s in segs), bool(closed)))
    return out


def _packed(s: Segment) -> tuple[Any, ...]:
    return (s.start, s.end, s.centre, s.clockwise) if isinstance(s, Arc) else (s.start, s.end)


def _segment(p: tuple[Any, ...]) -> Segment:
    return Arc(*p) if len(p) == 4 else Line(*p)


_AHEAD: list[dict[int, Fitted]] = []


@contextmanager
def fitted_ahead(fits: dict[int, Fitted]) -> Iterator[None]:
    """Within it, :func:`take` answers from ``fits`` (:func:`fit_ahead`'s)."""
    _AHEAD.append(fits)
    try:
        yield
    finally:
        _AHEAD.pop()


def take(entity: Any) -> Fitted | None:
    """The fit of ``entity`` made ahead, once (``None``: fit it here)."""
    if not _AHEAD:
        return None
    return _AHEAD[-1].pop(id(entity), None)
