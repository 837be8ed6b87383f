"""Hostile and damaged DXF files: units from the file, bad numbers, limits, one-line errors.

Each test is the regression test of one class of failure found by trying hostile inputs
(issues 13 and 14): a wrong program with exit 0, an internal error, or a hang. Expected
values come from the DXF reference ($INSUNITS codes) and from the files written here.
"""

from __future__ import annotations

import math
import re
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import ezdxf
import pytest

import camtool.importers.options as options_module
from camtool.cli.main import main
from camtool.importers.dxf import import_dxf, read_dxf
from camtool.importers.options import MAX_ENTITIES, ImportOptions
from camtool.model.errors import InputError, UsageError
from tests.shapes import segment_samples, write_dxf

_ENTITIES = """\
  0
SECTION
  2
ENTITIES
  0
LINE
  5
2A
  8
0
 10
{x0}
 20
0.0
 30
0.0
 11
{x1}
 21
0.0
 31
0.0
  0
ENDSEC
  0
EOF
"""


def _text_dxf(path: Path, *, header: str | None, x0: str = "0.0", x1: str = "10.0") -> Path:
    """A DXF written by hand: an optional HEADER section (its variables) and one LINE."""
    head = "" if header is None else f"  0\nSECTION\n  2\nHEADER\n{header}  0\nENDSEC\n"
    path.write_text(head + _ENTITIES.format(x0=x0, x1=x1), encoding="ascii")
    return path


def _insunits(code: int) -> str:
    return f"  9\n$ACADVER\n  1\nAC1009\n  9\n$INSUNITS\n 70\n{code}\n"


def _length(path: Path) -> float:
    (contour,) = read_dxf(path).contours
    (seg,) = contour.segments
    return seg.length


# ---------------------------------------------------------------------------- units (item 1)


@pytest.mark.parametrize(
    ("code", "mm"),
    [(4, 10.0), (1, 254.0), (6, 10_000.0)],  # DXF reference: 4 mm, 1 inch, 6 metre
)
def test_insunits_in_the_header_scales_the_drawing(tmp_path: Path, code: int, mm: float) -> None:
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(code))
    assert _length(path) == pytest.approx(mm, rel=1e-12)
    assert not [w for w in read_dxf(path).warnings if "units" in w]


def test_a_dxf_without_header_is_mm_with_a_warning_not_metres(tmp_path: Path) -> None:
    # ezdxf fills a missing HEADER with its defaults for new drawings: $INSUNITS 6 (m),
    # which made a 10 mm line 10 000 mm long with exit code 0.
    path = _text_dxf(tmp_path / "r12.dxf", header=None)
    assert ezdxf.readfile(path).header["$INSUNITS"] == 6  # the trap
    read = import_dxf(path)
    assert _length(path) == pytest.approx(10.0)
    assert read.units == "mm (assumed)"
    assert any("$INSUNITS" in w and "assuming mm" in w for w in read.drawing.warnings)


def test_a_header_without_insunits_is_mm_with_a_warning(tmp_path: Path) -> None:
    path = _text_dxf(tmp_path / "a.dxf", header="  9\n$ACADVER\n  1\nAC1009\n")
    assert import_dxf(path).units == "mm (assumed)"
    assert _length(path) == pytest.approx(10.0)


# ---------------------------------------------------------------------------- bad numbers (2, 3)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "1e400", "1e300", "2e9"])
def test_a_line_with_a_bad_coordinate_is_an_input_error(tmp_path: Path, value: str) -> None:
    # not: dropped as "zero length" (NaN) or an internal OverflowError (inf) later on
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4), x1=value)
    with pytest.raises(InputError) as info:
        read_dxf(path)
    message = str(info.value)
    assert "LINE #2A on layer '0'" in message
    assert "end (" in message
    assert "\n" not in message


@pytest.mark.parametrize(
    ("value", "far"),
    [("5.4e9", True), ("2e9", True), ("1e300", True), ("nan", False), ("-inf", False)],
)
def test_a_number_too_large_is_told_apart_from_one_not_a_number(
    tmp_path: Path, value: str, far: bool
) -> None:
    """A finite coordinate past the bound is a drawing far from 0 (a plan in map
    coordinates: UTM northings are thousands of km), told to be moved near 0; NaN and
    infinity are a damaged file."""
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4), x1=value)
    with pytest.raises(InputError) as info:
        read_dxf(path)
    message = str(info.value)
    assert ("move the drawing near 0" in message) is far
    assert ("the file is damaged" in message) is not far


