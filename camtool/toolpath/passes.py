"""Emit the moves of ordered cuts: depth passes, safe Z, plunges or ramps, tabs, lead arcs.

The last planning stage (see :mod:`camtool.toolpath.plan`). Cuts arrive in their
final cutting order, each already rotated and reversed as it will be cut; this
module turns them into :mod:`camtool.model.program` moves.

Design notes: docs/internals.md, ``camtool/toolpath/passes.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from itertools import pairwise
from typing import TYPE_CHECKING

from camtool.geometry.chain import moved_arc
from camtool.model.errors import ToolpathError, UsageError
from camtool.model.program import ArcMove, Linear, Move, Rapid
from camtool.model.shapes import Arc, Segment
from camtool.toolpath.cuts import Cut, Finding, where
from camtool.toolpath.leads import KeepOff, leads_for
from camtool.toolpath.options import PlanOptions
from camtool.toolpath.split import MIN_PIECE, Track

if TYPE_CHECKING:
    from camtool.toolpath.order import Nesting

Z_EPS = 1e-9
"""Z values closer than this (mm) are the same height: no Z move is written between them."""

MAX_MOVES = 5_000_000
"""Most moves one plan may emit (``camtool.toolpath.passes.MAX_MOVES``): a few hundred MB
of G-code, hours of streaming; beyond it an option is almost surely a typo."""

MAX_RAMP_LAPS = 1000.0
"""Most laps of a closed path (or legs of an open one) a ramp may take to descend one
pass (``camtool.toolpath.passes.MAX_RAMP_LAPS``). A 3 mm tool in a 4 mm hole follows a
3.1 mm loop: 1 mm down at 1° is 18 laps; a thousand laps is a typo in ``--ramp``."""


def pass_depths(depth: float, step: float | None) -> tuple[float, ...]:
    """The Z of each pass, top down: ``−step, −2·step, …, −depth``, mm.

    The passes are ``n = ceil(depth/step − 1e-9)``: all but the last are exactly
    ``k·step`` deep and the last is exactly ``depth`` (it is the shallower one
    when ``step`` does not divide ``depth``). The ``1e-9`` keeps a float ratio
    such as ``0.3/0.1 = 2.9999999999999996`` or ``3.0000000000000004`` from
    adding a pass a few nanometres thick; equal passes (``depth/n`` each) were not
    chosen because ``--step-down`` is the depth the user asked each pass to take.

    Args:
        depth: final depth below the top, mm (> 0).
        step: depth of each pass, mm (> 0); ``None``: one pass.
    """
    if step is None or step >= depth:
        return (-depth,)
    n = max(1, math.ceil(depth / step - 1e-9))
    return (*(-k * step for k in range(1, n)), -depth)


def emit_moves(
    cuts: Sequence[Cut], options: PlanOptions, *, helix: bool = True, z_axis: bool = False
) -> list[Move]:
    """The moves of :func:`emit` (without its findings)."""
    return emit(cuts, options, helix=helix, z_axis=z_axis)[0]


def emit(
    cuts: Sequence[Cut],
    options: PlanOptions,
    *,
    helix: bool = True,
    z_axis: bool = False,
    keep_off: KeepOff | None = None,
    nest: Nesting | None = None,
) -> tuple[list[Move], list[Finding]]:
    """The moves that cut ``cuts`` in order, with passes, tabs, ramps and lead arcs.

    Args:
        cuts: tool-centre paths in cutting order, each already rotated and
            reversed as it will be cut. Cut ``i`` gets contour number ``i + 1``
            on its moves.
        options: feeds (``feed_mm_min``, ``plunge_feed``), ``depth``,
            ``step_down``, ``safe_z``, ``clearance``, ``end_position``,
            ``ramp_deg``, ``tabs``/``tab_width``/``tab_height``/
            ``tool_diameter``, ``lead_in``, ``tolerance``, ``origin`` (where
            the tool is before the first move).
        helix: the target can write helical arcs (an arc move with Z). ``False``:
            the descending part of an arc in a ramp becomes chords within
            ``options.tolerance``, each a :class:`~camtool.model.program.Linear` with Z.
        z_axis: the machine has a programmable Z axis. Without a ``depth`` such a
            machine gets a Z program cutting at Z 0 (rapids at ``safe_z``); a
            machine without one (``False``, the default) gets a 2D program.
            With a ``depth`` the plan has Z either way.
        keep_off: the plan's material, from which lead arcs keep the tool
            (:class:`~camtool.toolpath.leads.KeepOff`); ``None``: each lead is
            checked against its own path only.
        nest: the nesting of the cuts' groups, when each cut's path is its group's
            contour itself (one cut per group, reversed or started elsewhere at most:
            cut on the line), so :func:`parts` need not find it again; ``None``: found
            from the cut paths.

    Returns:
        Rapid/Linear/ArcMove moves, absolute mm; ``z`` is ``None`` on every move
        of a 2D plan, and in a Z plan on cutting moves that keep Z. And the
        findings of this stage: ``lead-in`` where a lead arc had to be shortened
        (or left out) to stay on the waste side.

    Raises:
        ToolpathError: the tabs do not fit on a profile (names the contour).
        UsageError: the plan would need more than :data:`MAX_MOVES` moves (names
            the option that made it so, e.g. a ``--ramp`` far too shallow).
    """
    uses_z = options.depth is not None or z_axis
    writer = _Writer(options, helix, uses_z)
    writer.keep_off = keep_off
    if not uses_z:
        for number, cut in enumerate(cuts, start=1):
            writer.number = number
            _cut_2d(writer, cut)
        writer.finish()
        return writer.moves, writer.findings
    levels = (0.0,) if options.depth is None else pass_depths(options.depth, options.step_down)
    check_ramp(cuts, options, levels)
    part_of = parts(cuts, nest)
    i = 0
    while i < len(cuts):
        j = i + 1
        writer.part = part_of[i]
        if cuts[i].kind == "pocket":
            while j < len(cuts) and cuts[j].kind == "pocket" and cuts[j].group == cuts[i].group:
                j += 1
            _pocket_batch(writer, cuts[i:j], i + 1, levels)
        elif cuts[i].path.closed:
            writer.number = i + 1
            _cut_closed(writer, cuts[i], levels)
        else:
            writer.number = i + 1
            _cut_open(writer, cuts[i], levels)
        i = j
    writer.finish()
    return writer.moves, writer.findings


def parts(cuts: Sequence[Cut], groups: Nesting | None = None) -> list[int]:
    """The part of each cut: the index of its outermost enclosing closed cut (or its own).

    A *part* is what comes off the stock in one piece: an outermost closed cut path
    and every cut whose path lies inside it (holes, pockets, engravings). Cuts of one
    drawing contour (``group``, e.g. the rings of a pocket) are in one part even when
    none of them encloses the others. Containment is tested on the cut paths
    themselves (:func:`camtool.toolpath.order.nesting`), so it is the same before
    and after tool compensation. ``groups``: the nesting of the drawing contours, given
    when each cut is its group's contour on the line (one cut per group): the cut paths'
    own nesting, found once by the planner (a path reversed or started at another
    vertex covers what it covered).

    Returns:
        ``(len(cuts),)`` part keys: equal keys, same part.
    """
    from camtool.toolpath.order import nesting

    if not cuts:
        return []
    nest = nesting([c.path for c in cuts]) if groups is None else _by_cut(cuts, groups)
    first_of_group: dict[int, int] = {}
    out: list[int] = []
    areas: dict[int, float] = {}  # each cut's box area, computed once

    def area(j: int) -> float:
        if j not in areas:
            areas[j] = _bbox_area(cuts[j])
        return areas[j]

    for i in range(len(cuts)):
        around = nest.parents[i]
        outer = max(around, key=lambda j: (area(j), -j)) if around else i
        key = cuts[outer].group
        out.append(first_of_group.setdefault(key, outer))
    return out


def _by_cut(cuts: Sequence[Cut], groups: Nesting) -> Nesting:
    """``groups`` (indexed by contour) indexed by cut, for one cut per group."""
    from camtool.toolpath.order import Nesting

    cut_of = {cut.group: i for i, cut in enumerate(cuts)}
    return Nesting(tuple(tuple(sorted(cut_of[j] for j in groups.parents[c.group])) for c in cuts))


def _bbox_area(cut: Cut) -> float:
    x0, y0, x1, y1 = cut.path.bbox()
    return (x1 - x0) * (y1 - y0)


def check_ramp(cuts: Sequence[Cut], options: PlanOptions, levels: Sequence[float]) -> None:
    """Refuse a ramp so shallow that the plan would exceed :data:`MAX_MOVES` moves.

    A ramp descends ``Δz`` over ``L = Δz / tan(angle)`` of path: on a closed path of
    length ``P`` that is ``L / P`` laps, each as many moves as the path has segments;
    on an open path as many zigzag legs. The estimate is made before any move is
    written, with the deepest pass's ``Δz``.

    Raises:
        UsageError: the estimate is over :data:`MAX_MOVES`, or one path needs more
            than :data:`MAX_RAMP_LAPS` laps, naming ``--ramp``, the ramp length per
            pass and what to do.
    """
    angle = options.ramp_deg
    if angle is None or not cuts:
        return
    dz = max(a - b for a, b in pairwise((0.0, *levels)))
    ramp = dz / math.tan(math.radians(angle))
    total = 0.0
    worst = (0.0, 0.0)
    for cut in cuts:
        track = Track.of(cut.path)
        if not track.segments:
            continue
        laps = ramp / max(track.length, MIN_PIECE)
        total += len(levels) * (laps + 1.0) * len(track.segments)
        worst = max(worst, (laps, track.length))
    laps, length = worst
    if total > MAX_MOVES or laps > MAX_RAMP_LAPS:
        limit = (
            f"more than camtool.toolpath.passes.MAX_MOVES = {MAX_MOVES} moves"
            if total > MAX_MOVES
            else f"more than camtool.toolpath.passes.MAX_RAMP_LAPS = {MAX_RAMP_LAPS:g} laps"
        )
        raise UsageError(
            f"--ramp {angle:g}° needs {_length(ramp)} of ramp per pass ({dz:g} mm down at "
            f"{angle:g}°): {laps:.3g} laps of a {length:.4g} mm path, about {total:.3g} moves, "
            f"{limit}; give a steeper --ramp (e.g. --ramp {_steeper(dz, length):g}) or leave "
            "it out"
        )


def _length(mm: float) -> str:
    """A length for a message: mm, or m / km when it is long."""
    if mm >= 1e6:
        return f"{mm / 1e6:.3g} km"
    if mm >= 1e3:
        return f"{mm / 1e3:.3g} m"
    return f"{mm:.3g} mm"


def _steeper(dz: float, length: float) -> float:
    """A ramp angle (degrees, rounded up to 0.1°) that descends ``dz`` within ``length``."""
    if length <= 0:
        return 45.0
    return min(45.0, math.ceil(math.degrees(math.atan2(dz, length)) * 10.0) / 10.0)


class _Writer:
    """Builds the move list and tracks the tool's position (local to one emit)."""

    def __init__(self, options: PlanOptions, helix: bool, uses_z: bool) -> None:
        self.options = options
        self.helix = helix
        self.uses_z = uses_z
        self.moves: list[Move] = []
        self.x, self.y = options.origin
        self.z: float | None = None
        self.number = 0
        self.part: int | None = None
        self._part_here: int | None = None
        self._lift_at: int | None = None
        self.findings: list[Finding] = []
        self.keep_off: KeepOff | None = None
        self._positioned = False
        ramp = options.ramp_deg
        self.slope = None if ramp is None else math.tan(math.radians(ramp))

    def leads(self, cut: Cut) -> tuple[Arc, Arc] | None:
        """The lead arcs of ``cut`` (:func:`leads_for`), saying when they had to shrink."""
        asked = self.options.lead_in
        leads = leads_for(cut, asked, self.keep_off)
        if asked <= 0 or cut.kind != "profile" or cut.material_side is None:
            return leads
        got = 0.0 if leads is None else leads[0].radius
        if got < asked - 1e-9:
            from camtool.model.units import fmt_num

            what = (
                f"lead-in and lead-out arcs shortened to {fmt_num(got, 3)} mm radius"
                if got > 0
                else "no room for lead-in and lead-out arcs: the tool enters on the path"
            )
            self.findings.append(
                Finding(
                    "lead-in",
                    f"{where(cut.path)}: {what} (--lead-in {asked:g}) to stay off the part",
                    cut.path.start,
                    got,
                )
            )
        return leads

    def add(self, move: Move) -> None:
        """Append ``move``.

        Raises:
            UsageError: the plan has reached :data:`MAX_MOVES` moves.
        """
        if len(self.moves) >= MAX_MOVES:
            raise UsageError(
                f"the plan needs more than camtool.toolpath.passes.MAX_MOVES = {MAX_MOVES} "
                f"moves (reached at contour {self.number}); check --step-down, --ramp, "
                "--tolerance and --stepover, or split the drawing"
            )
        self.moves.append(move)

    def travel(self, x: float, y: float) -> None:
        """Rapid to ``(x, y)``: in 2D directly; with Z at safe Z (clearance between parts).

        With Z the tool first rises by a Z-only rapid (to ``clearance`` at the start
        and when :attr:`part` changes, else to ``safe_z``), moves in XY at that
        height and comes down by a Z-only rapid to ``safe_z``. A new part that starts
        where the tool stands (parts touching at a point) needs no travel: the tool
        rises to ``safe_z`` only, as between two cuts of one part.
        """
        if not self.uses_z:
            self.add(Rapid(x, y, contour=self.number))
            self.x, self.y = x, y
            return
        o = self.options
        new_part = self._part_here is None or self.part != self._part_here
        stays = self._positioned and (x, y) == (self.x, self.y)
        self.lift(o.clearance if new_part and not stays else o.safe_z)
        self._part_here = self.part
        if (x, y) != (self.x, self.y) or not self._positioned:
            # XY only (Z stays): the first one is written even at the start position,
            # since where the machine stands when the program starts is not known
            self.add(Rapid(x, y, contour=self.number))
            self._lift_at = None
            self._positioned = True
        self.x, self.y = x, y
        if self.z is not None and self.z > o.safe_z + Z_EPS:
            self.add(Rapid(x, y, o.safe_z, contour=self.number))
            self.z = o.safe_z

    def retract(self) -> None:
        """Z-only rapid up to safe Z, unless already there or above."""
        self.lift(self.options.safe_z)

    def lift(self, z: float) -> None:
        """Z-only rapid up to ``z`` (none when at or above it).

        A lift right after another lift (the retract at the end of a cut, then the
        rise to clearance before the next part) is merged into one move.
        """
        if self.z is not None and self.z >= z - Z_EPS:
            return
        move = Rapid(self.x, self.y, z, contour=self.number)
        if self._lift_at is not None and self._lift_at == len(self.moves) - 1:
            self.moves[-1] = move
        else:
            self.add(move)
            self._lift_at = len(self.moves) - 1
        self.z = z

    def finish(self) -> None:
        """The end of the program: up to clearance, then to ``end_position`` (if given)."""
        o = self.options
        if not self.moves:
            return
        if self.uses_z:
            self.lift(o.clearance)
        if o.end_position is not None:
            x, y = o.end_position
            self.number = 0
            self.add(Rapid(x, y, self.z, contour=0))
            self.x, self.y = x, y

    def vertical(self, z: float) -> None:
        """Z-only feed move: down at the plunge feed, up (onto a tab) at the cutting feed."""
        if self.z is not None and abs(z - self.z) <= Z_EPS:
            return
        up = self.z is not None and z > self.z
        feed = self.options.feed if up else self.options.plunge_feed
        self.add(Linear(self.x, self.y, feed, z, contour=self.number))
        self.z = z

    def cut(self, seg: Segment, z: float | None) -> None:
        """Cut along ``seg`` (starting where the tool is), descending to ``z`` if it differs.

        An arc starts where the tool is, which may lie a few µm off its start (a piece of
        an arc whose ends are not quite on one circle ends on its start's circle): an arc
        shorter than that, which the tool's place would turn round into nearly its whole
        circle, is the line to its end (:func:`~camtool.geometry.chain.moved_arc`).
        """
        feed = self.options.feed
        if z is not None and self.z is not None and abs(z - self.z) <= Z_EPS:
            z = None
        x, y = seg.end
        if isinstance(seg, Arc) and seg.start != (self.x, self.y):
            seg = moved_arc(seg, (self.x, self.y), seg.end)
        if isinstance(seg, Arc):
            if z is not None and not self.helix:
                self._chords(seg, z)
                return
            self.add(ArcMove(x, y, *seg.centre, seg.clockwise, feed, z, self.number))
        else:
            self.add(Linear(x, y, feed, z, contour=self.number))
        self.x, self.y = x, y
        if z is not None:
            self.z = z

    def _chords(self, arc: Arc, z: float) -> None:
        z0 = self.z if self.z is not None else z
        points = arc.points(self.options.tolerance)
        n = len(points) - 1
        for k, (x, y) in enumerate(points[1:], start=1):
            zk = z if k == n else z0 + (z - z0) * k / n
            self.add(Linear(x, y, self.options.feed, zk, contour=self.number))
        self.x, self.y = arc.end
        self.z = z

    def run(
        self,
        track: Track,
        s0: float,
        s1: float,
        z0: float,
        z1: float,
        spans: Sequence[tuple[float, float]] = (),
    ) -> None:
        """Cut ``track`` from arc length ``s0`` to ``s1``, Z linear from ``z0`` to ``z1``.

        Over ``spans`` (tab intervals on a closed track, repeated every lap) Z is
        held at or above the tab top; the tool rises at a tab's start and goes
        down at its end when the run is below it there.
        """
        if s1 - s0 <= MIN_PIECE:
            return
        ztab = self._tab_top()
        deep = ztab is not None and min(z0, z1) < ztab - Z_EPS
        raised = _unrolled(track, s0, s1, spans) if deep else []
        stops = {s0, s1}
        for a, b in raised:
            stops.update(s for s in (a, b) if s0 < s < s1)
            if z0 != z1 and ztab is not None:
                sc = s0 + (ztab - z0) / (z1 - z0) * (s1 - s0)
                if max(a, s0) < sc < min(b, s1):
                    stops.add(sc)

        def z_at(s: float, up: bool) -> float:
            z = z1 if s == s1 else z0 + (z1 - z0) * (s - s0) / (s1 - s0)
            return max(z, ztab) if up and ztab is not None else z

        for u, v in pairwise(sorted(stops)):
            if v - u <= MIN_PIECE:
                continue
            up = any(a < (u + v) / 2 < b for a, b in raised)
            zu, zv = z_at(u, up), z_at(v, up)
            self.vertical(zu)
            for seg, s_end in track.pieces(u, v):
                self.cut(seg, zv if s_end >= v else zu + (zv - zu) * (s_end - u) / (v - u))

    def _tab_top(self) -> float | None:
        o = self.options
        return None if o.depth is None or o.tabs == 0 else -o.depth + o.tab_height


