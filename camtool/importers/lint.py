"""``camtool inspect``: what a drawing holds and what to fix before cutting it.

Design notes: docs/internals.md, ``camtool/importers/lint.py``.
"""

from __future__ import annotations

import math
from collections import Counter, defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from camtool.geometry.chain import chain, joint_distance
from camtool.importers import read_drawing
from camtool.importers.options import ImportOptions
from camtool.model.errors import UsageError
from camtool.model.shapes import (
    FULL_CIRCLE_EPS,
    TAU,
    Arc,
    BBox,
    Contour,
    Drawing,
    Line,
    Point,
    Segment,
    distance,
)

if TYPE_CHECKING:
    from camtool.importers.dxf import DxfNote

SHOWN_PER_KIND = 10
"""The text report lists this many findings of each kind, then says how many more."""

_KIND_TITLES = {
    "open-contour": "open contours",
    "gap": "gaps just above the tolerance",
    "duplicate": "duplicate segments",
    "overlap": "overlapping segments",
    "zero-length": "zero-length segments or entities",
    "tiny-segment": "tiny segments",
    "construction": "not cut unless an operation names them (construction, not the part)",
    "skipped": "entities not read",
    "repaired": "repairs made to read a damaged file (ezdxf recover mode)",
    "noted": "what ezdxf noted while reading the file",
}


@dataclass(frozen=True)
class LayerContours:
    """Contours of one layer after chaining: how many closed and open, and their segments."""

    layer: str
    closed: int
    open: int
    lines: int
    arcs: int


@dataclass(frozen=True)
class StyleCount:
    """Contours drawn one way: on one layer, in one colour and linetype (before chaining).

    A job selects by these (docs/jobs.md). ``circles`` are whole circles (drillable),
    ``points`` the points (DXF POINTs, SVG dots) of the layer and colour.
    """

    layer: str
    colour: str
    linetype: str
    closed: int
    open: int
    circles: int
    points: int = 0


