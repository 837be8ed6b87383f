"""A trace against the drawing: overcut and what was not cut, by contour.

All inputs in mm, results in µm. Design notes: docs/internals.md, "The measures of a trace".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from camtool.accel.memo import LastAnswers
from camtool.model.shapes import Drawing, Line, Point, Segment
from camtool.model.units import fmt_num
from camtool.toolpath.options import DEFAULT_CHAIN_TOLERANCE
from camtool.verify import cutting_thin, nearest_exact, nearest_search, path_shortfall

FloatArray = npt.NDArray[np.float64]
IntArray = npt.NDArray[np.int64]


NOT_CUT_KINDS = ("tight-corner", "offset-vanished", "uncut", "self-crossing")
"""Plan finding kinds that say a feature cannot be cut as drawn with this tool."""


CHAIN_JOIN_MM = DEFAULT_CHAIN_TOLERANCE
"""Ends of two drawing contours at most this far apart belong to one contour of the plan,
mm, unless the plan says its own (``joint_mm``): the default ``--chain-tolerance`` (a
drawing of loose LINEs is planned as the closed contours its lines make, and the plan's
findings name those)."""


@dataclass(frozen=True)
class NotCut:
    """A feature of the drawing the planner reported it cannot cut as drawn.

    Attributes:
        kind: the plan finding's kind (one of :data:`NOT_CUT_KINDS`).
        at: where the feature is, mm: the drawing point farthest from the
            programmed path (a tight corner's vertex) or the finding's location.
        error_um: largest |d(q, trace) − r| over the drawing points of the feature, µm.
        samples: drawing points counted in this feature (left out of the main figure).
        value: the finding's size (a region's width mm, an area mm², ...), or ``None``.
    """

    kind: str
    at: Point
    error_um: float
    samples: int
    value: float | None = None

    @property
    def label(self) -> str:
        """A short name: ``"tight corner"``, ``"2 mm wide region"``, ``"uncut region"``."""
        if self.kind == "tight-corner":
            return "tight corner"
        if self.kind == "self-crossing":
            return "loops of a self-crossing contour"
        if self.kind == "offset-vanished" and self.value is not None:
            return f"{fmt_num(self.value, 3).rstrip('0').rstrip('.')} mm wide region"
        return "uncut region" if self.kind == "uncut" else "region narrower than the tool"


class FindingLike(Protocol):
    """What :func:`against_drawing` reads of a plan finding.

    :class:`camtool.toolpath.cuts.Finding` is one.
    """

    @property
    def kind(self) -> str: ...  # noqa: D102
    @property
    def at(self) -> Point | None: ...  # noqa: D102
    @property
    def value(self) -> float | None: ...  # noqa: D102


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
    drawing's) and, for a drawing of at least :data:`PREPARE_KERNELS_FROM` points, the
    compiled nearest search is loaded (:func:`near_kernels`) with the machine code of the
    kernels a comparison calls (:func:`_load_kernels`), so that workers forked next
    inherit both instead of each making them again (its loading alone is ~0.5 s). Only the
    time depends on it: the figures are the same.
    """
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
            are grouped into the plan's chains at it (:func:`_chains`).
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
    trace = thin.points
    off = nearest_search.nearest_distances(samples, *_chords(thin)) - tool_radius_mm
    apart = _not_cut(samples, sizes, tool_radius_mm, nominal, findings, joint_mm)
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
    if main.all():  # no feature apart: the arrays themselves, not copies
        kept, kept_at = off, samples
    elif main.any():
        kept, kept_at = off[main], samples[main]
    else:
        kept, kept_at = np.zeros(1), np.zeros((1, 2))
    worst = int(np.argmax(np.abs(kept)))
    overcut_um = 0.0
    if overcut and tool_radius_mm > 0:
        least = _least_nearest(trace, samples, sizes)
        overcut_um = max(0.0, float(tool_radius_mm - least)) * 1000.0
    return Against(
        max_um=float(abs(kept[worst])) * 1000.0,
        rms_um=float(np.sqrt(np.mean(kept * kept))) * 1000.0,
        at_mm=(float(kept_at[worst, 0]), float(kept_at[worst, 1])),
        overcut_um=overcut_um,
        samples=len(samples),
        not_cut=tuple(features),
    )


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