def _unrolled(
    track: Track, s0: float, s1: float, spans: Sequence[tuple[float, float]]
) -> list[tuple[float, float]]:
    """The ``spans`` of a closed track, repeated every lap, that overlap ``(s0, s1)``."""
    if not spans or not track.closed:
        return []
    total = track.length
    out = []
    for lap in range(math.floor(s0 / total), math.floor(s1 / total) + 1):
        for a, b in spans:
            a2, b2 = a + lap * total, b + lap * total
            if b2 > s0 and a2 < s1:
                out.append((a2, b2))
    return out


def _cut_2d(w: _Writer, cut: Cut) -> None:
    """What the planner always wrote for a 2D cut, plus lead arcs when asked."""
    leads = w.leads(cut)
    segments = list(cut.path.segments)
    if leads is not None:
        segments = [leads[0], *segments, leads[1]]
    w.travel(*segments[0].start)
    for seg in segments:
        w.cut(seg, None)


def _enter_open(w: _Writer, track: Track, z_from: float, z_to: float) -> None:
    """Go down from ``z_from`` to ``z_to`` at ``track``'s start and cut all of it at ``z_to``.

    With a ramp: zigzag along the track descending at the ramp angle until
    ``z_to`` is reached, return to the start at ``z_to``, then cut the track.
    """
    total = track.length
    if w.slope is None or total <= MIN_PIECE or z_from - z_to <= Z_EPS:
        w.vertical(z_to)
        w.run(track, 0.0, total, z_to, z_to)
        return
    w.vertical(z_from)
    back = track.reversed()
    left = (z_from - z_to) / w.slope
    pos, forward, z = 0.0, True, z_from
    while left > MIN_PIECE:
        step = min(total - pos if forward else pos, left)
        z_next = z_to if step >= left else z - step * w.slope
        if forward:
            w.run(track, pos, pos + step, z, z_next)
        else:
            w.run(back, total - pos, total - pos + step, z, z_next)
        pos += step if forward else -step
        left, z = left - step, z_next
        if left > MIN_PIECE:
            forward = not forward
    w.run(back, total - pos, total, z_to, z_to)
    w.run(track, 0.0, total, z_to, z_to)


