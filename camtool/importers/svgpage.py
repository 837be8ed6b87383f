"""An SVG document's page: its size and viewBox as one map from user units to mm, Y up.

Design notes: docs/internals.md, ``camtool/importers/svgdoc.py`` (its first point, the page).
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TypeAlias

from camtool.importers.svgcheck import NUMBER
from camtool.model.errors import InputError, TooLargeError, UsageError
from camtool.model.shapes import BBox, Contour, Line, Point
from camtool.model.units import LENGTH_UNITS, PX

Affine: TypeAlias = tuple[float, float, float, float, float, float]
"""``(a, b, c, d, e, f)``: ``x' = a·x + c·y + e``, ``y' = b·x + d·y + f`` (SVG's ``matrix()``)."""


def compose(outer: Affine, inner: Affine) -> Affine:
    """The map ``outer ∘ inner``: ``inner`` is applied first."""
    a1, b1, c1, d1, e1, f1 = outer
    a2, b2, c2, d2, e2, f2 = inner
    return (
        a1 * a2 + c1 * b2,
        b1 * a2 + d1 * b2,
        a1 * c2 + c1 * d2,
        b1 * c2 + d1 * d2,
        a1 * e2 + c1 * f2 + e1,
        b1 * e2 + d1 * f2 + f1,
    )


def apply(m: Affine, x: float, y: float) -> Point:
    """The image of the point ``(x, y)`` under ``m``."""
    return (m[0] * x + m[2] * y + m[4], m[1] * x + m[3] * y + m[5])


_PAGE_UNITS_MM = {**{u: LENGTH_UNITS[u] for u in ("mm", "cm", "in", "pt", "px")}, "pc": 25.4 / 6}


def page_matrix(
    root: ET.Element,
    name: str,
    warnings: list[str],
    units: str | None = None,
    illustrator: str | None = None,
) -> tuple[Affine, tuple[float, float], tuple[float, float] | None]:
    """Map from user units to mm, Y up; the viewport size in user units; the page in mm.

    The page is ``(width, height)`` in mm, its lower-left corner at the origin of the
    map's output; ``None`` when the document gives neither a size nor a viewBox.

    Removes ``width``, ``height``, ``viewBox``, ``preserveAspectRatio``, ``x`` and ``y`` from
    ``root``. Without an absolute ``width`` and ``height`` (missing, or relative: ``%``,
    ``em``) the user unit is ``units`` (``--units``), else the px (1/96 in) with a warning;
    with a viewBox, one missing side is taken from the viewBox's aspect ratio. Without a
    page height the Y flip is about the user-unit origin. ``illustrator``: the version of
    Adobe Illustrator that wrote the file (:func:`illustrator_version`), whose px are points.

    Raises:
        InputError: a malformed size or viewBox, or a size in a unit with no physical length.
        UsageError: ``units`` for a document whose size is given in absolute units.
    """
    width, width_text = _page_length(root, "width", name)
    height, height_text = _page_length(root, "height", name)
    box = _viewbox(root, name)
    legacy = legacy_inkscape(root, box is not None)
    if legacy is not None and units is None:  # --units says what the user unit is
        warnings.append(
            f"{name}: made by Inkscape {legacy}, which drew 90 px to the inch; its px are read "
            "as 96 to the inch (CSS, and Inkscape 0.92 and later unless told otherwise), so a "
            "part drawn there to size comes out 6.25 % small: give --scale 1.066667 (96/90) "
            "to cut it at the size Inkscape showed"
        )
    in_points = units is None and _illustrator_px(root, illustrator, box is not None)
    if in_points:
        remedy = "--scale 1.333333 (96/72)" if width or height else "--units pt"
        warnings.append(
            f"{name}: made by Adobe Illustrator {illustrator}, which writes its points (1/72 "
            "in) as px; they are read as px of 96 to the inch (CSS, as browsers and Inkscape "
            f"read them), so a part drawn there to size comes out 25 % small: give {remedy} "
            "to cut it at the size Illustrator showed"
        )
    if box is not None and width is not None and height is None:
        height = width * box[3] / box[2]
    elif box is not None and height is not None and width is None:
        width = height * box[2] / box[3]
    unit = PX
    if width is None and height is None:
        relative = [t for t in (width_text, height_text) if t]
        what = f"relative size {' x '.join(relative)}" if relative else "no width/height"
        if units is not None:
            unit = LENGTH_UNITS[units]
        elif not in_points:
            warnings.append(f"{name}: {what}; user units taken as px (1/96 in)")
    elif units is not None:
        given = " x ".join(str(root.get(a)) for a in ("width", "height") if root.get(a))
        raise UsageError(
            f"--units {units}: {name} gives its size ({given}), so its units are known; "
            "--units is for a drawing without them: leave it out, or use --scale to resize"
        )
    page: tuple[float, float] | None = None
    if box is None:
        sx = sy = unit
        tx = ty = 0.0
        viewport = (width / PX, height / PX) if width and height else (1000.0, 1000.0)
        if width and height:
            page = (width, height)
    elif width is None or height is None:
        sx = sy = unit
        tx, ty = -box[0] * unit, -box[1] * unit
        height = box[3] * unit
        viewport = (box[2], box[3])
        page = (box[2] * unit, height)
    else:
        sx, sy, tx, ty = _fit_viewbox(width, height, box, root.get("preserveAspectRatio"), name)
        viewport = (box[2], box[3])
        page = (width, height)
    for attr in ("width", "height", "viewBox", "preserveAspectRatio", "x", "y"):
        root.attrib.pop(attr, None)
    top = height if height is not None else 0.0
    return (sx, 0.0, 0.0, -sy, tx, top - ty), viewport, page


_LENGTH = re.compile(rf"\s*({NUMBER.pattern})\s*([a-zA-Z%]*)\s*", re.ASCII)
"""A length attribute: its number and its unit (empty when none is given)."""

INKSCAPE_VERSION = "{http://www.inkscape.org/namespaces/inkscape}version"
"""The attribute in which Inkscape records the version that saved the document."""


def legacy_inkscape(root: ET.Element, has_viewbox: bool) -> str | None:
    """The version of Inkscape before 0.92 that saved ``root`` with user units in its px.

    Inkscape before 0.92 drew 90 px to the inch, later versions 96 (CSS). The px matter
    where the page's size is in px (or has no unit) or, without a viewBox, where user
    units are px: the cases Inkscape's own file update (``sp_file_convert_dpi``) offers
    to rescale. ``None``: a later version, no version, or a page whose size fixes the
    user unit (an absolute size with a viewBox).
    """
    match = re.match(r"\s*(\d+)\.(\d+)", root.get(INKSCAPE_VERSION, ""))
    if match is None or (int(match[1]), int(match[2])) >= (0, 92):
        return None
    if _user_units_in_px(root, has_viewbox):
        return root.get(INKSCAPE_VERSION, "").split()[0]
    return None


_ILLUSTRATOR = re.compile(rb"<!--\s*Generator:\s*Adobe Illustrator\s+(\d+(?:\.\d+)*)")
"""The comment Adobe Illustrator's SVG export writes before the root element."""


def illustrator_version(head: bytes) -> str | None:
    """The version of Adobe Illustrator named in ``head``, a file's first bytes; else ``None``."""
    match = _ILLUSTRATOR.search(head)
    return None if match is None else match[1].decode("ascii")


_COREL = re.compile(rb"<!--\s*Creator:\s*CorelDRAW")
"""The comment CorelDRAW's SVG export writes before the root element."""


_ESCAPED = re.compile(r"_x([0-9A-Fa-f]{4})_")
"""A character Illustrator and CorelDRAW cannot put in an ``id``, as they write it there."""


def decoded_id(text: str | None) -> str | None:
    """``text`` with each ``_xHHHH_`` written back as its character (``_x0020_``: a space).

    An escape of a character no XML attribute can carry (a control character, a surrogate or
    a non-character: ``_x0000_``, ``_xD800_``, ``_xFFFF_``) stays as written.
    """
    return None if text is None else _ESCAPED.sub(_character, text)


def _character(match: re.Match[str]) -> str:
    code = int(match[1], 16)
    named = code >= 0x20 and code != 0x7F and not 0xD800 <= code <= 0xDFFF and code < 0xFFFE
    return chr(code) if named else match[0]


def top_level_layers(head: bytes, root: ET.Element) -> bool:
    """Whether the file (``head``: its first bytes) is one whose layers are the root's groups.

    Adobe Illustrator and CorelDRAW write each layer as a ``<g>`` child of the ``<svg>``
    element, named by its ``id`` (Illustrator: ``data-name`` too where the name is no
    valid id), with no mark of its own. A file Inkscape saved again (``inkscape:version``)
    has Inkscape's layers, or none.
    """
    writer = _ILLUSTRATOR.search(head) is not None or _COREL.search(head) is not None
    return writer and root.get(INKSCAPE_VERSION) is None


def _illustrator_px(root: ET.Element, version: str | None, has_viewbox: bool) -> bool:
    """Whether the user units of a file Illustrator ``version`` wrote are its points.

    Illustrator writes a point of its document as one px (``width="283.46px"`` for 100 mm)
    and its newer exports give no size at all. A file Inkscape saved again
    (``inkscape:version``) follows Inkscape's px; a page in absolute units with a viewBox
    fixes the user unit whoever wrote it.
    """
    if version is None or root.get(INKSCAPE_VERSION) is not None:
        return False
    return _user_units_in_px(root, has_viewbox)


def _user_units_in_px(root: ET.Element, has_viewbox: bool) -> bool:
    """Whether the page leaves the user unit to the px.

    So it does with a size in px, without a unit or missing, or an absolute size without a
    viewBox.
    """
    units = [_unit(root.get(a)) for a in ("width", "height")]
    in_px = units == [None, None] or any(u in ("", "px") for u in units)
    absolute = any(u in ("mm", "cm", "in", "pt", "pc") for u in units)
    return in_px or (absolute and not has_viewbox)


def _unit(text: str | None) -> str | None:
    """The unit of a length attribute (``""``: none given); ``None`` when there is no length."""
    match = _LENGTH.fullmatch(text or "")
    return None if match is None else match[2]


_RELATIVE_UNITS = frozenset({"%", "em", "ex", "rem", "ch", "vw", "vh", "vmin", "vmax"})
"""Units of a page size relative to what shows the file (its window, its font): react-icons
write ``width="1em" height="1em"``, sized by the text around the icon."""


def _page_length(root: ET.Element, attr: str, name: str) -> tuple[float | None, str]:
    """A page length: ``(mm, "")`` absolute, ``(None, text)`` relative, else ``(None, "")``.

    Relative: in a unit of :data:`_RELATIVE_UNITS` (``%``, ``em``...).
    """
    text = root.get(attr)
    if text is None or text.strip() in ("", "auto"):
        return None, ""
    match = _LENGTH.fullmatch(text)
    if match is None:
        raise InputError(f"{name}: <svg> {attr} {text!r} is not a length")
    value, unit = float(match.group(1)), match.group(2)
    if unit in _RELATIVE_UNITS:
        return None, f"{attr}={text.strip()!r}"
    if unit and unit not in _PAGE_UNITS_MM:
        known = ", ".join(_PAGE_UNITS_MM)
        raise InputError(f"{name}: <svg> {attr} {text!r}: unit {unit!r} unknown; use {known}")
    if value <= 0:
        raise InputError(f"{name}: <svg> {attr} {text!r} must be positive")
    return value * _PAGE_UNITS_MM[unit or "px"], ""


def _viewbox(root: ET.Element, name: str) -> tuple[float, float, float, float] | None:
    text = root.get("viewBox")
    if text is None:
        return None
    numbers = re.split(r"[\s,]+", text.strip(" \t\r\n\f"), flags=re.ASCII)
    if len(numbers) != 4 or not all(NUMBER.fullmatch(v) for v in numbers):
        # as SVG's grammar writes numbers: Python's float() would also read "1_00", "inf"
        # and digits of other scripts, which a browser refuses (and ignores the viewBox)
        raise InputError(f"{name}: viewBox {text!r} must be four numbers")
    x, y, w, h = (float(v) for v in numbers)
    if not (w > 0 and h > 0):
        raise InputError(f"{name}: viewBox {text!r} must have a positive width and height")
    return (x, y, w, h)


def _fit_viewbox(
    width: float,
    height: float,
    box: tuple[float, float, float, float],
    aspect: str | None,
    name: str,
) -> tuple[float, float, float, float]:
    """``(sx, sy, tx, ty)``: user units to mm, Y down (SVG 1.1 §7.8 preserveAspectRatio)."""
    words = (aspect or "xMidYMid meet").split()
    if words and words[0] == "defer":
        words = words[1:]
    align = words[0] if words else "xMidYMid"
    mode = words[1] if len(words) > 1 else "meet"
    aligns = {"none"} | {f"x{a}Y{b}" for a in ("Min", "Mid", "Max") for b in ("Min", "Mid", "Max")}
    if align not in aligns or mode not in ("meet", "slice") or len(words) > 2:
        raise InputError(f"{name}: preserveAspectRatio {aspect!r} is not valid")
    sx, sy = width / box[2], height / box[3]
    if align != "none":
        sx = sy = min(sx, sy) if mode == "meet" else max(sx, sy)
    share = {"Min": 0.0, "Mid": 0.5, "Max": 1.0}
    fx = share[align[1:4]] if align != "none" else 0.0
    fy = share[align[5:8]] if align != "none" else 0.0
    tx = -box[0] * sx + fx * (width - box[2] * sx)
    ty = -box[1] * sy + fy * (height - box[3] * sy)
    return sx, sy, tx, ty


_PAGE_SLACK_MM = 0.01
"""How far outside the page (mm) a contour may lie and still count as on it."""


def outside_page(box: BBox, page: tuple[float, float] | None) -> bool:
    """Whether ``box`` (mm) lies wholly outside the page (``None``: no page, so never).

    The root ``<svg>`` clips its content to its viewport (SVG 1.1 §14.3.3); camtool does
    not clip, so what lies outside it (an object left beside the page, a shape moved
    away by a stray transform) would be cut where the drawing program shows nothing.
    """
    if page is None:
        return False
    width, height = page
    s = _PAGE_SLACK_MM
    return box[2] < -s or box[0] > width + s or box[3] < -s or box[1] > height + s


def contour_off_page(contour: Contour, page: tuple[float, float] | None) -> bool:
    """:func:`outside_page` of ``contour``'s box, its box found only when its start is off the page.

    A contour whose start lies on the page (within the slack) has a box that reaches the
    page on every side, so it is not wholly outside: most contours are settled by one point.
    """
    if page is None:
        return False
    x, y = contour.start
    s = _PAGE_SLACK_MM
    if -s <= x <= page[0] + s and -s <= y <= page[1] + s:
        return False
    return outside_page(contour.bbox(), page)


def off_page_text(
    path: Path, count: int, what: str, first: str, box: BBox, page: tuple[float, float] | None
) -> str:
    """``PATH: N WHATs lie wholly outside the W × H mm page… (first FIRST at (x, y) mm)``."""
    width, height = page or (0.0, 0.0)
    many = f"{count} {what}s lie" if count > 1 else f"1 {what} lies"
    return (
        f"{path}: {many} wholly outside the {width:.4g} × {height:.4g} mm page, "
        f"where a viewer shows nothing (first {first} at ({box[0]:.4f}, {box[1]:.4f}) mm)"
    )


_BEYOND_MM = 0.1
"""How far beyond the page (mm) a contour on it must reach for a warning: less is a sliver
no one sees (a stroke's half-width over the edge, a rounding of the page size)."""


def beyond_page(box: BBox, page: tuple[float, float]) -> float:
    """How far (mm, >= 0) ``box`` reaches beyond the page on its farthest side."""
    width, height = page
    return max(-box[0], -box[1], box[2] - width, box[3] - height, 0.0)


def page_warnings(
    path: Path, contours: list[Contour], page: tuple[float, float] | None
) -> tuple[list[str], str]:
    """Warnings for the contours off the page, and what a refusal of the drawing's size adds.

    The root ``<svg>`` clips its content to the page (SVG 1.1 §14.3.3) and camtool cuts
    whole contours: one wholly outside the page is cut where a viewer shows nothing, one
    that reaches beyond it (by more than :data:`_BEYOND_MM`: Fritzing's part legs,
    art over an Illustrator artboard's edge) is cut whole where a viewer shows only its
    part on the page. Each kind gets a warning that counts them and names one (the first
    outside, the farthest beyond); the note (``""`` when none is wholly outside) is
    :func:`refusal_note`'s.
    """
    if page is None:
        return [], ""
    outside: list[Contour] = []
    beyond: list[tuple[float, Contour]] = []
    for contour in contours:
        if contour_off_page(contour, page):
            outside.append(contour)
        elif (reach := beyond_page(contour.bbox(), page)) > _BEYOND_MM:
            beyond.append((reach, contour))
    warnings: list[str] = []
    note = ""
    if outside:
        first = outside[0]
        text = off_page_text(path, len(outside), "contour", first.source, first.bbox(), page)
        them = "them" if len(outside) > 1 else "it"
        warnings.append(f"{text}; camtool cuts {them}: delete {them} or move {them} onto the page")
        note = refusal_note(text, len(outside))
    if beyond:
        reach, first = max(beyond, key=lambda pair: pair[0])
        box = first.bbox()
        many = f"{len(beyond)} contours reach" if len(beyond) > 1 else "1 contour reaches"
        them = "them" if len(beyond) > 1 else "it"
        warnings.append(
            f"{path}: {many} beyond the {page[0]:.4g} × {page[1]:.4g} mm page, where a viewer "
            f"shows only the part on the page (farthest: {first.source} at ({box[0]:.4f}, "
            f"{box[1]:.4f}) mm, {reach:.4g} mm beyond); camtool cuts {them} whole: trim "
            f"{them} to the page in the drawing program if the rest is not to be cut"
        )
    return warnings, note


def refusal_note(text: str, count: int) -> str:
    """What a refusal of the drawing's size adds when ``count`` shapes lie off the page."""
    they, them = ("they are", "them") if count > 1 else ("it is", "it")
    return (
        f"but {text}: if {they} not part of the job, delete {them} or move {them} onto the "
        f"page rather than scale the part down with {them} (--fit)"
    )


def check_travel(
    path: Path,
    check: Callable[[BBox], None],
    box: BBox,
    labelled: list[tuple[str, BBox | None]],
    page: tuple[float, float] | None,
) -> None:
    """``check(box)`` (mm); its TooLargeError names the first shape off the page, if any.

    Args:
        path: the drawing, for the message.
        check: the travel check (raises TooLargeError).
        box: the extent to check, mm.
        labelled: each shape's label and extent (``None``: no extent), mm.
        page: the page's width and height, mm (``None``: no page).

    Raises:
        TooLargeError: from ``check``, with what lies off the page when something does.
    """
    try:
        check(box)
    except TooLargeError as exc:
        off = [(label, b) for label, b in labelled if b is not None and outside_page(b, page)]
        if not off:
            raise
        note = off_page_text(path, len(off), "shape", *off[0], page)
        raise TooLargeError(f"{exc}; {refusal_note(note, len(off))}") from None


def is_background(contours: Sequence[Contour], page: tuple[float, float] | None) -> bool:
    """Whether ``contours`` are one rectangle of lines covering the whole page.

    Asked of a white shape without a stroke: the background matplotlib's figures, Figma's
    frames and draw.io's pages draw, which a viewer does not show on the white page. Its
    corners may be off the page's by 0.1 % of its larger side (at least 0.01 mm); ``page``
    in mm, its lower-left corner at the origin (:func:`page_matrix`).
    """
    if page is None or len(contours) != 1 or not contours[0].closed:
        return False
    segments = contours[0].segments
    if len(segments) != 4 or not all(isinstance(s, Line) for s in segments):
        return False
    slack = max(0.01, 1e-3 * max(page))
    sides = all(
        min(abs(s.end[0] - s.start[0]), abs(s.end[1] - s.start[1])) <= slack for s in segments
    )
    corners = zip(contours[0].bbox(), (0.0, 0.0, *page), strict=True)
    return sides and all(abs(a - b) <= slack for a, b in corners)
