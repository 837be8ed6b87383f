"""The biarc fit of one Bézier or elliptical arc, compiled (numba): the plain fit's floats, faster.

Design notes: docs/internals.md, ``camtool/accel/fitkernels.py``.

:func:`curve_pieces` is :func:`camtool.geometry.arcfit.fit_curve` of a quadratic or cubic
Bézier or an elliptical arc over ``u`` ∈ [0, 1], up to (not including) its final merge:
the same midpoint subdivision, samples, candidates, biarcs and two-sided errors, in the same
floating-point operations in the same order (``camtool/geometry/fiterror.py`` says which),
so every piece is the plain fit's bit for bit. The caller builds the segments and merges
them as the plain fit does (:func:`camtool.geometry.arcfit.merge_pieces`).
"""

from __future__ import annotations

import math
from typing import Any

import numba
import numpy as np

SAMPLES = 32
"""Coarse intervals per piece (``arcfit._SAMPLES``): 2·32 + 1 samples."""
SEG_SAMPLES = 16
"""Points per fitted segment for the segments -> curve error (``fiterror.SEG_SAMPLES``)."""
TAU = 2.0 * math.pi
MAX_SWEEP = math.pi
"""Largest sweep of a merged arc (``arcfit.MAX_SWEEP``), radians."""

OK = 0
"""Status: the pieces are the fit."""
DEEP = 1
"""Status: a piece needs more than ``max_depth`` subdivisions (the plain fit raises)."""
NOT_FINITE = 2
"""Status: a point or tangent is not finite (the plain fit raises, naming it)."""

LINE = 0
ARC_CCW = 1
ARC_CW = 2


@numba.njit(cache=True, nogil=True)
def _norm(x: float, y: float) -> float:
    return math.sqrt(x * x + y * y)


CUBIC = 0
"""Curve kind: ``par`` holds the 4 control points (x, y), mm."""
QUADRATIC = 1
"""Curve kind: ``par`` holds the 3 control points (x, y), mm."""
ELLIPSE_ARC = 2
"""Curve kind: ``par`` holds centre, a, b, t0, sweep, p0, p1 (``curves.ellipse_arc``'s)."""


@numba.njit(cache=True, nogil=True)
def _point(kind: int, par: Any, u: float) -> tuple[float, float]:
    """``point_at`` of ``camtool.geometry.curves``' curve of ``kind``: the same operations."""
    if kind == ELLIPSE_ARC:
        if u <= 0.0:
            return par[8], par[9]
        if u >= 1.0:
            return par[10], par[11]
        t = par[6] + par[7] * u
        c = math.cos(t)
        s = math.sin(t)
        return par[0] + par[2] * c + par[4] * s, par[1] + par[3] * c + par[5] * s
    v = 1.0 - u
    if kind == CUBIC:
        w0 = v * v * v
        w1 = 3.0 * v * v * u
        w2 = 3.0 * v * u * u
        w3 = u * u * u
        x = w0 * par[0] + w1 * par[2] + w2 * par[4] + w3 * par[6]
        y = w0 * par[1] + w1 * par[3] + w2 * par[5] + w3 * par[7]
        return x, y
    w0 = v * v
    w1 = 2.0 * v * u
    w2 = u * u
    return w0 * par[0] + w1 * par[2] + w2 * par[4], w0 * par[1] + w1 * par[3] + w2 * par[5]


@numba.njit(cache=True, nogil=True)
def _derivative(kind: int, par: Any, u: float) -> tuple[float, float]:
    """``tangent_at`` of the curve of ``kind``: the same operations."""
    if kind == ELLIPSE_ARC:
        t = par[6] + par[7] * u
        c = math.cos(t)
        s = math.sin(t)
        return par[7] * (par[4] * c - par[2] * s), par[7] * (par[5] * c - par[3] * s)
    v = 1.0 - u
    if kind == CUBIC:
        w0 = 3.0 * v * v
        w1 = 6.0 * v * u
        w2 = 3.0 * u * u
        return (
            w0 * (par[2] - par[0]) + w1 * (par[4] - par[2]) + w2 * (par[6] - par[4]),
            w0 * (par[3] - par[1]) + w1 * (par[5] - par[3]) + w2 * (par[7] - par[5]),
        )
    return (
        2.0 * (v * (par[2] - par[0]) + u * (par[4] - par[2])),
        2.0 * (v * (par[3] - par[1]) + u * (par[5] - par[3])),
    )


