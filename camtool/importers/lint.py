"""``camtool inspect``: what a drawing holds and what to fix before cutting it.

:func:`inspect_drawing` reads a drawing like ``camtool post`` does (same importer, same
options), chains it at the same tolerance and reports: entity counts by type and layer
(DXF), contour counts by layer, the bounding box, the units, the importer's warnings and
the findings of :mod:`camtool.importers.lint_checks` (open contours, gaps just above the
tolerance, duplicates and overlaps, zero-length and tiny segments, dropped entities),
each with its location, and for a damaged DXF what ezdxf's recover mode repaired (the
importer's warning only counts the repairs). :class:`InspectReport` gives a text for
people and a JSON object for scripts (``--json``).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from camtool.importers.lint_checks import Finding, check_drawing
from camtool.model.shapes import Arc, BBox, Contour

if TYPE_CHECKING:
    from camtool.importers import ImportOptions
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
    "skipped": "entities not read",
    "repaired": "repairs made to read a damaged file (ezdxf recover mode)",
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
class InspectReport:
    """What ``camtool inspect`` says about one drawing.

    Attributes:
        source: the file name.
        units: the drawing's unit as the importer read it (``"in"``, ``"mm (assumed)"``),
            or None when the importer has no unit to report.
        tolerance: the chaining tolerance used, mm.
        bbox: ``(xmin, ymin, xmax, ymax)`` of all contours, mm.
        entities: ``(type, layer, count)`` of the model-space entities (DXF), sorted.
        block_entities: ``(type, layer, count)`` of entities placed by INSERTs (DXF).
        layers: contour counts per layer after chaining, sorted by layer.
        warnings: the importer's warnings (skipped types, assumed units, repairs).
        findings: the checks' findings, by kind.
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

    def counts(self) -> dict[str, int]:
        """Number of findings of each kind, e.g. ``{"gap": 2}`` (kinds with none left out)."""
        return dict(Counter(f.kind for f in self.findings))

    def to_json(self) -> dict[str, object]:
        """The report as JSON-ready data (keys are a contract for scripts: add, never rename).

        ``source``, ``units``, ``tolerance_mm``, ``bbox_mm`` ``[xmin, ymin, xmax, ymax]``,
        ``size_mm`` ``[w, h]``, ``entities`` and ``block_entities`` (lists of
        ``{type, layer, count}``), ``contours`` ``{total, closed, open, by_layer: [{layer,
        closed, open, lines, arcs}]}``, ``warnings`` (strings), ``findings`` (list of
        ``{kind, message, location: [x, y] | null, sources}``) and ``finding_counts``.
        """
        x0, y0, x1, y1 = self.bbox

        def rows(table: tuple[tuple[str, str, int], ...]) -> list[dict[str, object]]:
            return [{"type": t, "layer": lay, "count": n} for t, lay, n in table]

        return {
            "source": self.source,
            "units": self.units,
            "tolerance_mm": self.tolerance,
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
            f"chaining tolerance {self.tolerance:g} mm",
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
    path: str | Path, options: ImportOptions | None = None, *, tiny_mm: float | None = None
) -> InspectReport:
    """Read a drawing and report its contents and the problems to fix before cutting.

    DXF files are read with :func:`camtool.importers.dxf.import_dxf`, which also counts
    entities by type and layer; other kinds go through
    :func:`camtool.importers.read_drawing` and have contour counts only.

    Args:
        path: the drawing file.
        options: importer options (``layers``, ``tolerance`` in mm: also the chaining
            tolerance the checks use, ``hatch_boundaries``); ``None`` takes the defaults.
        tiny_mm: segments shorter than this are reported as tiny; ``None`` is 10 × the
            tolerance.

    Raises:
        InputError: the drawing cannot be read (as :func:`camtool.importers.read_drawing`).
    """
    from camtool.importers import ImportOptions, read_drawing

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
        notes += [Finding("repaired", r, None) for r in read.repairs]
    else:
        drawing = read_drawing(path, options)
    chained, findings = check_drawing(drawing, options.tolerance, tiny_mm=tiny_mm)
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
    )


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
