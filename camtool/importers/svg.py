"""SVG importer: paths and basic shapes become contours in mm, Y up, arcs exact.

Design notes: docs/internals.md, ``camtool/importers/svg.py``.
"""

from __future__ import annotations

import io
import math
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import Any, TypeAlias

import svgelements as se

from camtool.accel.collector import collect_young
from camtool.geometry.arcfit import check_tolerance
from camtool.geometry.chain import closes_alone, with_end
from camtool.geometry.curves import ellipse_extent, merge_arcs, semi_axes_gap
from camtool.geometry.fitpool import (
    MIN_CURVES,
    CurveKey,
    SharedFits,
    fit_key,
    fitter_ahead,
    moved,
    shape_key,
)
from camtool.importers import svgclip
from camtool.importers.options import MAX_COORDINATE_MM, ImportOptions, check_curve_size
from camtool.importers.svgdoc import (
    SOURCE_ATTR,
    USE_ATTR,
    Prepared,
    Unseen,
    element_noun,
    prepare,
    unseen_warnings,
    zero_opacity,
)
from camtool.importers.svgdots import dots_warning, draws_dots, shape_marks, unclipped
from camtool.importers.svgpage import (
    Affine,
    apply,
    check_travel,
    compose,
    is_background,
    page_warnings,
)
from camtool.importers.svgstyle import (
    filter_of,
    filtered_warning,
    flattened,
    layer_of,
    on_layers,
    open_fills,
    open_fills_warning,
    style_of,
    unpainted,
    unseen_fill,
    wanted_layers,
    zero_width,
)
from camtool.model.errors import GeometryError, InputError, TooLargeError
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import (
    TAU,
    Arc,
    BBox,
    Contour,
    Drawing,
    Line,
    Mark,
    Point,
    Segment,
    bbox_union,
    distance,
)

_SHAPES = (se.Path, se.Rect, se.Circle, se.Ellipse, se.SimpleLine, se.Polyline, se.Polygon)
_STROKED = (se.Path, se.SimpleLine, se.Polyline, se.Polygon)
"""Shapes whose zero-length subpaths are dots (a zero radius or size draws nothing)."""


def read_svg(
    path: str | Path, options: ImportOptions | None = None, *, progress: Progress = no_progress
) -> Drawing:
    """Read an SVG file into a drawing in mm, Y up (:func:`svg_drawing`'s drawing)."""
    return svg_drawing(path, options, progress=progress)[0]


def svg_drawing(
    path: str | Path,
    options: ImportOptions | None = None,
    *,
    progress: Progress = no_progress,
    check: Callable[[BBox], None] | None = None,
) -> tuple[Drawing, float]:
    """Read an SVG file into a drawing in mm, Y up, and the tolerance its curves were fitted within.

    The page's bottom-left corner is the origin. ``width``/``height`` in mm, cm, in, pt,
    pc or px (1/96 in) with a ``viewBox`` set the scale; without an absolute size user units
    are px, with a warning.

    Args:
        path: the SVG file.
        options: ``layers`` (Inkscape layer labels or ids; hidden layers named here are read)
            and ``tolerance`` (mm, for Béziers and ellipses, once the drawing is scaled as
            ``scale`` or ``fit`` say: for ``fit``, the factor of the extent of the
            drawn segments' ends, :func:`_ends_boxes`) are used; ``units`` is the user
            unit of a document without an absolute size (refused for one with it).
        check: called with the extent of the drawn segments' ends (:func:`_ends_boxes`, mm,
            a box within the drawing's) before any curve is fitted; what it raises stops
            the reading (``camtool post`` refuses there a drawing too large for the
            machine, :func:`camtool.jobs.pipeline.post_path`).
        progress: told the stages (:class:`~camtool.model.progress.Step`): ``reading``
            (the file's name; ``total``: drawn shapes once counted, ``done`` as their
            segments are read), ``fitting`` (only when the curves are fitted ahead, see
            :func:`_prefitted`; ``total``: distinct curves) and ``contours`` (``total``:
            shapes). It changes nothing in the drawing.

    Returns:
        One contour per drawn subpath, and the warnings a user should see (assumed units,
        skipped elements by kind and count, hidden layers); and the tolerance the curves
        were fitted within, mm at the drawing's size
        (:meth:`~camtool.importers.options.ImportOptions.curve_tolerance`).

    Raises:
        UsageError: ``options.tolerance`` is not a positive number.
        InputError: the file is missing, malformed (XML, path data, transform, length,
            points, size, viewBox; the message names the element), names an unknown layer
            (the message lists the layers) or draws nothing.
    """
    path = Path(path)
    options = options or ImportOptions()
    check_tolerance(options.tolerance)
    with fitter_ahead(path):
        return _drawing(path, options, progress, check)