@dataclass(frozen=True)
class InspectReport:
    """What ``camtool inspect`` says about one drawing.

    Attributes:
        source: the file name.
        units: the drawing's unit as the importer read it (``"in"``, ``"mm (assumed)"``),
            or None when the importer has no unit to report.
        tolerance: the importer's tolerance (``--tolerance``): curve fitting, duplicates,
            overlaps and the default tiny-segment limit, mm.
        bbox: ``(xmin, ymin, xmax, ymax)`` of all contours, mm.
        entities: ``(type, layer, count)`` of the model-space entities (DXF), sorted.
        block_entities: ``(type, layer, count)`` of entities placed by INSERTs (DXF).
        layers: contour counts per layer after chaining, sorted by layer.
        warnings: the importer's warnings (skipped types, assumed units, repairs).
        findings: the checks' findings, by kind.
        chain_tolerance: ends closer than this are joined into one contour
            (``--chain-tolerance``), mm; None: the ends were joined within ``tolerance``.
        styles: the contours by layer, colour and linetype, before chaining.
    """

    source: str
    units: str | None
    tolerance: float
    bbox: BBox
    entities: tuple[tuple[str, str, int], ...] = field(default=())
    block_entities: tuple[tuple[str, str, int], ...] = field(default=())
    layers: tuple[LayerContours, ...] = field(default=())
    warnings: tuple[str, ...] = field(default=())
    findings: tuple[Finding, ...] = field(default=())
    chain_tolerance: float | None = None
    styles: tuple[StyleCount, ...] = field(default=())

    @property
    def joined_within(self) -> float:
        """The chaining tolerance, mm: ``chain_tolerance``, or ``tolerance`` when None."""
        return self.tolerance if self.chain_tolerance is None else self.chain_tolerance

    def counts(self) -> dict[str, int]:
        """Number of findings of each kind, e.g. ``{"gap": 2}`` (kinds with none left out)."""
        return dict(Counter(f.kind for f in self.findings))

    def to_json(self) -> dict[str, object]:
        """The report as JSON-ready data (keys are a contract for scripts: add, never rename).

        ``source``, ``units``, ``tolerance_mm``, ``chain_tolerance_mm`` (see
        :attr:`joined_within`), ``bbox_mm`` ``[xmin, ymin, xmax, ymax]``,
        ``size_mm`` ``[w, h]``, ``entities`` and ``block_entities`` (lists of
        ``{type, layer, count}``), ``contours`` ``{total, closed, open, by_layer: [{layer,
        closed, open, lines, arcs}]}``, ``warnings`` (strings), ``findings`` (list of
        ``{kind, message, location: [x, y] | null, sources}``), ``finding_counts`` and
        ``styles`` (list of ``{layer, colour, linetype, closed, open, circles, points}``:
        what a job's operations select by).
        """
        x0, y0, x1, y1 = self.bbox

        def rows(table: tuple[tuple[str, str, int], ...]) -> list[dict[str, object]]:
            return [{"type": t, "layer": lay, "count": n} for t, lay, n in table]

        return {
            "source": self.source,
            "units": self.units,
            "tolerance_mm": self.tolerance,
            "chain_tolerance_mm": self.joined_within,
            "bbox_mm": [x0, y0, x1, y1],
            "size_mm": [x1 - x0, y1 - y0],
            "entities": rows(self.entities),
            "block_entities": rows(self.block_entities),
            "contours": {
                "total": sum(lay.closed + lay.open for lay in self.layers),
                "closed": sum(lay.closed for lay in self.layers),
                "open": sum(lay.open for lay in self.layers),
                "by_layer": [vars(lay).copy() for lay in self.layers],
            },
            "styles": [vars(st).copy() for st in self.styles],
            "warnings": list(self.warnings),
            "findings": [f.to_json() for f in self.findings],
            "finding_counts": self.counts(),
        }

    def text(self) -> str:
        """The report for people: a few aligned sections, findings last."""
        x0, y0, x1, y1 = self.bbox
        closed = sum(lay.closed for lay in self.layers)
        opened = sum(lay.open for lay in self.layers)
        lines = [
            f"{self.source}",
            f"  units: {self.units or 'as the importer read them'}; coordinates in mm; "
            f"chaining tolerance {self.joined_within:g} mm",
            f"  size: {x1 - x0:.4f} x {y1 - y0:.4f} mm, "
            f"from ({x0:.4f}, {y0:.4f}) to ({x1:.4f}, {y1:.4f})",
            f"  contours: {closed + opened} ({closed} closed, {opened} open)",
        ]
        if self.entities:
            lines += ["", "entities in model space:", *_table(self.entities)]
        if self.block_entities:
            lines += ["", "entities placed by blocks (INSERT):", *_table(self.block_entities)]
        lines += ["", "contours by layer (after chaining):"]
        lines += _layer_table(self.layers)
        if self.styles:
            lines += [
                "",
                "layers, colours and linetypes (what a job selects by), each entity as read "
                "(closed = true/false judges the chains above):",
            ]
            lines += _style_table(self.styles)
        if self.warnings:
            lines += ["", "warnings:", *(f"  {w}" for w in self.warnings)]
        lines += ["", *self._findings_text()]
        return "\n".join(lines) + "\n"

    def _findings_text(self) -> list[str]:
        if not self.findings:
            return ["no problems found"]
        out = []
        for kind, count in self.counts().items():
            out.append(f"{_KIND_TITLES.get(kind, kind)}: {count}")
            shown = [f for f in self.findings if f.kind == kind][:SHOWN_PER_KIND]
            for f in shown:
                names = f" [{', '.join(f.sources)}]" if f.sources else ""
                out.append(f"  {f.message}{names}")
            if count > len(shown):
                out.append(f"  ... and {count - len(shown)} more (all of them with --json)")
        return out