@numba.njit(cache=True, nogil=True)
def _samples(kind: int, par: Any, ta: float, pa: Any, tb: float, pb: Any, fine: Any) -> bool:
    """``fine`` ← the piece's 2·SAMPLES + 1 samples (``arcfit._linspace``); False if not finite."""
    n = 2 * SAMPLES
    delta = tb - ta
    step = delta / n
    for i in range(1, n):
        t = (i / n) * delta + ta if step == 0 else i * step + ta
        x, y = _point(kind, par, t)
        if not (math.isfinite(x) and math.isfinite(y)):
            return False
        fine[i, 0] = x
        fine[i, 1] = y
    fine[0, 0], fine[0, 1] = pa[0], pa[1]
    fine[n, 0], fine[n, 1] = pb[0], pb[1]
    return True


@numba.njit(cache=True, nogil=True)
def _tangent(
    kind: int, par: Any, t: float, p: Any, span: float, speed: float
) -> tuple[int, float, float]:
    """``arcfit._Curve.tangent``: (1, unit x, unit y), (0, …) for none, (-1, …) not finite."""
    dx, dy = _derivative(kind, par, t)
    if not (math.isfinite(dx) and math.isfinite(dy)):
        return -1, 0.0, 0.0
    norm = _norm(dx, dy)
    if norm > 1e-9 * speed:
        return 1, dx / norm, dy / norm
    for k in range(3):
        share = 1e-4 if k == 0 else (1e-2 if k == 1 else 0.25)
        h = span * share
        p1x, p1y = _point(kind, par, t + h)
        p2x, p2y = _point(kind, par, t + 2 * h)
        if not (
            math.isfinite(p1x) and math.isfinite(p1y) and math.isfinite(p2x) and math.isfinite(p2y)
        ):
            return -1, 0.0, 0.0
        d1x = (p1x - p[0]) / h
        d1y = (p1y - p[1]) / h
        d2x = (4 * p1x - 3 * p[0] - p2x) / (2 * h)
        d2y = (4 * p1y - 3 * p[1] - p2y) / (2 * h)
        n1 = _norm(d1x, d1y)
        n2 = _norm(d2x, d2y)
        if n2 >= 0.5 * n1:
            bx, by, bn = d2x, d2y, n2
        else:
            bx, by, bn = d1x, d1y, n1
        if bn > 0:
            return 1, bx / bn, by / bn
    return 0, 0.0, 0.0


@numba.njit(cache=True, nogil=True)
def _arc_from(
    px: float, py: float, sx: float, sy: float, qx: float, qy: float, flat: float, row: Any
) -> None:
    """``arcfit._arc_from`` into ``row`` (kind, start, end, centre)."""
    vx = qx - px
    vy = qy - py
    chord = _norm(vx, vy)
    nv = -sy * vx + sx * vy
    sin_a = nv / chord
    cos_a = (sx * vx + sy * vy) / chord
    row[1], row[2], row[3], row[4] = px, py, qx, qy
    row[0] = LINE
    if abs(sin_a) < 1e-12:
        return
    radius = chord / (2.0 * abs(sin_a))
    sagitta = chord * abs(sin_a) / (2.0 * (1.0 + cos_a)) if cos_a > 0 else radius * (1 - cos_a)
    if sagitta <= flat:
        return
    k = (vx * vx + vy * vy) / (2.0 * nv)
    row[5] = px - k * sy
    row[6] = py + k * sx
    row[0] = ARC_CW if k < 0 else ARC_CCW


@numba.njit(cache=True, nogil=True)
def _reverse(row: Any) -> None:
    """``Segment.reversed`` of the row in place."""
    row[1], row[2], row[3], row[4] = row[3], row[4], row[1], row[2]
    if row[0] == ARC_CCW:
        row[0] = ARC_CW
    elif row[0] == ARC_CW:
        row[0] = ARC_CCW