def _drawing(
    path: Path,
    options: ImportOptions,
    progress: Progress,
    check: Callable[[BBox], None] | None,
) -> tuple[Drawing, float]:
    """:func:`svg_drawing`'s work."""
    progress(Step("reading", name=path.name))
    inkscape, named = wanted_layers(path, options.layers)
    prepared = prepare(
        path,
        inkscape,
        max_entities=options.max_entities,
        units=options.units,
        shown=options.shown,
    )
    svg = _parse(path, prepared)
    warnings = list(prepared.warnings)
    contours: list[Contour] = []
    marks: list[Mark] = []  # dots (camtool.importers.svgdots)
    unseen = Unseen()
    drawn: list[tuple[Any, list[Any] | None]] = []
    shapes = list(_shapes(svg))
    progress(Step("reading", 0, len(shapes), path.name))
    for i, shape in enumerate(shapes, start=1):
        values = shape.values
        line = isinstance(shape, se.SimpleLine)  # no inside: its fill shows nothing (SVG 2 §10.5)
        if str(values.get("visibility", "visible")).strip().lower() in ("hidden", "collapse"):
            unseen.hidden += 1
        elif zero_opacity(values.get("opacity")):
            unseen.faded += 1
        elif (
            not unpainted(shape.stroke)
            and zero_width(values.get("stroke-width"))
            and (line or unpainted(shape.fill))
        ):
            unseen.thin += 1
        elif unpainted(shape.stroke) and line:
            unseen.bare += 1
        elif unpainted(shape.fill) and unpainted(shape.stroke):
            unseen.invisible += 1
        elif flattened(shape.transform):
            unseen.flat += 1
        else:
            drawn.append((shape, _segments(shape)))
        progress(Step("reading", i, len(shapes), path.name))
    boxes: list[BBox | None] = []
    if options.fit is not None or check is not None:
        boxes = _ends_boxes(drawn, prepared.matrix)
    known = [b for b in boxes if b is not None]
    box = bbox_union(known) if known else None
    clips = svgclip.clipped_shapes(svg, _SHAPES)
    deferred = False  # too large with every shape: checked again without the unseen ones
    if check is not None and box is not None:
        try:
            check_travel(path, check, box, _labelled(drawn, boxes), prepared.page)
        except TooLargeError:
            if not any(id(shape) in clips or unseen_fill(shape) for shape, _ in drawn):
                raise
            deferred = True
    tolerance = options.curve_tolerance(box)
    fitter = _prefitted(drawn, prepared.matrix, tolerance, progress)
    regions: dict[tuple[int, Affine], tuple[Any, Any]] = {}
    kept: list[int] = []
    opened: list[Contour] = []  # open contours a viewer fills as if closed
    filtered: list[tuple[str, str]] = []  # (label, filter id) of shapes drawn through one
    progress(Step("contours", 0, len(drawn)))
    for i, (shape, segments) in enumerate(drawn, start=1):
        made = _contours(path, shape, segments, prepared.matrix, fitter)
        over = clips.get(id(shape))
        if unseen_fill(shape) and is_background(made, prepared.page):
            unseen.background += 1  # the page's white background: a viewer shows nothing of it
        elif not over or not _hidden_by_clip(
            path, shape, made, over, prepared.matrix, tolerance, regions
        ):
            contours.extend(made)
            if isinstance(shape, _STROKED) and draws_dots(shape):
                m = compose(prepared.matrix, affine_of(shape.transform))
                marks += unclipped(shape_marks(shape, segments, m, _label(shape)), over or ())
            kept.append(i - 1)
            opened += open_fills(shape, made)
            if made and (name := filter_of(shape)) is not None:
                filtered.append((made[0].source, name))
        progress(Step("contours", i, len(drawn)))
    clipped_away = len(drawn) - len(kept) - unseen.background
    if deferred and check is not None:
        left = [b for b in (boxes[k] for k in kept) if b is not None]
        if left:
            kept_boxes = [boxes[k] for k in kept]
            labelled = _labelled([drawn[k] for k in kept], kept_boxes)
            check_travel(path, check, bbox_union(left), labelled, prepared.page)
    if (clipped_away or unseen.background) and options.fit is not None and known:
        # --fit scales what is kept: without the hidden shapes' extent, by a larger factor,
        # which the curves' tolerance must follow (ImportOptions.curve_tolerance)
        left = [b for b in (boxes[k] for k in kept) if b is not None]
        finer = options.curve_tolerance(bbox_union(left)) if left else tolerance
        if finer < tolerance:
            tolerance, fitter = finer, Fitter(finer)
            contours = [
                c for k in kept for c in _contours(path, *drawn[k], prepared.matrix, fitter)
            ]
    if clipped_away:
        its, them = ("its", "it") if clipped_away == 1 else ("their", "them")
        warnings.append(
            f"{path}: skipped {clipped_away} {element_noun(clipped_away)} that {its} clip-path, "
            f"mask or viewport hides wholly (a viewer shows nothing of {them})"
        )
    if opened:
        warnings.append(open_fills_warning(path, len(opened), opened[0].source))
    if filtered:
        warnings.append(filtered_warning(path, len(filtered), *filtered[0]))
    warnings += unseen_warnings(path, unseen)
    if named:
        contours = on_layers(path, contours, named, (m.layer for m in marks))
        marks = [m for m in marks if m.layer in named]
    off_page, size_note = page_warnings(path, contours, prepared.page)
    warnings += off_page
    if marks:
        warnings.append(dots_warning(path, marks))
    if not contours and not marks:
        where = " in the selected layers" if options.layers else ""
        prefix = f"{path}: "
        skipped = [w.removeprefix(prefix) for w in warnings if w.startswith(prefix + "skipped")]
        why = f" ({'; '.join(skipped)})" if skipped else ""  # e.g. only <text>: what to do
        raise InputError(
            f"{path}: nothing to cut{where}; camtool reads path, rect, circle, ellipse, "
            f"line, polyline and polygon elements that are drawn{why}"
        )
    drawing = Drawing(tuple(contours), str(path), tuple(warnings), tuple(marks), size_note)
    return drawing, tolerance


