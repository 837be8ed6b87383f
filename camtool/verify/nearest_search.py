"""The nearest-segment search: distances from sample points to the nearest of many segments.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from types import ModuleType
from typing import Any

import numpy as np
import numpy.typing as npt

from camtool.accel.cores import Beside, beside
from camtool.accel.loader import KernelsOnDemand
from camtool.verify import nearest_exact

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


NEAREST_CHUNK = 20_000
"""Samples :func:`nearest_distances` measures at once (memory ~ 1 kB each)."""


def nearest_distances(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None = None
) -> FloatArray:
    """Distance of each sample to the nearest segment ``a[i] → b[i]``, mm.

    Exact to :data:`NEAREST_TOLERANCE_MM`. The segments owning the
    :data:`NEAREST_ENDS` nearest segment ends (a scipy k-d tree) give a distance
    ``d``; it is the true one when the k-th end ``rk`` lies so far that a segment with
    both ends beyond it comes no nearer, ``d² + L²/4 < rk²`` (``L`` the longest
    segment), or when the nearest end ``r`` bounds it tightly, ``sqrt(r² − L²/4) ≤ d``
    (:func:`~camtool.verify.nearest_exact.settled`). Samples neither test settles get
    GEOS's distance to the segments with an end near enough to be nearer.

    With numba (:func:`near_kernels`), the nearest ends come from
    :func:`camtool.accel.nearkernels.knn`, the k-d tree's answer bit for bit
    (where it cannot say so, from the k-d tree itself); the plain form is
    :func:`nearest_distances_kd`, kept for comparison.

    Args:
        samples: ``(N, 2)`` query points, mm.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm (``a[i] == b[i]``: a point).
        ends: the k-d tree of ``concatenate([a, b])`` when the caller measures several
            batches against the same segments (built here otherwise; the same answers).

    Returns:
        ``(N,)`` float64 distances, mm (``inf`` without segments).
    """
    return _nearest(samples, a, b, ends=ends, only_max=False)


def farthest_nearest(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None = None
) -> tuple[float, int]:
    """``max`` and first ``argmax`` of :func:`nearest_distances`, the same two numbers.

    Only the largest distance is wanted (the shortfall of a path from its trace), so a
    sample the cheap tests leave unsure is measured exactly only when it could reach
    the largest one settled (its distance to the segments of its nearest ends is an
    upper bound); the others cannot be the largest, nor tie with it.

    Args:
        samples: ``(N, 2)`` query points, mm, ``N >= 1``.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        ends: as for :func:`nearest_distances`.

    Returns:
        ``(distance mm, index)`` of the first sample farthest from the segments.
    """
    d = _nearest(samples, a, b, ends=ends, only_max=True)
    k = int(np.argmax(d))
    return float(d[k]), k


def _nearest(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None, only_max: bool
) -> FloatArray:
    """:func:`nearest_distances`; with ``only_max``, exact only where it can be the largest.

    With ``only_max`` an unsure sample that cannot reach the largest settled distance
    keeps its upper bound (:func:`_reaching`): the array's max and argmax are exact.
    """
    search = _box_search(samples, a, b, ends)
    if search is None:
        return _nearest_kd(samples, a, b, ends=ends, only_max=only_max)
    ends = ends or _LazyTree(search.points)
    d = np.empty(len(samples), dtype=np.float64)
    unsure = np.zeros(len(samples), dtype=bool)
    tied: list[tuple[IntArray, FloatArray, FloatArray]] = []  # only_max: asked last, if need be
    for i in range(0, len(samples), NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        near, rk, lower, ask = search.measure(part)
        if ask.any():  # ends tie at the k-th distance and the k-d tree's choice matters
            rows = np.flatnonzero(ask) + i
            if only_max:
                tied.append((rows, rk[rows - i], lower[rows - i]))
                near[rows - i] = 0.0  # below every distance until they are asked
            else:
                near[rows - i] = search.chosen(ends, rows)
        d[part] = near
        unsure[part] = ~search.settled(part, near, rk, lower)
        if only_max and ask.any():
            unsure[np.flatnonzero(ask) + i] = False  # asked last
    d = nearest_exact._settle_unsure(
        search.samples, d, unsure, search.a, search.b, search.nearby, only_max=only_max
    )
    if tied:
        _ask_reaching(search, ends, d, tied)
    return d


def _ask_reaching(
    search: _BoxSearch,
    ends: _LazyTree,
    d: FloatArray,
    tied: list[tuple[IntArray, FloatArray, FloatArray]],
) -> None:
    """Measure the tied samples of :func:`_nearest` (``only_max``) where they can be largest.

    ``d``, updated in place, holds every other sample's distance where it can be the
    largest, an upper bound below it elsewhere, and 0 for the tied ones (``tied``: their
    rows, the k-th end's distance ``rk`` and the vertex bound ``lower``). Each segment the
    k-d tree can keep for a tied sample has an end within ``rk`` of it, so its distance is
    at most ``rk`` (widened as :func:`~camtool.verify.nearest_exact._reaching` widens a
    bound); one whose bound is below the largest of ``d`` can be neither the largest nor
    tie with it, and keeps the bound. The others are asked the k-d tree, and measured
    exactly where its segments do not settle them, as :func:`_nearest` measures every
    tied sample otherwise: the largest distance and its first sample are the same, and
    the k-d tree of the ends is built only when a tied sample can be the largest.
    """
    rows = np.concatenate([r for r, _, _ in tied])
    rk = np.concatenate([k for _, k, _ in tied])
    lower = np.concatenate([low for _, _, low in tied])
    high = nearest_exact.widened(rk, search.samples)
    reach = high >= float(np.max(d))
    d[rows[~reach]] = high[~reach]
    asked = rows[reach]
    if len(asked) == 0:
        return
    d[asked] = search.chosen(ends, asked)
    unsure = np.zeros(len(d), dtype=bool)
    unsure[asked] = ~search.settled(asked, d[asked], rk[reach], lower[reach])
    nearest_exact._settle_unsure(
        search.samples, d, unsure, search.a, search.b, search.nearby, only_max=True
    )


@dataclass(frozen=True, eq=False)
class _BoxSearch:
    """The compiled nearest search of some samples among segments ``a → b`` (:func:`_box_search`).

    Attributes:
        samples: ``(N, 2)`` the query points, C-contiguous float64, mm.
        a: ``(M, 2)`` segment starts, likewise.
        b: ``(M, 2)`` segment ends, likewise.
        half: half the longest segment, mm.
        points: ``concatenate([a, b])``, the ends (as the k-d tree of ties holds them).
        tree: their search tree (:func:`_ends_tree`).
        kernels: :mod:`camtool.accel.nearkernels`.
        long: the few long segments (:func:`~camtool.verify.nearest_exact.long_segments`).
    """

    samples: FloatArray
    a: FloatArray
    b: FloatArray
    half: float
    points: FloatArray
    tree: tuple[Any, ...]
    kernels: ModuleType
    long: nearest_exact.LongSegments | None

    def measure(self, part: slice) -> tuple[FloatArray, FloatArray, FloatArray, Any]:
        """``near``, ``rk``, ``lower`` and ``ask`` of the samples ``part``.

        :func:`camtool.accel.nearkernels.near_segments`' distance to the segments of the
        nearest ends (unset where ``ask``: the k-d tree's choice among tied ends matters),
        the k-th end's distance and the vertex bound ``sqrt(r0² − half²)``, with the
        square roots the k-d tree takes.
        """
        near, r0_2, rk_2, ask = self.kernels.near_segments(
            self.samples[part], *self.tree, self.a, self.b, nearest_exact.NEAREST_ENDS
        )
        lower = np.sqrt(np.maximum(np.sqrt(r0_2) ** 2 - self.half * self.half, 0.0))
        return near, np.sqrt(rk_2), lower, ask

    def chosen(self, ends: _LazyTree, rows: IntArray) -> FloatArray:
        """The distance of samples ``rows`` to the segments of the ends the k-d tree keeps.

        In parts of :data:`NEAREST_CHUNK` rows (each row's distance is its own): the
        query's and the segments' arrays are ~0.4 kB a row, so all the samples of a long
        trace at once (360 000 in the budget's ideal trace) would be ~140 MB.
        """
        out = np.empty(len(rows), dtype=np.float64)
        k = nearest_exact.NEAREST_ENDS
        for i in range(0, len(rows), NEAREST_CHUNK):
            x = self.samples[rows[i : i + NEAREST_CHUNK]]
            found = ends.tree.query(x, k=k, workers=nearest_exact.kd_workers(len(x)))[1]
            seg = np.asarray(found).reshape(-1, k) % len(self.a)
            near = nearest_exact._to_segments(x, self.a[seg], self.b[seg])
            out[i : i + len(x)] = near.min(axis=1)
        return out

    def settled(self, rows: Any, near: FloatArray, rk: FloatArray, lower: FloatArray) -> Any:
        """Where ``near`` is the distance of the samples ``rows`` (a slice or indices).

        :func:`camtool.verify.nearest_exact.settled`, the k-d tree path's tests.
        """
        return nearest_exact.settled(self.samples[rows], near, rk, lower, self.half, self.long)

    def nearby(self, samples: FloatArray, upper: FloatArray, need: Any = None) -> FloatArray | None:
        """:func:`_nearby_boxes` among these segments."""
        return nearest_exact._nearby_boxes(
            samples, upper, self.a, self.b, self.tree, self.half, self.kernels, need
        )


def _box_search(
    samples: FloatArray, a: FloatArray, b: FloatArray, ends: _LazyTree | None = None
) -> _BoxSearch | None:
    """The compiled search of ``samples`` among ``a → b``, or ``None`` for the k-d tree path.

    ``None`` without the compiled search (:func:`near_kernels`: numba missing, or too few
    samples in this process so far), for fewer than :data:`NEAREST_ENDS` ends, and for
    many samples near the segments (:func:`_far`), which the k-d tree answers faster.
    Both paths give the same distances. ``ends``: the segments' ends
    (``concatenate([a, b])``, C-contiguous float64) with the search trees already built
    for other samples; built here otherwise.
    """
    kernels = near_kernels(len(samples))
    if kernels is None or len(a) == 0 or 2 * len(a) <= nearest_exact.NEAREST_ENDS:
        return None
    samples = np.ascontiguousarray(samples, dtype=np.float64)
    if ends is None:
        a = np.ascontiguousarray(a, dtype=np.float64)
        b = np.ascontiguousarray(b, dtype=np.float64)
        ends = _LazyTree(_end_points(a, b))
    else:
        a, b = _halves(np.ascontiguousarray(ends.points, dtype=np.float64))
    half = ends.half()
    if ends.built():  # the k-d tree path costs its queries only: ask whatever the count
        kd = not _far_kd(samples, ends.tree, half)
    elif len(samples) > BOX_TREE_UP_TO:
        kd = not _far(samples, ends.boxes(len(samples), kernels, any_built=True), half, kernels)
    elif len(samples) < DENSE_PROBE_FROM and len(ends.points) < DENSE_PROBE_ENDS:
        kd = False  # the probe would cost about what these samples' search costs
    elif len(samples) * KD_ENDS_PER_SAMPLE >= len(ends.points):
        kd = _dense(samples, ends.boxes(len(samples), kernels, any_built=True), half, kernels)
    else:
        kd = False  # a few samples against many ends: not worth a k-d tree
    if kd:
        ends.drop_boxes()  # the k-d tree answers these ends from now on
        return None
    tree = ends.boxes(len(samples), kernels)
    return _BoxSearch(samples, a, b, half, ends.points, tree, kernels, ends.long(half))


def farthest_off(samples: FloatArray, a: FloatArray, b: FloatArray, offset: float) -> float:
    """``max(|nearest_distances(samples, a, b) - offset|)``: the same float.

    For a caller that needs only the largest offset distance (the error budget's
    distance to the drawing: ``offset`` is the tool radius). The compiled search of
    :func:`_nearest` settles most samples; the others are made exact as it makes them
    only where they can reach the largest value, given bounds on their distance: at
    most the segment distance found (a sample its tests leave unsure) or the k-th end's
    distance (a sample where the k-d tree's choice among tied ends matters: every
    segment it can keep has an end that near), at least ``sqrt(r0² − L²/4)`` (``r0``
    the nearest end, ``L`` the longest segment), each widened by a billionth, 1e-12 mm
    and 64 ulps of the largest coordinate for the rounding of two formulas. So the k-d
    tree of every end is built only when a tied sample can be the largest: on issue
    17's benchmark part none can, which spares a budget worker that tree (~0.3 s).

    The exact stage gets what :func:`_settle_unsure` gets in :func:`_nearest` (the same
    unsure samples, so the same choice between its two ways of measuring), so a tied
    sample is left out only when it is sure whatever the k-d tree keeps (its upper bound
    passes the vertex test); one that may end unsure is asked the k-d tree as
    :func:`_nearest` asks it. Where :func:`_nearest` takes the k-d tree path
    (:func:`_box_search` gives none), every distance is measured on it.

    Args:
        samples: ``(N, 2)`` query points, mm, ``N >= 1``.
        a: ``(M, 2)`` segment starts, mm.
        b: ``(M, 2)`` segment ends, mm.
        offset: subtracted from each distance, mm.
    """
    search = _box_search(samples, a, b)
    if search is None:
        return _largest_off(_nearest_kd(samples, a, b, ends=None, only_max=False), offset)
    n = len(samples)
    d, lower, kth = np.empty(n), np.empty(n), np.empty(n)
    ask = np.zeros(n, dtype=bool)
    for i in range(0, n, NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        d[part], kth[part], lower[part], ask[part] = search.measure(part)
    d[ask] = 0.0  # unset there (the k-d tree's choice matters): a number until asked
    sure = ~ask & search.settled(slice(None), d, kth, lower)
    best = _largest_off(d[sure], offset)
    slack = nearest_exact.rounding_slack(search.samples)
    low = lower * (1.0 - 1e-9) - slack
    high = nearest_exact.widened(kth, search.samples)
    surely = high - lower <= nearest_exact.NEAREST_TOLERANCE_MM  # sure whatever the k-d tree keeps
    asked = ask & (~surely | _can_reach(high, low, offset, best))
    if asked.any():  # the k-d tree's choice, as _nearest takes it
        rows = np.flatnonzero(asked)
        d[rows] = search.chosen(_LazyTree(search.points), rows)
        sure[rows] = search.settled(rows, d[rows], kth[rows], lower[rows])
        best = max(best, _largest_off(d[rows[sure[rows]]], offset))
    unsure = ~sure & (asked | ~ask)
    if unsure.any():  # _settle_unsure's exact stage, only where a distance can be the largest
        need = _can_reach(d[unsure] * (1.0 + 1e-9) + slack, low[unsure], offset, best)
        x = search.samples[unsure]
        exact = search.nearby(x, d[unsure], need)
        if exact is None:
            exact = nearest_exact._all_exact_where(x, d[unsure], search.a, search.b, need)
        best = max(best, _largest_off(exact[need], offset))
    return best


def _can_reach(
    upper: FloatArray, lower: FloatArray, offset: float, best: float
) -> npt.NDArray[np.bool_]:
    """Where a distance within ``[lower, upper]`` may be ``offset`` ± at least ``best``."""
    return np.asarray((upper - offset >= best) | (offset - lower >= best))


def _largest_off(distances: FloatArray, offset: float) -> float:
    """``max(|distances - offset|)`` (``-inf`` for none)."""
    return float(np.max(np.abs(distances - offset))) if len(distances) else -math.inf


MERGE_ENDS_PER_SAMPLE = 16
"""Ends per sample up to which :func:`_ends_tree` merges the ends at one point into a place."""


def _ends_tree(points: FloatArray, samples: int, kernels: ModuleType) -> tuple[Any, ...]:
    """The search tree of the segment ends ``points`` (``concatenate([a, b])``) for ``samples``.

    :func:`camtool.accel.nearkernels.tree`, its places along the segments. The ends at
    one point are one place for at least one sample per :data:`MERGE_ENDS_PER_SAMPLE`
    ends: the 737 736 ends of the benchmark part are 115 838 places (two segments
    meet at each, and the part is cut in three passes), and the drawing's search takes
    about a fifth of the time; a few samples against a long trace (the shortfall's
    unsure ones) search every end instead of paying for the merge. The answers are the
    same.
    """
    merge = len(points) <= MERGE_ENDS_PER_SAMPLE * samples
    return tuple(kernels.tree(points, segments=True, merge=merge))


def _near_segments_numpy(
    chunk: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    kernels: ModuleType,
) -> tuple[FloatArray, FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """:func:`camtool.accel.nearkernels.near_segments` with numpy's segment distances.

    The form it replaced (its :func:`_tied` and :func:`_to_segments` in numpy), kept
    as the tests' reference: the same ``near``, ``r0_2``, ``rk_2`` and ``ask``.
    """
    k = nearest_exact.NEAREST_ENDS
    r0_2, rk_2, index, state = kernels.knn(chunk, *tree, k)
    seg = index % len(a)
    near = nearest_exact._to_segments(chunk, a[seg], b[seg]).min(axis=1)
    ask = np.zeros(len(chunk), dtype=bool)
    tied = state != 0
    if tied.any():
        near[tied], asks = _tied(chunk[tied], rk_2[tied], a, b, tree, kernels)
        ask[np.flatnonzero(tied)[asks]] = True
    return near, r0_2, rk_2, ask


def _tied(
    samples: FloatArray,
    kth2: FloatArray,
    a: FloatArray,
    b: FloatArray,
    tree: tuple[Any, ...],
    kernels: ModuleType,
) -> tuple[FloatArray, npt.NDArray[np.bool_]]:
    """The k-d tree's ``d`` where ends tie at the k-th distance, when its choice cannot matter.

    The k-d tree keeps every end nearer than the k-th distance (``S``) and some of those
    exactly at it (``T``); ``d`` is the least segment distance over what it keeps. With
    ``V`` the least over ``S`` and ``T``: when ``S`` reaches ``V``, or so many ends of
    ``T`` reach it that any choice keeps one, ``d`` is ``V`` whatever it chose.

    Returns:
        ``d`` ``(U,)`` and ``(U,)`` True where the choice matters (``d`` is then unset).
    """
    least = np.empty(len(samples), dtype=np.float64)
    settled = np.empty(len(samples), dtype=bool)
    for i in range(0, len(samples), TIED_CHUNK):  # ~1.5 kB per sample at once
        part = slice(i, i + TIED_CHUNK)
        found, d2, count = kernels.within(samples[part], *tree, kth2[part])
        cap = found.shape[1]
        width = max(1, min(cap, int(count.max())))  # the columns any sample fills
        found, d2 = found[:, :width], d2[:, :width]
        valid = np.arange(width)[None, :] < count[:, None]
        seg = found % len(a)
        values = nearest_exact._to_segments(samples[part], a[seg], b[seg])
        values[~valid] = np.inf
        nearer = valid & (d2 < kth2[part, None])
        at = valid & (d2 == kth2[part, None])
        low = values.min(axis=1)
        low_nearer = np.where(nearer, values, np.inf).min(axis=1)
        pick = nearest_exact.NEAREST_ENDS - nearer.sum(axis=1)
        reaching = (at & (values == low[:, None])).sum(axis=1)
        least[part] = low
        settled[part] = (count <= cap) & ((low_nearer == low) | (at.sum(axis=1) - reaching < pick))
    return least, ~settled


TIED_CHUNK = 2_000
"""Samples :func:`_tied` measures at once."""


KD_LEAF_SIZE = 64
"""Points a leaf of :class:`_LazyTree`'s k-d tree holds (scipy's default is 16). scipy grows
the tree's nodes in a vector that doubles as it fills, so fewer, larger leaves lower the
peak of memory while a long contour's tree is built, for the same time (figures:
docs/performance.md). A leaf's size changes how the tree is searched, not what it finds."""


class _LazyTree:
    """The search structures of some points, each built when first asked for.

    scipy's k-d tree (:attr:`tree`) and, for segment ends ``concatenate([a, b])``
    (:func:`_end_points`), the compiled search's trees (:meth:`boxes`) and half the
    longest segment (:meth:`half`): the batches of samples measured against one trace
    share them instead of building them once a batch.
    """

    def __init__(self, points: FloatArray) -> None:
        self.points = points
        self._tree: Any = None
        self._beside: Beside[Any] | None = None
        self._boxes: dict[bool, tuple[Any, ...]] = {}
        self._half: float | None = None
        self._lengths: FloatArray | None = None
        self._long: tuple[nearest_exact.LongSegments | None] | None = None

    def built(self) -> bool:
        """Whether :attr:`tree` has been built (asked for before), or is being built beside."""
        return self._tree is not None or self._beside is not None

    @property
    def tree(self) -> Any:
        if self._tree is None:
            self._tree = self._build() if self._beside is None else self._beside.result()
            self._beside = None
        return self._tree

    def _build(self) -> Any:
        from scipy.spatial import cKDTree

        # no copy of the ends: the points are not written to while the tree lives; boxes
        # not shrunk to their points, and split at the sliding midpoint, not the median:
        # quicker to build (the last contour waits for it; docs/performance.md), the same
        # nearest distances. Where two ends tie at the k-th, the tree's choice moves a
        # distance the vertex bound accepts by at most NEAREST_TOLERANCE_MM.
        return cKDTree(
            self.points,
            leafsize=KD_LEAF_SIZE,
            copy_data=False,
            compact_nodes=False,
            balanced_tree=False,
        )

    def build_beside(self) -> None:
        """Start building :attr:`tree` in a thread (:func:`camtool.accel.cores.beside`).

        For a caller likely to ask for it while the other core is idle. The caller
        must call :meth:`settle` before it forks or lets these points go.
        """
        if self._tree is None and self._beside is None:
            self._beside = beside(self._build)

    def settle(self) -> None:
        """Wait for a tree :meth:`build_beside` started, if one is being built."""
        if self._beside is not None:
            self._beside.join()

    def long(self, half: float) -> nearest_exact.LongSegments | None:
        """:func:`~camtool.verify.nearest_exact.long_segments` of these ends (made once)."""
        if self._long is None:
            lengths = self._segment_lengths()
            self._long = (nearest_exact.long_segments(*_halves(self.points), half, lengths),)
            self._lengths = None  # asked for by half and long only, once each
        return self._long[0]

    def drop_boxes(self) -> None:
        """Let the compiled search's trees go (the k-d tree answers from now on)."""
        self._boxes.clear()

    def half(self) -> float:
        """Half the longest of the segments ``a[i] → b[i]`` whose ends these points are, mm."""
        if self._half is None:
            self._half = float(np.max(self._segment_lengths())) / 2.0
        return self._half

    def _segment_lengths(self) -> FloatArray:
        """The lengths of the segments ``a[i] → b[i]``, mm (kept until :meth:`long` asks)."""
        if self._lengths is None:
            a, b = _halves(self.points)
            self._lengths = np.hypot(*(b - a).T)
        return self._lengths

    def boxes(
        self, samples: int, kernels: ModuleType, *, any_built: bool = False
    ) -> tuple[Any, ...]:
        """:func:`_ends_tree` of these segment ends for ``samples`` samples.

        ``any_built``: a tree built already for another number of samples will do (the
        same answers, :func:`_ends_tree`).
        """
        merge = len(self.points) <= MERGE_ENDS_PER_SAMPLE * samples
        if any_built and self._boxes:
            return next(iter(self._boxes.values()))
        if merge not in self._boxes:
            self._boxes[merge] = _ends_tree(self.points, samples, kernels)
        return self._boxes[merge]


def _halves(points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(a, b)`` of segment ends ``concatenate([a, b])`` (views)."""
    n = len(points) // 2
    return points[:n], points[n:]


NEAR_KERNELS_FROM = 500_000
"""Samples :func:`nearest_distances` has measured in this process (this call's included)
from which it loads the numba search: loading numba and its cache costs about 0.5 s and
100 MB once, the search saves about 1–3 µs a sample (most far from the trace, a drawing
point against the tool-centre path), so a small part (the logo) keeps the k-d tree."""


NEAR_KERNELS = KernelsOnDemand("camtool.accel.nearkernels", NEAR_KERNELS_FROM)
"""The nearest-search kernels of this process, loaded from :data:`NEAR_KERNELS_FROM` samples on."""


def near_kernels(work: int = NEAR_KERNELS_FROM) -> ModuleType | None:
    """:mod:`camtool.accel.nearkernels` once the samples asked for reach the threshold.

    ``work``: the samples the caller is about to measure, added to those before
    (:data:`NEAR_KERNELS_FROM`; the default loads at once). ``None`` before that, with
    ``CAMTOOL_ACCEL=0`` and without numba; :func:`nearest_distances_kd` then answers, the same.
    """
    return NEAR_KERNELS.get(work)


def nearest_distances_kd(samples: FloatArray, a: FloatArray, b: FloatArray) -> FloatArray:
    """:func:`nearest_distances` with the nearest ends from scipy's k-d tree (the plain form)."""
    return _nearest_kd(samples, a, b, ends=None, only_max=False)


def _nearest_kd(
    samples: FloatArray, a: FloatArray, b: FloatArray, *, ends: _LazyTree | None, only_max: bool
) -> FloatArray:
    """:func:`nearest_distances_kd` (``ends``, ``only_max``: as for :func:`_nearest`)."""
    if len(a) == 0:
        return np.full(len(samples), np.inf)
    half = float(np.max(np.hypot(*(b - a).T))) / 2.0 if ends is None else ends.half()
    tree = (ends or _LazyTree(_end_points(a, b))).tree
    d = np.empty(len(samples), dtype=np.float64)
    unsure = np.empty(len(samples), dtype=bool)
    # the few long segments apart, in the cheap tests and in the exact stage
    long = nearest_exact.long_segments(a, b, half) if ends is None else ends.long(half)
    for i in range(0, len(samples), NEAREST_CHUNK):
        part = slice(i, i + NEAREST_CHUNK)
        d[part], unsure[part] = nearest_exact._nearest_chunk(samples[part], a, b, tree, half, long)
    nearby = partial(nearest_exact._nearby_exact, a=a, b=b, ends=tree, half=half, long=long)
    return nearest_exact._settle_unsure(samples, d, unsure, a, b, nearby, only_max=only_max)


BOX_TREE_UP_TO = 20_000
"""Samples up to which :func:`_nearest` asks the box tree it has built whether or not they
lie far from the segments (:func:`_far`): the shortfall's few unsure samples
(:class:`_Bounded`) search it in milliseconds, where a k-d tree would be built for them
(and scipy loaded, ~0.3 s). Both give the same distances; only the time depends on it."""


KD_ENDS_PER_SAMPLE = 1000
"""Segment ends per sample (this call's) up to which :func:`_box_search` asks whether the
samples lie near a dense trace (:func:`_dense`) under :data:`BOX_TREE_UP_TO` samples. A
k-d tree is built once for all the ends and then serves every batch measured against them
(:class:`_LazyTree`: the shortfall's rounds and batches of one contour), and near a dense
trace it answers a sample several times faster than the box tree (docs/performance.md);
for a few samples against many ends its build costs more than it saves. Only the time
depends on it."""


DENSE_NODES_PER_LEVEL = 4
"""Boxes a level that a search to the k-th nearest end opens (median over a probe) above
which the trace is dense for :func:`_dense`: where the trace runs once, two a level (the
bench's 40 lines: 15 boxes in 7 levels); where it passes again and again, its boxes
(consecutive ends) overlap (its 1 000-line zig-zag, 6 µm apart: 250 in 7)."""


DENSE_PROBE = 256
"""Samples :func:`_dense` looks at (evenly spread)."""


DENSE_PROBE_FROM = 4 * DENSE_PROBE
"""Samples from which :func:`_box_search` asks :func:`_dense`: fewer, against fewer than
:data:`DENSE_PROBE_ENDS` ends (a small contour's path samples and trace), search the box
tree whatever the trace, as the probe alone would search a quarter of them or more. Both
give the same distances; only the time depends on it."""

DENSE_PROBE_ENDS = 1 << 17
"""Segment ends from which a few samples still ask :func:`_dense` (:data:`DENSE_PROBE_FROM`):
near a long dense trace the box tree opens many of its boxes for each sample, and the
k-d tree built once serves every later batch."""


FAR_PROBE = 1000
"""Samples :func:`_far` looks at (evenly spread)."""


FAR_RATIO = 8.0
"""Median nearest-end distance, in half the longest segment, from which the box tree
searches (:func:`_far`)."""


def _far(samples: FloatArray, tree: tuple[Any, ...], half: float, kernels: ModuleType) -> bool:
    """Whether the samples lie far from the segments for their length: the box tree's case.

    The compiled box tree answers a sample a tool radius from a dense trace (a drawing
    point against the tool-centre path) 2–3× faster than scipy's k-d tree, but one near
    the trace (a path sample, a drawing cut on its line) several times slower: a LibreCAD
    hatch cut on the line took 13.6 s in the box tree and 2.0 s in the k-d tree. The
    median distance of :data:`FAR_PROBE` samples to their nearest end, against half the
    longest segment (:data:`FAR_RATIO`), decides. Both give the same distances; only the
    time depends on it.
    """
    return _far_apart(kernels.knn(_probe(samples, FAR_PROBE), *tree, 1)[0], half)


def _far_apart(r0_2: FloatArray, half: float) -> bool:
    """:func:`_far`'s test of the probe's squared nearest-end distances ``r0_2``."""
    return bool(np.median(r0_2) > (FAR_RATIO * half) ** 2)


def _probe(samples: FloatArray, count: int) -> FloatArray:
    """About ``count`` of ``samples``, evenly spread (C-contiguous, for the kernels)."""
    return np.ascontiguousarray(samples[:: max(1, len(samples) // count)])


def _dense(samples: FloatArray, tree: tuple[Any, ...], half: float, kernels: ModuleType) -> bool:
    """Whether the samples lie near a dense trace, where the k-d tree answers them faster.

    Near: not :func:`_far` (on :data:`DENSE_PROBE` samples). Dense: a search to each
    probe's k-th nearest end opens more than :data:`DENSE_NODES_PER_LEVEL` boxes a level
    of ``tree`` (:func:`camtool.accel.nearkernels.nodes_within`), which counts the box
    tree's work and is the same in every run. Both paths give the same distances.
    """
    probe = _probe(samples, DENSE_PROBE)
    r0_2, rk_2 = kernels.knn(probe, *tree, nearest_exact.NEAREST_ENDS)[:2]
    if _far_apart(r0_2, half):
        return False
    opened = kernels.nodes_within(probe, tree[1], tree[2], np.sqrt(rk_2))
    levels = len(tree[2]) - 1
    return bool(np.median(opened) > DENSE_NODES_PER_LEVEL * levels)


def _far_kd(samples: FloatArray, tree: Any, half: float) -> bool:
    """:func:`_far` asked of scipy's k-d tree ``tree`` of the ends (built already)."""
    probe = _probe(samples, FAR_PROBE)
    r0 = tree.query(probe, k=1, workers=nearest_exact.kd_workers(len(probe)))[0]
    return _far_apart(np.square(r0), half)


def lazy_ends(a: FloatArray, b: FloatArray) -> _LazyTree:
    """The search trees of the segments ``a → b`` (``(M, 2)`` mm each), built when first asked.

    For a caller that measures several batches of samples against the same segments: pass
    it as :func:`nearest_distances`'s ``ends`` to every batch (the same distances as one
    call with all the samples).
    """
    return _LazyTree(_end_points(a, b))


def _end_points(a: FloatArray, b: FloatArray) -> FloatArray:
    """``concatenate([a, b])``: the segments' ends, as the searches' trees hold them.

    Where ``a`` and ``b`` are already the two halves of one array of float64 (as
    :func:`_chords` makes them), that array itself: the same values, without a second copy
    of every end at the comparison's peak of memory (~11 MiB on the benchmark part).
    """
    base = a.base
    if (
        isinstance(base, np.ndarray)
        and base is b.base
        and base.dtype == np.float64
        and base.flags.c_contiguous
        and base.shape == (len(a) + len(b), 2)
        and a.flags.c_contiguous
        and b.flags.c_contiguous
        and a.ctypes.data == base.ctypes.data
        and b.ctypes.data == base.ctypes.data + a.nbytes
    ):
        return base
    return np.concatenate([a, b])