def _one(build: Callable[[Any], None]) -> Callable[[Any], None]:
    def add(msp: Any) -> None:
        msp.add_line((0, 0), (10, 0))
        build(msp)

    return add


def _arc_nan_start(msp: Any) -> None:
    msp.add_arc((0, 0), 5, math.nan, 90)


def _ellipse_inf_param(msp: Any) -> None:
    msp.add_ellipse((0, 0), (5, 0), ratio=0.5, start_param=0, end_param=math.inf)


def _bulge_inf(msp: Any) -> None:
    msp.add_lwpolyline([(0, 0, 0, 0, math.inf), (10, 0, 0, 0, 0)], format="xyseb")


def _polyline_bulge_nan(msp: Any) -> None:
    p = msp.add_polyline2d([(0, 0), (5, 1), (5, 5)])
    p.vertices[0].dxf.bulge = math.nan


def _spline_huge(msp: Any) -> None:
    msp.add_open_spline([(0, 0), (1, 1e20), (2, 1), (3, 0)])


def _insert_nan_scale(msp: Any) -> None:
    block = msp.doc.blocks.new("B")
    block.add_line((0, 0), (1, 1))
    msp.add_blockref("B", (0, 0), dxfattribs={"xscale": math.nan})


def _insert_scale(axis: str) -> Callable[[Any], None]:
    def build(msp: Any) -> None:
        block = msp.doc.blocks.new("B")
        block.add_lwpolyline([(0, 0), (10, 0), (10, 10)])
        block.add_arc((5, 5), 3, 0, 90)
        msp.add_blockref("B", (50, 50), dxfattribs={axis: 7})  # 7 becomes 0 below

    build.__name__ = f"_insert_zero_{axis}"
    return build


_INSERT_ZERO_X = _insert_scale("xscale")
_INSERT_ZERO_Y = _insert_scale("yscale")


def _zero_extrusion(msp: Any) -> None:
    msp.add_arc((0, 0), 5, 0, 90, dxfattribs={"extrusion": (0, 0, -1)})  # -1 becomes 0 below


@pytest.mark.parametrize(
    ("build", "names"),
    [
        (_arc_nan_start, ("ARC #", "start_angle nan")),  # not: skipped as zero length
        (_ellipse_inf_param, ("ELLIPSE #", "end_param inf")),  # not: exit 2, fit_curve's usage
        (_bulge_inf, ("LWPOLYLINE #", "bulge", "inf")),  # not: internal ZeroDivisionError
        (_polyline_bulge_nan, ("POLYLINE #", "vertex 1 bulge nan")),  # not: an arc, exit 0
        (_spline_huge, ("SPLINE #", "control point 2", "1e+20")),  # not: a CPU spin
        (_insert_nan_scale, ("INSERT #", "xscale nan")),  # not: skipped as zero length
        (_zero_extrusion, ("ARC #", "extrusion (0.0, 0.0, 0.0) is not a direction")),
        (_INSERT_ZERO_X, ("INSERT #", "xscale 0", "no size")),  # not: internal error
        (_INSERT_ZERO_Y, ("INSERT #", "yscale 0", "no size")),  # (ezdxf's ZeroDivisionError)
    ],
)
def test_bad_numbers_are_input_errors_naming_the_entity(
    tmp_path: Path, build: Callable[[Any], None], names: tuple[str, ...]
) -> None:
    path = write_dxf(tmp_path / "bad.dxf", _one(build))
    if build is _zero_extrusion:  # ezdxf will not write a null extrusion itself
        path.write_text(path.read_text().replace("\n230\n-1.0\n", "\n230\n0.0\n"))
    if build in (_INSERT_ZERO_X, _INSERT_ZERO_Y):  # nor a scale of 0
        text = path.read_text()
        assert text.count("\n7.0\n") == 1
        path.write_text(text.replace("\n7.0\n", "\n0.0\n"))
    with pytest.raises(InputError) as info:
        read_dxf(path)
    message = str(info.value)
    assert message.startswith(f"{path}: ")
    assert "on layer '0'" in message
    for name in names:
        assert name in message