_DISTINCT_MM = 1e-6
"""Ends at least this far apart (mm) make a segment :func:`_ends_boxes` counts: well above
:data:`ZERO_LENGTH_MM`, under which :func:`convert` drops a segment."""


def _ends_boxes(drawn: list[tuple[Any, list[Any] | None]], page: Affine) -> list[BBox | None]:
    """Per drawn shape, the extent (mm) of its segments' ends, before any curve is fitted.

    Only the ends of segments whose ends are more than :data:`_DISTINCT_MM` apart are
    taken: such a segment is drawn (:func:`convert` drops only segments of zero length,
    and a fit ends where its curve does), so each end taken is a point of the drawing,
    and their union lies within the drawing's box. So ``--fit``'s factor for it is at
    least the drawing's (curves fitted for it are fitted at least as finely as the
    drawing's own factor asks), and a drawing whose union is larger than a machine's
    travel is larger than it. ``None`` for a shape with no such end (``Move`` points,
    and the shapes whose segments svgelements could not give, are left out).
    """
    return [_shape_ends_box(shape, segments, page) for shape, segments in drawn]


def _shape_ends_box(shape: Any, segments: list[Any] | None, page: Affine) -> BBox | None:
    """One shape's box of :func:`_ends_boxes`."""
    if not segments:
        return None
    xs: list[float] = []
    ys: list[float] = []
    m = compose(page, affine_of(shape.transform))
    for seg in segments:
        if isinstance(seg, se.Move) or seg.start is None or seg.end is None:
            continue
        x0, y0 = apply(m, float(seg.start.x), float(seg.start.y))
        x1, y1 = apply(m, float(seg.end.x), float(seg.end.y))
        # a number past MAX_COORDINATE_MM (or not finite) is refused later, with its
        # own message: it is no extent to judge
        sane = max(abs(x0), abs(y0), abs(x1), abs(y1)) <= MAX_COORDINATE_MM
        if sane and math.hypot(x1 - x0, y1 - y0) > _DISTINCT_MM:
            xs += (x0, x1)
            ys += (y0, y1)
    if not xs:
        return None
    return (min(xs), min(ys), max(xs), max(ys))