def _closed_pass(
    w: _Writer,
    track: Track,
    s: float,
    z_from: float,
    z_to: float,
    spans: Sequence[tuple[float, float]] = (),
) -> float:
    """One pass round a closed track from arc length ``s``; returns where it ended.

    Without a ramp: go down at ``s`` and cut one loop at ``z_to``. With one: ramp
    round the loop from ``s`` over ``L = Δz/tan(angle)``, then cut a whole loop at
    ``z_to`` from there (the ramped stretch is cut again at full depth).
    """
    total = track.length
    if w.slope is not None and z_from - z_to > Z_EPS:
        ramp = (z_from - z_to) / w.slope
        w.run(track, s, s + ramp, z_from, z_to, spans)
        s += ramp
    else:
        w.vertical(z_to)
    w.run(track, s, s + total, z_to, z_to, spans)
    return (s + total) % total


def _cut_closed(w: _Writer, cut: Cut, levels: Sequence[float]) -> None:
    """All passes of one closed cut (with lead arcs and tabs when asked)."""
    o = w.options
    track = Track.of(cut.path)
    if not track.segments:
        return
    spans: tuple[tuple[float, float], ...] = ()
    if o.tabs > 0 and cut.outside_profile and cut.kind == "profile":
        spans = tab_spans(track.length, o.tabs, o.tab_width + o.tool_diameter, where(cut.path))
    leads = w.leads(cut)
    if leads is not None:
        lead_in, lead_out = leads
        lead = Track.from_segments([lead_in], closed=False)
        for z_from, z_to in pairwise((0.0, *levels)):
            w.travel(*lead_in.start)
            _enter_open(w, lead, z_from, z_to)
            w.run(track, 0.0, track.length, z_to, z_to, spans)
            w.cut(lead_out, None)
            w.retract()
        return
    w.travel(*track.start)
    if w.slope is not None:
        w.vertical(0.0)
    s = 0.0
    for z_from, z_to in pairwise((0.0, *levels)):
        s = _closed_pass(w, track, s, z_from, z_to, spans)
    w.retract()