def inspect_drawing(
    path: str | Path,
    options: ImportOptions | None = None,
    *,
    tiny_mm: float | None = None,
    chain_tolerance: float | None = None,
) -> InspectReport:
    """Read a drawing and report its contents and the problems to fix before cutting.

    DXF files are read with :func:`camtool.importers.dxf.import_dxf`, which also counts
    entities by type and layer; other kinds go through
    :func:`camtool.importers.read_drawing` and have contour counts only.

    Args:
        path: the drawing file.
        options: importer options (``layers``, ``tolerance`` in mm: also the limit of
            the duplicate and overlap checks, ``hatch_boundaries``); ``None`` takes the
            defaults.
        tiny_mm: segments shorter than this are reported as tiny; ``None`` is 10 × the
            tolerance.
        chain_tolerance: ends closer than this (mm, ≥ 0) are joined, as ``camtool post
            --chain-tolerance`` joins them (:func:`camtool.geometry.chain.joint_distance`);
            ``None`` joins ends within ``options.tolerance``.

    Raises:
        InputError: the drawing cannot be read (as :func:`camtool.importers.read_drawing`).
        UsageError: ``chain_tolerance`` is negative or NaN.
    """
    options = options or ImportOptions()
    path = Path(path)
    notes: list[Finding] = []
    units: str | None = None
    entities: tuple[tuple[str, str, int], ...] = ()
    block_entities: tuple[tuple[str, str, int], ...] = ()
    if path.suffix.lower() == ".dxf":
        from camtool.importers.dxf import import_dxf

        read = import_dxf(path, options)
        drawing, units = read.drawing, read.units
        entities, block_entities = read.entity_counts, read.block_entity_counts
        notes = [_note_finding(n) for n in read.notes]
        kind = "repaired" if read.recovered else "noted"
        notes += [Finding(kind, r, None) for r in read.repairs]
    else:
        drawing = read_drawing(path, options)
    chained, findings = check_drawing(
        drawing, options.tolerance, tiny_mm=tiny_mm, chain_tolerance=chain_tolerance
    )
    notes += _construction(drawing)
    order = list(_KIND_TITLES)
    every = sorted(
        [*findings, *notes], key=lambda f: order.index(f.kind) if f.kind in order else 99
    )
    return InspectReport(
        source=str(path),
        units=units,
        tolerance=options.tolerance,
        bbox=drawing.bbox(),
        entities=entities,
        block_entities=block_entities,
        layers=_by_layer(chained),
        warnings=drawing.warnings,
        findings=tuple(every),
        chain_tolerance=chain_tolerance,
        styles=_styles(drawing),
    )


def _styles(drawing: Drawing) -> tuple[StyleCount, ...]:
    """The drawing's contours (and points) counted by layer, colour and linetype."""
    from camtool.model.shapes import circle_of

    counts: dict[tuple[str, str, str], list[int]] = {}
    for c in drawing.contours:
        row = counts.setdefault((c.layer, c.colour, c.linetype), [0, 0, 0, 0])
        row[0 if c.closed else 1] += 1
        row[2] += circle_of(c) is not None
    for m in drawing.marks:
        counts.setdefault((m.layer, m.colour, ""), [0, 0, 0, 0])[3] += 1
    return tuple(
        StyleCount(layer, colour, linetype, *row)
        for (layer, colour, linetype), row in sorted(
            counts.items(), key=lambda item: (item[0][0].casefold(), item[0][1], item[0][2])
        )
    )


def _style_table(styles: tuple[StyleCount, ...]) -> list[str]:
    wl = max(len("layer"), *(len(st.layer) for st in styles))
    wt = max(len("linetype"), *(len(st.linetype or "continuous") for st in styles))
    out = [f"  {'layer':<{wl}}  colour   {'linetype':<{wt}}  closed   open  circles  points"]
    out += [
        f"  {st.layer:<{wl}}  {st.colour or '-':<7}  {st.linetype or 'continuous':<{wt}}  "
        f"{st.closed:>6} {st.open:>6} {st.circles:>8} {st.points:>7}"
        for st in styles
    ]
    return out


