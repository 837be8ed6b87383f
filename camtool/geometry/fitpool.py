"""Many curve fits at once: the same biarc fits, on the machine's cores, results in order.

Design notes: docs/internals.md, ``camtool/geometry/fitpool.py``.
"""

from __future__ import annotations

import pickle
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager, suppress
from pathlib import Path
from typing import Any, TypeAlias

import numpy as np

from camtool.accel import enabled
from camtool.accel.ahead import HelperAhead
from camtool.accel.cores import default_jobs
from camtool.accel.pool import map_forked
from camtool.geometry.arcfit import (
    FIT_KERNELS,
    KERNEL_FROM,
    MAX_DEPTH,
    fit_curve,
    fit_limits,
    segments_of,
)
from camtool.geometry.curves import (
    cubic_bezier,
    cubic_bezier_points,
    ellipse_arc,
    ellipse_arc_points,
    quadratic_bezier,
    quadratic_bezier_points,
)
from camtool.model.shapes import Arc, Line, Segment

__all__ = [
    "AHEAD_FROM_BYTES",
    "FIT_KERNELS",
    "KERNEL_FROM",
    "MIN_CURVES",
    "CurveKey",
    "SharedFits",
    "fit_key",
    "fit_many",
    "fit_shared",
    "fitter_ahead",
    "moved",
    "shape_key",
    "start_ahead",
    "stop_ahead",
]

CurveKey: TypeAlias = tuple[str, tuple[Any, ...]]
"""A curve by kind and exact arguments: ``("cubic", (p0, p1, p2, p3))``, ``("quadratic",
(p0, p1, p2))`` or ``("ellipse_arc", (centre, a, b, t0, sweep, p0, p1))`` (mm, Y up), the
arguments of :func:`~camtool.geometry.curves.cubic_bezier`, ``quadratic_bezier`` or
``ellipse_arc``."""

MIN_CURVES = 400
"""Fewer keys than this are fitted here, without workers (a pool costs ~10 ms a worker; a
fit ~1 ms: below a few hundred curves the pool would not pay for itself)."""

_CHUNK = 48  # keys per task sent to a worker: pickling overhead vs balance between workers

_BEZIERS: dict[str, tuple[Any, Any]] = {
    "cubic": (cubic_bezier, cubic_bezier_points),
    "quadratic": (quadratic_bezier, quadratic_bezier_points),
}

_KINDS = {"cubic": 0, "quadratic": 1, "ellipse_arc": 2}
"""The compiled fitter's curve kinds (``fitkernels.CUBIC``, ``QUADRATIC``, ``ELLIPSE_ARC``)."""

_Packed: TypeAlias = tuple[Any, ...]


def fit_key(key: CurveKey, tolerance: float) -> list[Segment]:
    """The biarc fit of the curve ``key`` names, over its whole range ``u`` ∈ [0, 1].

    Raises:
        KeyError: unknown kind.
        UsageError, GeometryError: from :func:`~camtool.geometry.arcfit.fit_curve`.
    """
    kind, args = key
    kernels = FIT_KERNELS.get(1)
    if kernels is not None:
        segs = _compiled(kernels, key, tolerance)
        if segs is not None:
            return segs
    if kind == "ellipse_arc":
        point_at, tangent_at = ellipse_arc(*args)
        points_at = ellipse_arc_points(*args)
    else:
        make, make_points = _BEZIERS[kind]
        point_at, tangent_at = make(args)
        points_at = make_points(args)
    return fit_curve(point_at, tangent_at, 0.0, 1.0, tolerance, points_at=points_at)


def _compiled(kernels: Any, key: CurveKey, tolerance: float) -> list[Segment] | None:
    """The compiled fit of the curve ``key``; ``None`` where the plain fit must answer.

    ``None`` when the fit fails (a point not finite, too many subdivisions): the plain fit
    then raises with its message. Raises UsageError for a bad tolerance, as the plain fit.
    """
    kind, args = key
    par = np.array(
        [v for a in args for v in (a if isinstance(a, tuple) else (a,))], dtype=np.float64
    )
    limit, flat = fit_limits(tolerance)
    status, rows, piece, errors = kernels.curve_pieces(_KINDS[kind], par, limit, flat, MAX_DEPTH)
    if status != kernels.OK:
        return None
    return segments_of(kernels.merge(rows, piece, errors, limit))