def test_an_insert_at_z_scale_0_is_read_as_its_flat_content(tmp_path: Path) -> None:
    """A Z scale of 0 (out of the DXF range) flattens only Z: the block's flat content,
    placed at (50, 50), is the same as at Z scale 1 (an open polyline and an arc of radius 3
    about (55, 55), from the file's numbers)."""

    def build(msp: Any) -> None:
        _insert_scale("zscale")(msp)

    path = write_dxf(tmp_path / "z.dxf", build)
    text = path.read_text()
    assert text.count("\n7.0\n") == 1
    path.write_text(text.replace("\n7.0\n", "\n0.0\n"))
    drawing = read_dxf(path)
    ends = sorted((c.start, c.end) for c in drawing.contours)
    assert ends == [((50.0, 50.0), (60.0, 60.0)), ((58.0, 55.0), (55.0, 58.0))]


def test_a_spline_with_a_null_normal_is_read_as_autocad_2007_writes_it(tmp_path: Path) -> None:
    """AutoCAD 2007 writes planar SPLINEs with the normal (0, 0, 0) (bjnortier/dxf's
    splines.dxf); their control points are in world coordinates, so the normal places
    nothing: the spline is read (its ends are its first and last control points, clamped)."""

    def build(msp: Any) -> None:
        spline = msp.add_open_spline([(0, 0), (10, 10), (20, 0), (30, 10)], degree=3)
        spline.dxf.extrusion = (0, 0, -1)  # -1 becomes 0 below: ezdxf writes no null one

    path = write_dxf(tmp_path / "s.dxf", build)
    path.write_text(path.read_text().replace("\n230\n-1.0\n", "\n230\n0.0\n"))
    assert "\n210\n0.0\n220\n0.0\n230\n0.0\n" in path.read_text()
    (contour,) = read_dxf(path).contours
    assert contour.start == (0.0, 0.0) and contour.end == (30.0, 10.0)


def test_an_ellipse_ratio_above_one_is_read_as_the_curve_it_describes(tmp_path: Path) -> None:
    """DXF reference: the ratio is in (0, 1]; dxf-parser's ellipse.dxf has 1.9863 and 4.

    The numbers still give one curve, c + M cos t + ratio · (Z × M) sin t, which viewers
    draw and ezdxf's auditor keeps (it swaps the axes): read as that, with a warning. With
    M = (5, 0) and ratio 2 it is the ellipse x²/25 + y²/100 = 1.
    """

    def build(msp: Any) -> None:
        msp.add_ellipse((0, 0), (5, 0), ratio=0.5)

    path = write_dxf(tmp_path / "e.dxf", build)
    path.write_text(path.read_text().replace("\n 40\n0.5\n", "\n 40\n2.0\n"))
    drawing = read_dxf(path)
    (contour,) = drawing.contours
    assert contour.closed
    assert drawing.bbox() == pytest.approx((-5.0, -10.0, 5.0, 10.0), abs=1e-3)
    for x, y in segment_samples(contour.segments, 8):  # within the 1 µm fit tolerance
        assert math.hypot(x / 5.0, y / 10.0) == pytest.approx(1.0, abs=0.001 / 5.0)
    assert any("1 ELLIPSE(s) with an axis ratio above 1" in w for w in drawing.warnings)


def test_a_negative_arc_radius_is_read_as_autocad_does(tmp_path: Path) -> None:
    # AutoCAD ignores the sign of the radius (as ezdxf's Circle.vertices notes); the arc
    # used to come out on the opposite side of its centre.
    def build(msp: Any) -> None:
        msp.add_arc((0, 0), 5, 0, 90).dxf.radius = -5

    (contour,) = read_dxf(write_dxf(tmp_path / "a.dxf", build)).contours
    (arc,) = contour.segments
    assert arc.start == pytest.approx((5.0, 0.0))
    assert arc.end == pytest.approx((0.0, 5.0), abs=1e-12)


def test_an_ellipse_with_a_null_major_axis_is_skipped_not_an_internal_error(
    tmp_path: Path,
) -> None:
    def build(msp: Any) -> None:
        msp.add_ellipse((0, 0), (5, 0), ratio=0.5)

    path = write_dxf(tmp_path / "e.dxf", _one(build))
    path.write_text(path.read_text().replace("\n 11\n5.0\n", "\n 11\n0.0\n"))
    read = read_dxf(path)
    assert any("skipped 1 ELLIPSE entity (zero size)" in w for w in read.warnings)


