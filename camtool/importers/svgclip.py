"""Clipping paths of an SVG: which drawn shapes a ``clip-path`` hides, wholly or in part.

camtool cuts whole shapes. A viewer shows a clipped shape only inside its clipping path
(SVG 1.1 §14.3.5, CSS Masking 1 §6), so cutting the shape whole would cut what the drawing
shows nothing of. Here each drawn shape under a ``clip-path`` (its own, or a group's, a
``<use>``'s or the ``<svg>``'s) is compared with the clip's region, in mm on the page:

- wholly inside every clip (a page-sized clip around everything, as PDF imports and many
  exports write): read as it is;
- wholly outside one: the viewer shows nothing of it, so it is skipped and counted;
- partly hidden: refused, naming the shape and the clip (cutting it would cut what the
  clip hides, as a DXF INSERT with an XCLIP would; see ``camtool/importers/dxf_blocks.py``);
- a nested ``<svg>`` viewport clips too: svgdoc gives it a clip of its rectangle.
- a clip whose region camtool cannot work out (text in the clip, ``objectBoundingBox``
  units, a clip of the clip or of a child of it, a CSS shape such as ``circle(50%)``):
  refused.

The region is the union of the clip's children, each in the user space of the element
that references the clip (``clipPathUnits="userSpaceOnUse"``) times the clip's own
``transform`` (svgdoc moves every ``<clipPath>`` to the document's start, so that
svgelements composes no ancestor's transform into the children's). Subpaths are combined
even-odd: a point of odd winding number has a non-zero one, so for ``clip-rule="nonzero"``
the region taken lies within the true one, and a shape is only ever refused, never read,
for the difference.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from typing import Any

import shapely
import svgelements as se

from camtool.importers.svgmasks import MASK_CLIP, VIEWPORT_CLIP
from camtool.importers.svgpage import Affine, compose
from camtool.importers.svgtree import SOURCE_ATTR
from camtool.importers.svgvalues import URL_REF
from camtool.model.errors import InputError

CLIP_SLACK_MM = 0.01
"""How far outside its clip (mm) a shape may reach and still count as inside it (a shape
on the clip's edge, as a page-sized clip around a page-sized frame)."""


@dataclass
class Clip:
    """One ``clip-path`` reference: the element carrying it and what it names."""

    owner: Any
    """The svgelements element with the ``clip-path`` property (its user space is the clip's)."""
    target: Any | None
    """The ``se.ClipPath`` named, or ``None`` when ``why`` says why it cannot be used."""
    why: str = ""
    """Why the region cannot be worked out; ``""`` when it can."""
    region: Any = field(default=None, repr=False)
    """The region in mm on the page (a shapely geometry, prepared), once worked out."""
    grown: Any = field(default=None, repr=False)
    """``region`` grown by :data:`CLIP_SLACK_MM` (prepared), once worked out."""


def clipped_shapes(svg: Any, shape_types: tuple[type, ...]) -> dict[int, tuple[Clip, ...]]:
    """The clips over each drawn shape of ``svg``, by ``id()`` of the shape (outermost first).

    Only shapes under at least one clip are keys. ``shape_types``: the svgelements classes
    of drawn shapes; groups, ``<use>`` clones and nested ``<svg>`` are walked.
    """
    found: dict[int, tuple[Clip, ...]] = {}
    objects = getattr(svg, "objects", {}) or {}
    root = _clip_of(svg, objects)

    def walk(node: Any, clips: tuple[Clip, ...]) -> None:
        for child in node:
            own = _clip_of(child, objects)
            here = (*clips, own) if own is not None else clips
            if isinstance(child, shape_types):
                if here:
                    found[id(child)] = here
            elif isinstance(child, se.Group | se.Use):
                walk(child, here)

    walk(svg, (root,) if root is not None else ())
    return found


def _clip_of(element: Any, objects: dict[str, Any]) -> Clip | None:
    """The clip ``element`` carries itself (``clip-path`` does not inherit), or ``None``."""
    text = _clip_text(getattr(element, "values", None) or {})
    if not text:
        return None
    match = URL_REF.fullmatch(text)
    if match is None:
        return Clip(element, None, f"clip-path {text!r} is a CSS shape")
    target = getattr(element, "clip_path", None)
    if not isinstance(target, se.ClipPath):
        target = objects.get(match.group(1))
    if not isinstance(target, se.ClipPath):
        return None  # names no <clipPath>: ignored, as viewers ignore it (CSS Masking 1 §6.1)
    if str(getattr(target, "unit_type", "")).strip() == "objectBoundingBox":
        return Clip(element, target, "clipPathUnits is objectBoundingBox")
    if _clip_text(target.values):
        return Clip(element, target, "the <clipPath> is clipped itself")
    return Clip(element, target)


def clip_region(
    clip: Clip,
    page: Affine,
    affine_of: Callable[[Any], Affine],
    subpaths: Callable[[Any, Affine], list[list[tuple[float, float]]]],
    shape_types: tuple[type, ...],
    made: dict[tuple[int, Affine], tuple[Any, Any]],
) -> Any:
    """The region of ``clip`` in mm on the page (a shapely geometry; empty: hides everything).

    ``subpaths(shape, matrix)``: a clip child's subpaths as point lists in mm, closed or
    not (an open subpath clips as if closed, as it is filled). ``made``: the regions
    worked out so far, by the ``<clipPath>`` and the matrix of the element using it (a
    plot's every line may name the one clip of its axes).

    Raises:
        InputError: (message without the file's name) the clip holds text, or a child
            clipped itself (:func:`_children`).
    """
    if clip.region is not None:
        return clip.region
    owner = compose(page, affine_of(clip.owner.transform))
    key = (id(clip.target), owner)
    known = made.get(key)
    if known is not None:
        clip.region, clip.grown = known
        return clip.region
    polygons = [
        even_odd(subpaths(child, compose(owner, affine_of(child.transform))))
        for child in _children(clip.target, shape_types)
    ]
    set_region(clip, shapely.union_all(polygons) if polygons else shapely.Polygon())
    made[key] = (clip.region, clip.grown)
    return clip.region


def set_region(clip: Clip, region: Any) -> None:
    """Give ``clip`` its ``region`` (mm, a shapely geometry) and the region grown by the slack."""
    clip.region = region
    clip.grown = shapely.buffer(region, CLIP_SLACK_MM)
    shapely.prepare(clip.region)
    shapely.prepare(clip.grown)


def _children(node: Any, shape_types: tuple[type, ...], placed: bool = False) -> Iterator[Any]:
    """The shapes a clip is made of, each a child or placed by a ``<use>`` child.

    A clip's content is shapes, text and ``<use>`` of either (SVG 1.1 §14.3.5): a group, an
    image, a ``<switch>`` or a ``<use>`` of anything else adds nothing (as resvg's
    masking/clipPath tests show), nor does a child hidden by ``visibility`` (svgelements
    leaves out those with ``display:none``).

    Raises:
        InputError: (message without the file's name) the clip holds text, or a child that
            is clipped itself.
    """
    for child in node:
        values = getattr(child, "values", None) or {}
        if str(values.get("visibility", "visible")).strip().lower() in ("hidden", "collapse"):
            continue
        if isinstance(child, (*shape_types, se.Text)) and _clip_text(values):
            raise InputError("a shape in it has a clip-path of its own")
        if isinstance(child, shape_types):
            yield child
        elif isinstance(child, se.Text):
            raise InputError("it holds text, whose outline camtool does not compute")
        elif isinstance(child, se.Use) and not placed:
            yield from _children(child, shape_types, placed=True)


def _clip_text(values: Any) -> str:
    """The ``clip-path`` an element carries (``""``: none)."""
    text = str(values.get("clip-path") or "").strip()
    return "" if text.lower() == "none" else text


def hidden_part(clip: Clip, lines: list[list[tuple[float, float]]], filled: bool) -> str:
    """How much of a shape ``clip`` hides (its region worked out): its ``lines`` and fill.

    ``lines``: the shape's outline, points in mm. ``"none"``: every line lies within
    :data:`CLIP_SLACK_MM` of the region; ``"all"``: no line meets the region (its edge
    included), nor (``filled``: the shape is painted inside) does the shape's inside, so
    a viewer shows nothing of it; else ``"part"`` (a filled rectangle clipped by a star
    shows a star: its outline is hidden wholly, its fill is not).
    """
    outline = shapely.MultiLineString([p for p in lines if len(p) > 1])
    region = clip.region
    if outline.is_empty:
        return "none"
    if region.is_empty:
        return "all"
    if clip.grown.covers(outline):
        return "none"
    if region.intersects(outline):
        return "part"
    if filled and region.intersects(even_odd(lines)):
        return "part"
    return "all"


def even_odd(subpaths: list[list[tuple[float, float]]]) -> Any:
    """The inside of ``subpaths`` (points in mm, each closed back to its start) by even-odd."""
    shape = shapely.Polygon()
    for points in subpaths:
        if len(points) >= 3:
            shape = shapely.symmetric_difference(shape, shapely.make_valid(shapely.Polygon(points)))
    return shape


def clip_label(clip: Clip, label: Callable[[Any], str]) -> str:
    """``the clip-path #ID on ELEMENT``, ``the mask #ID on ELEMENT``, or a nested viewport."""
    name = str(getattr(clip.target, "id", None) or "")
    owner = label(clip.owner)
    if name.startswith(VIEWPORT_CLIP):
        return f"the viewport of the nested {owner}"
    if name.startswith(MASK_CLIP):
        mask = str(getattr(clip.target, "values", {}).get(SOURCE_ATTR, "mask")).removeprefix("mask")
        return f"the mask {mask} on {owner}"
    return f"the clip-path #{name} on {owner}" if name else f"the clip-path on {owner}"


def remedy(clip: Clip) -> str:
    """What a user does about a clip that hides part of a shape, or that camtool cannot read."""
    name = str(getattr(clip.target, "id", None) or "")
    if name.startswith(VIEWPORT_CLIP):
        return (
            "trim the shape to the <svg>'s x, y, width and height in the drawing program, or "
            'set overflow="visible" on the <svg> to cut the whole shape'
        )
    kind = "Mask" if name.startswith(MASK_CLIP) else "Clip"
    return (
        f"release the {kind.lower()} in the drawing program (Inkscape: Object > {kind} > "
        f"Release) and trim the shape to it (Path > Intersection), or delete the {kind.lower()} "
        "to cut the whole shape"
    )
