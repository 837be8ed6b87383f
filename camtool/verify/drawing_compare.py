"""A trace against the drawing: overcut and what was not cut, by contour.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from camtool.accel.collector import release_free
from camtool.accel.memo import LastAnswers
from camtool.model.shapes import Drawing, Line, Point, Segment
from camtool.verify import (
    cutting_thin,
    nearest_along,
    nearest_exact,
    nearest_search,
    path_shortfall,
)
from camtool.verify.not_cut import (
    CHAIN_JOIN_MM,
    NOT_CUT_KINDS,
    FindingLike,
    NotCut,
    chains,
    not_cut_groups,
)

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


@dataclass(frozen=True)
class Against:
    """The machined edge compared with the drawing.

    The machined edge is the trace swept by the tool radius r: a drawing point q
    is off by ``d(q, trace) − r`` (> 0: material left, < 0: cut too deep), and a
    trace point p gouges the drawing by ``r − d(p, drawing)`` where that is > 0.
    Drawing points of features the planner reported as impossible with this
    tool (:data:`NOT_CUT_KINDS`) are measured apart, in ``not_cut``.

    Attributes:
        max_um: largest |d(q, trace) − r| over the sampled drawing that was cut
            as drawn (``not_cut`` features left out), µm.
        rms_um: RMS of the same, µm.
        at_mm: drawing point where the max occurs.
        overcut_um: largest gouge of the drawing, µm (0 when none).
        samples: drawing points measured (all, features included).
        not_cut: the features not cut as drawn, each with its own error.
    """

    max_um: float
    rms_um: float
    at_mm: Point
    overcut_um: float
    samples: int
    not_cut: tuple[NotCut, ...] = ()

    @property
    def strict_max_um(self) -> float:
        """The largest error over the whole drawing, features not cut as drawn included, µm."""
        return max([self.max_um, *(f.error_um for f in self.not_cut)])


AGAINST_SPACING_MM = 0.005
"""Spacing of the drawing's points :func:`against_drawing` measures by default, mm."""


PREPARE_KERNELS_FROM = 20_000
"""Drawing points (100 mm of edge at :data:`AGAINST_SPACING_MM`) from which
:func:`prepare_comparison` loads the compiled nearest search: the comparisons of such a
drawing (and the shortfall of its toolpath) measure more than :data:`NEAR_KERNELS_FROM`
samples; the preview benchmark's part has 112 688, ``make demo``'s plate 48 577, its logo
6 911 (which keeps the k-d tree)."""


def prepare_comparison(drawing: Drawing) -> None:
    """Ahead of comparing traces with ``drawing`` here and in forked workers: make them once.

    The drawing's points are sampled now (and kept, as every comparison keeps its last
    drawing's), scipy's k-d tree is loaded (the worst-distance search of every comparison
    builds one, :class:`~camtool.verify.nearest_search._LazyTree`) and, for a drawing of at
    least :data:`PREPARE_KERNELS_FROM` points, the compiled nearest search
    (:func:`near_kernels`) with the machine code of the kernels a comparison calls
    (:func:`_load_kernels`), so that workers forked next inherit them instead of each
    loading them again. Only the time depends on it: the figures are the same.
    """
    import scipy.spatial  # noqa: F401

    samples, _ = _sample_drawing(drawing, AGAINST_SPACING_MM)
    if len(samples) >= PREPARE_KERNELS_FROM:
        _load_kernels()


def prepare_stream() -> None:
    """Ahead of streaming a trace here and in a forked helper: load what both call once.

    numba's compiler registries (its first call, ~0.2 s), the kernels the measures of
    every chunk call on its read-only carriage (``to_line``, ``extent``) and the
    compiled nearest search of the shortfall (:func:`near_kernels`, ``load_cached``),
    so that a helper forked next inherits them instead of loading them again, while this
    process would load them at its first chunk anyway. Only the time depends on it.
    """
    from camtool.verify.dda import compiled

    kernels = compiled()
    near = nearest_search.near_kernels()
    if kernels is None or near is None:
        return
    near.load_cached()
    points = np.zeros((2, 2))
    points.flags.writeable = False  # as a chunk's carriage comes
    kernels.to_line(points, 0.0, 0.0, 1.0, 0.0, np.zeros(2))
    kernels.extent(points)


