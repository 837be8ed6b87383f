"""The usual arcs of a program conformed in arrays, a chunk at a time, for the writer.

An answer is given only for an arc whose blocks are surely
:func:`~camtool.post.arcconform.conform_arc`'s own (the rounded centre plainly passes),
keyed by the writer's exact arguments; every other arc is the writer's to conform. Behind
the accel switch (``CAMTOOL_ACCEL=0``: :func:`start` gives ``None``), kept beside the
rules it computes in arrays, as the search's own array tests are: the accel layer, left
of ``post``, cannot read them.

Design notes: docs/internals.md, ``camtool/post/arcbatch.py``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from camtool.accel import enabled
from camtool.model.program import ArcMove, Program

if TYPE_CHECKING:
    import numpy as np
    import numpy.typing as npt

    from camtool.post.arcconform import Grid
    from camtool.post.wordaddress_arcs import ArcWriter

    FloatArray = npt.NDArray[np.floating[Any]]
    BoolArray = npt.NDArray[np.bool_]

Key = tuple[
    tuple[float, float], tuple[float, float], tuple[float, float], bool, tuple[float, float]
]
"""An arc's arguments: ``(written start, end, centre, clockwise, exact start)``, mm."""
Blocks = list[tuple[tuple[float, float], tuple[float, float] | None]]
"""One block ``(end, absolute centre)``, mm, as the writer keeps an arc's blocks."""

MIN_ARCS = 64
"""Arcs in a program from which chunks are conformed in arrays (below, numpy's cost per
call is more than the Python it saves)."""
MOVES_PER_ARC = 10
"""Moves per distinct arc up to which a batch is made. Its prediction walks every move of
the program (a few µs a move) and pays for itself only where distinct arcs, each ~25 µs
conformed alone, are common: a program that cuts its arcs again (at other depths, or
copies) has the writer reuse their blocks (docs/internals.md)."""
MAX_MOVES = 400_000
"""Moves above which no batch is made: its prediction keeps ~360 bytes an arc, ~100 MB at
this size."""
CHUNK = 512
"""Arcs conformed in one go: the chunk holding the arc the writer asks for."""


class ArcBatch:
    """Answers for the arcs of one program, a chunk at a time as the writer asks.

    Args:
        writer: the writer (its dialect's rule and grid, and what it prints).
        program: the program it writes.
    """

    def __init__(self, writer: ArcWriter, program: Program) -> None:
        from camtool.accel.conformahead import arc_calls

        self.writer = writer
        self.grid = grid_of(writer)
        self.rule = writer.spec.arc_check
        self.calls = arc_calls(writer, program)
        self.where = {call[1:]: i for i, call in enumerate(self.calls)}
        self.done: set[int] = set()
        self.answers: dict[Key, Blocks] = {}

    def take(self, key: Key) -> Blocks | None:
        """The blocks of the arc ``key`` when it is a plain one, else ``None``."""
        found = self.answers.pop(key, None)
        if found is not None:
            return found
        at = self.where.get(key[1:])
        if at is None or at // CHUNK in self.done:
            return None
        chunk = at // CHUNK
        self.done.add(chunk)
        keys = self._keys(self.calls[chunk * CHUNK : (chunk + 1) * CHUNK])
        for k, blocks in zip(keys, plain_blocks(self.grid, self.rule, keys), strict=True):
            if blocks is not None:
                self.answers[k] = blocks
        return self.answers.pop(key, None)

    def _keys(self, calls: Sequence[Any]) -> list[Key]:
        from camtool.accel.conformahead import key_of

        keys = []
        for call in calls:
            key = key_of(self.writer, call)
            if key is not None:
                keys.append(key)
        return keys


def start(writer: ArcWriter, program: Program) -> ArcBatch | None:
    """The batch for ``program``'s arcs, or ``None`` when it does not :func:`apply`."""
    return ArcBatch(writer, program) if applies(writer, program) else None


def grid_of(writer: ArcWriter) -> Grid:
    """The grid ``writer`` prints arcs on (its dialect's quantum)."""
    from camtool.post.arcconform import Grid

    return Grid.of(writer.spec.quantum_mm())


def applies(writer: ArcWriter, program: Program) -> bool:
    """Whether ``writer`` takes answers from a batch for ``program``.

    Not switched off, with an arc check on a ``10**-d`` mm grid (else grid values are
    not ``k / 10**d``), at most :data:`MAX_MOVES` moves, and at least :data:`MIN_ARCS`
    distinct arcs, one in :data:`MOVES_PER_ARC` moves at least.
    """
    if writer.spec.arc_check == "none" or not enabled():
        return False
    if grid_of(writer).decimals is None:
        return False
    if len(program.moves) > MAX_MOVES:
        return False
    centres = [m.cx for m in program.moves if isinstance(m, ArcMove)]
    if len(centres) < MIN_ARCS:
        return False
    distinct = len(set(centres))  # told apart by their centre's x: an estimate from below
    return distinct >= MIN_ARCS and distinct * MOVES_PER_ARC >= len(program.moves)