def _chords(thin: cutting_thin.ThinTrace) -> tuple[FloatArray, FloatArray]:
    """The machined edge's segments: ``(a, b)`` joining consecutive rows of a run of ``thin``.

    A trace of single points (no two rows in one run) gives each point as a segment
    from the point to the next, so that their nearest distances still count.
    """
    trace, runs = thin.points, thin.runs
    joined = np.ones(len(trace) - 1, dtype=bool) if runs is None else runs[1:] == runs[:-1]
    if not joined.any():
        joined[:] = True
    count = int(np.count_nonzero(joined))
    ends = np.empty((2 * count, 2), dtype=np.float64)  # a then b: the search's ends, no copy
    np.compress(joined, trace[:-1], axis=0, out=ends[:count])
    np.compress(joined, trace[1:], axis=0, out=ends[count:])
    return ends[:count], ends[count:]


def _not_cut(
    samples: FloatArray,
    sizes: list[int],
    tool_radius_mm: float,
    nominal: Sequence[FloatArray],
    findings: Sequence[FindingLike],
    joint_mm: float = CHAIN_JOIN_MM,
) -> list[tuple[FindingLike, IntArray, Point]]:
    """:func:`not_cut_groups` of the drawing's ``samples`` when there is anything to group.

    The drawing's contours are grouped into chains at ``joint_mm`` (:func:`_chains`).
    """
    if not nominal or not any(f.kind in NOT_CUT_KINDS and f.at is not None for f in findings):
        return []
    nominal_off = _distance_to(samples, nominal) - tool_radius_mm
    chain_of, run_of = _chains(samples, sizes, joint_mm)
    return not_cut_groups(
        samples, chain_of, nominal_off, findings, tool_radius_mm, runs=run_of, joint_mm=joint_mm
    )