def _cut_open(w: _Writer, cut: Cut, levels: Sequence[float]) -> None:
    """All passes of one open cut: back and forth if it may be reversed, else from its start."""
    track = Track.of(cut.path)
    if not track.segments:
        return
    w.travel(*track.start)
    for k, (z_from, z_to) in enumerate(pairwise((0.0, *levels))):
        if k and cut.may_reverse:
            track = track.reversed()
        elif k:
            w.travel(*track.start)
        _enter_open(w, track, z_from, z_to)
    w.retract()


def _pocket_batch(w: _Writer, cuts: Sequence[Cut], first: int, levels: Sequence[float]) -> None:
    """Pocket cuts of one group, level by level, re-entering each cut from safe Z."""
    for z_from, z_to in pairwise((0.0, *levels)):
        for number, cut in enumerate(cuts, start=first):
            w.number = number
            track = Track.of(cut.path)
            if not track.segments:
                continue
            w.travel(*track.start)
            if track.closed:
                if w.slope is not None:
                    w.vertical(z_from)
                _closed_pass(w, track, 0.0, z_from, z_to)
            else:
                _enter_open(w, track, z_from, z_to)
            w.retract()


ENTRY_MARGIN = 0.05
"""Fraction of the path length kept free of tabs at each end (the entry)."""