def _construction(drawing: Drawing) -> list[Finding]:
    """A ``construction`` finding per layer and linetype that ``post`` leaves uncut."""
    from camtool.model.construction import construction_layer, line_kind

    groups: dict[tuple[str, str], list[Contour]] = {}
    for c in drawing.contours:
        if c.linetype or construction_layer(c.layer):
            groups.setdefault((c.layer, c.linetype), []).append(c)
    out = []
    for (layer, linetype), contours in sorted(groups.items()):
        what = line_kind(linetype)
        first = contours[0]
        out.append(
            Finding(
                "construction",
                f"{len(contours)} contour(s) on layer {layer!r} ({what}), first at "
                f"({first.start[0]:.4f}, {first.start[1]:.4f})",
                first.start,
                tuple(c.source for c in contours[:5] if c.source),
            )
        )
    return out


def _note_finding(note: DxfNote) -> Finding:
    """An entity the DXF reader dropped, as a ``zero-length`` or ``skipped`` finding."""
    kind = "zero-length" if note.reason == "zero length" else "skipped"
    where = f" at ({note.location[0]:.4f}, {note.location[1]:.4f})" if note.location else ""
    msg = f"{note.source} on layer {note.layer!r}{where}: {note.reason}"
    return Finding(kind, msg, note.location, (note.source,))


def _by_layer(chained: list[Contour]) -> tuple[LayerContours, ...]:
    table: dict[str, list[int]] = {}
    for c in chained:
        row = table.setdefault(c.layer, [0, 0, 0, 0])
        row[0 if c.closed else 1] += 1
        arcs = sum(isinstance(s, Arc) for s in c.segments)
        row[2] += len(c.segments) - arcs
        row[3] += arcs
    return tuple(LayerContours(lay, *table[lay]) for lay in sorted(table, key=str.casefold))


def _table(rows: tuple[tuple[str, str, int], ...]) -> list[str]:
    wt = max(len("type"), *(len(t) for t, _, _ in rows))
    wl = max(len("layer"), *(len(lay) for _, lay, _ in rows))
    out = [f"  {'type':<{wt}}  {'layer':<{wl}}  count"]
    out += [f"  {t:<{wt}}  {lay:<{wl}}  {n:>5}" for t, lay, n in rows]
    return out


def _layer_table(layers: tuple[LayerContours, ...]) -> list[str]:
    wl = max(len("layer"), *(len(lay.layer) for lay in layers)) if layers else 5
    out = [f"  {'layer':<{wl}}  closed   open  lines   arcs"]
    out += [
        f"  {lay.layer:<{wl}}  {lay.closed:>6} {lay.open:>6} {lay.lines:>6} {lay.arcs:>6}"
        for lay in layers
    ]
    return out


# ------------------------------------------------------------------ drawing checks

GAP_FACTOR = 10.0
"""Open ends closer than this many tolerances (but farther than one) are reported as gaps."""
TINY_FACTOR = 10.0
"""Default tiny-segment limit, in tolerances."""
ZERO_LENGTH_MM = 1e-9
"""Segments shorter than this are zero-length."""


@dataclass(frozen=True)
class Finding:
    """One thing to look at before cutting.

    Attributes:
        kind: ``open-contour``, ``gap``, ``duplicate``, ``overlap``, ``zero-length``,
            ``tiny-segment``, ``skipped`` (an entity the importer dropped) or ``repaired``
            (what ezdxf's recover mode repaired, or could not, in a damaged DXF file).
        message: a sentence for the user, lowercase, with numbers in mm.
        location: where, mm (WCS, Y up), or None when the importer gave no point.
        sources: the entities or contours involved (``Contour.source`` values).
    """

    kind: str
    message: str
    location: Point | None
    sources: tuple[str, ...] = ()

    def to_json(self) -> dict[str, object]:
        """``{"kind", "message", "location": [x, y] | null, "sources": [...]}``."""
        where = None if self.location is None else [self.location[0], self.location[1]]
        return {
            "kind": self.kind,
            "message": self.message,
            "location": where,
            "sources": list(self.sources),
        }