def test_a_tiny_bulge_is_a_line_not_a_huge_arc(tmp_path: Path) -> None:
    # sagitta = bulge × chord / 2 = 5e-11 mm: a line; as an arc its radius was 2.5e11 mm
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0, 0, 0, 1e-11), (10, 0, 0, 0, 0)], format="xyseb")

    (contour,) = read_dxf(write_dxf(tmp_path / "b.dxf", build)).contours
    assert type(contour.segments[0]).__name__ == "Line"


_ARC_BLOCK = re.compile(r"G[23] ")


@pytest.mark.parametrize("target", ["grbl", "linuxcnc"])
def test_a_speck_arc_is_cut_as_a_speck_not_as_its_whole_circle(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], target: str
) -> None:
    # An ARC of 0.005° on radius 50 (0.0044 mm; its ends within the 0.01 mm chaining
    # tolerance): an arc block that ends where it starts is a whole circle on the
    # controller, here 100 mm across. The program stays within 0.01 mm of the speck.
    def build(msp: Any) -> None:
        msp.add_arc((100, 100), 50, 0, 0.005)
        msp.add_line((0, 0), (10, 0))

    path = write_dxf(tmp_path / "speck.dxf", build)
    out = tmp_path / "speck.nc"
    assert main(["post", str(path), "-t", target, "-o", str(out)]) == 0
    capsys.readouterr()
    x = y = None
    for line in out.read_text().splitlines():
        words = dict(re.findall(r"([XY])(-?[0-9.]+)", line))
        end = (
            float(words.get("X", 0.0 if x is None else x)),
            float(words.get("Y", 0.0 if y is None else y)),
        )
        if _ARC_BLOCK.match(line):
            assert end != (x, y), f"a whole circle: {line}"
            assert math.dist(end, (150.0, 100.0)) < 0.01
        x, y = end


def test_an_arc_centre_beyond_the_limit_is_refused(tmp_path: Path) -> None:
    # bulge 1e-8 on a 1000 mm chord: sagitta 5 µm, radius 2.5e10 mm, beyond ±1e9 mm
    def build(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0, 0, 0, 1e-8), (1000, 0, 0, 0, 0)], format="xyseb")

    with pytest.raises(InputError, match=r"LWPOLYLINE #\w+ on layer '0': an arc of it has its"):
        read_dxf(write_dxf(tmp_path / "b.dxf", build))


def test_the_bound_is_in_mm_after_units(tmp_path: Path) -> None:
    # 1e7 m = 1e10 mm is beyond ±1e9 mm although 1e7 is a small number
    path = _text_dxf(tmp_path / "m.dxf", header=_insunits(6), x1="1e7")
    with pytest.raises(InputError, match=r"LINE #2A on layer '0': end \(1e\+07, 0, 0\)"):
        read_dxf(path)


def test_an_entity_without_a_layer_is_on_layer_0(tmp_path: Path) -> None:
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4))
    path.write_text(path.read_text().replace("  8\n0\n", ""))
    (contour,) = read_dxf(path).contours
    assert contour.layer == "0"
    (contour,) = read_dxf(path, ImportOptions(layers=("0",))).contours
    assert contour.source == "LINE #2A"


@pytest.mark.parametrize(
    "text",
    [
        "  0\nSECTION\n  2\nHEADER\n  9\n$ACADVER\n",  # cut inside the HEADER
        "  0\nSECTION\n",  # cut after the first tag
        "  0\nSECTION\n  2\n",  # cut inside a tag
    ],
)
def test_a_truncated_dxf_is_an_input_error(tmp_path: Path, text: str) -> None:
    # not: an internal StopIteration from ezdxf's dxf_info
    path = tmp_path / "cut.dxf"
    path.write_text(text)
    with pytest.raises(InputError, match="damaged DXF file") as info:
        read_dxf(path)
    assert "\n" not in str(info.value)


def test_post_of_a_bad_dxf_exits_3_with_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = _text_dxf(tmp_path / "bad.dxf", header=_insunits(4), x0="nan")
    assert main(["post", str(path), "-t", "grbl", "-o", str(tmp_path / "out.nc")]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert err.startswith("camtool: error: ") and "LINE #2A" in err and "start (nan" in err
    assert not (tmp_path / "out.nc").exists()


# ---------------------------------------------------------------------------- recover (item 6)


def test_the_recover_warning_is_one_line_and_inspect_lists_the_repairs(tmp_path: Path) -> None:
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4))
    path.write_text(path.read_text().replace("  0\nEOF\n", ""))  # no EOF: recover mode
    read = import_dxf(path)
    assert read.recovered
    (warning,) = [w for w in read.drawing.warnings if "damaged" in w]
    assert "\n" not in warning and "camtool inspect" in warning


