"""Dots: zero-length strokes an SVG viewer draws by their round or square caps.

The expected marks come from the rule of SVG 1.1 §11.4 (``stroke-linecap``; SVG 2 §13.5.4):
a zero-length subpath is drawn with ``round`` or ``square`` caps and not with ``butt``, a
lone ``moveto`` never, and from the drawing's coordinates (a 100 × 100 mm page whose
viewBox is in mm: ``(x, y)`` is ``(x, 100 - y)`` mm, Y up). Chromium's rendering of the
first test's file, checked by hand, draws dots at ``a`` to ``e`` and nothing at the others.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.job import Job
from camtool.jobs.jobfile import load_job
from camtool.jobs.run import run_job
from camtool.model.program import DrillCycle, Rapid
from camtool.post.registry import load_target

PAGE = (
    '<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" '
    'viewBox="0 0 100 100">\n{}\n</svg>\n'
)
FRAME = '<rect id="frame" x="5" y="5" width="90" height="90" fill="none" stroke="black"/>'
DOTS = """
<line id="a" x1="30" y1="30" x2="30" y2="30" stroke="black" stroke-width="3"
      stroke-linecap="round"/>
<path id="b" d="M 50 50 Z" stroke="black" stroke-width="2" stroke-linecap="square"/>
<path id="c" d="M 60 20 L 60 20 M 70 20" stroke="black" stroke-linecap="round"/>
<g stroke-linecap="round"><path id="d" d="M 20 80 C 20 80 20 80 20 80" stroke="red"/></g>
<polyline id="e" points="40 60 40 60" stroke="black" stroke-linecap="round" fill="none"/>
"""
NOT_DOTS = """
<line id="butt" x1="10" y1="10" x2="10" y2="10" stroke="black" stroke-width="3"/>
<path id="filled" d="M 80 80 Z" fill="black" stroke="none" stroke-linecap="round"/>
<path id="thin" d="M 85 85 Z" stroke="black" stroke-width="0" stroke-linecap="round"/>
<path id="moves" d="M 15 15 L 25 15 M 35 35" stroke="black" stroke-linecap="round"/>
<path id="loop" d="M 90 50 C 95 45 95 55 90 50" stroke="black" stroke-linecap="round"/>
"""


def test_zero_length_strokes_with_round_or_square_caps_are_marks(tmp_path: Path) -> None:
    svg = tmp_path / "dots.svg"
    svg.write_text(PAGE.format(FRAME + DOTS + NOT_DOTS))
    drawing = read_drawing(svg)
    got = {m.source: m.at for m in drawing.marks}
    assert got == {
        "line#a": (30.0, 70.0),
        "path#b": (50.0, 50.0),
        "path#c": (60.0, 80.0),  # the lone `M 70 20` after it is not stroked
        "path#d": (20.0, 20.0),  # the cap inherited from the group
        "polyline#e": (40.0, 40.0),
    }
    assert {m.colour for m in drawing.marks} == {"#000000", "#ff0000"}
    (said,) = [w for w in drawing.warnings if "dots" in w]
    assert "skipped 5 dots" in said and "line#a at (30.0000, 70.0000) mm" in said
    assert "drill operation" in said
    # the curves that move are cut as before: the frame, the line of `moves`, the loop
    assert sorted(c.source for c in drawing.contours) == [
        "path#loop",
        "path#moves",
        "rect#frame",
    ]


def test_a_drawing_of_dots_alone_is_read_and_its_dots_drilled(tmp_path: Path) -> None:
    svg = tmp_path / "template.svg"
    svg.write_text(PAGE.format(DOTS))
    drawing = read_drawing(svg)
    assert not drawing.contours and len(drawing.marks) == 5
    job = tmp_path / "job.toml"
    job.write_text(
        '[job]\norigin = "drawing"\n'
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 2\n'
        '[[operations]]\ntype = "drill"\ntool = 1\npoints = true\ndepth = 3\n'
    )
    done = run_job(drawing, load_target("linuxcnc"), load_job(job))
    drilled = sorted((c.x, c.y) for _, c in done.program.commands if isinstance(c, DrillCycle))
    assert drilled == [(20.0, 20.0), (30.0, 70.0), (40.0, 40.0), (50.0, 50.0), (60.0, 80.0)]


def test_a_layer_of_dots_can_be_named(tmp_path: Path) -> None:
    from camtool.importers.options import ImportOptions

    body = (
        '<g inkscape:groupmode="layer" inkscape:label="Holes">'
        '<path id="h" d="M 30 30 Z" stroke="black" stroke-linecap="round"/></g>'
        f'<g inkscape:groupmode="layer" inkscape:label="Edge">{FRAME}</g>'
    )
    page = PAGE.replace(
        "<svg ", '<svg xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" ', 1
    )
    svg = tmp_path / "layers.svg"
    svg.write_text(page.format(body))
    holes = read_drawing(svg, ImportOptions(layers=("Holes",)))
    assert [m.layer for m in holes.marks] == ["Holes"] and not holes.contours
    edge = read_drawing(svg, ImportOptions(layers=("Edge",)))
    assert not edge.marks and [c.source for c in edge.contours] == ["rect#frame"]


def test_a_dot_a_clip_hides_is_left_out(tmp_path: Path) -> None:
    # the clip shows the left half of the page: the line of `p` and the dot at (20, 20) lie
    # in it, the dot at (80, 80) does not (a viewer shows nothing there, so nothing to drill)
    body = (
        '<clipPath id="left"><rect x="0" y="0" width="50" height="100"/></clipPath>'
        '<g clip-path="url(#left)">'
        '<path id="p" d="M 10 10 L 30 10 M 20 20 Z M 80 80 Z" stroke="black" '
        'stroke-linecap="round" fill="none"/></g>'
    )
    svg = tmp_path / "clipped.svg"
    svg.write_text(PAGE.format(body))
    drawing = read_drawing(svg)
    assert [m.at for m in drawing.marks] == [(20.0, 80.0)]
    assert [c.source for c in drawing.contours] == ["path#p"]


def test_fit_sizes_what_is_cut_and_a_dot_is_cut_only_when_drilled(tmp_path: Path) -> None:
    # a 10 mm square and a dot 70 mm away: a plain post cuts the square alone, so --fit 50 50
    # makes it 50 mm (k = 5); a job that drills the dot fits both in 50 mm (80 mm wide
    # from the square's left to the dot: k = 50 / 80)
    from camtool.toolpath.options import PlanOptions

    body = (
        '<rect id="sq" x="10" y="80" width="10" height="10" fill="none" stroke="black"/>'
        '<path id="dot" d="M 90 10 Z" stroke="black" stroke-width="2" stroke-linecap="round"/>'
    )
    svg = tmp_path / "far.svg"
    svg.write_text(PAGE.format(body))
    drawing = read_drawing(svg)
    plain = Job.single(PlanOptions(fit=(50.0, 50.0), placement="lower-left"))
    done = run_job(drawing, load_target("linuxcnc"), plain)
    xs = [m.x for m in done.program.moves if not isinstance(m, Rapid)]
    assert max(xs) - min(xs) == pytest.approx(50.0)
    job = tmp_path / "job.toml"
    job.write_text(
        '[job]\norigin = "lower-left"\nfit = [50, 50]\n'
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 1\n'
        '[[operations]]\ntype = "drill"\ntool = 1\npoints = "only"\ndepth = 1\n'
        '[[operations]]\ntype = "engrave"\ntool = 1\nclosed = true\ndepth = 0.5\n'
    )
    done = run_job(drawing, load_target("linuxcnc"), load_job(job))
    (hole,) = [c for _, c in done.program.commands if isinstance(c, DrillCycle)]
    square = [m.x for m in done.program.moves if not isinstance(m, Rapid) and m.x < hole.x]
    assert hole.x - min(square) == pytest.approx(50.0)  # 80 mm × 50 / 80
    assert max(square) - min(square) == pytest.approx(10.0 * 50.0 / 80.0)