def check_drawing(
    drawing: Drawing,
    tolerance: float,
    *,
    tiny_mm: float | None = None,
    chain_tolerance: float | None = None,
) -> tuple[list[Contour], list[Finding]]:
    """Chain the drawing's contours and run every check.

    Args:
        drawing: contours in mm, one per entity as read.
        tolerance: the tolerance of the duplicate and overlap checks, mm (> 0), as
            ``--tolerance``; also the chaining tolerance when ``chain_tolerance`` is None.
        tiny_mm: segments shorter than this are ``tiny-segment``; ``None`` is
            :data:`TINY_FACTOR` × ``tolerance``.
        chain_tolerance: the chaining tolerance, mm (≥ 0), as ``--chain-tolerance``:
            contours are chained, and gaps judged, at
            :func:`~camtool.geometry.chain.joint_distance` of it, as the planner does.

    Returns:
        ``(chained contours, findings)``; findings ordered by kind, then as found.

    Raises:
        UsageError: ``chain_tolerance`` is negative or NaN.
    """
    if chain_tolerance is not None and not chain_tolerance >= 0:
        raise UsageError(f"--chain-tolerance must be ≥ 0 mm, got {chain_tolerance!r}")
    tiny = TINY_FACTOR * tolerance if tiny_mm is None else tiny_mm
    joint = tolerance if chain_tolerance is None else joint_distance(chain_tolerance)
    chained = chain(drawing.contours, joint)
    findings = [
        *open_contours(chained),
        *gaps(chained, joint),
        *duplicates(drawing.contours, tolerance),
        *short_segments(drawing.contours, tiny),
    ]
    return chained, findings


def open_contours(chained: Sequence[Contour]) -> list[Finding]:
    """An ``open-contour`` finding per open contour, located at its start."""
    out = []
    for c in chained:
        if not c.closed:
            msg = (
                f"open contour from {_pt(c.start)} to {_pt(c.end)}, {c.length:.4g} mm long; "
                "an inside/outside offset or a pocket needs it closed"
            )
            out.append(Finding("open-contour", msg, c.start, (_name(c),)))
    return out


def gaps(chained: Sequence[Contour], tolerance: float) -> list[Finding]:
    """Pairs of open ends ``tolerance < d ≤ GAP_FACTOR · tolerance`` apart, at their midpoint.

    A contour's own two ends count too, unless it is a single line (whose ends are
    its length apart).
    """
    limit = GAP_FACTOR * tolerance
    ends: list[tuple[Point, int]] = []
    for i, c in enumerate(chained):
        if not c.closed:
            ends += [(c.start, i), (c.end, i)]
    cells: dict[tuple[int, int], list[int]] = defaultdict(list)
    for k, (p, _) in enumerate(ends):
        cells[(math.floor(p[0] / limit), math.floor(p[1] / limit))].append(k)
    out = []
    said: set[tuple[str, tuple[str, ...]]] = set()
    for k, (p, i) in enumerate(ends):
        cx, cy = math.floor(p[0] / limit), math.floor(p[1] / limit)
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for m in cells.get((cx + dx, cy + dy), ()):
                    q, j = ends[m]
                    d = distance(p, q)
                    own_line = i == j and len(chained[i].segments) == 1
                    if m > k and tolerance < d <= limit and not own_line:
                        mid = ((p[0] + q[0]) / 2, (p[1] + q[1]) / 2)
                        msg = (
                            f"gap of {d:.4g} mm at {_pt(mid)}: above the chaining tolerance "
                            f"{tolerance:g} mm, so these ends are not joined"
                        )
                        srcs = tuple(dict.fromkeys((_name(chained[i]), _name(chained[j]))))
                        if (msg, srcs) not in said:  # two specks' four ends: one gap
                            said.add((msg, srcs))
                            out.append(Finding("gap", msg, mid, srcs))
    return out