# ---------------------------------------------------------------------------- limits (item 4)


def _laugh_blocks(doc: Any, levels: int, copies: int) -> None:
    """Block ``L{k}`` places ``L{k-1}`` ``copies`` times: ``L{levels}`` is copies**levels LINEs."""
    block = doc.blocks.new("L0")
    block.add_line((0, 0), (1, 1))
    for k in range(1, levels + 1):
        block = doc.blocks.new(f"L{k}")
        for i in range(copies):
            block.add_blockref(f"L{k - 1}", (i, 0))


def _laugh(levels: int, copies: int, *, line: bool = False) -> Callable[[Any], None]:
    """Model space places ``L{levels}`` once (and a LINE of its own with ``line``)."""

    def build(msp: Any) -> None:
        _laugh_blocks(msp.doc, levels, copies)
        msp.add_blockref(f"L{levels}", (0, 0))
        if line:
            msp.add_line((0, 0), (10, 0))

    return build


def _timed(path: Path, options: ImportOptions | None = None) -> tuple[Exception, float]:
    start = time.perf_counter()
    with pytest.raises(InputError) as info:
        read_dxf(path, options)
    return info.value, time.perf_counter() - start


def test_a_block_laugh_is_refused_before_expanding(tmp_path: Path) -> None:
    path = write_dxf(tmp_path / "laugh.dxf", _laugh(30, 10))  # 10^30 LINEs
    error, seconds = _timed(path)
    assert seconds < 5
    assert f"more than {MAX_ENTITIES:,} entities" in str(error)
    assert "--max-entities" in str(error)