def plain_blocks(grid: Grid, rule: str, keys: Sequence[Key]) -> list[Blocks | None]:
    """``conform_arc``'s blocks for each arc ``keys`` gives when the rounded centre plainly passes.

    ``None`` for an arc that may need the search (or more): its blocks are not known here.
    Why an answer is ``conform_arc``'s own: docs/internals.md, ``camtool/post/arcbatch.py``.
    """
    import numpy as np

    from camtool.post.arcconform import _reference

    d = grid.decimals
    if not keys or d is None:
        return [None] * len(keys)
    n = len(keys)
    raw = np.array(
        [(w[0], w[1], e[0], e[1], c[0], c[1], h[0], h[1]) for w, e, c, _, h in keys],
        dtype=np.float64,
    )
    cw = np.array([k[3] for k in keys], dtype=bool)
    finite = np.isfinite(raw).all(axis=1)
    raw[~finite] = 1.0  # kept out below; a number for the arithmetic meanwhile
    q = grid.mm
    s = _indices(grid, raw[:, 0:2])
    e = _indices(grid, raw[:, 2:4])
    c = _indices(grid, raw[:, 4:6])
    tens = float(10**d)
    ok = finite & (np.abs(np.hstack((s, e, c))) < _BIG_INDEX).all(axis=1)
    # on_grid: the written start is a grid point; the exact start within a quantum of it
    ok &= np.abs(s / tens - raw[:, 0:2]).max(axis=1) <= 1e-7 * q
    ok &= np.hypot(raw[:, 0] - raw[:, 6], raw[:, 1] - raw[:, 7]) <= 0.99 * q
    ok &= (s != e).any(axis=1)  # ends that print the same: a full circle, or nothing
    refs: list[Any] = [None] * n
    for i in np.flatnonzero(ok):
        w, end, centre, clockwise, here = keys[int(i)]
        if math.dist(end, centre) == 0.0:
            ok[i] = False
            continue
        refs[i] = _reference(w, end, centre, clockwise, here)
    ref = np.array(
        [
            (r.centre[0], r.centre[1], r.radius, r.angle, r.sweep) if r else (0, 0, 1, 0, 1)
            for r in refs
        ],
        dtype=np.float64,
    )
    with np.errstate(all="ignore"):
        ok &= _plainly_passes(rule, q, cw, s, e, c, ref)
        ok &= _accepted(rule, grid, s[:, 0], s[:, 1], e, c, ok)
    out: list[Blocks | None] = [None] * n
    for i in np.flatnonzero(ok):
        out[i] = [
            (grid.point((int(e[i, 0]), int(e[i, 1]))), grid.point((int(c[i, 0]), int(c[i, 1]))))
        ]
    return out


_BIG_INDEX = 2**52
"""Grid indices from this on are not kept (:func:`_indices`): no arc of them is answered."""


def _indices(grid: Grid, values: FloatArray) -> npt.NDArray[np.int64]:
    """:meth:`Grid.index` of each value (``(N, 2)`` mm → ``(N, 2)`` grid indices).

    Its float path in arrays (the same IEEE operations); the values it leaves to the
    digits of their repr are rounded by it, one by one. An index of :data:`_BIG_INDEX`
    or more (in size) is given as :data:`_BIG_INDEX`: :func:`plain_blocks` answers no
    arc with one.
    """
    import numpy as np

    from camtool.post.arcconform import _FAST_BELOW, _ROOM, _TENS

    d = grid.decimals
    assert d is not None
    x = values * _TENS[d]
    a = np.abs(x)
    fast = a < _FAST_BELOW
    whole = np.floor(np.where(fast, a, 0.0))
    f = a - whole
    fast &= np.abs(f - 0.5) > a * _ROOM
    k = np.where(f > 0.5, whole + 1.0, whole)
    k = np.where(x < 0, -k, k)
    out = np.where(fast, k, 0.0).astype(np.int64)
    for i, j in zip(*np.nonzero(~fast), strict=True):
        index = grid.index(float(values[i, j]))  # a Python int: any size
        out[i, j] = index if abs(index) < _BIG_INDEX else _BIG_INDEX
    return out