def _chains(
    samples: FloatArray, sizes: list[int], joint_mm: float = CHAIN_JOIN_MM
) -> tuple[IntArray, IntArray]:
    """``(S,)`` chain and run of each sample of :func:`_sample_drawing`.

    A chain is a set of the drawing's contours joined end to end (within ``joint_mm``,
    the plan's joint distance), as the planner chains them: a finding about a planned
    contour names every drawing contour of its chain. A run is a contour together with
    the ones before it in the drawing's order that continue it (same chain, its start at
    the previous one's end): the samples along a run follow the edge, so a stretch off
    the drawing is not split where one LINE ends and the next begins.
    """
    counts = np.asarray(sizes, dtype=np.int64)
    n = len(counts)
    first = np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64)
    last = first + counts - 1
    parent = list(range(n))

    def root(k: int) -> int:
        while parent[k] != k:
            parent[k] = parent[parent[k]]
            k = parent[k]
        return k

    if n > 1:
        from scipy.spatial import cKDTree

        ends = np.concatenate([samples[first], samples[last]])
        for a, b in cKDTree(ends).query_pairs(joint_mm):
            ra, rb = root(int(a) % n), root(int(b) % n)
            if ra != rb:
                parent[max(ra, rb)] = min(ra, rb)
    chain = np.asarray([root(k) for k in range(n)], dtype=np.int64)
    run = np.arange(n, dtype=np.int64)
    if n > 1:  # a contour that goes on from the one before keeps its run number
        gap = np.hypot(*(samples[first[1:]] - samples[last[:-1]]).T)
        goes_on = (chain[1:] == chain[:-1]) & (gap <= joint_mm)
        run = np.concatenate([[0], np.cumsum(~goes_on)]).astype(np.int64)
    return np.repeat(chain, counts), np.repeat(run, counts)


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
    same = _same_contour(sizes)
    a, b = samples[:-1][same], samples[1:][same]
    n = len(points)
    if n == 0 or len(a) == 0:
        return math.inf
    if n < OVERCUT_PRUNE_FROM:
        return float(np.min(nearest_search.nearest_distances(points, a, b)))
    every = OVERCUT_ANCHOR
    anchors = np.append(np.arange(0, n - 1, every), n - 1)
    got = nearest_search.nearest_distances(points[anchors], a, b)
    upper = float(np.min(got))
    scale = max(
        path_shortfall._largest_magnitude(points), path_shortfall._largest_magnitude(samples)
    )
    slack = nearest_exact.NEAREST_TOLERANCE_MM + 1e-12 + 128.0 * float(np.spacing(scale))
    left = np.minimum(np.arange(n) // every, len(anchors) - 1)
    right = np.minimum(left + 1, len(anchors) - 1)
    lower = np.full(n, -math.inf)
    for side in (left, right):
        gap = np.hypot(*(points - points[anchors[side]]).T) * (1.0 + 1e-9)
        np.maximum(lower, got[side] * (1.0 - 1e-9) - gap - slack, out=lower)
    maybe = lower <= upper
    maybe[anchors] = False  # measured
    if not maybe.any():
        return upper
    return min(upper, float(np.min(nearest_search.nearest_distances(points[maybe], a, b))))


PLAN_TOLERANCE_MM = 0.002
"""Least distance of the programmed edge from the drawing that counts as "not as drawn", mm."""


def not_cut_groups(
    samples: FloatArray,
    contour_of: IntArray,
    nominal_off: FloatArray,
    findings: Sequence[FindingLike],
    tool_radius_mm: float,
    *,
    runs: IntArray | None = None,
    joint_mm: float = CHAIN_JOIN_MM,
) -> list[tuple[FindingLike, IntArray, Point]]:
    """The drawing points of each feature the plan reported as not cut as drawn.

    A feature is a stretch of one drawing contour where even the *programmed*
    edge (the nominal path swept by the tool) lies off the drawing by more than
    a threshold: ``max(PLAN_TOLERANCE_MM, 3 × the median such distance)`` (the
    median absorbs the dialect's rounding). A stretch belongs to a finding that
    names its contour: a ``tight-corner`` finding every stretch of the contour
    through its corner whose peak exceeds ``max(2 × threshold, r / 100)`` (the
    finding locates only the first of its corners), an ``offset-vanished`` one
    the stretches of the smallest contour around its location, an ``uncut`` one
    those within ``max(2r, 2√area)`` of its location on the nearest contour, a
    ``self-crossing`` one every stretch of the contour through its crossing (the loops
    its offset left). Stretches no finding names stay in the main figure: the planner did not
    say why they are off.

    Args:
        samples: ``(S, 2)`` drawing points, mm, contour after contour.
        contour_of: ``(S,)`` index of the contour of each sample (of the chain of
            drawing contours the plan made one contour of: :func:`_chains`).
        runs: ``(S,)`` index of the run of each sample, where a stretch may go on
            from one drawing contour into the next (:func:`_chains`); ``None``: the
            contours of ``contour_of``.
        nominal_off: ``(S,)`` distance of each sample from the programmed path
            minus the tool radius, mm.
        findings: plan findings; only :data:`NOT_CUT_KINDS` with a location count.
        tool_radius_mm: tool radius, mm.
        joint_mm: the plan's joint distance, mm (the pieces of a closed chain meet
            within it: :func:`_named_contour`).

    Returns:
        ``(finding, sample indices, location mm)`` per feature, in finding order (the
        stretches of one finding at one place merged: :func:`_merged`).
    """
    size = np.abs(nominal_off)
    threshold = max(PLAN_TOLERANCE_MM, 3.0 * float(np.median(size)))
    stretches = _stretches(samples, contour_of if runs is None else runs, size > threshold)
    closed_gaps = [f.value or 0.0 for f in findings if f.kind == "closed-gap"]
    # the pieces of a contour the plan closed meet within its gap (measured after the
    # chaining moved their ends by up to the joint distance)
    meet_mm = joint_mm + max(closed_gaps, default=0.0)
    taken = [False] * len(stretches)
    out: list[tuple[FindingLike, IntArray, Point]] = []
    for finding in findings:
        if finding.kind not in NOT_CUT_KINDS or finding.at is None:
            continue
        at = np.asarray(finding.at, dtype=np.float64)
        contour = _named_contour(
            samples,
            contour_of,
            at,
            inside=finding.kind == "offset-vanished",
            runs=runs,
            joint_mm=meet_mm,
        )
        for k, index in enumerate(stretches):
            if taken[k] or contour_of[index[0]] != contour:
                continue
            peak = int(index[np.argmax(size[index])])
            if finding.kind == "tight-corner":
                if size[peak] <= max(2.0 * threshold, tool_radius_mm / 100.0):
                    continue
                where = (float(samples[peak, 0]), float(samples[peak, 1]))
            elif finding.kind == "self-crossing":  # every loop the offset left: one feature
                where = (float(at[0]), float(at[1]))
            else:
                if finding.kind == "uncut":
                    reach = max(2.0 * tool_radius_mm, 2.0 * math.sqrt(max(finding.value or 0, 0)))
                    if np.min(np.hypot(*(samples[index] - at).T)) > reach:
                        continue
                where = (float(at[0]), float(at[1]))
            taken[k] = True
            out.append((finding, index, where))
    return _merged(out)


def _merged(
    groups: list[tuple[FindingLike, IntArray, Point]],
) -> list[tuple[FindingLike, IntArray, Point]]:
    """``groups`` with those of one finding at one place made one feature, in order.

    A feature drawn as several contours not in a row in the drawing (loose LINEs in any
    order) comes as one stretch per contour: a tight corner's two sides each peak at the
    drawn vertex, a narrow region's sides are all at the finding's location.
    """
    out: list[tuple[FindingLike, IntArray, Point]] = []
    for finding, index, where in groups:
        for k, (other, known, at) in enumerate(out):
            if other is finding and math.dist(at, where) <= CHAIN_JOIN_MM:
                out[k] = (finding, np.concatenate([known, index]), at)
                break
        else:
            out.append((finding, index, where))
    return out


def _stretches(
    samples: FloatArray, contour_of: IntArray, flagged: npt.NDArray[np.bool_]
) -> list[IntArray]:
    """Runs of consecutive flagged samples of one contour (joined across a closed one's seam)."""
    out: list[IntArray] = []
    cuts = np.flatnonzero(np.diff(contour_of)) + 1  # samples come contour after contour
    for lo, hi in zip([0, *cuts.tolist()], [*cuts.tolist(), len(contour_of)], strict=True):
        idx = np.arange(lo, hi)
        f = flagged[idx]
        if not f.any():
            continue
        if f.all():
            out.append(idx)
            continue
        edges = np.flatnonzero(np.diff(f.astype(np.int8)))
        starts = [0, *(edges + 1).tolist()]
        pieces = [idx[a:b] for a, b in zip(starts, [*starts[1:], len(idx)], strict=True)]
        pieces = [p for p in pieces if flagged[p[0]]]
        closed = math.dist(samples[idx[0]], samples[idx[-1]]) <= 1e-9
        if (
            closed and f[0] and f[-1] and len(pieces) > 1
        ):  # the seam of a closed contour splits one run
            pieces = [np.concatenate([pieces[-1], pieces[0]]), *pieces[1:-1]]
        out.extend(pieces)
    return out


def _named_contour(
    samples: FloatArray,
    contour_of: IntArray,
    at: FloatArray,
    *,
    inside: bool,
    runs: IntArray | None = None,
    joint_mm: float = CHAIN_JOIN_MM,
) -> int:
    """The contour a finding at ``at`` names: the smallest closed one around it, or the nearest.

    When ``at`` lies on the drawing, the contour that starts there (a closed contour of no
    area, drawn there and back, is located at its start; another may pass through it).

    A contour here may be a chain of several drawing contours (``runs``: the pieces, each
    sampled in order along the edge, listed in any order and direction, their ends within
    ``joint_mm``, the plan's joint distance or a gap it closed): it is closed when every
    piece's end meets another's, and around ``at`` when a ray from ``at`` crosses its
    pieces an odd number of times (the even-odd rule); the smallest is the one of least
    bounding box.
    """
    pieces = contour_of if runs is None else runs
    gap = np.hypot(*(samples - at).T)
    nearest = int(np.argmin(gap))
    if inside and gap[nearest] > 1e-9:
        best = _around(samples, contour_of, at, pieces, joint_mm)
        if best >= 0:
            return best
    elif inside:  # on the drawing: a region of no area, located at its contour's start
        on = np.flatnonzero(gap <= 1e-9)
        first = on[(on == 0) | (pieces[on] != pieces[np.maximum(on - 1, 0)])]
        nearest = int(first[0]) if len(first) else nearest  # where a contour starts
    return int(contour_of[nearest])


def _around(
    samples: FloatArray, contour_of: IntArray, at: FloatArray, runs: IntArray, joint_mm: float
) -> int:
    """:func:`_named_contour`'s smallest closed contour around ``at``, or -1 when none is."""
    order = np.argsort(contour_of, kind="stable")  # each contour's samples, in their order
    cuts = np.flatnonzero(np.diff(contour_of[order])) + 1
    best, best_area = -1, math.inf
    for idx in np.split(order, cuts):
        pts = samples[idx]
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        if len(idx) < 4 or not (lo[0] <= at[0] <= hi[0] and lo[1] <= at[1] <= hi[1]):
            continue
        area = float((hi[0] - lo[0]) * (hi[1] - lo[1]))
        if area >= best_area:
            continue
        piece = runs[idx]
        same = piece[1:] == piece[:-1]  # chords join consecutive samples of one piece
        starts = np.flatnonzero(np.concatenate([[True], ~same]))
        stops = np.concatenate([starts[1:], [len(idx)]]) - 1
        if not _ends_meet(np.concatenate([pts[starts], pts[stops]]), joint_mm):
            continue
        a, b = pts[:-1][same], pts[1:][same]
        up = (a[:, 1] > at[1]) != (b[:, 1] > at[1])
        if not up.any():
            continue
        a, b = a[up], b[up]
        x = a[:, 0] + (at[1] - a[:, 1]) * (b[:, 0] - a[:, 0]) / (b[:, 1] - a[:, 1])
        if int(np.count_nonzero(x > at[0])) % 2 == 1:
            best, best_area = int(contour_of[idx[0]]), area
    return best


def _ends_meet(ends: FloatArray, joint_mm: float) -> bool:
    """Whether each of the pieces' ``ends`` (their starts, then their ends) meets another.

    A closed drawing contour's two ends coincide; the pieces of a closed chain meet end
    to end within the plan's joint distance ``joint_mm``.
    """
    if len(ends) == 2:
        return math.dist(ends[0], ends[1]) <= joint_mm * (1.0 + 1e-9)
    from scipy.spatial import cKDTree

    gap, _ = cKDTree(ends).query(ends, k=2)
    return bool(np.all(gap[:, 1] <= joint_mm * (1.0 + 1e-9)))


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
    """:func:`_distance_to` without the kept answer."""
    import shapely

    chords = [np.stack([p[:-1], p[1:]], axis=1) for p in lines if len(p) > 1]
    singles = [p for p in lines if len(p) == 1]
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


def _sample_contour(segments: tuple[Segment, ...], spacing_mm: float) -> FloatArray:
    pts: list[Point] = []
    for seg in segments:
        n = _segment_samples(seg, spacing_mm)
        if isinstance(seg, Line):
            (x0, y0), (x1, y1) = seg.start, seg.end
            pts.extend((x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n))
        else:
            pts.extend(seg.point_at(k / n) for k in range(n))
    pts.append(segments[-1].end)
    return np.asarray(pts, dtype=np.float64)


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