@numba.njit(cache=True, nogil=True)
def _biarc(
    pa: Any, s0x: float, s0y: float, pb: Any, s1x: float, s1y: float, flat: float, rows: Any
) -> int:
    """``arcfit._biarc`` into ``rows``; returns how many segments (1 or 2)."""
    vx = pb[0] - pa[0]
    vy = pb[1] - pa[1]
    vv = vx * vx + vy * vy
    vt = vx * (s0x + s1x) + vy * (s0y + s1y)
    one_minus_cos = max(0.0, 1.0 - (s0x * s1x + s0y * s1y))
    d = vv / (vt + math.sqrt(vt * vt + 2.0 * one_minus_cos * vv))
    jx = 0.5 * (pa[0] + pb[0] + d * (s0x - s1x))
    jy = 0.5 * (pa[1] + pb[1] + d * (s0y - s1y))
    tiny = 1e-9 * math.sqrt(vv)
    if _norm(jx - pa[0], jy - pa[1]) <= tiny or _norm(pb[0] - jx, pb[1] - jy) <= tiny:
        _arc_from(pa[0], pa[1], s0x, s0y, pb[0], pb[1], flat, rows[0])
        return 1
    _arc_from(pa[0], pa[1], s0x, s0y, jx, jy, flat, rows[0])
    _arc_from(pb[0], pb[1], -s1x, -s1y, jx, jy, flat, rows[1])
    _reverse(rows[1])
    return 2


@numba.njit(cache=True, nogil=True)
def _dist_row(x: float, y: float, row: Any) -> float:
    """``fiterror.dist_line``/``dist_arc`` of one point to one segment row."""
    if row[0] == LINE:
        return _seg_dist_line(x, y, (row[1], row[2]), (row[3], row[4]))
    cx, cy = row[5], row[6]
    sx, sy, ex, ey = row[1], row[2], row[3], row[4]
    ux = sx - cx
    uy = sy - cy
    vx = ex - cx
    vy = ey - cy
    rx = x - cx
    ry = y - cy
    qx, qy = rx, ry
    if row[0] == ARC_CW:  # the cross products of the mirrored arc
        ux, uy, vx, vy = uy, ux, vy, vx
        qx, qy = ry, rx
    c1 = ux * qy - uy * qx
    c2 = qx * vy - qy * vx
    wide = ux * vy - uy * vx
    if wide > 0:
        inside = c1 >= 0 and c2 >= 0
    elif wide < 0:
        inside = c1 >= 0 or c2 >= 0
    elif ux * vx + uy * vy < 0:
        inside = c1 >= 0
    else:
        inside = True
    if inside:
        return abs(math.sqrt(rx * rx + ry * ry) - _norm(ux, uy))
    ax = x - sx
    ay = y - sy
    bx = x - ex
    by = y - ey
    return math.sqrt(min(ax * ax + ay * ay, bx * bx + by * by))


@numba.njit(cache=True, nogil=True)
def _seg_dist2(px: float, py: float, ax: float, ay: float, bx: float, by: float) -> float:
    """Squared distance from ``p`` to the segment ``a``–``b``, ``ll = 0`` dividing by 1."""
    dx = bx - ax
    dy = by - ay
    rx = px - ax
    ry = py - ay
    ll = dx * dx + dy * dy
    u = min(max((rx * dx + ry * dy) / (ll if ll > 0 else 1.0), 0.0), 1.0)
    ex = rx - u * dx
    ey = ry - u * dy
    return ex * ex + ey * ey


@numba.njit(cache=True, nogil=True)
def _sweep(row: Any) -> float:
    """``fiterror.arc_sweep`` of an arc row."""
    cx, cy = row[5], row[6]
    ccw = (math.atan2(row[4] - cy, row[3] - cx) - math.atan2(row[2] - cy, row[1] - cx)) % TAU
    if ccw == 0.0:
        ccw = TAU
    return -(TAU - ccw) if row[0] == ARC_CW else ccw


@numba.njit(cache=True, nogil=True)
def _sample_row(row: Any, n: int, out: Any) -> None:
    """``fiterror.sample`` of a segment row: ``out[: n + 1]`` ← points evenly along it."""
    if row[0] == LINE:
        x0, y0, x1, y1 = row[1], row[2], row[3], row[4]
        for k in range(n + 1):
            u = k / n
            out[k, 0] = x0 + u * (x1 - x0)
            out[k, 1] = y0 + u * (y1 - y0)
        return
    cx, cy = row[5], row[6]
    start = math.atan2(row[2] - cy, row[1] - cx)
    sweep = _sweep(row)
    r = _norm(row[1] - cx, row[2] - cy)
    for k in range(n + 1):
        a = start + sweep * (k / n)
        out[k, 0] = cx + r * math.cos(a)
        out[k, 1] = cy + r * math.sin(a)