def _plainly_passes(
    rule: str,
    q: float,
    cw: BoolArray,
    s: npt.NDArray[np.int64],
    e: npt.NDArray[np.int64],
    c: npt.NDArray[np.int64],
    ref: FloatArray,
) -> BoolArray:
    """:func:`~camtool.post.arcconform.plainly_passes` of each arc, test by test, in arrays."""
    import numpy as np

    from camtool.post.arccheck import GRBL_ANGULAR_EPSILON as EPS
    from camtool.post.arcconform import DEVIATION_QUANTA, SHORTCUT_MAX_MM, SLACK_MM, SLACK_RAD

    tau = 2 * math.pi
    cx_c, cy_c, radius, angle, ref_sweep = ref.T
    u0x, u0y = (s[:, 0] - c[:, 0]) * q, (s[:, 1] - c[:, 1]) * q
    u1x, u1y = (e[:, 0] - c[:, 0]) * q, (e[:, 1] - c[:, 1]) * q
    r0, r1 = np.hypot(u0x, u0y), np.hypot(u1x, u1y)
    big = np.maximum(np.maximum(r0, r1), radius)
    ok = (r0 > 0) & (r1 > 0) & (big < SHORTCUT_MAX_MM) & _rule_room(rule, r0, r1)
    cross, dot = u0x * u1y - u0y * u1x, u0x * u1x + u0y * u1y
    raw = np.arctan2(cross, dot)
    flat = (cross == 0.0) & (dot > 0.0)
    raw = np.where(flat, 0.0, raw)
    ok &= flat | ~((np.abs(raw) <= 2 * EPS) | (np.abs(np.abs(raw) - math.pi) <= SLACK_RAD))
    sweep = np.where(
        cw,
        np.where(raw >= -EPS, raw - tau, raw),
        np.where(raw <= EPS, raw + tau, raw),
    )
    turn_gap = np.abs(np.abs(sweep) - np.abs(ref_sweep))
    ok &= turn_gap <= math.pi / 2 - SLACK_RAD
    rho0 = r0
    rho1 = r0 if rule == "grbl" else r1
    cx, cy = c[:, 0] * q, c[:, 1] * q
    dx, dy = cx - cx_c, cy - cy_c
    delta = np.hypot(dx, dy)
    rho_min, rho_max = np.minimum(rho0, rho1), np.maximum(rho0, rho1)
    slope = np.abs(rho1 - rho0) / np.abs(sweep)
    ok &= rho_min * rho_min - rho_max * delta - slope * delta > 1e-6 * rho_min * rho_min
    ok &= ~((delta != 0.0) & (delta * sweep == 0.0))
    f_min, f_max = _radial_span(rho0, rho1, u0x, u0y, dx, dy, delta, sweep)
    ok &= f_min > 0.0
    brad = np.maximum(f_max + delta * delta / (2 * f_min) - radius, radius - f_min)
    end_angle = angle + ref_sweep  # Reference.at(1.0)
    a0x, a0y = cx_c + radius * np.cos(angle), cy_c + radius * np.sin(angle)
    a1x, a1y = cx_c + radius * np.cos(end_angle), cy_c + radius * np.sin(end_angle)
    p1x, p1y = cx + rho1 * u1x / r1, cy + rho1 * u1y / r1
    g0 = _angle(s[:, 0] * q - cx_c, s[:, 1] * q - cy_c, a0x - cx_c, a0y - cy_c)
    g1 = _angle(p1x - cx_c, p1y - cy_c, a1x - cx_c, a1y - cy_c)
    eta = np.arcsin(np.minimum(1.0, delta / rho_min))
    ok &= g0 + g1 + turn_gap + 2 * eta < math.pi - SLACK_RAD
    end_gap = np.hypot(e[:, 0] * q - a1x, e[:, 1] * q - a1y)
    ok &= np.isfinite(brad + g0 + g1 + eta + end_gap)
    bound = np.maximum(brad + radius * (np.maximum(g0, g1) + SLACK_RAD), end_gap)
    ok &= bound + SLACK_MM <= DEVIATION_QUANTA * q
    return ok & np.isfinite(bound)


def _rule_room(rule: str, r0: FloatArray, r1: FloatArray) -> BoolArray:
    """:func:`~camtool.post.arcconform._rule_room` in arrays."""
    import numpy as np

    from camtool.post import arccheck as ac
    from camtool.post.arcconform import SLACK_MM

    m = ac.MARGIN_MM + SLACK_MM
    delta = np.abs(r1 - r0)
    if rule == "grbl":
        relative = (delta <= ac.GRBL_CEILING_MM - m) & (delta <= ac.GRBL_RELATIVE * r0 - m)
        return (delta <= ac.GRBL_TOLERANCE_MM - m) | relative
    relative = delta <= ac.LINUXCNC_RELATIVE * np.maximum(r0, r1) - m
    small = (delta <= ac.LINUXCNC_TOLERANCE_MM - m) | relative
    big_enough = np.minimum(r0, r1) >= ac.LINUXCNC_MIN_RADIUS_MM + m
    return small & (delta <= ac.LINUXCNC_CEILING_MM - m) & big_enough