def test_a_huge_minsert_grid_is_refused(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        msp.doc.blocks.new("B").add_line((0, 0), (1, 1))
        msp.add_blockref("B", (0, 0)).grid(size=(100_000, 100_000), spacing=(2, 2))

    error, seconds = _timed(write_dxf(tmp_path / "grid.dxf", build))
    assert seconds < 5 and "--max-entities" in str(error)


def _grid(rows: int, columns: int) -> Callable[[Any], None]:
    """A MINSERT of ``rows`` × ``columns`` cells of a block of one LINE, 2 mm apart."""

    def build(msp: Any) -> None:
        msp.doc.blocks.new("B").add_line((0, 0), (1, 0))
        msp.add_blockref("B", (0, 0)).grid(size=(rows, columns), spacing=(2, 2))

    return build


def test_block_references_may_add_a_bounded_number_unless_the_limit_is_given(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # The file holds 2 entities (the MINSERT, the block's LINE); it expands to the MINSERT
    # and its 20 × 20 LINEs: 401, so the references add 399.
    path = write_dxf(tmp_path / "grid.dxf", _grid(20, 20))
    monkeypatch.setattr(options_module, "MAX_EXPANSION", 398)
    error, _ = _timed(path)
    assert "its block references expand the 2 entities the file holds to 401, more than " in (
        str(error)
    )
    assert "allow them with --max-entities 401" in str(error)
    assert len(read_dxf(path, ImportOptions(max_entities=401)).contours) == 400
    monkeypatch.setattr(options_module, "MAX_EXPANSION", 399)
    assert len(read_dxf(path).contours) == 400


def test_a_million_cell_minsert_within_the_travel_is_refused_before_any_cell_is_read(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # 1 000 × 1 000 cells of a 1 mm LINE: a 2 kB file that ezdxf would expand to 10^6
    # entities (gigabytes), under the 5 000 000 of --max-entities.
    import camtool.importers.dxf as dxf_importer

    def never(*args: Any, **kwargs: Any) -> None:
        raise AssertionError("a cell was read")

    monkeypatch.setattr(dxf_importer._Reader, "_item", never)
    error, _ = _timed(write_dxf(tmp_path / "grid.dxf", _grid(1000, 1000)))
    assert "expand the 2 entities the file holds to 1,000,001" in str(error)


def test_the_limit_counts_exactly_and_can_be_raised(tmp_path: Path) -> None:
    # 2^4 = 16 LINEs, + 1 + 2 + 4 + 8 + 16 INSERTs = 47 entities placed
    path = write_dxf(tmp_path / "small.dxf", _laugh(4, 2))
    assert len(read_dxf(path, ImportOptions(max_entities=47)).contours) == 16
    _timed(path, ImportOptions(max_entities=46))


def test_a_block_cycle_with_a_laugh_inside_is_skipped_and_bounded(tmp_path: Path) -> None:
    # A places B and 10 copies of the 10^12 laugh L12; B places A (a cycle); model space
    # places B. Counted with A open, B looked small, and expanding B expanded A's
    # 10^13 entities; blocks on a cycle are now skipped whole, wherever they are placed.
    def build(msp: Any) -> None:
        _laugh_blocks(msp.doc, 12, 10)
        a = msp.doc.blocks.new("A")
        b = msp.doc.blocks.new("B")
        a.add_blockref("B", (0, 0))
        for i in range(10):
            a.add_blockref("L12", (i, 0))
        b.add_blockref("A", (0, 0))
        msp.add_blockref("B", (0, 0))
        msp.add_line((0, 0), (10, 0))

    path = write_dxf(tmp_path / "cycle.dxf", build)
    start = time.perf_counter()
    read = read_dxf(path)
    assert time.perf_counter() - start < 5
    assert len(read.contours) == 1
    assert any("block 'B' contains itself" in w for w in read.warnings)


def test_a_block_on_a_cycle_is_skipped_with_a_warning(tmp_path: Path) -> None:
    def build(msp: Any) -> None:
        a = msp.doc.blocks.new("A")
        b = msp.doc.blocks.new("B")
        a.add_line((0, 0), (1, 0))
        a.add_blockref("B", (0, 0))
        b.add_blockref("A", (0, 0))
        msp.add_blockref("A", (0, 0))
        msp.add_line((0, 0), (10, 0))

    read = read_dxf(write_dxf(tmp_path / "cycle.dxf", build))
    assert len(read.contours) == 1
    assert any("block 'A' contains itself" in w for w in read.warnings)


def test_a_deep_block_chain_does_not_recurse(tmp_path: Path) -> None:
    # more nested blocks than Python's recursion limit: counted without recursion, then
    # the expansion stops at MAX_NESTING with a warning
    depth = sys.getrecursionlimit() + 100
    read = read_dxf(write_dxf(tmp_path / "deep.dxf", _laugh(depth, 1, line=True)))
    assert len(read.contours) == 1
    assert any("nested deeper than 32 levels" in w for w in read.warnings)


def test_max_entities_must_be_positive() -> None:
    with pytest.raises(UsageError, match="--max-entities"):
        ImportOptions(max_entities=0)


# ---------------------------------------------------------------------------- the CLI option


@pytest.mark.parametrize(
    "command",
    [
        ["post", "-t", "grbl", "-o", "{out}/o.nc"],
        ["inspect"],
        ["preview", "-o", "{out}/p.svg"],
        ["batch", "-t", "grbl", "-o", "{out}/b", "-j", "1"],
    ],
)
def test_max_entities_on_every_command_that_reads_drawings(
    tmp_path: Path, command: list[str], capsys: pytest.CaptureFixture[str]
) -> None:
    path = write_dxf(tmp_path / "small.dxf", _laugh(4, 2))  # 47 entities placed
    args = [a.format(out=tmp_path) for a in command]
    args.insert(1, str(path))
    assert main([*args, "--max-entities", "46"]) == 3
    assert "more than 46 entities" in capsys.readouterr().err
    assert main([*args, "--max-entities", "47", *(["--force"] if "batch" in args else [])]) == 0


# ---------------------------------------------------------------------------- found by fuzzing


def test_an_infinite_integer_group_code_is_an_input_error(tmp_path: Path) -> None:
    # not: an internal OverflowError (int(float("inf"))) from ezdxf's tag compiler
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4))
    path.write_text(path.read_text().replace("  8\n0\n", "  8\n0\n 62\ninf\n"))
    with pytest.raises(InputError, match="not a readable DXF file") as info:
        read_dxf(path)
    assert "\n" not in str(info.value)


def test_an_entity_of_an_unknown_type_without_a_layer_is_skipped(tmp_path: Path) -> None:
    # not: an internal DXFAttributeError ("layer" is no attribute of an unknown entity)
    path = _text_dxf(tmp_path / "a.dxf", header=_insunits(4))
    widget = "  0\nWIDGET\n  5\n1F\n 10\n1.0\n 20\n1.0\n"
    path.write_text(path.read_text().replace("  0\nLINE\n", widget + "  0\nLINE\n"))
    read = import_dxf(path)
    assert not read.recovered
    assert len(read.drawing.contours) == 1
    assert ("WIDGET", "0", 1) in read.entity_counts
    assert any("skipped 1 WIDGET entity" in w for w in read.drawing.warnings)


def test_a_curve_too_large_for_the_tolerance_is_refused(tmp_path: Path) -> None:
    # 1e9 mm across within ±1e9 mm, but 1e12 times the 0.001 mm tolerance: fitting it
    # would take minutes; 1e8 times (100 m at 1 µm) is the bound
    def build(msp: Any) -> None:
        msp.add_ellipse((0, 0), (5e8, 0), ratio=0.5)

    start = time.perf_counter()
    with pytest.raises(InputError, match=r"ELLIPSE #\w+ on layer '0': a curve 1e\+09 across"):
        read_dxf(write_dxf(tmp_path / "e.dxf", build))
    assert time.perf_counter() - start < 5


def test_a_reader_bug_on_a_hostile_file_is_an_error_naming_the_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """ezdxf 1.4 raises AttributeError on dxf-parser's blocks.dxf (a VIEWPORT without the
    XDATA it expects); its recover mode then fails on the file's LWPOLYLINE. Both as ezdxf
    raises them here: a message naming the file, not an internal error."""
    import ezdxf
    from ezdxf import recover

    def viewport_bug(name: str) -> None:
        raise AttributeError("'NoneType' object has no attribute 'get_xlist'")

    def recover_fails(name: str) -> None:
        raise ezdxf.DXFStructureError("missing 'AcDbPolyline' subclass in LWPOLYLINE(#3AC)")

    path = write_dxf(tmp_path / "blocks.dxf", lambda msp: msp.add_line((0, 0), (1, 0)))
    monkeypatch.setattr(ezdxf, "readfile", viewport_bug)
    monkeypatch.setattr(recover, "readfile", recover_fails)
    with pytest.raises(InputError, match=r"blocks\.dxf: not a readable DXF file \('NoneType'"):
        read_dxf(path)


def test_an_arc_whose_start_and_end_angles_are_equal_is_a_point_not_a_circle(
    tmp_path: Path,
) -> None:
    # TrueView and BricsCAD draw ARC(45°, 45°) as a point (ezdxf issue 330, whose
    # arc_angle_span_deg gives 0); read by its equal ends it would be a 100 mm circle.
    # 0° to 360° is the whole circle.
    def build(msp: Any) -> None:
        msp.add_arc((100, 100), 50, 45, 45)
        msp.add_arc((10, 10), 5, 0, 360)

    read = read_dxf(write_dxf(tmp_path / "eq.dxf", build))
    (contour,) = read.contours
    (circle,) = contour.segments
    assert circle.centre == (10.0, 10.0) and math.isclose(circle.length, 10 * math.pi)
    assert any("skipped 1 ARC entity (zero length" in w for w in read.warnings)


def test_an_ellipse_whose_start_and_end_parameters_are_equal_is_a_point_not_a_whole_one(
    tmp_path: Path,
) -> None:
    # The same rule for ELLIPSE (ezdxf issue 330 names it with ARC; ezdxf's
    # ellipse_param_span gives 0). A HATCH's ellipse edge is read as an ELLIPSE, and so are
    # the arcs of a block placed with unequal scales: their whole circles stay whole.
    # Parameters 0 to 2π and 1 to 1 + 2π are whole ellipses.
    def build(msp: Any) -> None:
        msp.add_ellipse((100, 100), (50, 0), ratio=0.5, start_param=1.0, end_param=1.0)
        msp.add_ellipse((10, 10), (5, 0), ratio=0.5, start_param=0.0, end_param=math.tau)
        msp.add_ellipse((40, 10), (5, 0), ratio=0.5, start_param=1.0, end_param=1.0 + math.tau)
        hatch = msp.add_hatch()
        hatch.paths.add_edge_path().add_ellipse((100, 0), (5, 0), 0.5, 60, 60)
        block = msp.doc.blocks.new("HOLE")
        block.add_arc((0, 0), 2, 30, 390)
        msp.add_blockref("HOLE", (70, 10), dxfattribs={"xscale": 2, "yscale": 1})

    path = write_dxf(tmp_path / "eq.dxf", build)
    read = read_dxf(path, ImportOptions(hatch_boundaries=True))
    # each contour by its left edge (fitted within 0.001 mm): the two whole ellipses, the
    # arc placed as an ellipse
    assert sorted((round(c.bbox()[0], 2), c.closed) for c in read.contours) == [
        (5.0, True),
        (35.0, True),
        (66.0, True),
    ]
    assert any("skipped 1 ELLIPSE entity (zero length" in w for w in read.warnings)
    assert any("skipped 1 HATCH entity (no boundary path)" in w for w in read.warnings)


def test_an_assertion_in_ezdxf_s_recover_mode_is_a_damaged_file_not_an_internal_error(
    tmp_path: Path,
) -> None:
    # Found by fuzzing samples/part.dxf: a group code "E74" sends the file to recover mode,
    # and a group code 74 made 0 leaves a layout name that is not text, which ezdxf's
    # audit asserts (not: "internal error: AssertionError").
    lines = (Path(__file__).parents[2] / "samples" / "part.dxf").read_text().split("\n")
    assert lines[1740] == " 74" and lines[6274] == " 74"
    lines[1740], lines[6274] = "E74", " 0"
    path = tmp_path / "part.dxf"
    path.write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"not a readable DXF file .*recover mode failed"):
        read_dxf(path)


