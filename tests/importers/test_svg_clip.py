"""SVG clipping paths: a clip that hides nothing is read, one that hides a shape wholly skips
it, one that hides part of it (or cannot be worked out) is refused.

Expected outcomes come from the geometry of each case, worked out by hand (SVG 1.1 §14.3.5:
the clip is in the user space of the element that references it, times the clip's own
``transform``), and from resvg's masking/clipPath tests, which paint green what a viewer
shows and red what it must not.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest
import shapely

from camtool.importers.svg import read_svg
from camtool.importers.svgclip import CLIP_SLACK_MM, Clip, even_odd, hidden_part, set_region
from camtool.model.errors import InputError
from tests.importers.svgutil import svg

CORPUS = Path(os.environ.get("CAMTOOL_CORPUS_DIR", Path(__file__).resolve().parents[2] / ".corpus"))
BREEZE = CORPUS / "pkg/breeze-icon-theme/usr/share/icons/breeze"

SQUARE = '<rect id="sq" x="20" y="20" width="60" height="60" fill="none" stroke="black"'


def _sources(path: Path) -> list[str]:
    return [c.source for c in read_svg(path).contours]


def test_a_clip_around_everything_hides_nothing(tmp_path: Path) -> None:
    body = (
        '<defs><clipPath id="page"><rect width="100" height="100"/></clipPath></defs>'
        f'<g clip-path="url(#page)">{SQUARE}/><circle id="c" cx="50" cy="50" r="10" '
        'fill="none" stroke="black"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert sorted(c.source for c in drawing.contours) == ["circle#c", "rect#sq"]
    assert not [w for w in drawing.warnings if "clip" in w], drawing.warnings


def test_a_clip_that_hides_part_of_a_shape_is_refused(tmp_path: Path) -> None:
    # the square's edges lie 30 from the centre, its corners 42.4: a circle of 35 shows
    # the edges' middles and hides the corners
    clip = '<clipPath id="c"><circle cx="50" cy="50" r="35"/></clipPath>'
    body = f'{clip}{SQUARE} clip-path="url(#c)"/>'
    with pytest.raises(InputError, match=r"clip-path #c on rect#sq hides part of rect#sq") as err:
        read_svg(svg(tmp_path, body))
    assert "Object > Clip > Release" in str(err.value)


def test_a_shape_wholly_outside_its_clip_is_skipped(tmp_path: Path) -> None:
    # a circle of 25 shows nothing of the square's outline (30 from the centre at least)
    body = (
        f'<clipPath id="c"><circle cx="50" cy="50" r="25"/></clipPath>'
        f'<g clip-path="url(#c)">{SQUARE}/><circle id="in" cx="50" cy="50" r="10" '
        'fill="none" stroke="black"/></g>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["circle#in"]
    assert any(
        "skipped 1 element that its clip-path, mask or viewport hides wholly" in w
        for w in drawing.warnings
    )


def test_a_filled_shape_whose_outline_is_hidden_still_shows_its_fill(tmp_path: Path) -> None:
    # the outline lies outside the circle, but the fill inside it is shown: a disc, which
    # cutting the square would not make
    body = (
        '<clipPath id="c"><circle cx="50" cy="50" r="25"/></clipPath>'
        '<rect id="sq" x="20" y="20" width="60" height="60" fill="green" clip-path="url(#c)"/>'
    )
    with pytest.raises(InputError, match="hides part of rect#sq"):
        read_svg(svg(tmp_path, body))


@pytest.mark.parametrize(
    ("offset", "read"),
    [(0.0, True), (-10.0, False)],
)
def test_the_clip_is_in_the_user_space_of_the_element_using_it(
    tmp_path: Path, offset: float, read: bool
) -> None:
    # as Illustrator writes it: the clip a <use> of a rectangle in <defs>, all inside a
    # translated group. The region is the group's translation times the clip's own
    # transform (translate(offset, 0)): the triangle (x 40..75) lies inside 30..80 without
    # it, and reaches outside 20..70 with it. Composed twice (as svgelements would compose
    # the group around the <clipPath>) the region would be 60..110 and refuse both.
    body = (
        '<g transform="translate(30,0)"><defs><rect id="R" width="50" height="50"/></defs>'
        f'<clipPath id="C" transform="translate({offset},0)"><use xlink:href="#R"/></clipPath>'
        '<path id="tri" clip-path="url(#C)" d="M10,10 L45,10 L45,45 Z" fill="none" '
        'stroke="#000"/></g>'
    )
    path = svg(tmp_path, body)
    if read:
        assert _sources(path) == ["path#tri"]
    else:
        with pytest.raises(InputError, match="hides part of path#tri"):
            read_svg(path)


def test_a_clip_defined_after_its_use_and_on_the_root(tmp_path: Path) -> None:
    # Figma writes the <defs> last; a clip on the <svg> itself clips everything
    body = f'{SQUARE}/><defs><clipPath id="late"><rect width="50" height="100"/></clipPath></defs>'
    path = svg(tmp_path, body, root='width="100mm" height="100mm" viewBox="0 0 100 100" '
               'clip-path="url(#late)"')  # fmt: skip
    with pytest.raises(InputError, match=r"clip-path #late on svg.* hides part of rect#sq"):
        read_svg(path)


def test_an_outer_clip_that_hides_all_wins_over_an_inner_one_that_hides_part(
    tmp_path: Path,
) -> None:
    body = (
        '<clipPath id="none"><rect x="90" y="90" width="5" height="5"/></clipPath>'
        '<clipPath id="half"><rect width="50" height="100"/></clipPath>'
        f'<g clip-path="url(#none)">{SQUARE} clip-path="url(#half)"/></g>'
        '<circle id="kept" cx="50" cy="50" r="5" fill="none" stroke="black"/>'
    )
    assert _sources(svg(tmp_path, body)) == ["circle#kept"]


@pytest.mark.parametrize(
    ("clip", "why"),
    [
        ('style="clip-path: circle(20px)"', "clip-path 'circle(20px)' is a CSS shape"),
        ('clip-path="url(#t)"', "it holds text"),
        ('clip-path="url(#o)"', "clipPathUnits is objectBoundingBox"),
        ('clip-path="url(#cc)"', "the <clipPath> is clipped itself"),
        ('clip-path="url(#cs)"', "a shape in it has a clip-path of its own"),
    ],
)
def test_a_clip_camtool_cannot_work_out_is_refused(tmp_path: Path, clip: str, why: str) -> None:
    body = (
        '<clipPath id="t"><text x="10" y="50">A</text></clipPath>'
        '<clipPath id="o" clipPathUnits="objectBoundingBox"><rect width="1" height="1"/></clipPath>'
        '<clipPath id="p"><rect width="100" height="100"/></clipPath>'
        '<clipPath id="cc" clip-path="url(#p)"><rect width="100" height="100"/></clipPath>'
        '<clipPath id="cs"><rect width="100" height="100" clip-path="url(#p)"/></clipPath>'
        f"{SQUARE} {clip}/>"
    )
    with pytest.raises(InputError, match="rect#sq is clipped by") as err:
        read_svg(svg(tmp_path, body))
    assert why in str(err.value)


@pytest.mark.parametrize(
    "content",
    [
        '<g><rect width="100" height="100"/></g>',  # a group is no valid child
        '<use xlink:href="#grp"/>',  # nor a <use> of one
        '<rect width="100" height="100" visibility="hidden"/>',
        '<rect width="100" height="100" display="none"/>',
        "",  # an empty clip hides everything
    ],
)
def test_what_adds_nothing_to_a_clip(tmp_path: Path, content: str) -> None:
    # resvg masking/clipPath: g-, with-invalid-child-via-use, invisible-child-1/2, no-children
    body = (
        '<defs><g id="grp"><rect width="100" height="100"/></g></defs>'
        f'<clipPath id="c">{content}</clipPath>{SQUARE} clip-path="url(#c)"/>'
        '<circle id="kept" cx="50" cy="50" r="5" fill="none" stroke="black"/>'
    )
    assert _sources(svg(tmp_path, body)) == ["circle#kept"]


def test_a_reference_to_no_clip_is_ignored_as_viewers_ignore_it(tmp_path: Path) -> None:
    assert _sources(svg(tmp_path, f'{SQUARE} clip-path="url(#missing)"/>')) == ["rect#sq"]


def _clip(region: object) -> Clip:
    clip = Clip(owner=None, target=None)
    set_region(clip, region)
    return clip


@pytest.mark.parametrize("hide", ['display="none"', 'style="display:none"'])
def test_a_clip_path_clips_with_display_none_on_it(tmp_path: Path, hide: str) -> None:
    """display does not apply to a <clipPath> (SVG 1.1 §14.3.5; resvg's
    painting/display/none-on-clipPath paints the clipped rect green): it still clips."""
    clip = f'<defs><clipPath id="c" {hide}><circle cx="50" cy="50" r="20"/></clipPath></defs>'
    inside = '<circle id="in" cx="50" cy="50" r="10" fill="green" clip-path="url(#c)"/>'
    outside = '<rect id="out" width="10" height="10" fill="green" clip-path="url(#c)"/>'
    assert _sources(svg(tmp_path, clip + inside + outside)) == ["circle#in"]
    across = '<rect id="all" width="100" height="100" fill="green" clip-path="url(#c)"/>'
    with pytest.raises(InputError, match=r"the clip-path #c on rect#all hides part of rect#all"):
        read_svg(svg(tmp_path, clip + across))


def test_hidden_part_by_the_slack() -> None:
    region = _clip(shapely.box(0, 0, 10, 10))
    inside = [[(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]]
    just_out = [[(0.0, 0.0), (10.0 + CLIP_SLACK_MM / 2, 0.0)]]
    too_far = [[(0.0, 0.0), (10.0 + 2 * CLIP_SLACK_MM, 0.0)]]
    along_edge_outside = [[(0.0, -CLIP_SLACK_MM / 2), (10.0, -CLIP_SLACK_MM / 2)]]
    assert hidden_part(region, inside, filled=False) == "none"
    assert hidden_part(region, just_out, filled=False) == "none"
    # along the edge and beyond: the part on the edge is shown (half its stroke)
    assert hidden_part(region, too_far, filled=False) == "part"
    assert hidden_part(region, along_edge_outside, filled=False) == "none"
    assert hidden_part(region, [[(20.0, 20.0), (30.0, 20.0)]], filled=False) == "all"
    # touching the region at one point: shown there, so not skipped
    assert hidden_part(region, [[(10.0, 10.0), (20.0, 20.0)]], filled=False) == "part"
    assert hidden_part(_clip(shapely.Polygon()), inside, filled=True) == "all"


def test_even_odd_makes_holes_of_nested_subpaths() -> None:
    outer = [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 10.0)]
    inner = [(2.0, 2.0), (8.0, 2.0), (8.0, 8.0), (2.0, 8.0)]
    assert even_odd([outer, inner]).area == pytest.approx(100 - 36)
    assert even_odd([outer, list(reversed(inner))]).area == pytest.approx(100 - 36)


@pytest.mark.skipif(not BREEZE.exists(), reason="corpus not fetched (make corpus)")
def test_breeze_icons_of_figma_clip_each_frame_to_its_size() -> None:
    # KDE's Breeze icons (Debian's breeze-icon-theme), exported by Figma: every icon's
    # group is clipped to its 16 x 16 frame, the <clipPath> written after it. In
    # debug-step-over the arrow's tip reaches y = -0.81, above the frame: a viewer cuts the
    # tip off, so the path is refused; debug-run's shapes lie inside: read.
    with pytest.raises(InputError, match=r"clip-path #clip0_9_370 on g\[1\] hides part of"):
        read_svg(BREEZE / "actions/16/debug-step-over.svg")
    # color-management's five clipped uses and path lie inside their clips: all read
    drawing = read_svg(BREEZE / "actions/16/color-management.svg")
    sources = {c.source for c in drawing.contours}
    assert {"use#use3393 > path#H", "use#use3395 > path#J", "path#path3397"} <= sources
    assert {"use#use3399 > path#I", "use#use3403 > path#H"} <= sources
    assert not [w for w in drawing.warnings if "hides wholly" in w]


# ------------------------------------------------------------------ nested <svg> viewports


def test_a_nested_viewport_that_hides_part_of_a_shape_is_refused(tmp_path: Path) -> None:
    # SVG 1.1 §7.2: a nested <svg> clips to its x, y, width, height (resvg's
    # nested-svg-with-rect.svg shows a square of a circle); one with overflow visible not
    body = (
        '<svg id="vp" x="40" y="40" width="20" height="20"><circle id="c" cx="25" cy="25" '
        'r="30"/></svg>'
    )
    with pytest.raises(InputError, match="the viewport of the nested svg#vp hides part of") as e:
        read_svg(svg(tmp_path, body))
    assert 'overflow="visible"' in str(e.value)
    visible = body.replace('<svg id="vp"', '<svg id="vp" overflow="visible"')
    assert _sources(svg(tmp_path, visible)) == ["circle#c"]


def test_a_nested_viewport_of_percentages_clips_its_own_size(tmp_path: Path) -> None:
    # resvg's nested-svg-with-relative-width-and-height: x, y 25 % and width, height 50 % of
    # a 200 x 200 viewBox make the viewport 50..150; a rect of 100 % inside it is that
    # viewport's size (100, not the document's 200), so it lies on the clip's edge: read.
    # A rect 1 unit wider reaches outside: refused.
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<svg x="25%" y="25%" width="50%" height="50%"><rect id="r" width="{w}" '
        'height="100%" fill="none" stroke="black"/></svg>'
    )
    drawing = read_svg(svg(tmp_path, body.format(w="100%"), root=root))
    assert [c.bbox() for c in drawing.contours] == [pytest.approx((50, 50, 150, 150))]
    with pytest.raises(InputError, match="hides part of rect#r"):
        read_svg(svg(tmp_path, body.format(w="101"), root=root))


@pytest.mark.parametrize(
    ("size", "why"), [('width="-5"', "must not be negative"), ('width="abc"', "must be a number")]
)
def test_a_nested_viewport_of_a_bad_size_is_refused(tmp_path: Path, size: str, why: str) -> None:
    body = f'<svg {size} height="50">{SQUARE}/></svg>'
    with pytest.raises(InputError, match=r"svg\[2\]: bad width") as e:
        read_svg(svg(tmp_path, body))
    assert why in str(e.value)


@pytest.mark.parametrize("overflow", ["", 'overflow="visible"'])
@pytest.mark.parametrize(
    "size",
    ['width="0" height="50" viewBox="0 0 10 10"', 'width="50" height="50" viewBox="0 0 0 10"'],
)
def test_a_nested_viewport_of_no_width_shows_nothing(
    tmp_path: Path, size: str, overflow: str
) -> None:
    # SVG 1.1 §7.10 and §7.7: a width of 0, or a viewBox's, disables rendering, whatever
    # the overflow: the square is skipped, the frame beside it cut (svgelements reads
    # nothing of a document with a viewBox scaled into no width)
    body = (
        '<rect id="frame" x="1" y="1" width="98" height="98" fill="none" stroke="black"/>'
        f"<svg {size} {overflow}>{SQUARE}/></svg>"
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.source for c in drawing.contours] == ["rect#frame"]
    assert any("hides wholly" in w for w in drawing.warnings)


def test_a_nested_viewport_without_a_viewbox_moves_its_content_to_its_x_and_y(
    tmp_path: Path,
) -> None:
    # SVG 1.1 §7.7: the viewport at (40, 30) holds its content unscaled; svgelements left it
    # at the origin, and gave a rect without x the viewport's x (40: twice over, once the
    # viewport was moved)
    body = (
        '<svg x="40" y="30" width="20" height="20" overflow="visible"><rect id="r" '
        'width="5" height="5" fill="none" stroke="black"/><path id="p" d="M 1 1 L 4 1" '
        'stroke="black"/></svg>'
    )
    boxes = {c.source: c.bbox() for c in read_svg(svg(tmp_path, body)).contours}
    assert boxes["rect#r"] == pytest.approx((40, 65, 45, 70))
    assert boxes["path#p"] == pytest.approx((41, 69, 44, 69))


def test_a_nested_viewport_with_a_transform_clips_where_it_is_moved(tmp_path: Path) -> None:
    # SVG 2: a transform on a nested <svg> moves its viewport too (resvg's
    # nested-svg-with-transform-and-clip): the 20 x 20 viewport at (30, 30) holds the
    # square at 32..48 once moved, and the clip is moved with it
    body = (
        '<svg width="20" height="20" transform="translate(30 30)"><rect id="r" x="2" y="2" '
        'width="16" height="16" fill="none" stroke="black"/></svg>'
    )
    drawing = read_svg(svg(tmp_path, body))
    assert [c.bbox() for c in drawing.contours] == [pytest.approx((32, 52, 48, 68))]


# ------------------------------------------------------------------ masks


@pytest.mark.parametrize(
    ("paint", "outcome"),
    [
        ('fill="white"', "read"),  # shows the square whole
        ('fill="#808080" fill-opacity="0.5"', "read"),  # grey, half opaque: still shows
        ('fill="url(#light)"', "read"),  # a gradient of white stops, partly opaque
        ('fill="black"', "skipped"),  # no light: shows nothing
        ('fill="none"', "skipped"),
        ('fill="url(#fade)"', "fill 'url(#fade)' may hide in part"),  # a stop of opacity 0
        ('fill="white" stroke="black"', "stroke 'black' may hide"),
        # a clear fill leaves its stroke to judge: black hides, so the mask is refused
        ('fill="white" fill-opacity="0" stroke="black"', "stroke 'black' may hide"),
    ],
)
def test_a_mask_is_the_clip_of_its_shapes_when_each_surely_shows_or_hides(
    tmp_path: Path, paint: str, outcome: str
) -> None:
    # CSS Masking 1 §7: a luminance mask shows its element where its content is light and
    # opaque. The mask's rectangle 10..90 holds the square 20..80 whole.
    body = (
        '<linearGradient id="light"><stop offset="0" stop-color="white" stop-opacity="0.4"/>'
        '<stop offset="1" stop-color="#fff" stop-opacity="0.75"/></linearGradient>'
        '<linearGradient id="fade"><stop offset="0" stop-color="white" stop-opacity="0"/>'
        '<stop offset="1" stop-color="white"/></linearGradient>'
        f'<mask id="m"><rect x="10" y="10" width="80" height="80" {paint}/></mask>'
        f'<g mask="url(#m)">{SQUARE}/></g>'
        '<circle id="kept" cx="5" cy="5" r="2" fill="none" stroke="black"/>'
    )
    path = svg(tmp_path, body)
    if outcome == "read":
        assert _sources(path) == ["rect#sq", "circle#kept"]
    elif outcome == "skipped":
        assert _sources(path) == ["circle#kept"]
    else:
        with pytest.raises(InputError, match=r"g\[1\] is masked by <mask> #m, which camtool") as e:
            read_svg(path)
        assert outcome in str(e.value)
        assert "Object > Mask > Release" in str(e.value)


def test_a_mask_that_shows_part_of_a_shape_is_refused_as_a_mask(tmp_path: Path) -> None:
    body = (
        '<mask id="m"><rect width="50" height="100" fill="white"/></mask>'
        f'{SQUARE} style="mask: url(#m)"/>'
    )
    with pytest.raises(InputError, match="the mask #m on rect#sq hides part of rect#sq") as e:
        read_svg(svg(tmp_path, body))
    assert "Object > Mask > Release" in str(e.value)


def test_a_mask_in_user_space_clips_to_its_rectangle_too(tmp_path: Path) -> None:
    # maskUnits="userSpaceOnUse": the mask's x, y, width, height (here 0..50 across) bound
    # what its white page-sized content lets through
    body = (
        '<mask id="m" maskUnits="userSpaceOnUse" x="0" y="0" width="50" height="100">'
        '<rect x="-1000" y="-1000" width="3000" height="3000" fill="white"/></mask>'
        f'<g mask="url(#m)">{SQUARE}/></g>'
    )
    with pytest.raises(InputError, match=r"the mask #m on g.* hides part of rect#sq"):
        read_svg(svg(tmp_path, body))


@pytest.mark.parametrize(
    ("mask", "why"),
    [
        ('<mask id="m" maskContentUnits="objectBoundingBox"><rect width="1" height="1" '
         'fill="white"/></mask>', 'maskContentUnits="objectBoundingBox"'),
        ('<mask id="m" x="0" y="0" width="1" height="1"><rect width="100" height="100" '
         'fill="white"/></mask>', "its rectangle is in objectBoundingBox units"),
        ('<mask id="m"><text x="10" y="50" fill="white">A</text></mask>', "it holds <text>"),
        ('<mask id="m"><rect width="100" height="100" fill="white" mask="url(#n)"/></mask>'
         '<mask id="n"><rect width="100" height="100" fill="white"/></mask>',
         "has a mask of its own"),
        ('<mask id="m"><rect width="100" height="100" fill="white"/>'
         '<rect width="10" height="10" fill="black"/></mask>',
         "hides part of what lies under it"),
        ('<mask id="m"><switch><rect width="100" height="100" fill="white"/></switch></mask>',
         "it holds <switch>"),
        ('<mask id="m" maskUnits="userSpaceOnUse" width="zz"><rect width="100" height="100" '
         'fill="white"/></mask>', "its rectangle's 'zz': must be a number"),
    ],
)  # fmt: skip
def test_a_mask_that_amounts_to_no_clip_is_refused(tmp_path: Path, mask: str, why: str) -> None:
    with pytest.raises(InputError, match="is masked by <mask> #m, which camtool cannot") as e:
        read_svg(svg(tmp_path, f'{mask}<g mask="url(#m)">{SQUARE}/></g>'))
    assert why in str(e.value)


LINUXCNC_ICONS = CORPUS / "pkg/linuxcnc/usr/share/icons/hicolor/scalable/apps"


@pytest.mark.skipif(not LINUXCNC_ICONS.exists(), reason="corpus not fetched (make corpus)")
def test_the_linuxcnc_logo_s_shine_masks_hide_nothing() -> None:
    # LinuxCNC's own icon (Debian's linuxcnc-uspace): ten masks whose content is a
    # page-sized path filled with a gradient of white stops at opacity 0.38..0.75, so each
    # masked group shows whole, as before masks were read
    drawing = read_svg(LINUXCNC_ICONS / "linuxcncicon.svg")
    sources = {c.source.partition(" subpath")[0] for c in drawing.contours}
    assert "path#path248" in sources  # in g#g236, under mask #mask224-2-9-8
    assert not [w for w in drawing.warnings if "hides wholly" in w]


@pytest.mark.parametrize(("xlim", "read"), [((0.0, 10.0), True), ((2.0, 8.0), False)])
def test_matplotlib_clips_each_line_to_its_axes(
    tmp_path: Path, xlim: tuple[float, float], read: bool
) -> None:
    # matplotlib's SVG backend (an exporter camtool does not control) clips every line to
    # its axes with a <clipPath> of the axes' rectangle: a sine over 0..10 drawn in axes
    # of 0..10 lies inside it (its ends on the edge); in axes of 2..8 its ends are hidden
    import numpy as np
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    x = np.linspace(0.0, 10.0, 200)
    ax.plot(x, np.sin(x))
    ax.set_xlim(*xlim)
    ax.axis("off")
    path = tmp_path / "plot.svg"
    fig.savefig(path, format="svg")
    assert "clip-path" in path.read_text(encoding="utf-8")
    if read:
        # the open line spans the axes: matplotlib's default subplot from 0.125 to 0.9 of
        # the 4 in (101.6 mm) figure; the closed contour is the figure's white background
        (line,) = [c for c in read_svg(path).contours if not c.closed]
        x0, _, x1, _ = line.bbox()
        assert (x0, x1) == pytest.approx((0.125 * 101.6, 0.9 * 101.6), abs=1e-6)
    else:
        with pytest.raises(InputError, match=r"the clip-path #\w+ on path\[\d+\] hides part of"):
            read_svg(path)


# ------------------------------------------------------------------ symbols


def test_a_symbol_with_a_viewbox_is_placed_in_the_viewport_of_its_use(tmp_path: Path) -> None:
    # resvg's structure/symbol/with-viewBox.svg, in a 200 x 200 page: the use (100 % of the
    # page) shows the viewBox -100 -100 400 400 at half size, so the rect 20..180 lies at
    # 60..140 (y flipped: 60..140 too)
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<symbol id="s" viewBox="-100 -100 400 400"><rect id="r" x="20" y="20" width="160" '
        'height="160" fill="none" stroke="black"/></symbol><use id="u" href="#s"/>'
    )
    (contour,) = read_svg(svg(tmp_path, body, root=root)).contours
    assert contour.bbox() == pytest.approx((60, 60, 140, 140))
    assert contour.source == "use#u > rect#r"


@pytest.mark.parametrize(
    ("symbol", "use", "box"),
    [
        # SVG 2 §5.6: the symbol's own size when the use gives none (20 × 20 for its
        # viewBox 0 0 10 10: the 10 × 5 rect at 20..40, 20..30)
        ('width="20" height="20"', 'x="20" y="20"', (20, 20, 40, 30)),
        # its x and y place the viewport, moved by the use's: 30, 25
        ('x="10" y="5" width="20" height="20"', 'x="20" y="20"', (30, 25, 50, 35)),
        # the use's size wins over the symbol's; its x and y still count
        ('x="10" y="5" width="20" height="20"', 'x="20" y="20" width="40" height="40"',
         (30, 25, 70, 45)),
        # refX and refY move nothing (Chromium ignores them too)
        ('refX="5" refY="5" width="20" height="20"', 'x="20" y="20"', (20, 20, 40, 30)),
    ],
)  # fmt: skip
def test_a_symbols_own_place_and_size_count(
    tmp_path: Path, symbol: str, use: str, box: tuple[float, ...]
) -> None:
    # Each box is what Chromium's getBBox gives for the document; without the symbol's own
    # x, y, width and height the viewport would sit at the use's x, y, 100 % wide.
    body = (
        f'<symbol id="s" viewBox="0 0 10 10" {symbol}><rect width="10" height="5" '
        f'fill="red"/></symbol><use href="#s" {use}/>'
    )
    x0, y0, x1, y1 = box
    (contour,) = read_svg(svg(tmp_path, body)).contours
    assert contour.bbox() == pytest.approx((x0, 100 - y1, x1, 100 - y0), abs=1e-9)


def read_or_refused(path: Path, read: bool, bbox: tuple[float, ...], refusal: str) -> None:
    """``path`` reads as one contour of ``bbox`` (``read``), else is refused (``refusal``)."""
    if read:
        assert [c.bbox() for c in read_svg(path).contours] == [pytest.approx(bbox, abs=1e-9)]
    else:
        with pytest.raises(InputError, match=refusal):
            read_svg(path)


@pytest.mark.parametrize(("size", "read"), [('width="200" height="200"', True),
                                            ('width="100" height="100"', False)])  # fmt: skip
def test_a_symbol_clips_to_the_size_of_its_use(tmp_path: Path, size: str, read: bool) -> None:
    # resvg's structure/symbol/with-custom-use-size.svg: a symbol is a viewport; the rect
    # 20..180 fits a use of 200 and reaches outside one of 100
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<symbol id="s"><rect id="r" x="20" y="20" width="160" height="160" fill="none" '
        f'stroke="black"/></symbol><use id="u" href="#s" {size}/>'
    )
    refusal = r"the viewport of the nested use#u > symbol#s hides"
    read_or_refused(svg(tmp_path, body, root=root), read, (20, 20, 180, 180), refusal)


@pytest.mark.parametrize(("side", "read"), [("40", True), ("160", False)])
def test_a_symbol_placed_by_a_use_of_a_use_clips_to_the_inner_use(
    tmp_path: Path, side: str, read: bool
) -> None:
    # resvg's structure/symbol/indirect-symbol-reference.svg: a <use> in <defs> sizes the
    # symbol's viewport 100 x 100 and moves it by (40, 40); the drawn <use> places that use.
    # The rect 20..20+side lies at 60..60+side: 60..100 fits the viewport 40..140; 60..220
    # reaches outside it (a viewer shows 60..140), so it is refused, not cut whole
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        f'<defs><symbol id="s"><rect id="r" x="20" y="20" width="{side}" height="{side}" '
        'fill="none" stroke="black"/></symbol><use id="inner" href="#s" width="100" '
        'height="100" transform="translate(40 40)"/></defs><use id="outer" href="#inner"/>'
    )
    refusal = r"the viewport of the nested .*symbol#s hides"
    read_or_refused(svg(tmp_path, body, root=root), read, (60, 100, 100, 140), refusal)


@pytest.mark.parametrize("size", ['width="100" height="150"', ""])
@pytest.mark.parametrize(("r", "read"), [("10", True), ("60", False)])
def test_a_use_of_an_svg_without_a_viewbox_clips_to_its_viewport(
    tmp_path: Path, size: str, r: str, read: bool
) -> None:
    # resvg's structure/use/xlink-to-svg-element-with-rect.svg: the <svg> in <defs> at
    # (40, 40) is a viewport of the use's size (100 x 150), else its own (80 x 80), its
    # content not scaled. The circle (20, 20) r 10 lies at (60, 60), inside either; r 60
    # reaches outside it (a viewer shows a part of it), so it is refused, not cut whole
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<defs><svg id="v" x="40" y="40" width="80" height="80"><circle id="c" cx="20" '
        f'cy="20" r="{r}" fill="none" stroke="black"/></svg></defs><use id="u" href="#v" {size}/>'
    )
    refusal = r"the viewport of the nested use#u > svg#v hides"
    read_or_refused(svg(tmp_path, body, root=root), read, (50, 130, 70, 150), refusal)


@pytest.mark.parametrize(
    ("use", "own", "bbox"),
    [
        # resvg's structure/use/xlink-to-svg-element-with-viewBox.svg, moved by x, y: the
        # use's 100 x 150 shows the viewBox 0 0 200 200 at half size, centred (meet): the
        # circle (100, 100) r 80 at (10 + 50, 5 + 25 + 50) r 40, y flipped on the 200 page
        ('x="10" y="5" width="100" height="150"', "", (20, 80, 100, 160)),
        # the use's size wins over the <svg>'s own (SVG 1.1 §5.6)
        ('x="10" y="5" width="100" height="150"', 'width="50" height="60"', (20, 80, 100, 160)),
        # width alone: the height is the <svg>'s 100 %, the page's 200; the circle is
        # scaled by 0.5 and centred in y: (10 + 50, 5 + 50 + 50) r 40
        ('x="10" y="5" width="100"', "", (20, 55, 100, 135)),
        # no size on the use: the <svg>'s own 100 x 150
        ('x="10" y="5"', 'width="100" height="150"', (20, 80, 100, 160)),
        # the <svg>'s own x adds to the use's; 200 x 200, the page: the circle at (103, 100)
        ('width="200" height="200"', 'x="3" width="50" height="50"', (23, 20, 183, 180)),
        # at 0, 0 of 100 x 100: the circle at (50, 50) r 40
        ('x="0" y="0" width="100" height="100"', 'width="50" height="50"', (10, 110, 90, 190)),
        # as Inkscape writes a clone: 100 %, moved by a transform (20, 30): (120, 130)
        (
            'width="100%" height="100%" transform="translate(20 30)"',
            'width="50" height="50"',
            (40, -10, 200, 150),
        ),
    ],
)
def test_a_use_sizes_the_svg_it_places(tmp_path: Path, use: str, own: str, bbox: tuple) -> None:
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        f'<defs><svg id="s" viewBox="0 0 200 200" {own} overflow="visible"><circle id="c" '
        f'cx="100" cy="100" r="80" fill="none" stroke="black"/></svg></defs>'
        f'<use id="u" href="#s" {use}/>'
    )
    (contour,) = read_svg(svg(tmp_path, body, root=root)).contours
    assert contour.bbox() == pytest.approx(bbox, abs=1e-9)


@pytest.mark.parametrize(
    ("size", "why"), [('width="-5"', "must not be negative"), ('width="abc"', "must be a number")]
)
def test_a_use_of_a_bad_size_is_refused(tmp_path: Path, size: str, why: str) -> None:
    # the size goes to the viewport that the use of a symbol stands for, where svgelements
    # would read nothing of the document: refused as a nested <svg>'s is, naming the use
    body = f'<symbol id="s" viewBox="0 0 10 10">{SQUARE}/></symbol><use id="u" href="#s" {size}/>'
    with pytest.raises(InputError, match=r"use#u: bad width") as e:
        read_svg(svg(tmp_path, body))
    assert why in str(e.value)


def test_a_use_sizes_an_svg_of_a_small_viewbox(tmp_path: Path) -> None:
    # the <svg>'s viewBox 10 x 10 shown in the use's 100 x 100: scaled by 10, the circle
    # (5, 5) r 4 at (50, 50) r 40
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<defs><svg id="s" width="50" height="50" viewBox="0 0 10 10"><circle id="c" cx="5" '
        'cy="5" r="4" fill="none" stroke="black"/></svg></defs>'
        '<use id="u" href="#s" x="0" y="0" width="100" height="100"/>'
    )
    (contour,) = read_svg(svg(tmp_path, body, root=root)).contours
    assert contour.bbox() == pytest.approx((10, 110, 90, 190), abs=1e-9)


def test_a_use_places_what_a_clip_ignores(tmp_path: Path) -> None:
    # resvg's structure/use/xlink-to-a-child-of-an-invalid-element.svg: a <g> is not a
    # clip's content, so the clip ignores it, but the rect in it is an element like any
    # other for the <use> that places it: drawn at 20..180
    root = 'width="200mm" height="200mm" viewBox="0 0 200 200"'
    body = (
        '<clipPath id="c"><g id="g"><rect id="r" x="20" y="20" width="160" height="160" '
        'fill="green"/></g></clipPath><use id="u" xlink:href="#r"/>'
    )
    (contour,) = read_svg(svg(tmp_path, body, root=root)).contours
    assert contour.bbox() == pytest.approx((20, 20, 180, 180), abs=1e-9)


def test_a_mask_on_the_whole_drawing(tmp_path: Path) -> None:
    # the mask on the <svg> itself: its white half shows the square's left part only
    root = 'width="100mm" height="100mm" viewBox="0 0 100 100" mask="url(#m)"'
    body = f'<mask id="m"><rect width="50" height="100" fill="white"/></mask>{SQUARE}/>'
    with pytest.raises(InputError, match=r"the mask #m on svg\[1\] hides part of rect#sq"):
        read_svg(svg(tmp_path, body, root=root))


def test_fit_tolerance_follows_what_the_clips_leave(tmp_path: Path) -> None:
    # --fit 100 100 scales the kept curve (a Bézier loop 10 mm wide, 15 high) by 100 / 15,
    # so its fit must be within 0.001 / 6.67 mm. A shape its clip hides wholly, 80 mm away,
    # is not cut: measured with it, the factor would be 100 / 85 and the fit about 6 times
    # too coarse once scaled.
    from camtool.importers.options import ImportOptions
    from camtool.importers.svg import svg_drawing

    body = (
        '<path id="kept" d="M 10 10 C 10 20 20 20 20 10 C 20 0 10 0 10 10 Z" fill="none" '
        'stroke="black"/><clipPath id="c"><rect width="1" height="1"/></clipPath>'
        '<circle id="far" cx="92" cy="92" r="3" fill="none" stroke="black" '
        'clip-path="url(#c)"/>'
    )
    options = ImportOptions(tolerance=0.001, fit=(100.0, 100.0))
    drawing, tolerance = svg_drawing(svg(tmp_path, body), options)
    assert [c.source for c in drawing.contours] == ["path#kept"]
    x0, y0, x1, y1 = drawing.contours[0].bbox()
    # at least as fine as the kept drawing's own factor asks (8.5e-4 with the far circle)
    assert tolerance <= 0.001 / min(100 / (x1 - x0), 100 / (y1 - y0))


def test_a_shape_its_clip_hides_wholly_does_not_count_toward_the_travel(
    tmp_path: Path,
) -> None:
    """The travel check before fitting measures every shape; a clipped-away one is not cut.

    A 10 mm part, and a circle 400 mm away that its clip hides wholly: camtool cuts only
    the part, so the drawing fits grbl's 300 × 200 mm travel, though all its shapes
    together do not. A part that is too large by itself is still refused.
    """
    from camtool.cli.main import main

    far = (
        '<clipPath id="c"><rect width="1" height="1"/></clipPath>'
        '<circle id="far" cx="400" cy="50" r="3" fill="none" stroke="black" '
        'clip-path="url(#c)"/>'
    )
    part = '<rect id="part" x="10" y="10" width="10" height="10" fill="none" stroke="black"/>'
    root = 'width="500mm" height="100mm" viewBox="0 0 500 100"'
    out = tmp_path / "part.gcode"
    args = ["post", str(svg(tmp_path, part + far, root)), "-t", "grbl", "-o", str(out)]
    assert main(args) == 0
    code = out.read_text()
    xs = [float(x) for x in re.findall(r"^G1 X(-?[\d.]+)", code, re.MULTILINE)]
    assert xs and min(xs) == 10.0 and max(xs) == 20.0  # the part only, not the far circle
    big = '<rect id="big" x="0" y="0" width="350" height="10" fill="none" stroke="black"/>'
    out.unlink()
    args = ["post", str(svg(tmp_path, big + far, root, "big.svg")), "-t", "grbl", "-o", str(out)]
    assert main(args) == 1 and not out.exists()