def _parse(path: Path, prepared: Prepared) -> Any:
    """The prepared file parsed by svgelements, and the XML tree it leaves behind freed.

    svgelements leaves the elements it read in reference cycles (its table of ids points
    back into the tree), which only the cyclic collector frees; the ``camtool`` command
    runs it rarely (:data:`camtool.accel.collector.THRESHOLD`), so the young generations
    are collected here, where that garbage is made.
    """
    width, height = prepared.viewport
    try:
        svg = se.SVG.parse(
            io.BytesIO(prepared.data), reify=False, ppi=96.0, width=width, height=height
        )
    except (ValueError, TypeError, IndexError, KeyError, ZeroDivisionError) as exc:
        raise InputError(f"{path}: svgelements cannot read this SVG ({exc!r})") from exc
    collect_young()
    if svg is None:  # svgelements' answer to display:none on the root
        raise InputError(
            f"{path}: nothing to cut: the <svg> element itself is hidden (display:none), so "
            "the whole drawing is; remove display:none from it to cut what it holds"
        )
    return svg


def _shapes(node: Any) -> Iterator[Any]:
    """Drawn shapes under ``node`` in document order (groups, ``<svg>``, ``<use>`` clones)."""
    for child in node:
        if isinstance(child, _SHAPES):
            yield child
        elif isinstance(child, se.Group | se.Use):
            yield from _shapes(child)


def _contours(
    path: Path, shape: Any, segments: list[Any] | None, page: Affine, fitter: Fitter
) -> list[Contour]:
    """The shape's contours, from its ``segments`` read ahead.

    ``None``: svgelements failed on them ahead, so they are asked again here, in the
    shape's turn (the error is the one it always was).
    """
    values = shape.values
    label = _label(shape)
    layer = layer_of(values)
    m = compose(page, affine_of(shape.transform))
    try:
        if segments is None:
            subpaths = convert(shape_segments(shape), m, fitter.tolerance, fitter)
        else:
            subpaths = convert(segments, m, fitter.tolerance, fitter)
    except (GeometryError, InputError) as exc:
        raise InputError(f"{path}: {label}: {exc}") from exc
    many = len(subpaths) > 1
    colour, linetype = style_of(values)
    return [
        Contour(segs, closed, layer, f"{label} subpath {k}" if many else label, colour, linetype)
        for k, (segs, closed) in enumerate(subpaths, start=1)
    ]


def _hidden_by_clip(
    path: Path,
    shape: Any,
    contours: list[Contour],
    clips: tuple[svgclip.Clip, ...],
    page: Affine,
    tolerance: float,
    regions: dict[tuple[int, Affine], tuple[Any, Any]],
) -> bool:
    """Whether ``clips`` hide all of ``shape`` (its ``contours``); none of it: ``False``.

    ``regions``: the clips' regions worked out so far (:func:`svgclip.clip_region`).

    Raises:
        InputError: a clip hides part of the shape (camtool would cut the hidden part), or
            its region cannot be worked out (:mod:`camtool.importers.svgclip`).
    """
    lines = [c.points(tolerance) for c in contours]
    filled = not unpainted(shape.fill)
    parts = []
    for clip in clips:
        try:
            if clip.why:
                raise InputError(clip.why)
            svgclip.clip_region(clip, page, affine_of, _clip_subpaths, _SHAPES, regions)
        except (InputError, GeometryError) as exc:
            raise InputError(
                f"{path}: {_label(shape)} is clipped by {svgclip.clip_label(clip, _label)}, "
                f"whose region camtool cannot work out ({exc}); {svgclip.remedy(clip)}"
            ) from None
        parts.append((svgclip.hidden_part(clip, lines, filled), clip))
    if any(part == "all" for part, _ in parts):
        return True
    for part, clip in parts:
        if part == "part":
            raise InputError(
                f"{path}: {svgclip.clip_label(clip, _label)} hides part of {_label(shape)}, "
                "and camtool cuts whole shapes: the hidden part would be cut; "
                f"{svgclip.remedy(clip)}"
            )
    return False