def comparison_preloads(drawing: Drawing) -> list[Callable[[], object]]:
    """What :func:`prepare_comparison` will load for ``drawing``, as tasks for a wait.

    For a job that will compare a trace with ``drawing`` but first waits for another
    process (:func:`camtool.accel.cores.meanwhile`: ``post --preview`` waits ~0.4 s for
    the offsets' child to load OpenCASCADE): the compiled nearest search
    (:func:`near_kernels`, numba's import ~0.15 s), then numba's first call, which loads
    its compiler's registries (~0.2 s), then the machine code of the kernels a comparison
    calls (:func:`_load_kernels`, ~0.08 s), three tasks so that a short wait ends sooner;
    only when ``drawing`` has at least :data:`PREPARE_KERNELS_FROM` points at
    :data:`AGAINST_SPACING_MM` (counted, not sampled). Only the time depends on it. The
    drawing compared may be scaled from this one (``--fit``), so the count is an
    estimate; a wrong one costs time and memory, not figures.
    """
    count = sum(_contour_samples(c.segments, AGAINST_SPACING_MM) for c in drawing.contours)
    return (
        [nearest_search.near_kernels, _first_call, _load_kernels]
        if count >= PREPARE_KERNELS_FROM
        else []
    )


def _first_call() -> None:
    """Make :func:`near_kernels`' first call, on one point: numba loads its registries then."""
    kernels = nearest_search.near_kernels()
    if kernels is not None:
        kernels.build(np.zeros((1, 2)))


def _load_kernels() -> None:
    """:func:`near_kernels` with the kernels a comparison calls loaded (``load_cached``)."""
    kernels = nearest_search.near_kernels()
    if kernels is not None:
        kernels.load_cached()


def against_drawing(
    points: FloatArray,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    resolution_mm: float = cutting_thin.AGAINST_RESOLUTION_MM,
    runs: IntArray | None = None,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
    overcut: bool = True,
    joint_mm: float = CHAIN_JOIN_MM,
) -> Against:
    """Compare a cutting trace with the drawing it was made from (shapely nearest queries).

    The trace is a polyline through its points, thinned to points about
    ``resolution_mm`` apart (never more than 400 000): a thinned-out point lies
    within about that distance of the polyline, so it bounds the error of this
    measure (the step-level deviation from the path is :func:`deviation`).

    With ``findings`` and the ``nominal`` path, the drawing points the planner
    could not cut as drawn (:func:`not_cut_groups`) are measured apart.

    Args:
        points: ``(N, 2)`` float64 cutting trace (rapids left out), mm, in the
            drawing's coordinates.
        drawing: the drawing.
        tool_radius_mm: tool radius; 0 for a scribing point or an engraving on the line.
        spacing_mm: largest distance between sampled drawing points, mm.
        resolution_mm: spacing of the thinned trace, mm.
        runs: ``(N,)`` id of the continuous cut each point belongs to (the rows
            between two rapids); the trace is not joined across two runs, so a
            rapid never counts as cutting. ``None``: one run.
        nominal: the programmed cutting path, one ``(M, 2)`` polyline (mm) per
            run of cutting moves.
        findings: the plan's findings; those of :data:`NOT_CUT_KINDS` with a
            location name the features measured apart.
        overcut: measure the overcut (``False``: ``overcut_um`` is 0, for a caller that
            reads only the other figures, as the error budget does).
        joint_mm: the distance within which the plan joined contour ends, mm
            (:attr:`~camtool.toolpath.plan.PlanReport.joint_mm`): the drawing's contours
            are grouped into the plan's chains at it (:func:`~camtool.verify.not_cut.chains`).
    """
    return against_thinned(
        cutting_thin.thin_cutting(points, runs, resolution_mm),
        drawing,
        tool_radius_mm,
        spacing_mm=spacing_mm,
        nominal=nominal,
        findings=findings,
        overcut=overcut,
        joint_mm=joint_mm,
    )