@numba.njit(cache=True, nogil=True)
def _join(a: Any, b: Any, tol: float, out: Any) -> bool:
    """``arcfit._join`` of rows ``a`` and ``b`` into ``out``; False where they do not join."""
    if a[0] == LINE and b[0] == LINE:
        out[0], out[1], out[2], out[3], out[4] = LINE, a[1], a[2], b[3], b[4]
        out[5], out[6] = 0.0, 0.0
        return True
    if a[0] == LINE or b[0] == LINE or a[0] != b[0]:
        return False
    ra = _norm(a[1] - a[5], a[2] - a[6])
    rb = _norm(b[1] - b[5], b[2] - b[6])
    if _norm(b[5] - a[5], b[6] - a[6]) > tol or abs(ra - rb) > tol:
        return False
    x0, y0, x1, y1 = a[1], a[2], b[3], b[4]
    ux = x1 - x0
    uy = y1 - y0
    chord = _norm(ux, uy)
    if chord <= 1e-9 * ra:
        return False
    nx = -uy / chord
    ny = ux / chord
    mx = 0.5 * (x0 + x1)
    my = 0.5 * (y0 + y1)
    cx = 0.5 * (a[5] + b[5])
    cy = 0.5 * (a[6] + b[6])
    lam = (cx - mx) * nx + (cy - my) * ny
    out[0], out[1], out[2], out[3], out[4] = a[0], x0, y0, x1, y1
    out[5] = mx + lam * nx
    out[6] = my + lam * ny
    sweep = _sweep(out)
    if abs(sweep) > MAX_SWEEP + 1e-9:
        return False
    return not abs(sweep - _sweep(a) - _sweep(b)) > 1e-6


@numba.njit(cache=True, nogil=True)
def _hausdorff(seg: Any, rows: Any, lo: int, hi: int) -> float:
    """``arcfit._hausdorff`` of ``seg`` against ``rows[lo:hi]``."""
    there = -math.inf
    fine = np.empty((4 * SEG_SAMPLES + 1, 2))
    _sample_row(seg, 4 * SEG_SAMPLES, fine)
    for k in range(4 * SEG_SAMPLES + 1):
        best = math.inf
        for i in range(lo, hi):
            best = min(best, _dist_row(fine[k, 0], fine[k, 1], rows[i]))
        there = max(there, best)
    back = -math.inf
    for i in range(lo, hi):
        _sample_row(rows[i], SEG_SAMPLES, fine)
        for k in range(SEG_SAMPLES + 1):
            back = max(back, _dist_row(fine[k, 0], fine[k, 1], seg))
    return max(there, back)


@numba.njit(cache=True, nogil=True)
def merge(rows: Any, piece: Any, errors: Any, tol: float) -> Any:
    """``arcfit._merge`` of the pieces :func:`curve_pieces` gives: the merged rows."""
    m = rows.shape[0]
    out = np.empty((m, 7))
    joined = np.empty(7)
    nout = 0
    first = 0  # the current group's first row
    group_error = 0.0
    for i in range(m):
        error = errors[piece[i]]
        if nout > 0 and _join(out[nout - 1], rows[i], tol, joined):
            err = max(group_error, error)
            if err + _hausdorff(joined, rows, first, i + 1) <= tol:
                out[nout - 1] = joined
                group_error = err
                continue
        out[nout] = rows[i]
        nout += 1
        first = i
        group_error = error
    return out[:nout].copy()