def _clip_subpaths(shape: Any, m: Affine) -> list[list[Point]]:
    """A clip child's subpaths as points in mm (``m``: its coordinates to mm), finely."""
    fine = svgclip.CLIP_SLACK_MM / 10
    subpaths = convert(shape_segments(shape), m, fine)
    return [Contour(segs, closed).points(fine) for segs, closed in subpaths]


def _labelled(
    drawn: list[tuple[Any, list[Any] | None]], boxes: list[BBox | None]
) -> list[tuple[str, BBox | None]]:
    """Each drawn shape's label and extent, for :func:`~camtool.importers.svgpage.check_travel`."""
    return [(_label(shape), b) for (shape, _), b in zip(drawn, boxes, strict=True)]


def _label(shape: Any) -> str:
    """How messages name a drawn shape: its element and id, and the ``<use>`` placing it."""
    values = shape.values
    label = str(values.get(SOURCE_ATTR, type(shape).__name__.lower()))
    use = values.get(USE_ATTR)
    if use and use != label:
        label = f"{use} > {label}"
    return label


# ------------------------------------------------------------------ curve fits, ahead


class Fitter:
    """Fits curves by :data:`~camtool.geometry.fitpool.CurveKey` within ``tolerance`` mm.

    ``done`` holds fits made ahead (on the machine's cores, :func:`_prefitted`), ``index``
    their keys' places by the key's exact ``repr`` (every float's bits, ``-0.0`` apart from
    ``0.0``); any other key, or one whose fit failed ahead, is fitted here, as without it.
    A Bézier of a shape fitted before is that fit moved onto it
    (:class:`~camtool.geometry.fitpool.SharedFits` ahead,
    :func:`~camtool.geometry.fitpool.moved` here: the same fits either way).
    """

    def __init__(
        self, tolerance: float, done: SharedFits | None = None, index: dict[str, int] | None = None
    ):
        self.tolerance = tolerance
        self.done, self.index = done, index or {}
        self.shapes: dict[Any, tuple[CurveKey, list[Segment]]] = {}

    def __call__(self, key: CurveKey) -> list[Segment]:
        """The fit of ``key`` (a new list), made ahead or here."""
        if self.done is not None:
            i = self.index.get(repr(key))
            segs = None if i is None else self.done.get(i)
            if segs is not None:
                return list(segs)
        shape = shape_key(key)
        met = self.shapes.get(shape) if shape is not None else None
        if met is not None:
            return moved(met[1], met[0], key)
        segs = fit_key(key, self.tolerance)
        if shape is not None:
            self.shapes[shape] = (key, segs)
        return list(segs)


class _Recorder(Fitter):
    """Gives the keys to its ``done`` (each once) instead of fitting; answers a line to the end.

    The line stands for the fit only to carry the pen on to the next segment's key (a fit
    ends exactly at the curve's end, unless it is dropped as of zero length: the keys that
    follow then differ and are fitted when met, see :class:`Fitter`).
    """

    def __call__(self, key: CurveKey) -> list[Segment]:
        text = repr(key)
        if text not in self.index:
            assert self.done is not None
            self.index[text] = self.done.add(key)
        args = key[1]
        if key[0] == "ellipse_arc":
            return [Line(args[5], args[6])]
        return [Line(args[0], args[-1])]


_CURVES = (se.CubicBezier, se.QuadraticBezier, se.Arc)


def _segments(shape: Any) -> list[Any] | None:
    """The shape's segments (:func:`shape_segments`); ``None`` where svgelements fails."""
    try:
        return shape_segments(shape)
    except Exception:  # raised again when the shape's turn comes, after the shapes before it
        return None