def test_a_polyline_vertex_without_its_location_is_a_damaged_entity(tmp_path: Path) -> None:
    # Found by fuzzing samples/logo.dxf: a VERTEX whose group code 10 was damaged has no
    # location in ezdxf (not: "internal error: TypeError: 'NoneType' object is not
    # subscriptable" while converting the POLYLINE).
    def build(msp: Any) -> None:
        polyline = msp.add_polyline2d([(0, 0), (10, 0), (10, 10), (0, 10)], close=True)
        polyline.vertices[2].dxf.discard("location")

    with pytest.raises(InputError) as caught:
        read_dxf(write_dxf(tmp_path / "damaged.dxf", build))
    assert "POLYLINE #" in str(caught.value)
    assert "vertex 3 has no location (group codes 10 and 20); the file is damaged" in str(
        caught.value
    )


def test_a_file_whose_model_layout_is_lost_is_refused_naming_it(tmp_path: Path) -> None:
    # Found by fuzzing LibreCAD's library/elektro/connector/c8.dxf (dxflib): its layout
    # dictionary's "Model" entry made to point to handle -99999; ezdxf recovers a document
    # without a model space (not: "internal error: KeyError: 'MODEL'").
    from tests.corpus.conftest import CORPUS

    c8 = CORPUS / "pkg/librecad-data/usr/share/librecad/library/elektro/connector/c8.dxf"
    if not c8.is_file():
        pytest.skip("the corpus is not fetched (python tests/corpus/fetch_corpus.py)")
    text, count = re.subn(r"(\n  3\r?\nModel\r?\n350\r?\n)22(\r?\n)", r"\1-99999\2", c8.read_text())
    assert count == 1
    path = tmp_path / "lost.dxf"
    path.write_text(text)
    with pytest.raises(InputError, match=r"lost\.dxf: no model space \(its \*Model_Space"):
        read_dxf(path)