def duplicates(contours: Sequence[Contour], tolerance: float) -> list[Finding]:
    """Duplicate segments (either direction) and overlapping collinear / co-circular ones.

    Findings are grouped per pair of contours (two copies of a fitted spline give one
    ``duplicate`` finding that counts its segments), located at the first one found.
    """
    segs = [(s, k) for k, c in enumerate(contours) for s in c.segments]
    if len(segs) < 2:
        return []
    found = _candidates([s for s, _ in segs], tolerance)
    groups: dict[tuple[int, int, str], list[Any]] = {}
    for i, j in zip(found[0].tolist(), found[1].tolist(), strict=True):
        (a, ka), (b, kb) = segs[i], segs[j]
        if _same(a, b, tolerance):
            kind, length, where = "duplicate", a.length, a.start
        else:
            shared = _overlap(a, b, tolerance)
            if shared is None:
                continue
            kind, (length, where) = "overlap", shared
        group = groups.setdefault((min(ka, kb), max(ka, kb), kind), [0, 0.0, where, _kind(a)])
        group[0] += 1
        group[1] += length
    out = []
    for (ka, kb, kind), (count, length, where, seg) in groups.items():
        names = tuple(dict.fromkeys((_name(contours[ka]), _name(contours[kb]))))
        if kind == "duplicate":
            what = f"duplicate {seg}" if count == 1 else f"{count} duplicate segments"
            msg = (
                f"{what} at {_pt(where)}, {length:.4g} mm: drawn twice, so cut twice unless "
                "a whole contour repeats another (post then cuts it once and says so)"
            )
        else:
            what = f"overlapping {seg}s share" if count == 1 else f"{count} overlaps share"
            msg = f"{what} {length:.4g} mm at {_pt(where)}"
        out.append(Finding(kind, msg, where, names))
    return out


_SLACK = 1e-9
"""Relative widening of :func:`_candidates`' tests (and absolute, in mm, below 1 mm): numpy's
``hypot`` and ``atan2`` may differ from :mod:`math`'s in the last bit, and a candidate too
many costs one exact test, a candidate missed a finding."""


def _candidates(segs: Sequence[Segment], tol: float) -> Any:
    """Pairs that :func:`_same` or :func:`_overlap` may accept: ``(2, m)`` int array, i < j.

    Ordered by ``i``, then ``j``. A superset of the accepted pairs, in arrays: boxes grown by
    ``tol`` that meet (shapely's ``STRtree`` on their envelopes), both lines with the shorter's
    ends within ``tol`` of the longer's line, or both arcs with centres and radii within
    ``tol``. The exact tests decide.
    """
    import numpy as np
    from shapely import STRtree, linestrings

    n = len(segs)
    nan = (math.nan, math.nan, math.nan)
    ends = np.array([(*s.start, *s.end) for s in segs], dtype=np.float64)  # x0, y0, x1, y1
    circle = np.array(  # cx, cy, 1.0 clockwise / 0.0 of arcs; NaN for lines
        [(*s.centre, float(s.clockwise)) if isinstance(s, Arc) else nan for s in segs],
        dtype=np.float64,
    ).reshape(n, 3)
    grown = _boxes(ends, circle) + np.array([-tol, -tol, tol, tol])
    grown += _SLACK * np.maximum(1.0, np.abs(grown)) * np.array([-1, -1, 1, 1])
    corners = grown.reshape(n, 2, 2)
    diagonals = linestrings(corners)
    found = STRtree(diagonals).query(diagonals)
    i, j = found[:, found[0] < found[1]]
    arc = ~np.isnan(circle[:, 0])
    radius = np.hypot(ends[:, 0] - circle[:, 0], ends[:, 1] - circle[:, 1])
    both_arcs = arc[i] & arc[j]
    near = np.hypot(circle[i, 0] - circle[j, 0], circle[i, 1] - circle[j, 1])
    close = _within(near, tol) & _within(np.abs(radius[i] - radius[j]), tol)
    keep = np.where(both_arcs, close, ~arc[i] & ~arc[j] & _collinear(ends, i, j, tol))
    i, j = i[keep], j[keep]
    order = np.lexsort((j, i))
    return np.stack((i[order], j[order]))