def shape_segments(shape: Any) -> list[Any]:
    """The shape's svgelements segments, untransformed, each smooth curve's control as SVG's.

    ``S`` reflects the previous segment's second control point only when that segment is a
    cubic (``C``/``S``), ``T`` the previous control point only when it is a quadratic
    (``Q``/``T``); after any other segment the (first) control point is the current point
    (SVG 1.1 §8.3.6, §8.3.7). svgelements reflects either kind's last control point, which
    makes ``S`` after ``Q`` and ``T`` after ``C`` another curve, millimetres off, and every
    ``T`` chained after such a ``T`` with it.

    Raises:
        Exception: whatever svgelements raises on the shape's segments.
    """
    out = list(shape.segments(transformed=False))
    moved = False  # out[k - 1] is a quadratic whose control point was corrected
    for k in range(1, len(out)):
        seg, before = out[k], out[k - 1]
        now = False
        if isinstance(seg, se.CubicBezier) and seg.smooth:
            if isinstance(before, se.QuadraticBezier):
                out[k] = se.CubicBezier(seg.start, seg.start, seg.control2, seg.end)
        elif isinstance(seg, se.QuadraticBezier) and seg.smooth:
            if isinstance(before, se.CubicBezier):
                out[k], now = se.QuadraticBezier(seg.start, seg.start, seg.end), True
            elif moved and isinstance(before, se.QuadraticBezier):
                control = before.control.reflected_across(seg.start)
                out[k], now = se.QuadraticBezier(seg.start, control, seg.end), True
        moved = now
    return out


def _prefitted(
    drawn: list[tuple[Any, list[Any] | None]],
    page: Affine,
    tolerance: float,
    progress: Progress = no_progress,
) -> Fitter:
    """A :class:`Fitter` holding the fits of the drawing's curves, made on every core.

    Only for at least :data:`~camtool.geometry.fitpool.MIN_CURVES` curves: the shapes are
    converted once with a :class:`_Recorder` to give the curves, in order, to a
    :class:`~camtool.geometry.fitpool.SharedFits` (a shape that fails here fails again,
    with its message, when converted for real), which fits each shape once, telling
    ``progress`` the ``fitting`` stage (``total``: the distinct shapes) as the fits come
    in (with a helper started ahead, it fits them as they are given, and the fits are
    taken as the contours need them).
    """
    count = sum(isinstance(seg, _CURVES) for _, segs in drawn for seg in segs or ())
    if count < MIN_CURVES:
        return Fitter(tolerance)
    fits = SharedFits(tolerance)
    recorder = _Recorder(tolerance, fits)
    for shape, segments in drawn:
        if segments is None:
            continue
        try:
            convert(segments, compose(page, affine_of(shape.transform)), tolerance, recorder)
        except Exception:  # converted again below, raising in order
            continue
    fits.close(lambda n, total: progress(Step("fitting", n, total)))
    return Fitter(tolerance, fits, recorder.index)


# ------------------------------------------------------------------ path segments to mm

ZERO_LENGTH_MM = 1e-9
"""Segments shorter than this (mm) are dropped; ends closer than this are one point."""
_SEMI = 1e-7  # a centre this close (× chord) to the chord midpoint is a half ellipse


def affine_of(matrix: Any) -> Affine:
    """An svgelements ``Matrix`` as an :data:`Affine`."""
    return (
        float(matrix.a),
        float(matrix.b),
        float(matrix.c),
        float(matrix.d),
        float(matrix.e),
        float(matrix.f),
    )


Subpath: TypeAlias = tuple[tuple[Segment, ...], bool]
"""One subpath's segments (each starting where the previous ended) and whether it is closed."""


