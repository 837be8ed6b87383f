"""Which drawing points make the features the plan reported it cannot cut as drawn.

The drawing's contours are grouped into the chains the planner made of them
(:func:`chains`), and each finding of :data:`NOT_CUT_KINDS` names the stretches of its
contour that even the programmed edge misses (:func:`not_cut_groups`).
:mod:`camtool.verify.drawing_compare` measures those features apart. All in mm.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np
import numpy.typing as npt

from camtool.model.shapes import Point
from camtool.model.units import fmt_num
from camtool.toolpath.options import DEFAULT_CHAIN_TOLERANCE

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


def chains(
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
            drawing contours the plan made one contour of: :func:`chains`).
        runs: ``(S,)`` index of the run of each sample, where a stretch may go on
            from one drawing contour into the next (:func:`chains`); ``None``: the
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
    vanished: set[int] = set()  # the contours offset-vanished findings named
    taken = [False] * len(stretches)
    of_contour: dict[int, list[int]] = {}  # each contour's stretches, in order
    for k, index in enumerate(stretches):
        of_contour.setdefault(int(contour_of[index[0]]), []).append(k)
    drawing: _Contours | None = None  # indexed at the first finding
    out: list[tuple[FindingLike, IntArray, Point]] = []
    for finding in findings:
        if finding.kind not in NOT_CUT_KINDS or finding.at is None:
            continue
        at = np.asarray(finding.at, dtype=np.float64)
        inside = finding.kind == "offset-vanished"
        drawing = drawing or _Contours(samples, contour_of, runs)
        contour = drawing.named(at, inside=inside, joint_mm=meet_mm, named=vanished)
        if inside:
            vanished.add(contour)
        for k in of_contour.get(contour, ()):
            if taken[k]:
                continue
            index = stretches[k]
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
    of_finding: dict[int, list[int]] = {}  # each finding's features in ``out``, in order
    for finding, index, where in groups:
        mine = of_finding.setdefault(id(finding), [])
        for k in mine:
            known, at = out[k][1], out[k][2]
            if math.dist(at, where) <= CHAIN_JOIN_MM:
                out[k] = (finding, np.concatenate([known, index]), at)
                break
        else:
            mine.append(len(out))
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


class _Contours:
    """The drawing's samples by contour, indexed once for every finding (:meth:`named`).

    ``contour_of``: ``(S,)`` each sample's contour (a chain of drawing contours,
    :func:`chains`); ``runs``: its piece (``None``: the contours). A finding's nearest
    samples come from a k-d tree (scipy's ``cKDTree``) and the contours around it from
    their bounding boxes, so that each finding costs what lies near it, not the whole
    drawing; the answers are those of a scan of every sample (the same distances,
    ``numpy.hypot``, and the first sample of least distance).
    """

    def __init__(self, samples: FloatArray, contour_of: IntArray, runs: IntArray | None) -> None:
        self.samples, self.contour_of = samples, contour_of
        self.pieces = contour_of if runs is None else runs
        order = np.argsort(contour_of, kind="stable")  # each contour's samples, in their order
        cuts = np.flatnonzero(np.diff(contour_of[order])) + 1
        self.groups = np.split(order, cuts)
        starts = np.concatenate([[0], cuts]).astype(np.int64)
        ordered = samples[order]
        self.lo = np.minimum.reduceat(ordered, starts, axis=0)
        self.hi = np.maximum.reduceat(ordered, starts, axis=0)
        self.sizes = np.diff(np.concatenate([starts, [len(order)]]))
        from scipy.spatial import cKDTree

        self.tree = cKDTree(samples)

    def _within(self, at: FloatArray, reach: float) -> tuple[IntArray, FloatArray]:
        """The samples within ``reach`` of ``at`` (and a little more), by index, and their gaps."""
        near = np.asarray(
            sorted(self.tree.query_ball_point(at, reach * (1.0 + 1e-9) + 1e-12)), dtype=np.int64
        )
        return near, np.hypot(*(self.samples[near] - at).T)

    def named(self, at: FloatArray, *, inside: bool, joint_mm: float, named: set[int]) -> int:
        """The contour a finding at ``at`` names: the smallest closed one around it, or the nearest.

        With ``inside``, a contour in ``named`` (another ``offset-vanished`` finding's: the
        planner gives one a contour) is passed over: two thin bars that cross, each narrower
        than the tool, have their findings at one place.

        When ``at`` lies on the drawing, the contour that starts there (a closed contour of
        no area, drawn there and back, is located at its start; another may pass through it).

        A contour here may be a chain of several drawing contours (the pieces, each sampled
        in order along the edge, listed in any order and direction, their ends within
        ``joint_mm``, the plan's joint distance or a gap it closed): it is closed when every
        piece's end meets another's, and around ``at`` when a ray from ``at`` crosses its
        pieces an odd number of times (the even-odd rule); the smallest is the one of least
        bounding box.
        """
        least = float(self.tree.query(at)[0])
        near, gap = self._within(at, least)
        nearest = int(near[np.argmin(gap)])  # the first sample of least distance
        if inside and float(np.min(gap)) > 1e-9:
            best = self._around(at, joint_mm, named)
            if best >= 0:
                return best
        elif inside:  # on the drawing: a region of no area, located at its contour's start
            near, gap = self._within(at, 1e-9)
            on = near[gap <= 1e-9]
            pieces = self.pieces
            first = on[(on == 0) | (pieces[on] != pieces[np.maximum(on - 1, 0)])]
            nearest = int(first[0]) if len(first) else nearest  # where a contour starts
        return int(self.contour_of[nearest])

    def _around(self, at: FloatArray, joint_mm: float, named: set[int]) -> int:
        """:meth:`named`'s smallest closed contour around ``at`` not in ``named``, or -1."""
        lo, hi = self.lo, self.hi
        holds = (self.sizes >= 4) & (lo[:, 0] <= at[0]) & (at[0] <= hi[:, 0])
        holds &= (lo[:, 1] <= at[1]) & (at[1] <= hi[:, 1])
        best, best_area = -1, math.inf
        for g in np.flatnonzero(holds).tolist():
            idx = self.groups[g]
            if int(self.contour_of[idx[0]]) in named:
                continue
            area = float((hi[g, 0] - lo[g, 0]) * (hi[g, 1] - lo[g, 1]))
            if area >= best_area:
                continue
            pts = self.samples[idx]
            piece = self.pieces[idx]
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
                best, best_area = int(self.contour_of[idx[0]]), area
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