def _within(value: Any, tol: float) -> Any:
    import numpy as np

    return value <= tol + _SLACK * np.maximum(1.0, tol)


def _collinear(ends: Any, i: Any, j: Any, tol: float) -> Any:
    """Per pair of lines: the shorter's ends within ``tol`` of the longer's line (or a point)."""
    import numpy as np

    span = ends[:, 2:] - ends[:, :2]
    length = np.hypot(span[:, 0], span[:, 1])
    swap = length[j] > length[i]
    long, short = np.where(swap, j, i), np.where(swap, i, j)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = span[long, 0] / length[long], span[long, 1] / length[long]
        off = [
            np.abs(
                (ends[short, c] - ends[long, 0]) * -uy + (ends[short, c + 1] - ends[long, 1]) * ux
            )
            for c in (0, 2)
        ]
        scale = np.maximum(np.abs(ends[long]).max(axis=1), length[long])
        slack = _SLACK * np.maximum(1.0, scale)
        return ~(length[long] > 0) | ((off[0] <= tol + slack) & (off[1] <= tol + slack))


def _boxes(ends: Any, circle: Any) -> Any:
    """``(n, 4)`` boxes ``(xmin, ymin, xmax, ymax)`` of lines and arcs, as :meth:`Arc.bbox`.

    An arc's box holds its ends and each point of its circle at 0°, 90°, 180° and 270° that
    its sweep passes; a full circle (ends within :data:`FULL_CIRCLE_EPS` × max(1, r)) all four.
    """
    import numpy as np

    x = ends[:, 0::2]
    y = ends[:, 1::2]
    box = np.stack((x.min(axis=1), y.min(axis=1), x.max(axis=1), y.max(axis=1)), axis=1)
    arcs = np.flatnonzero(~np.isnan(circle[:, 0]))
    if not len(arcs):
        return box
    e, (cx, cy, cw) = ends[arcs], circle[arcs].T
    r = np.hypot(e[:, 0] - cx, e[:, 1] - cy)
    a0 = np.arctan2(e[:, 1] - cy, e[:, 0] - cx)
    ccw = np.mod(np.arctan2(e[:, 3] - cy, e[:, 2] - cx) - a0, TAU)
    full = np.hypot(e[:, 2] - e[:, 0], e[:, 3] - e[:, 1]) <= FULL_CIRCLE_EPS * np.maximum(1.0, r)
    span = np.where(full | (ccw == 0.0), TAU, np.where(cw == 1.0, TAU - ccw, ccw))
    for quad, col, sign in (
        (0.0, 2, 1),
        (math.pi / 2, 3, 1),
        (math.pi, 0, -1),
        (1.5 * math.pi, 1, -1),
    ):
        delta = np.where(cw == 1.0, np.mod(a0 - quad, TAU), np.mod(quad - a0, TAU))
        passed = delta <= span + _SLACK
        extreme = (cx if col % 2 == 0 else cy) + sign * r
        outer = np.maximum if sign > 0 else np.minimum
        box[arcs, col] = np.where(passed, outer(extreme, box[arcs, col]), box[arcs, col])
    return box