@numba.njit(cache=True, nogil=True)
def _piece_error(rows: Any, nseg: int, fine: Any, pa: Any, limit: float) -> float:
    """``fiterror.piece_error`` of ``rows[:nseg]`` against the samples ``fine``."""
    n = fine.shape[0]
    if nseg == 0:
        worst = -math.inf
        for i in range(n):
            dx = fine[i, 0] - pa[0]
            dy = fine[i, 1] - pa[1]
            worst = max(worst, math.sqrt(dx * dx + dy * dy))
        return worst
    forward = -math.inf
    for i in range(n):
        best = _dist_row(fine[i, 0], fine[i, 1], rows[0])
        for s in range(1, nseg):
            best = min(best, _dist_row(fine[i, 0], fine[i, 1], rows[s]))
        forward = max(forward, best)
    if forward > limit:
        return forward
    sag = 0.0
    m = (n - 1) // 2
    if m > 0:
        sag = -math.inf
        for i in range(m):
            mx, my = fine[2 * i + 1, 0], fine[2 * i + 1, 1]
            ax, ay = fine[2 * i, 0], fine[2 * i, 1]
            bx, by = fine[2 * i + 2, 0], fine[2 * i + 2, 1]
            sag = max(sag, math.sqrt(_seg_dist2(mx, my, ax, ay, bx, by)))
    backward = -math.inf
    pts = np.empty((SEG_SAMPLES + 1, 2))
    for s in range(nseg):
        _sample_row(rows[s], SEG_SAMPLES, pts)
        for k in range(SEG_SAMPLES + 1):
            x, y = pts[k, 0], pts[k, 1]
            best = math.inf
            for j in range(n - 1):
                d2 = _seg_dist2(x, y, fine[j, 0], fine[j, 1], fine[j + 1, 0], fine[j + 1, 1])
                best = min(best, d2)
            backward = max(backward, math.sqrt(best))  # √ of the least: the least √
    return max(forward, backward + 0.5 * sag)


@numba.njit(cache=True, nogil=True)
def curve_pieces(kind: int, par: Any, tol: float, flat: float, max_depth: int) -> Any:
    """The pieces of the plain fit of one curve over ``u`` ∈ [0, 1].

    Args:
        kind: :data:`CUBIC`, :data:`QUADRATIC` or :data:`ELLIPSE_ARC`.
        par: the curve's arguments flattened, float64 (see each kind).
        tol: the fit's internal tolerance (97 % of the user's), mm.
        flat: sagitta below which an arc is a line (a tenth of the user's tolerance), mm.
        max_depth: subdivision limit.

    Returns:
        ``(status, rows, piece, errors)``: :data:`OK`, :data:`DEEP` or :data:`NOT_FINITE`;
        ``rows`` ``(M, 7)`` float64, one segment each (kind :data:`LINE`/:data:`ARC_CCW`/
        :data:`ARC_CW`, start x y, end x y, centre x y); ``piece`` ``(M,)`` the index of the
        piece each row belongs to; ``errors`` ``(P,)`` each piece's error, mm. Pieces with
        no segment (a point) have an error and no row.
    """
    n = 2 * SAMPLES + 1
    fine = np.empty((n, 2))
    cand = np.zeros((2, 7))
    rows = np.zeros((64, 7))
    piece = np.zeros(64, dtype=np.int64)
    errors = np.zeros(32)
    nrows = 0
    npieces = 0
    # the stack of pieces still to fit: ta, pa.x, pa.y, tb, pb.x, pb.y, depth
    stack = np.empty((max_depth + 2, 7))
    x0, y0 = _point(kind, par, 0.0)
    x1, y1 = _point(kind, par, 1.0)
    if not (math.isfinite(x0) and math.isfinite(y0) and math.isfinite(x1) and math.isfinite(y1)):
        return NOT_FINITE, rows[:0], piece[:0], errors[:0]
    stack[0, 0], stack[0, 1], stack[0, 2] = 0.0, x0, y0
    stack[0, 3], stack[0, 4], stack[0, 5], stack[0, 6] = 1.0, x1, y1, 0.0
    top = 1
    pa = np.empty(2)
    pb = np.empty(2)
    while top > 0:
        top -= 1
        ta, pa[0], pa[1] = stack[top, 0], stack[top, 1], stack[top, 2]
        tb, pb[0], pb[1] = stack[top, 3], stack[top, 4], stack[top, 5]
        depth = int(stack[top, 6])
        if not _samples(kind, par, ta, pa, tb, pb, fine):
            return NOT_FINITE, rows[:0], piece[:0], errors[:0]
        nseg = -1  # no candidate
        worst = -math.inf
        for i in range(n):
            worst = max(worst, _seg_dist_line(fine[i, 0], fine[i, 1], pa, pb))
        if worst <= tol:
            if pa[0] == pb[0] and pa[1] == pb[1]:
                nseg = 0
            else:
                cand[0, 0] = LINE
                cand[0, 1], cand[0, 2], cand[0, 3], cand[0, 4] = pa[0], pa[1], pb[0], pb[1]
                nseg = 1
        else:
            vx = pb[0] - pa[0]
            vy = pb[1] - pa[1]
            chord = _norm(vx, vy)
            if chord != 0.0:
                speed = chord / (tb - ta)
                ok0, s0x, s0y = _tangent(kind, par, ta, pa, tb - ta, speed)
                if ok0 < 0:
                    return NOT_FINITE, rows[:0], piece[:0], errors[:0]
                ok1, s1x, s1y = _tangent(kind, par, tb, pb, ta - tb, speed)
                if ok1 < 0:
                    return NOT_FINITE, rows[:0], piece[:0], errors[:0]
                ahead = s0x * vx + s0y * vy > 0.0 and s1x * vx + s1y * vy > 0.0
                if ok0 > 0 and ok1 > 0 and ahead:
                    nseg = _biarc(pa, s0x, s0y, pb, s1x, s1y, flat, cand)
        if nseg >= 0:
            error = _piece_error(cand, nseg, fine, pa, tol)
            if error <= tol:
                if nrows + nseg > rows.shape[0]:
                    rows = _grow(rows)
                    piece = _grow_int(piece)
                for s in range(nseg):
                    rows[nrows] = cand[s]
                    piece[nrows] = npieces
                    nrows += 1
                if npieces == errors.shape[0]:
                    errors = _grow_1d(errors)
                errors[npieces] = error
                npieces += 1
                continue
        if depth >= max_depth:
            return DEEP, rows[:0], piece[:0], errors[:0]
        tm = 0.5 * (ta + tb)
        pmx, pmy = _point(kind, par, tm)
        if not (math.isfinite(pmx) and math.isfinite(pmy)):
            return NOT_FINITE, rows[:0], piece[:0], errors[:0]
        # right half below the left one: the left is fitted first, as the plain recursion
        stack[top, 0], stack[top, 1], stack[top, 2] = tm, pmx, pmy
        stack[top, 3], stack[top, 4], stack[top, 5] = tb, pb[0], pb[1]
        stack[top, 6] = depth + 1
        stack[top + 1, 0], stack[top + 1, 1], stack[top + 1, 2] = ta, pa[0], pa[1]
        stack[top + 1, 3], stack[top + 1, 4], stack[top + 1, 5] = tm, pmx, pmy
        stack[top + 1, 6] = depth + 1
        top += 2
    return OK, rows[:nrows].copy(), piece[:nrows].copy(), errors[:npieces].copy()