def test_a_damaged_layout_does_not_stop_the_empty_model_space_message(tmp_path: Path) -> None:
    # Found by fuzzing LibreCAD's library/elektro/coil/L7.dxf: five damaged lines leave
    # ezdxf's recovered document with nothing in model space and a layout whose block
    # record lost its attributes (not: "internal error: AttributeError: 'BlockRecord'
    # object has no attribute 'dxf'" while looking for a drawing in paper space).
    from tests.corpus.conftest import CORPUS

    l7 = CORPUS / "pkg/librecad-data/usr/share/librecad/library/elektro/coil/L7.dxf"
    if not l7.is_file():
        pytest.skip("the corpus is not fetched (python tests/corpus/fetch_corpus.py)")
    lines = l7.read_text().split("\n")
    damage = {
        735: (
            "Center (2x) ________  __  ________  __  _____",
            "Center (2x) ________  __  ______P_  __  _____",
        ),
        748: (" 74", " 360"),
        1122: ("100", "1e308"),
        1192: ("  3", "  0"),
        1544: ("  3", "  -1e308"),
    }
    for k, (was, now) in damage.items():
        assert lines[k] == was
        lines[k] = now
    path = tmp_path / "damaged.dxf"
    path.write_text("\n".join(lines))
    with pytest.raises(InputError, match=r"damaged DXF file .* with nothing left in model space"):
        read_dxf(path)