def fit_many(
    keys: Sequence[CurveKey],
    tolerance: float,
    jobs: int | None = None,
    *,
    done: Callable[[int], None] | None = None,
) -> list[list[Segment] | None]:
    """:func:`fit_key` of every key, in order; ``None`` where that fit raised.

    Args:
        keys: the curves.
        tolerance: mm (> 0), as for :func:`fit_key`.
        jobs: worker processes; ``None``: :func:`~camtool.accel.cores.default_jobs`. With
            1, fewer than :data:`MIN_CURVES` keys, or the compiled fitter loaded
            (:data:`FIT_KERNELS`), every fit runs in this process.
        done: called in this process with the number of keys fitted so far, as they
            come in (after each fit here, after each worker's chunk of keys with a pool);
            for a progress report, it does not change the fits.

    Returns:
        One entry per key: its segments (exactly :func:`fit_key`'s), or ``None``.
    """
    workers = default_jobs() if jobs is None else max(1, jobs)
    workers = min(workers, -(-len(keys) // _CHUNK))
    if workers > 1 and len(keys) >= MIN_CURVES and FIT_KERNELS.get(len(keys)) is None:
        packed = _in_pool(keys, tolerance, workers, done)
        if packed is not None:
            return [None if p is None else _unpack(p) for p in packed]
    fits = []
    for key in keys:
        fits.append(_fit_or_none(key, tolerance))
        if done is not None:
            done(len(fits))
    return fits


def _in_pool(
    keys: Sequence[CurveKey],
    tolerance: float,
    workers: int,
    done: Callable[[int], None] | None = None,
) -> list[_Packed | None] | None:
    """The packed fits from ``workers`` forked processes; ``None`` if no pool runs them.

    ``done`` is called here with the count of fits received, after each chunk.
    """
    chunks = [(list(keys[i : i + _CHUNK]), tolerance) for i in range(0, len(keys), _CHUNK)]
    received = [0]

    def chunk_done(chunk: list[_Packed | None]) -> None:
        received[0] += len(chunk)
        if done is not None:
            done(received[0])

    results = map_forked(_fit_chunk, chunks, workers, chunk_done)
    return None if results is None else [p for chunk in results for p in chunk]


def _fit_chunk(task: tuple[list[CurveKey], float]) -> list[_Packed | None]:
    keys, tolerance = task
    out: list[_Packed | None] = []
    for key in keys:
        segs = _fit_or_none(key, tolerance)
        out.append(None if segs is None else _pack(segs))
    return out


AHEAD_FROM_BYTES = 1 << 18
"""A drawing file of at least this many bytes (256 KiB) starts the fitter ahead
(:func:`start_ahead`): enough, in the SVGs measured, for :data:`MIN_CURVES` curves."""

_WARM_UP: CurveKey = ("cubic", ((0.0, 0.0), (1.0, 2.0), (3.0, 2.0), (4.0, 0.0)))
"""A curve the helper fits once it has loaded the compiled fitter: numba loads a kernel's
cached machine code at its first call."""


def _load_ahead() -> None:
    """In the helper: load the compiled fitter (:data:`FIT_KERNELS`) and its kernels."""
    if FIT_KERNELS.get(KERNEL_FROM) is not None:
        fit_key(_WARM_UP, 0.01)


_PART = 256
"""Curves in a request to the helper and fits in a part of its answer (:func:`_fit_ahead`):
few enough that the first part comes soon and this process takes each as it needs it."""


def _fit_ahead(requests: Iterator[bytes]) -> Iterator[bytes]:
    """In the helper: the packed fits of each pickled ``(tolerance, keys)``, by parts.

    Each part is the fits of at most :data:`_PART` keys, pickled, in the keys' order. One
    part, ``None`` pickled, when the compiled fitter could not be loaded (no numba): the
    plain fits are the caller's, on its pool.
    """
    for request in requests:
        tolerance, keys = pickle.loads(request)
        if FIT_KERNELS.loaded() is None:
            yield pickle.dumps(None)
            return
        for at in range(0, len(keys), _PART):
            fits = _fit_chunk((keys[at : at + _PART], tolerance))
            yield pickle.dumps(fits, protocol=pickle.HIGHEST_PROTOCOL)


FITTER = HelperAhead(_load_ahead, _fit_ahead, streamed=True)
"""This process's fitter started ahead (:func:`start_ahead`), used by one :class:`SharedFits`."""


def start_ahead(size: int) -> None:
    """Start a helper that loads the compiled fitter now, for a drawing file of ``size`` bytes.

    Loading numba and the fitter's cached kernels takes a core a while (figures:
    docs/performance.md); a big SVG's reader spends its first seconds on the document's
    XML and svgelements' parse, on one core, before its first fit. The helper
    (:class:`~camtool.accel.ahead.HelperAhead`) loads them on the other core meanwhile,
    and :class:`SharedFits` then sends it the curves (the same fits: the same compiled
    code, its answer pickled bit for bit).
    Started only with the accel layer on, from :data:`AHEAD_FROM_BYTES`, on two cores or
    more, where this process has not loaded the fitter itself; the caller calls
    :func:`stop_ahead` when its reading ends, however it ends.
    """
    if size < AHEAD_FROM_BYTES or not enabled() or default_jobs() < 2:
        return
    if FIT_KERNELS.loaded() is None:
        FITTER.start()
        FITTER.load()


def stop_ahead() -> None:
    """End the helper :func:`start_ahead` started if no fit used it (idempotent)."""
    FITTER.stop()


@contextmanager
def fitter_ahead(path: Path) -> Iterator[None]:
    """:func:`start_ahead` for the drawing file at ``path``, :func:`stop_ahead` at the end."""
    with suppress(OSError):  # a missing file: the reader says so
        start_ahead(path.stat().st_size)
    try:
        yield
    finally:
        stop_ahead()


def _fit_or_none(key: CurveKey, tolerance: float) -> list[Segment] | None:
    try:
        return fit_key(key, tolerance)
    except Exception:  # the caller fits it again and raises it in order
        return None


def _pack(segs: Iterable[Segment]) -> _Packed:
    """Segments as plain tuples of floats (small pickles): ``(start, end)`` or with centre."""
    return tuple(
        (s.start, s.end, s.centre, s.clockwise) if isinstance(s, Arc) else (s.start, s.end)
        for s in segs
    )


def _unpack(packed: _Packed) -> list[Segment]:
    return [Arc(*p) if len(p) == 4 else Line(*p) for p in packed]


SHAPE_DIGITS = 9
"""Decimals (mm) of a Bézier's control points relative to its start that make its shape
(:func:`shape_key`): the copies of one part placed apart are one shape, fitted once."""


def shape_key(key: CurveKey) -> Any:
    """A Bézier's control points relative to its start, rounded; ``None`` for other curves.

    Two Béziers of one shape are translates of each other within ~1e-9 mm, far inside the
    share of the tolerance a fit keeps in hand (:func:`~camtool.geometry.arcfit.fit_curve`
    uses 97 % of it): the fit of one, :func:`moved` onto the other, holds the tolerance
    there too. Elliptical arcs are fitted each.
    """
    kind, args = key
    if kind not in _BEZIERS:
        return None
    x0, y0 = args[0]
    rel = tuple((round(x - x0, SHAPE_DIGITS), round(y - y0, SHAPE_DIGITS)) for x, y in args[1:])
    return (kind, rel)


def moved(segs: Sequence[Segment], fitted: CurveKey, copy: CurveKey) -> list[Segment]:
    """The fit ``segs`` of curve ``fitted`` translated onto ``copy`` of the same shape.

    Every point moves by the difference of the two curves' starts; the first and last points
    are then set to ``copy``'s own ends exactly, so that the fit starts and ends where its
    curve does (the numbers may differ from a fit of ``copy`` of its own in their last bits).
    """
    (ax, ay), (bx, by) = fitted[1][0], copy[1][0]
    dx, dy = bx - ax, by - ay

    def at(p: tuple[float, float]) -> tuple[float, float]:
        return (p[0] + dx, p[1] + dy)

    out: list[Segment] = [
        Arc(at(s.start), at(s.end), at(s.centre), s.clockwise)
        if isinstance(s, Arc)
        else Line(at(s.start), at(s.end))
        for s in segs
    ]
    if out:
        out[0] = _ends(out[0], start=copy[1][0])
        out[-1] = _ends(out[-1], end=copy[1][-1])
    return out


def _ends(s: Segment, start: Any = None, end: Any = None) -> Segment:
    a, b = start or s.start, end or s.end
    return Arc(a, b, s.centre, s.clockwise) if isinstance(s, Arc) else Line(a, b)


class SharedFits:
    """:func:`fit_many` of the first curve of each shape (:func:`shape_key`), moved onto the rest.

    A panelised drawing repeats its parts: each shape is fitted once, on the machine's cores,
    and its fit :func:`moved` onto every other curve of that shape (the first one met, in
    the order :meth:`add` is given them, is the one fitted). With a helper started ahead
    (:func:`start_ahead`), the new shapes go to it as they are added, :data:`_PART` at a
    time, so that it fits them while the caller goes on, and :meth:`get` takes its fits
    part by part as they are asked for; what it could not send is fitted here.

    Args:
        tolerance: mm (> 0), as for :func:`fit_key`.
        jobs: worker processes, as for :func:`fit_many` (``1``: no helper either).
    """

    def __init__(self, tolerance: float, jobs: int | None = None) -> None:
        self.tolerance, self.jobs = tolerance, jobs
        self.keys: list[CurveKey] = []
        self.fitted_as: list[int] = []  # per key, the key whose fit it takes
        self.distinct: list[int] = []  # the keys fitted, in order
        self.fits: dict[int, list[Segment] | None] = {}
        self.sent = self.taken = 0  # of distinct: sent to the helper, taken from it
        self._first: dict[Any, int] = {}
        workers = default_jobs() if jobs is None else max(1, jobs)
        self.ahead = workers > 1 and FIT_KERNELS.loaded() is None and FITTER.helper is not None
        self.closed = False

    def add(self, key: CurveKey) -> int:
        """Add the curve ``key``; its index for :meth:`get`."""
        i = len(self.keys)
        self.keys.append(key)
        shape = shape_key(key)
        j = i if shape is None else self._first.setdefault(shape, i)
        self.fitted_as.append(j)
        if j == i:
            self.distinct.append(i)
            if self.ahead and len(self.distinct) - self.sent >= _PART:
                self._send()
        return i

    def close(self, done: Callable[[int, int], None] | None = None) -> None:
        """No more curves: the last ones go to the helper, or all are fitted here now.

        ``done`` is called with the shapes fitted so far and their count (from ``0``);
        with a helper, only ``0``: its fits are taken as :meth:`get` needs them.
        """
        self.closed = True
        total = len(self.distinct)
        if done is not None:
            done(0, total)
        if self.ahead:
            self._send()
            if self.ahead and FITTER.end():
                return
        told = None if done is None else (lambda n: done(n, total))
        self._fit_here(told)

    def get(self, i: int) -> list[Segment] | None:
        """The fit of curve ``i``: :func:`fit_key`'s, or its shape's :func:`moved` onto it.

        ``None`` where that fit raised. Only once :meth:`close` was called.
        """
        assert self.closed
        j = self.fitted_as[i]
        while j not in self.fits:
            self._take()
        segs = self.fits[j]
        return segs if segs is None or j == i else moved(segs, self.keys[j], self.keys[i])

    def _send(self) -> None:
        """The shapes added since the last send, to the helper (none left: no helper)."""
        batch = [self.keys[i] for i in self.distinct[self.sent :]]
        if not batch:
            return
        request = pickle.dumps((self.tolerance, batch), protocol=pickle.HIGHEST_PROTOCOL)
        if FITTER.send(request):
            self.sent = len(self.distinct)
        else:
            self.ahead = False  # it died: what it did not send is fitted here

    def _take(self) -> None:
        """The helper's next part; where it has none, the rest of the fits made here."""
        part = FITTER.take() if self.ahead else None
        fits = None if part is None else pickle.loads(part)
        if not isinstance(fits, list) or not fits or self.taken + len(fits) > self.sent:
            FITTER.stop()  # it died, hung or has no numba
            self.ahead = False
            self._fit_here()
            return
        for packed in fits:
            self.fits[self.distinct[self.taken]] = None if packed is None else _unpack(packed)
            self.taken += 1
        if self.taken == len(self.distinct):
            FITTER.stop()  # it has sent every fit: it leaves

    def _fit_here(self, done: Callable[[int], None] | None = None) -> None:
        rest = self.distinct[self.taken :]
        fits = fit_many([self.keys[i] for i in rest], self.tolerance, self.jobs, done=done)
        self.fits.update(zip(rest, fits, strict=True))
        self.taken = len(self.distinct)


def fit_shared(
    keys: Sequence[CurveKey],
    tolerance: float,
    jobs: int | None = None,
    *,
    done: Callable[[int, int], None] | None = None,
) -> list[list[Segment] | None]:
    """Every fit of a :class:`SharedFits` given ``keys`` in order (``done``: its :meth:`close`'s).

    Returns:
        One entry per key, as :func:`fit_many` (``None`` where its shape's fit raised).
    """
    fits = SharedFits(tolerance, jobs)
    for key in keys:
        fits.add(key)
    fits.close(done)
    return [fits.get(i) for i in range(len(keys))]