def short_segments(contours: Sequence[Contour], tiny_mm: float) -> list[Finding]:
    """``zero-length`` and ``tiny-segment`` findings, located at the segment's start."""
    out = []
    for c in contours:
        for s in c.segments:
            if s.length <= ZERO_LENGTH_MM:
                msg = f"zero-length {_kind(s)} at {_pt(s.start)}"
                out.append(Finding("zero-length", msg, s.start, (_name(c),)))
            elif s.length < tiny_mm:
                msg = f"tiny {_kind(s)} of {s.length:.3g} mm at {_pt(s.start)} (< {tiny_mm:g} mm)"
                out.append(Finding("tiny-segment", msg, s.start, (_name(c),)))
    return out


def _same(a: Segment, b: Segment, tol: float) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, Arc) and isinstance(b, Arc):
        if distance(a.centre, b.centre) > tol or abs(a.radius - b.radius) > tol:
            return False
        if a.is_full_circle or b.is_full_circle:
            return a.is_full_circle and b.is_full_circle
        b = b if a.clockwise == b.clockwise else b.reversed()
        return distance(a.start, b.start) <= tol and distance(a.end, b.end) <= tol
    fwd = distance(a.start, b.start) <= tol and distance(a.end, b.end) <= tol
    return fwd or (distance(a.start, b.end) <= tol and distance(a.end, b.start) <= tol)


def _overlap(a: Segment, b: Segment, tol: float) -> tuple[float, Point] | None:
    """Shared length (> ``tol``) and a point of it, for collinear lines or co-circular arcs."""
    if isinstance(a, Line) and isinstance(b, Line):
        return _line_overlap(a, b, tol)
    if isinstance(a, Arc) and isinstance(b, Arc):
        return _arc_overlap(a, b, tol)
    return None


def _line_overlap(a: Line, b: Line, tol: float) -> tuple[float, Point] | None:
    long, short = (a, b) if a.length >= b.length else (b, a)
    if not long.length > 0:  # two points: duplicates or apart, never overlapping
        return None
    (x0, y0), (x1, y1) = long.start, long.end
    ux, uy = (x1 - x0) / long.length, (y1 - y0) / long.length
    off = [(p[0] - x0) * -uy + (p[1] - y0) * ux for p in (short.start, short.end)]
    if max(abs(o) for o in off) > tol:
        return None
    ts = sorted((p[0] - x0) * ux + (p[1] - y0) * uy for p in (short.start, short.end))
    lo, hi = max(0.0, ts[0]), min(long.length, ts[1])
    if hi - lo <= tol:
        return None
    mid = (lo + hi) / 2
    return hi - lo, (x0 + ux * mid, y0 + uy * mid)


def _arc_overlap(a: Arc, b: Arc, tol: float) -> tuple[float, Point] | None:
    if distance(a.centre, b.centre) > tol or abs(a.radius - b.radius) > tol:
        return None
    (s1, e1), (s2, e2) = _ccw_span(a), _ccw_span(b)
    best = (0.0, 0.0)
    for k in (-1, 0, 1):
        lo, hi = max(s1, s2 + k * TAU), min(s1 + e1, s2 + e2 + k * TAU)
        if hi - lo > best[0]:
            best = (hi - lo, (lo + hi) / 2)
    length = best[0] * a.radius
    if length <= tol:
        return None
    ang = best[1]
    return length, (a.centre[0] + a.radius * math.cos(ang), a.centre[1] + a.radius * math.sin(ang))


def _ccw_span(arc: Arc) -> tuple[float, float]:
    """The arc as a counter-clockwise interval ``(start angle in [0, 2π), extent)``."""
    sweep = arc.sweep
    start = arc.start_angle if sweep > 0 else arc.start_angle + sweep
    return start % TAU, abs(sweep)


def _kind(s: Segment) -> str:
    return "arc" if isinstance(s, Arc) else "line"


def _name(c: Contour) -> str:
    return c.source or f"contour on layer {c.layer!r}"


def _pt(p: Point) -> str:
    return f"({p[0]:.4f}, {p[1]:.4f})"