def against_thinned(
    thin: cutting_thin.ThinTrace,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
    overcut: bool = True,
    joint_mm: float = CHAIN_JOIN_MM,
) -> Against:
    """:func:`against_drawing` of a trace already thinned (:class:`ThinTrace`).

    The arguments are :func:`against_drawing`'s; ``thin`` is its thinned cutting trace
    (of a whole trace, or of one streamed by :class:`CuttingStream`).
    """
    samples, sizes = _sample_drawing(drawing, spacing_mm)
    if thin.rows < 2 or len(samples) == 0:
        return Against(0.0, 0.0, (0.0, 0.0), 0.0, 0)
    off = _off_drawing(samples, thin, tool_radius_mm)
    apart = _not_cut(samples, sizes, tool_radius_mm, nominal, findings, joint_mm)
    release_free()
    main = _cut_as_drawn(len(samples), apart)
    features = [
        NotCut(
            kind=finding.kind,
            at=at,
            error_um=float(np.max(np.abs(off[index]))) * 1000.0,
            samples=len(index),
            value=finding.value,
        )
        for finding, index, at in apart
    ]
    if main.all():  # no feature apart: the array itself, not a copy
        kept, rows = off, None
    elif main.any():
        kept, rows = off[main], np.flatnonzero(main)
    else:
        kept, rows = np.zeros(1), None
    worst = int(np.argmax(np.abs(kept)))
    max_um = float(abs(kept[worst])) * 1000.0
    rms_um = float(np.sqrt(np.mean(kept * kept))) * 1000.0
    if main.any():
        row = worst if rows is None else int(rows[worst])
        at_mm = (float(samples[row, 0]), float(samples[row, 1]))
    else:
        at_mm = (0.0, 0.0)
    del off, kept, rows, main, apart  # not held while the overcut's search builds its trees
    overcut_um = 0.0
    if overcut and tool_radius_mm > 0:
        least = _least_nearest(thin.points, samples, sizes)
        overcut_um = max(0.0, float(tool_radius_mm - least)) * 1000.0
    return Against(
        max_um=max_um,
        rms_um=rms_um,
        at_mm=at_mm,
        overcut_um=overcut_um,
        samples=len(samples),
        not_cut=tuple(features),
    )


AGAINST_BLOCK = 1 << 18
"""Drawing samples :func:`against_thinned` measures at once against one trace: the nearest
search's working arrays (its unsure samples, their bounds, their nearby ends) exist for one
block at a time, not for the whole drawing. Only the memory depends on it."""


def _off_drawing(samples: FloatArray, thin: cutting_thin.ThinTrace, radius: float) -> FloatArray:
    """``d(q, trace) − radius`` for each drawing sample ``q`` (``(N, 2)`` mm), mm.

    :func:`~camtool.verify.nearest_search.nearest_distances`, :data:`AGAINST_BLOCK`
    samples at a time, every block against the same search trees of the trace's ends:
    the same distances as one call.
    """
    a, b = _chords(thin)
    ends = nearest_search.lazy_ends(a, b)
    off = np.empty(len(samples), dtype=np.float64)
    for lo in range(0, len(samples), AGAINST_BLOCK):
        block = samples[lo : lo + AGAINST_BLOCK]
        off[lo : lo + len(block)] = nearest_search.nearest_distances(block, a, b, ends=ends)
        release_free()  # each search's freed pages back, before the next allocates its own
    off -= radius
    return off


def against_worst(
    thin: cutting_thin.ThinTrace,
    drawing: Drawing,
    tool_radius_mm: float,
    *,
    spacing_mm: float = AGAINST_SPACING_MM,
    nominal: Sequence[FloatArray] = (),
    findings: Sequence[FindingLike] = (),
    joint_mm: float = CHAIN_JOIN_MM,
) -> float:
    """``against_thinned(...).max_um`` alone, the same float, for the error budget.

    The distance to the drawing of the samples cut as drawn is measured exactly only
    where it can be the largest (:func:`farthest_off`); the arguments are
    :func:`against_thinned`'s.
    """
    samples, sizes = _sample_drawing(drawing, spacing_mm)
    if thin.rows < 2 or len(samples) == 0:
        return 0.0
    apart = _not_cut(samples, sizes, tool_radius_mm, nominal, findings, joint_mm)
    main = _cut_as_drawn(len(samples), apart)
    if not main.any():
        return 0.0
    kept = samples if main.all() else samples[main]
    return nearest_search.farthest_off(kept, *_chords(thin), tool_radius_mm) * 1000.0


def _halves(joined: npt.NDArray[np.bool_], points: FloatArray) -> tuple[FloatArray, FloatArray]:
    """``(points[:-1][joined], points[1:][joined])``, the two halves of one array.

    The nearest search's trees hold a segment's ends as that array
    (:func:`~camtool.verify.nearest_search.nearest_distances`): no second copy of every end.
    """
    count = int(np.count_nonzero(joined))
    ends = np.empty((2 * count, 2), dtype=np.float64)
    np.compress(joined, points[:-1], axis=0, out=ends[:count])
    np.compress(joined, points[1:], axis=0, out=ends[count:])
    return ends[:count], ends[count:]