def tab_spans(
    length: float, count: int, span: float, where: str = ""
) -> tuple[tuple[float, float], ...]:
    """Where the tool rises over the tabs, as arc-length intervals along a closed path.

    Args:
        length: the path's length, mm (> 0).
        count: number of tabs (≥ 1).
        span: length of path over each tab, mm: ``tab_width + tool_diameter``.
        where: the contour's name for the error message (see
            :func:`camtool.toolpath.cuts.where`).

    Returns:
        ``count`` intervals ``(start, end)`` in mm from the path's start, in
        order, each ``span`` long, centred at ``5 % + (k + ½)·90 %/count`` of the
        length, so none overlaps another or the first/last 5 %.

    Raises:
        ToolpathError: the tabs do not fit (``span`` is not shorter than the
            spacing ``0.9·length/count``).
    """
    spacing = (1.0 - 2.0 * ENTRY_MARGIN) * length / count
    if span >= spacing:
        raise ToolpathError(
            f"{count} tab(s) do not fit on {where or 'a contour'} ({length:.3f} mm long): "
            f"each needs {span:.3f} mm of path (tab width + tool diameter) and they are "
            f"{spacing:.3f} mm apart; use fewer --tabs or a smaller --tab-width"
        )
    margin = ENTRY_MARGIN * length
    centres = [margin + (k + 0.5) * spacing for k in range(count)]
    return tuple((c - span / 2.0, c + span / 2.0) for c in centres)