def convert(
    segments: Iterable[Any], m: Affine, tolerance: float, fitter: Fitter | None = None
) -> list[Subpath]:
    """Turn svgelements path segments (local coordinates) into subpaths in mm, Y up.

    Each ``Move`` starts a subpath; ``Close`` draws the line back to the subpath's start
    (unless within ``tolerance`` of it: the last segment is then moved to end there) and
    closes it. A subpath whose last point is within 1e-9 mm of
    its first is closed too. Zero-length segments are dropped; consecutive arcs on one
    circle (a ``<circle>``'s quarters, an arc split in two) are merged.

    Args:
        segments: svgelements segments of one shape, untransformed.
        m: local coordinates to mm, Y up.
        tolerance: largest distance, mm, between a Bézier or a non-circular elliptical arc
            and the arcs and lines fitted to it (> 0).
        fitter: fits the curves (the same fits, some made ahead); ``None``: a
            :class:`Fitter` of ``tolerance``.

    Returns:
        ``(segments, closed)`` per subpath that draws something.

    Raises:
        GeometryError: a curve could not be fitted (from :func:`fit_curve`).
        InputError: a point, control point or arc centre is NaN, infinite or beyond
            ±:data:`~camtool.importers.options.MAX_COORDINATE_MM` once mapped to mm (checked
            before any fitting, which would spin on a control point at 1e20).
    """
    fitter = fitter or Fitter(tolerance)
    out: list[Subpath] = []
    current: list[Segment] = []
    start: Point | None = None
    cursor: Point | None = None

    def flush(closed: bool, snap: float = ZERO_LENGTH_MM) -> None:
        if current:
            segs = merge_arcs(current)
            if (
                start is not None
                and distance(segs[-1].end, start) <= snap
                and (len(segs) > 1 or closes_alone(segs[0]))
            ):
                segs[-1] = with_end(segs[-1], start)
                closed = True
            out.append((tuple(segs), closed))
        current.clear()

    for seg in segments:
        if isinstance(seg, se.Move):
            flush(False)
            start = cursor = _pt(m, seg.end)
            continue
        if cursor is None or start is None:  # svgelements always starts with Move
            start = cursor = _pt(m, seg.start)
        if isinstance(seg, se.Close):
            # a gap within the tolerance is the rounding of relative coordinates (CorelDRAW's
            # 2 decimals): the last segment is moved to end at the start, rather than a
            # closing line as thin as a spike (offsetting reads it as the contour crossing)
            gap = distance(cursor, start)
            alone = len(current) == 1 and not closes_alone(current[0])
            if gap > tolerance or (gap > ZERO_LENGTH_MM and alone):
                current.append(Line(cursor, start))
            flush(True, snap=tolerance)
            cursor = start
            continue
        new = segment(seg, cursor, m, tolerance, fitter)
        for piece in new:
            if isinstance(piece, Arc):
                _check(piece.centre, "an arc centre")
        current.extend(new)
        if new:
            cursor = new[-1].end
    flush(False)
    return out


def segment(
    seg: Any, p0: Point, m: Affine, tolerance: float, fitter: Fitter | None = None
) -> list[Segment]:
    """One svgelements drawing segment from ``p0`` (mm, already mapped) as lines and arcs.

    ``fitter`` fits its curve (``None``: a :class:`Fitter` of ``tolerance``).

    Raises:
        ValueError: ``seg`` is of a kind svgelements does not produce in a path.
    """
    if isinstance(seg, se.Line):
        return _line(p0, _pt(m, seg.end))
    fitter = fitter or Fitter(tolerance)
    if isinstance(seg, se.CubicBezier):
        ctrl = (p0, _pt(m, seg.control1), _pt(m, seg.control2), _pt(m, seg.end))
        _check_size(ctrl, tolerance)
        return _fit(("cubic", ctrl), fitter)
    if isinstance(seg, se.QuadraticBezier):
        ctrl3 = (p0, _pt(m, seg.control), _pt(m, seg.end))
        _check_size(ctrl3, tolerance)
        return _fit(("quadratic", ctrl3), fitter)
    if isinstance(seg, se.Arc):
        return _arc(seg, p0, m, tolerance, fitter)
    raise ValueError(f"unexpected path segment {type(seg).__name__}")


def _pt(m: Affine, p: Any) -> Point:
    """``p`` mapped to mm, checked to be finite and within the bound."""
    return _check(apply(m, float(p.x), float(p.y)), "a point")


def _check_size(points: Iterable[Point], tolerance: float) -> None:
    """Refuse a curve whose control points span too much for ``tolerance`` (InputError)."""
    xs, ys = zip(*points, strict=True)
    _check_extent(2.0 * max(max(xs) - min(xs), max(ys) - min(ys)), tolerance)


def _check_extent(extent: float, tolerance: float) -> None:
    """Refuse a curve ``extent`` mm across, too much for ``tolerance`` (InputError)."""
    try:
        check_curve_size(extent, tolerance)
    except ValueError as exc:
        raise InputError(str(exc).replace(" across", " mm across", 1)) from None


def _check(p: Point, what: str) -> Point:
    x, y = p
    if not (abs(x) <= MAX_COORDINATE_MM and abs(y) <= MAX_COORDINATE_MM):
        raise InputError(
            f"{what} at ({x:g}, {y:g}) mm, not a finite number within ±1e9 mm; the "
            "path data, a transform or the viewBox holds a number far too large"
        )
    return p