def _chords(thin: cutting_thin.ThinTrace) -> tuple[FloatArray, FloatArray]:
    """The machined edge's segments: ``(a, b)`` joining consecutive rows of a run of ``thin``.

    A trace of single points (no two rows in one run) gives each point as a segment
    from the point to the next, so that their nearest distances still count.
    """
    trace, runs = thin.points, thin.runs
    joined = np.ones(len(trace) - 1, dtype=bool) if runs is None else runs[1:] == runs[:-1]
    if not joined.any():
        joined[:] = True
    return _halves(joined, trace)


def _not_cut(
    samples: FloatArray,
    sizes: list[int],
    tool_radius_mm: float,
    nominal: Sequence[FloatArray],
    findings: Sequence[FindingLike],
    joint_mm: float = CHAIN_JOIN_MM,
) -> list[tuple[FindingLike, IntArray, Point]]:
    """:func:`not_cut_groups` of the drawing's ``samples`` when there is anything to group.

    The drawing's contours are grouped into chains at ``joint_mm`` (:func:`chains`).
    """
    if not nominal or not any(f.kind in NOT_CUT_KINDS and f.at is not None for f in findings):
        return []
    nominal_off = _distance_to(samples, nominal) - tool_radius_mm
    chain_of, run_of = chains(samples, sizes, joint_mm)
    return not_cut_groups(
        samples, chain_of, nominal_off, findings, tool_radius_mm, runs=run_of, joint_mm=joint_mm
    )


def _cut_as_drawn(
    count: int, apart: list[tuple[FindingLike, IntArray, Point]]
) -> npt.NDArray[np.bool_]:
    """Which of ``count`` drawing samples are cut as drawn: in none of ``apart``'s groups.

    ``apart`` is :func:`_not_cut`'s: the samples a finding (an uncut feature) accounts for,
    which the comparison reports apart instead of in its largest distance and rms.
    """
    main = np.ones(count, dtype=bool)
    for _, index, _ in apart:
        main[index] = False
    return main


OVERCUT_PRUNE_FROM = 20_000
"""Trace points from which :func:`_least_nearest` measures only those that can be nearest."""


OVERCUT_BOUND_ROWS = 1 << 20
"""Trace points :func:`_least_nearest` bounds at a time (~60 MB of temporaries, whatever
the trace's length)."""


OVERCUT_ANCHOR = 4
"""Every how many trace points :func:`_least_nearest` measures first, to bound the others:
on the benchmark part (369 000 thinned trace points 1.5 mm from 112 000 drawing
chords) 92 000 anchors and 105 000 points left took 0.30 s where all took 0.55 s (every
8th: 0.41 s). Only the time depends on it."""