@numba.njit(cache=True, nogil=True)
def _seg_dist_line(x: float, y: float, a: Any, b: Any) -> float:
    """``fiterror.dist_line`` of one point to ``a``–``b``."""
    dx = b[0] - a[0]
    dy = b[1] - a[1]
    rx = x - a[0]
    ry = y - a[1]
    ll = dx * dx + dy * dy
    if ll > 0:
        u = min(max((rx * dx + ry * dy) / ll, 0.0), 1.0)
        ex = rx - u * dx
        ey = ry - u * dy
    else:
        ex, ey = rx, ry
    return math.sqrt(ex * ex + ey * ey)


@numba.njit(cache=True, nogil=True)
def line_error(fine: Any, pax: float, pay: float, pbx: float, pby: float) -> float:
    """Largest ``fiterror.dist_line`` of the samples ``fine`` ``(N, 2)`` to ``pa``–``pb``, mm.

    The ends come as four floats (a call with tuples costs numba more than the loop).
    """
    worst = -math.inf
    pa = (pax, pay)
    pb = (pbx, pby)
    for i in range(fine.shape[0]):
        worst = max(worst, _seg_dist_line(fine[i, 0], fine[i, 1], pa, pb))
    return worst


@numba.njit(cache=True, nogil=True)
def piece_error(rows: Any, nseg: int, fine: Any, pax: float, pay: float, limit: float) -> float:
    """``fiterror.piece_error`` of the segment rows ``rows[:nseg]`` against ``fine``, mm."""
    return _piece_error(rows, nseg, fine, (pax, pay), limit)


@numba.njit(cache=True, nogil=True)
def _grow(a: Any) -> Any:
    out = np.zeros((2 * a.shape[0], a.shape[1]))
    out[: a.shape[0]] = a
    return out


@numba.njit(cache=True, nogil=True)
def _grow_int(a: Any) -> Any:
    out = np.zeros(2 * a.shape[0], dtype=np.int64)
    out[: a.shape[0]] = a
    return out


@numba.njit(cache=True, nogil=True)
def _grow_1d(a: Any) -> Any:
    out = np.zeros(2 * a.shape[0])
    out[: a.shape[0]] = a
    return out
