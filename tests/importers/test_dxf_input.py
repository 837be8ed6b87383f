"""DXF input handling: skipped constructs and their messages, HATCH, layers, damaged files."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import ezdxf
import pytest

from camtool.importers import read_drawing
from camtool.importers.dxf import import_dxf, read_dxf
from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError
from camtool.model.shapes import Arc, Line
from tests.shapes import write_dxf


def _with_a_line(extra: Any) -> Any:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (10, 0))
        msp.doc.blocks.new("B").add_line((1, 1, 2), (4, 1, 5))
        extra(msp)

    return build


def _add_mesh(msp: Any) -> None:
    with msp.add_mesh().edit_data() as mesh:
        mesh.vertices = [(0, 0, 0), (1, 0, 0), (0, 1, 1)]
        mesh.faces = [(0, 1, 2)]


def _warning(path: Path, build: Any, options: ImportOptions | None = None) -> str:
    """The one skip warning a drawing of a line plus ``build``'s entities gives.

    The drawing has a block ``B`` holding one 3D line, for ``build`` to place or not.
    """
    d = read_dxf(write_dxf(path, _with_a_line(build)), options)
    assert len(d.contours) == 1, d.contours
    (skip,) = [w for w in d.warnings if "skipped" in w]
    return skip


@pytest.mark.parametrize(
    ("build", "expected"),
    [
        (lambda m: [m.add_text("a"), m.add_text("b")], "skipped 2 TEXT entities (text is not cut"),
        (lambda m: m.add_mtext("note"), "skipped 1 MTEXT entity (text is not cut"),
        (
            lambda m: m.add_linear_dim(base=(0, 3), p1=(0, 0), p2=(10, 0)).render(),
            "skipped 1 DIMENSION entity (annotation, not a contour)",
        ),
        (
            lambda m: m.add_point((1, 1)),
            "skipped 1 POINT entity (a point has no path to cut; a drill operation of a job "
            "drills it)",
        ),
        (
            lambda m: m.add_3dface([(0, 0, 0), (1, 0, 0), (1, 1, 1)]),
            "skipped 1 3DFACE entity (3D entity; camtool cuts 2D contours)",
        ),
        (
            _add_mesh,
            "skipped 1 MESH entity (3D entity",
        ),
        (
            lambda m: m.add_polyline3d([(0, 0, 0), (1, 1, 1)]),
            "skipped 1 POLYLINE entity (3D entity; camtool cuts 2D contours)",
        ),
        (
            lambda m: m.add_polyface().append_face([(0, 0, 0), (1, 0, 0), (1, 1, 0)]),
            "skipped 1 POLYFACE entity (3D entity",
        ),
        (
            lambda m: m.add_solid([(0, 0), (1, 0), (0, 1)]),
            "skipped 1 SOLID entity (filled area; draw its outline to cut it)",
        ),
        (
            lambda m: m.add_arc((0, 0), 1, 0, 90, dxfattribs={"extrusion": (0, 1, 0)}),
            "skipped 1 ARC entity (not parallel to XY)",
        ),
        (
            lambda m: m.add_line((5, 5), (5, 5)),
            "skipped 1 LINE entity (zero length)",
        ),
        (  # a 3D line, as the 3D POLYLINE: its projection is not a contour of the part
            lambda m: m.add_line((5, 5, 0), (20, 5, 10)),
            "skipped 1 LINE entity (3D entity; camtool cuts 2D contours)",
        ),
        (
            lambda m: m.add_blockref("B", (0, 0)),
            "skipped 1 LINE entity (3D entity; camtool cuts 2D contours)",
        ),
    ],
    ids=[
        "text",
        "mtext",
        "dimension",
        "point",
        "3dface",
        "mesh",
        "3dpolyline",
        "polyface",
        "solid",
        "tilted",
        "zero",
        "3dline",
        "3dline-in-block",
    ],
)
def test_unsupported_entities_are_skipped_with_one_warning_per_type(
    tmp_path: Path, build: Any, expected: str
) -> None:
    assert expected in _warning(tmp_path / "s.dxf", build)


def test_image_is_skipped(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        image_def = msp.doc.add_image_def(filename="photo.png", size_in_pixel=(64, 48))
        msp.add_image(image_def, insert=(0, 0), size_in_units=(6.4, 4.8))

    assert "skipped 1 IMAGE entity (picture or underlay" in _warning(tmp_path / "i.dxf", build)


def test_a_wipeout_warns_that_what_it_masks_is_still_cut(tmp_path: Path) -> None:
    """A WIPEOUT hides what lies under it on screen; camtool does not clip by it."""

    def build(msp: Any) -> None:  # over the line _warning draws
        msp.add_wipeout([(2, -2), (8, 2)])

    assert "skipped 1 WIPEOUT entity (a mask: what it covers on screen is still read and cut" in (
        _warning(tmp_path / "w.dxf", build)
    )


def test_text_inside_a_block_is_counted_with_the_rest(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_text("top")
        block = msp.doc.blocks.new("LABEL")
        block.add_text("inside", dxfattribs={"insert": (1, 2)})
        block.add_line((0, 0), (0, 1))
        msp.add_blockref("LABEL", (100, 0), dxfattribs={"rotation": 90})

    read = import_dxf(write_dxf(tmp_path / "t.dxf", _with_a_line(build)))
    assert len(read.drawing.contours) == 2
    assert sum("skipped 2 TEXT entities" in w for w in read.drawing.warnings) == 1
    # the note places the block's text where the INSERT puts it: (1, 2) turned 90°, +(100, 0)
    inside = next(n for n in read.notes if "in INSERT" in n.source)
    assert inside.location == pytest.approx((98.0, 1.0))
    assert read.block_entity_counts == (("LINE", "0", 1), ("TEXT", "0", 1))


def _hatch_build(msp: Any) -> None:
    hatch = msp.add_hatch(dxfattribs={"layer": "FILL"})
    # polyline path: a 10 x 10 square whose top edge bulges out as a half circle
    hatch.paths.add_polyline_path(
        [(0, 0, 0), (10, 0, 0), (10, 10, 1.0), (0, 10, 0)], is_closed=True
    )
    # edge path: line, clockwise arc, line, ellipse quarter, back to start
    edge = hatch.paths.add_edge_path()
    edge.add_line((20, 0), (30, 0))
    edge.add_arc((30, 5), 5, -90, 90, ccw=True)  # (30,0) → (35,5) → (30,10)
    edge.add_line((30, 10), (25, 10))
    edge.add_ellipse((25, 0), major_axis=(0, 10), ratio=0.5, start_angle=0, end_angle=90)
    edge.add_line((20, 0), (20, 0.0))  # a zero-length edge CAD programs leave behind


def test_hatch_is_skipped_without_the_option(tmp_path: Path) -> None:
    skip = _warning(tmp_path / "h.dxf", _hatch_build)
    assert "skipped 1 HATCH entity" in skip and "--hatch-boundaries" in skip


def test_hatch_boundaries_become_closed_contours(tmp_path: Path) -> None:
    path = write_dxf(tmp_path / "h.dxf", _with_a_line(_hatch_build))
    d = read_dxf(path, ImportOptions(hatch_boundaries=True))
    _, square, edges = d.contours
    handle = ezdxf.readfile(path).modelspace().query("HATCH")[0].dxf.handle
    assert square.source == f"HATCH #{handle} path 1" and square.layer == "FILL"
    assert edges.source == f"HATCH #{handle} path 2"
    assert square.closed and edges.closed and edges.end == edges.start
    # square with a half-circle top: area 100 + π·5²/2 (polygon area with 1e-6 mm chords)
    assert abs(square.signed_area()) == pytest.approx(100 + math.pi * 12.5, rel=1e-6)
    kinds = [type(s) for s in square.segments]
    assert kinds.count(Arc) == 1 and kinds.count(Line) == 3
    # edge path: the 10 x 10 square (20..30) + a half disc of radius 5 on its right, less
    # what lies left of the quarter ellipse (centre (25, 0), semi-axes 5 and 10):
    # 100 + 12.5π - (50 - 50π/4); the ellipse is fitted within 0.001 mm over ~12 mm
    want = 100 + 12.5 * math.pi - (50 - 50 * math.pi / 4)
    assert abs(edges.signed_area()) == pytest.approx(want, abs=0.001 * 12)


def test_layers_select_and_match_case_insensitively(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.doc.layers.add("CUT")
        msp.doc.layers.add("Engrave")
        msp.add_line((0, 0), (1, 0), dxfattribs={"layer": "CUT"})
        msp.add_line((0, 1), (1, 1), dxfattribs={"layer": "Engrave"})
        msp.add_circle((5, 5), 1, dxfattribs={"layer": "CUT"})

    path = write_dxf(tmp_path / "l.dxf", build)
    cut = read_drawing(path, ImportOptions(layers=("cut",)))
    assert [c.layer for c in cut.contours] == ["CUT", "CUT"]
    both = read_drawing(path, ImportOptions(layers=("CUT", "engrave")))
    assert len(both.contours) == 3


def test_unknown_layer_lists_the_layers_present(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0), dxfattribs={"layer": "CUT"})

    path = write_dxf(tmp_path / "l.dxf", build)
    with pytest.raises(InputError, match=r"no layer 'CUTS' in the drawing; its layers are .*CUT"):
        read_drawing(path, ImportOptions(layers=("CUTS",)))


def test_a_layer_named_with_a_comma_is_listed_whole_and_said_where_to_name_it(
    run: Any, tmp_path: Path
) -> None:
    # --layers splits at commas, so "Outline, top" reaches the reader as two names; the
    # refusal lists each layer quoted (one name, not two) and points to a job file,
    # whose layers list names it whole and cuts its square.
    def build(msp: Any) -> None:
        msp.doc.layers.add("Outline, top")
        square = [(0, 0), (10, 0), (10, 10), (0, 10)]
        msp.add_lwpolyline(square, close=True, dxfattribs={"layer": "Outline, top"})

    path = write_dxf(tmp_path / "l.dxf", build)
    code, err = run("post", str(path), "-t", "grbl", "--layers", "Outline, top")
    assert code == 3, err
    assert "its layers are '0', 'Defpoints', 'Outline, top' (--layers splits" in err
    assert "in a job file's layers list" in err
    job = tmp_path / "job.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 1.0\nfeed = 300\n\n'
        '[[operations]]\nname = "o"\ntype = "profile"\ntool = 1\n'
        'layers = ["Outline, top"]\nside = "on"\ndepth = 1.0\n'
    )
    out = tmp_path / "o.nc"
    code, err = run("post", str(path), "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 0, err
    assert "G1 X10.000 Y0.000" in out.read_text()


def test_layer_with_nothing_usable_says_which_layers(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.doc.layers.add("NOTES")
        msp.add_line((0, 0), (1, 0))
        msp.add_text("x", dxfattribs={"layer": "NOTES"})

    with pytest.raises(InputError, match="no usable entity in model space on layers NOTES"):
        read_dxf(write_dxf(tmp_path / "n.dxf", build), ImportOptions(layers=("NOTES",)))


def test_damaged_file_is_recovered_with_a_warning(tmp_path: Path) -> None:
    good = write_dxf(tmp_path / "good.dxf", lambda m: m.add_circle((5, 5), 2.0))
    text = good.read_text()
    damaged = tmp_path / "damaged.dxf"
    damaged.write_text(text.replace("EOF", ""))  # the last tag cut off
    d = read_dxf(damaged)
    (arc,) = d.contours[0].segments
    assert isinstance(arc, Arc) and arc.radius == 2.0
    (warning,) = d.warnings
    assert warning.startswith(f"{damaged}: damaged DXF file (")
    assert "recover mode" in warning and "missing EOF" in warning and "1 fixes" in warning
    assert import_dxf(damaged).recovered


def test_unreadable_file_is_an_input_error_with_exit_3(tmp_path: Path) -> None:
    bad = tmp_path / "notes.dxf"
    bad.write_text("this is not a drawing\n")
    with pytest.raises(InputError) as info:
        read_dxf(bad)
    assert info.value.exit_code == 3
    msg = str(info.value)
    assert msg.startswith(f"{bad}: not a readable DXF file")
    assert "recover mode failed" in msg and "export it as DXF" in msg


def test_empty_file(tmp_path: Path) -> None:
    empty = tmp_path / "empty.dxf"
    empty.write_bytes(b"")
    with pytest.raises(InputError, match="empty file"):
        read_dxf(empty)


def test_paper_space_only_drawing_says_so(tmp_path: Path) -> None:
    doc = ezdxf.new("R2010")
    doc.layouts.get("Layout1").add_line((0, 0), (1, 0))
    path = tmp_path / "paper.dxf"
    doc.saveas(path)
    with pytest.raises(InputError, match=r"model space is empty; the drawing is in paper space"):
        read_dxf(path)


def test_paper_space_is_ignored_silently_when_model_space_has_entities(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.add_line((0, 0), (1, 0))
        msp.doc.layouts.get("Layout1").add_circle((0, 0), 5)

    d = read_dxf(write_dxf(tmp_path / "both.dxf", build))
    assert len(d.contours) == 1 and not any("paper" in w for w in d.warnings)


def test_spline_fit_polyline_uses_the_curve_not_its_frame(tmp_path: Path) -> None:
    # A spline-fit 2D POLYLINE holds its control frame (vertex flag 16) and the fitted
    # vertices (flag 8); only the latter are on the drawn curve.
    def build(msp: Any) -> None:
        p = msp.add_polyline2d([(0, 0), (5, 5), (10, 0)], dxfattribs={"flags": 4})
        for v in p.vertices:
            v.dxf.flags = 16
        for x, y in [(0, 0), (5, 2.5), (10, 0)]:
            p.append_vertex((x, y), dxfattribs={"flags": 8})

    (contour,) = read_dxf(write_dxf(tmp_path / "sf.dxf", build)).contours
    assert [s.start for s in contour.segments] == [(0.0, 0.0), (5.0, 2.5)]


def test_flat_3d_polyline_is_read_as_lines(tmp_path: Path) -> None:
    # Some programs write 2D outlines as 3D POLYLINEs at one height: they are 2D.
    def build(msp: Any) -> None:
        msp.add_polyline3d([(0, 0, 2), (4, 0, 2), (4, 3, 2)], close=True)

    (contour,) = read_dxf(write_dxf(tmp_path / "p3.dxf", build)).contours
    assert contour.closed and [s.length for s in contour.segments] == [4.0, 3.0, 5.0]


def test_hatch_spline_edge_is_fitted(tmp_path: Path) -> None:
    # quadratic Bézier (0,20) (5,30) (10,20) closed by its chord: area 2/3 · 10 · 5
    def build(msp: Any) -> None:
        edge = msp.add_hatch().paths.add_edge_path()
        edge.add_spline(
            control_points=[(0, 20), (5, 30), (10, 20)], knot_values=[0, 0, 0, 1, 1, 1], degree=2
        )
        edge.add_line((10, 20), (0, 20))

    (contour,) = read_dxf(
        write_dxf(tmp_path / "hs.dxf", build), ImportOptions(hatch_boundaries=True)
    ).contours
    assert contour.closed and contour.bbox() == pytest.approx((0, 20, 10, 25), abs=0.001)
    assert abs(contour.signed_area()) == pytest.approx(100 / 3, abs=0.001 * 12)