def _radial_span(
    rho0: FloatArray,
    rho1: FloatArray,
    u0x: FloatArray,
    u0y: FloatArray,
    dx: FloatArray,
    dy: FloatArray,
    delta: FloatArray,
    sweep: FloatArray,
) -> tuple[FloatArray, FloatArray]:
    """:func:`~camtool.post.arcconform._radial_span` in arrays.

    A sweep is at most a turn (and a few ulps), so at most two turns of each root lie
    within it; three are tried.
    """
    import numpy as np

    tau = 2 * math.pi
    b = rho1 - rho0
    x0 = np.arctan2(u0y, u0x) - np.arctan2(dy, dx)
    lo_v = np.minimum(rho0 + delta * np.cos(x0), rho1 + delta * np.cos(x0 + sweep))
    hi_v = np.maximum(rho0 + delta * np.cos(x0), rho1 + delta * np.cos(x0 + sweep))
    k = b / (delta * sweep)
    has = np.abs(k) <= 1.0 + 1e-9
    root = np.arcsin(np.clip(k, -1.0, 1.0))
    lo, hi = np.minimum(x0, x0 + sweep), np.maximum(x0, x0 + sweep)
    for base in (root, math.pi - root):
        n = np.ceil((lo - base) / tau)
        for step in range(3):
            x = base + tau * (n + step)
            t = (x - x0) / sweep
            inside = has & (x <= hi) & (t > 0.0) & (t < 1.0)
            value = rho0 + b * t + delta * np.cos(x)
            lo_v = np.where(inside, np.minimum(lo_v, value), lo_v)
            hi_v = np.where(inside, np.maximum(hi_v, value), hi_v)
    none = delta == 0.0
    lo_v = np.where(none, np.minimum(rho0, rho1), lo_v)
    hi_v = np.where(none, np.maximum(rho0, rho1), hi_v)
    return lo_v, hi_v


def _angle(vx: FloatArray, vy: FloatArray, wx: FloatArray, wy: FloatArray) -> FloatArray:
    """Unsigned angle between two vectors, rad (0…π)."""
    import numpy as np

    return np.arctan2(np.abs(vx * wy - vy * wx), vx * wx + vy * wy)


def _accepted(
    rule: str,
    grid: Grid,
    sx: npt.NDArray[np.int64],
    sy: npt.NDArray[np.int64],
    e: npt.NDArray[np.int64],
    c: npt.NDArray[np.int64],
    ok: BoolArray,
) -> BoolArray:
    """Whether the controller accepts each block (printed start, end, centre), for ``ok`` ones.

    GRBL: ``_grbl_error`` in float32 arrays. LinuxCNC: :func:`arc_error`, arc by arc.
    """
    import numpy as np

    from camtool.post import arccheck as ac

    d = grid.decimals
    assert d is not None
    tens = float(10**d)
    if rule != "grbl":
        out = np.zeros(len(ok), dtype=bool)
        for i in np.flatnonzero(ok):
            start = grid.point((int(sx[i]), int(sy[i])))
            end = grid.point((int(e[i, 0]), int(e[i, 1])))
            centre = grid.point((int(c[i, 0]), int(c[i, 1])))
            out[i] = ac.arc_error(start, end, centre, rule=rule) is None
        return out
    f32 = np.float32
    startx, starty = sx / tens, sy / tens  # Grid.value: the correctly rounded decimal
    endx, endy = e[:, 0] / tens, e[:, 1] / tens
    centrex, centrey = c[:, 0] / tens, c[:, 1] / tens
    ci = (centrex - startx).astype(f32)  # gcode.c's I and J words
    cj = (centrey - starty).astype(f32)
    x = (endx.astype(f32) - startx.astype(f32)) - ci
    y = (endy.astype(f32) - starty.astype(f32)) - cj
    target_r, r = np.sqrt(x * x + y * y), np.sqrt(ci * ci + cj * cj)
    delta = np.abs(target_r - r)
    refused = (delta > f32(ac.GRBL_TOLERANCE_MM)) & (
        (delta > f32(ac.GRBL_CEILING_MM)) | (delta > f32(ac.GRBL_RELATIVE) * r)
    )
    return ~refused & (r != 0)