def _least_nearest(points: FloatArray, samples: FloatArray, sizes: list[int]) -> float:
    """``min(nearest_distances(points, chords))`` of the drawing's chords: the same float.

    The chords join consecutive ``samples`` of a contour (``sizes`` points each, as
    :func:`_sample_drawing` gives them). Only the least distance is wanted (the overcut).
    For many points, every :data:`OVERCUT_ANCHOR`-th (and the last) is measured first;
    a point's distance to the drawing is at least an anchor's less the distance between
    the two (the triangle inequality), and an anchor's exact distance is at least what
    :func:`nearest_distances` gives less :data:`NEAREST_TOLERANCE_MM`. Only the points
    whose bound from the anchors on either side, less a rounding margin, reaches the
    least anchor's distance are measured; each point's distance is its own, so the
    least of them is the least of all, bit for bit. ``inf`` without chords.
    """
    a, b = _halves(_same_contour(sizes), samples)
    n = len(points)
    if n == 0 or len(a) == 0:
        return math.inf
    if n < OVERCUT_PRUNE_FROM:
        return float(np.min(nearest_search.nearest_distances(points, a, b)))
    every = OVERCUT_ANCHOR
    anchors = np.append(np.arange(0, n - 1, every), n - 1)
    ends = nearest_search.lazy_ends(a, b)  # the chords' search trees, built once for both
    got = nearest_search.nearest_distances(points[anchors], a, b, ends=ends)
    upper = float(np.min(got))
    scale = max(
        path_shortfall._largest_magnitude(points), path_shortfall._largest_magnitude(samples)
    )
    slack = nearest_exact.NEAREST_TOLERANCE_MM + 1e-12 + 128.0 * float(np.spacing(scale))
    maybe = np.empty(n, dtype=bool)
    for lo in range(0, n, OVERCUT_BOUND_ROWS):  # the bounds' temporaries a part at a time
        hi = min(n, lo + OVERCUT_BOUND_ROWS)
        left = np.minimum(np.arange(lo, hi) // every, len(anchors) - 1)
        right = np.minimum(left + 1, len(anchors) - 1)
        lower = np.full(hi - lo, -math.inf)
        for side in (left, right):
            gap = np.hypot(*(points[lo:hi] - points[anchors[side]]).T) * (1.0 + 1e-9)
            np.maximum(lower, got[side] * (1.0 - 1e-9) - gap - slack, out=lower)
        maybe[lo:hi] = lower <= upper
    maybe[anchors] = False  # measured
    if not maybe.any():
        return upper
    nearest = nearest_search.nearest_distances(points[maybe], a, b, ends=ends)
    return min(upper, float(np.min(nearest)))


_DISTANCE_TO: LastAnswers[FloatArray] = LastAnswers()
"""The last :func:`_distance_to` answer, with the very arrays it was for: the error budget
asks it again for the same samples and path."""


def _distance_to(samples: FloatArray, lines: Sequence[FloatArray]) -> FloatArray:
    """Distance of each sample to the nearest of ``lines`` (polylines ``(M, 2)``), mm.

    The same ``samples`` and ``lines`` objects as the last call, when they cannot change
    (read-only arrays, ``lines`` a tuple: see :func:`_sample_drawing` and
    :func:`camtool.verify.trace_sources._nominal_lines`), give the last answer again.
    """
    frozen = (
        not samples.flags.writeable
        and isinstance(lines, tuple)
        and not any(line.flags.writeable for line in lines)
    )
    if not frozen:
        return _distance_to_now(samples, lines)
    answer = _DISTANCE_TO.get(samples, lines)
    if answer is None:
        answer = _distance_to_now(samples, lines)
        answer.flags.writeable = False
        _DISTANCE_TO.keep(answer, samples, lines)
    return answer


def _distance_to_now(samples: FloatArray, lines: Sequence[FloatArray]) -> FloatArray:
    """:func:`_distance_to` without the kept answer: GEOS's distances.

    Shapely's nearest query, or the same floats from
    :func:`~camtool.verify.nearest_along.along_distances` (the drawing's points come along
    its contours).
    """
    import shapely

    chords = [np.stack([p[:-1], p[1:]], axis=1) for p in lines if len(p) > 1]
    singles = [p for p in lines if len(p) == 1]
    if chords or singles:
        ends = np.concatenate(chords + [np.stack([p, p], axis=1) for p in singles])
        along = nearest_along.along_distances(samples, ends[:, 0], ends[:, 1])
        if along is not None:
            return along
    parts = []
    if chords:
        parts.append(shapely.linestrings(np.concatenate(chords)))
    if singles:
        parts.append(shapely.points(np.concatenate(singles)))
    if not parts:
        return np.full(len(samples), np.inf)
    tree = shapely.STRtree(np.concatenate(parts))
    _, d = tree.query_nearest(shapely.points(samples), return_distance=True, all_matches=False)
    return np.asarray(d, dtype=np.float64)


def _contour_ids(sizes: list[int]) -> IntArray:
    """``(S,)`` index of the contour of each point of :func:`_sample_drawing`."""
    return np.repeat(np.arange(len(sizes), dtype=np.int64), sizes)


_SAMPLED: LastAnswers[tuple[FloatArray, tuple[int, ...]]] = LastAnswers()
"""The last drawing :func:`_sample_drawing` sampled (the error budget compares the same
drawing once per source)."""


def _sample_drawing(drawing: Drawing, spacing_mm: float) -> tuple[FloatArray, list[int]]:
    """Points along every contour, at most ``spacing_mm`` apart, and the count per contour.

    Contour after contour; the counts feed :func:`_contour_ids` and :func:`_same_contour`.
    The last drawing's points are kept (read-only) and given again for the same drawing.
    """
    kept = _SAMPLED.get(drawing, spacing_mm)
    if kept is not None:
        return kept[0], list(kept[1])
    samples, sizes = _sample_drawing_now(drawing, spacing_mm)
    samples.flags.writeable = False
    _SAMPLED.keep((samples, tuple(sizes)), drawing, spacing_mm)
    return samples, sizes


def _sample_drawing_now(drawing: Drawing, spacing_mm: float) -> tuple[FloatArray, list[int]]:
    """:func:`_sample_drawing` without the kept copy.

    The points are written into one array sized in advance (what stacking the
    contours' arrays gives, without holding them all twice: 9.6 M points of a
    213-icon drawing are 154 MB).
    """
    sizes = [_contour_samples(c.segments, spacing_mm) for c in drawing.contours]
    out = np.empty((sum(sizes), 2), dtype=np.float64)
    at = 0
    for contour, size in zip(drawing.contours, sizes, strict=True):
        out[at : at + size] = _sample_contour(contour.segments, spacing_mm)
        at += size
    return out, sizes


def _contour_samples(segments: tuple[Segment, ...], spacing_mm: float) -> int:
    """How many points :func:`_sample_contour` gives for ``segments``."""
    return sum(_segment_samples(seg, spacing_mm) for seg in segments) + 1


def _segment_samples(seg: Segment, spacing_mm: float) -> int:
    """Points :func:`_sample_contour` takes along ``seg`` (its end is the next one's start)."""
    return max(1, math.ceil(seg.length / spacing_mm))


ARC_ARRAYS_FROM = 16
"""Arcs of at least this many sample points are sampled in arrays (below, numpy's calls
cost more than the points)."""


def _sample_contour(segments: tuple[Segment, ...], spacing_mm: float) -> FloatArray:
    """``(N, 2)`` points along ``segments``, mm, then the last segment's end.

    Each segment gives :func:`_segment_samples` points: its start, then ``k / n`` of the way.
    A line's points are ``start + (end - start) * k / n``, made for all the contour's lines
    at once in numpy with the same operations in the same order as one at a time (the
    same floats); an arc's are :meth:`~camtool.model.shapes.Arc.point_at`'s, their
    cosines and sines ``math``'s (numpy's may differ in the last bit on some CPUs).
    """
    counts = [_segment_samples(seg, spacing_mm) for seg in segments]
    out = np.empty((sum(counts) + 1, 2), dtype=np.float64)
    lines: list[tuple[int, int, float, float, float, float]] = []
    at = 0
    for seg, n in zip(segments, counts, strict=True):
        if isinstance(seg, Line):
            (x0, y0), (x1, y1) = seg.start, seg.end
            lines.append((at, n, x0, y0, x1 - x0, y1 - y0))
        elif n < ARC_ARRAYS_FROM:
            out[at : at + n] = [seg.point_at(k / n) for k in range(n)]
        else:  # point_at's operations in arrays, its cosines and sines math's
            fractions = np.arange(n) / n
            angles = (seg.start_angle + seg.sweep * fractions).tolist()
            (cx, cy), r = seg.centre, seg.radius
            # ends at two radii: a spiral, each point at its own radius, as point_at runs it
            radii: float | FloatArray = r + seg.spiral * fractions if seg.spiral else r
            out[at : at + n, 0] = cx + radii * np.fromiter(map(math.cos, angles), np.float64, n)
            out[at : at + n, 1] = cy + radii * np.fromiter(map(math.sin, angles), np.float64, n)
        at += n
    out[at] = segments[-1].end
    if lines:
        first, sizes, xs, ys, dxs, dys = (np.array(col) for col in zip(*lines, strict=True))
        which = np.repeat(np.arange(len(lines)), sizes)
        k = np.arange(len(which)) - np.repeat(np.cumsum(sizes) - sizes, sizes)
        rows = first[which] + k
        steps = sizes.astype(np.float64)[which]
        out[rows, 0] = xs[which] + dxs[which] * k / steps
        out[rows, 1] = ys[which] + dys[which] * k / steps
    return out


def _same_contour(sizes: list[int]) -> npt.NDArray[np.bool_]:
    """Mask of the sample chords that join two points of the same contour.

    ``sizes``: points per contour, as :func:`_sample_drawing` gives them.
    """
    mask = np.ones(sum(sizes) - 1, dtype=bool)
    edge = 0
    for size in sizes[:-1]:
        edge += size
        mask[edge - 1] = False
    return mask