def _line(p0: Point, p1: Point) -> list[Segment]:
    return [Line(p0, p1)] if distance(p0, p1) > ZERO_LENGTH_MM else []


def _fit(key: CurveKey, fitter: Fitter) -> list[Segment]:
    """The fit of ``key``, or none when its segments are no longer than a point.

    Their lengths are summed only until the sum is past :data:`ZERO_LENGTH_MM` (the first
    segment, as a rule): the answer is the whole sum's, since no length is negative.
    """
    segs = fitter(key)
    total = 0.0
    for seg in segs:
        total += seg.length
        if total > ZERO_LENGTH_MM:
            return segs
    return []


def _arc(seg: Any, p0: Point, m: Affine, tolerance: float, fitter: Fitter) -> list[Segment]:
    """An svgelements elliptical arc: an exact Arc where its image is a circle, else fitted.

    svgelements keeps the arc as centre ``c``, ``prx`` (the point at t = 0), ``pry`` (at
    t = π/2) and a signed ``sweep`` in t, so the local curve is ``c + a cos t + b sin t``
    with ``a = prx - c``, ``b = pry - c``.
    """
    p1 = _pt(m, seg.end)
    sweep = float(seg.sweep or 0.0)
    (cx, cy), (sx, sy), (ex, ey) = _xy(seg.center), _xy(seg.start), _xy(seg.end)
    ax, ay = float(seg.prx.x) - cx, float(seg.prx.y) - cy
    bx, by = float(seg.pry.x) - cx, float(seg.pry.y) - cy
    det = ax * by - ay * bx
    if sweep == 0.0 or not math.isfinite(det) or abs(det) <= 1e-300:
        return _line(p0, p1)  # SVG F.6.2: a zero radius makes a straight line
    # svgelements takes the centre from sqrt(max-radius-correction), which leaves ~1e-8
    # of noise on half ellipses (radii scaled up to fit the chord); put them back exactly
    mx, my = 0.5 * (sx + ex), 0.5 * (sy + ey)
    if math.hypot(cx - mx, cy - my) <= _SEMI * math.hypot(ex - sx, ey - sy):
        cx, cy, sweep = mx, my, math.copysign(math.pi, sweep)
    dx, dy = sx - cx, sy - cy
    t0 = math.atan2((ax * dy - ay * dx) / det, (dx * by - dy * bx) / det)
    centre = apply(m, cx, cy)
    big_a = (m[0] * ax + m[2] * ay, m[1] * ax + m[3] * ay)
    big_b = (m[0] * bx + m[2] * by, m[1] * bx + m[3] * by)
    cross = big_a[0] * big_b[1] - big_a[1] * big_b[0]
    if semi_axes_gap(big_a, big_b, cross) <= 0.1 * tolerance:
        return _circular(p0, p1, centre, ccw=cross * sweep > 0.0, sweep=sweep)
    _check(centre, "an ellipse centre")
    ends = (t0, t0 + sweep) if sweep > 0.0 else (t0 + sweep, t0)
    _check_extent(ellipse_extent(centre, big_a, big_b, *ends), tolerance)  # the part cut
    return _fit(("ellipse_arc", (centre, big_a, big_b, t0, sweep, p0, p1)), fitter)


def _xy(p: Any) -> Point:
    return (float(p.x), float(p.y))


def _circular(p0: Point, p1: Point, centre: Point, *, ccw: bool, sweep: float) -> list[Segment]:
    if distance(p0, p1) <= ZERO_LENGTH_MM:
        if abs(abs(sweep) - TAU) > 1e-9:
            return []  # SVG F.6.2: an arc whose ends coincide is omitted
        return [Arc(p0, p0, centre, not ccw)]
    # centre exactly on the bisector of the chord, so both ends are on one circle
    (x0, y0), (x1, y1) = p0, p1
    mx, my = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    chord = math.hypot(x1 - x0, y1 - y0)
    nx, ny = -(y1 - y0) / chord, (x1 - x0) / chord
    lam = (centre[0] - mx) * nx + (centre[1] - my) * ny
    return [Arc(p0, p1, (mx + lam * nx, my + lam * ny), not ccw)]
