"""Point-list importer: CSV/TXT/XY rows and the thesis GUI's Matlab xy matrices (Angel-11 §3)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from camtool.cli.main import main
from camtool.importers import DRAWING_SUFFIXES, read_drawing
from camtool.importers.options import ImportOptions
from camtool.importers.points import holds_rows, read_points
from camtool.model.errors import InputError, UsageError
from camtool.model.shapes import Contour, Line

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"

# Angel-11 §3, "Worked example (verbatim, L3183-L3228)": the star's xy matrix in 0.1 mm
STAR_X = (151, 400, 630, 575, 815, 501, 400, 294, 6, 220, 153)
STAR_Y = (86, 265, 86, 431, 639, 642, 999, 645, 665, 428, 86)
STAR_MM = [(15.1, 8.6), (40.0, 26.5), (63.0, 8.6), (57.5, 43.1), (81.5, 63.9), (50.1, 64.2),
           (40.0, 99.9), (29.4, 64.5), (0.6, 66.5), (22.0, 42.8), (15.3, 8.6)]  # fmt: skip


def vertices(contour: Contour) -> list[tuple[float, float]]:
    assert all(isinstance(s, Line) for s in contour.segments)
    return [contour.start, *(s.end for s in contour.segments)]


def write(tmp_path: Path, name: str, text: str) -> Path:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    return path


# ------------------------------------------------------------------ the thesis star


def test_star_csv_sample_has_the_eleven_thesis_points() -> None:
    # Angel-11 §3: "esta figura consta de 11 puntos (10 líneas)"; xy/10 in mm
    drawing = read_points(ROOT / "samples" / "star.csv")
    assert len(drawing.contours) == 1
    star = drawing.contours[0]
    assert vertices(star) == STAR_MM
    assert [(x / 10, y / 10) for x, y in zip(STAR_X, STAR_Y, strict=True)] == STAR_MM
    assert len(star.segments) == 10
    # Angel-11 §3: "it starts at (151,86) and ends at (153,86)" - not closed
    assert not star.closed
    assert drawing.warnings == ()


def test_star_matlab_text_equals_the_csv() -> None:
    # tests/data/star.m is the thesis's printed xy/lxy/velxy block, verbatim (Angel-11 §3)
    from_m = read_points(DATA / "star.m")
    from_csv = read_points(ROOT / "samples" / "star.csv")
    assert [c.segments for c in from_m.contours] == [c.segments for c in from_csv.contours]
    assert from_m.contours[0].source == "stroke 1 (line 1)"


def test_star_reads_through_read_drawing() -> None:
    for suffix in (".csv", ".txt", ".xy", ".m"):
        assert suffix in DRAWING_SUFFIXES
    assert vertices(read_drawing(ROOT / "samples" / "star.csv").contours[0]) == STAR_MM


# ------------------------------------------------------------------ text rows


@pytest.mark.parametrize(
    "row",
    [
        *("1,2", "1;2", "1\t2", "1 2", "  1 ,  2  ", "1, 2", "1;  2", "1.0, 2.0", "1.0 , 2"),
        *("1,2\t", '"1","2"', '"1";"2"', '" 1 ", "2"'),  # a trailing tab; quoted fields (RFC 4180)
    ],
)
def test_separators(tmp_path: Path, row: str) -> None:
    text = f"{row}\n{row.replace('1', '4').replace('2', '6')}\n"
    drawing = read_points(write(tmp_path, "p.csv", text))
    assert vertices(drawing.contours[0]) == [(1.0, 2.0), (4.0, 6.0)]


def test_header_blank_lines_nan_rows_and_comments_split_strokes(tmp_path: Path) -> None:
    text = (
        "# exported by hand\n"
        "X;Y\n"
        "0;0\n1;0\n\n"  # blank line ends stroke 1
        "5;5\n6;5\nNaN;NaN\n"  # NaN row ends stroke 2
        "0;9\n1;9\nnan\n"
        "\n\n"
    )
    drawing = read_points(write(tmp_path, "p.txt", text))
    assert [vertices(c) for c in drawing.contours] == [
        [(0.0, 0.0), (1.0, 0.0)],
        [(5.0, 5.0), (6.0, 5.0)],
        [(0.0, 9.0), (1.0, 9.0)],
    ]
    assert [c.source for c in drawing.contours] == [
        "stroke 1 (line 3)",
        "stroke 2 (line 6)",
        "stroke 3 (line 9)",
    ]
    assert all(c.layer == "0" for c in drawing.contours)


@pytest.mark.parametrize("brk", ["\u2028", "\u2029", "\x85", "\x0c", "\x0b", "\x1e"])
def test_a_comment_ends_at_its_line_end_only(tmp_path: Path, brk: str) -> None:
    """``str.splitlines`` also breaks a line at these; numpy's ``loadtxt`` (the judge here)
    and Python's own file reading keep them in the comment, and so must the reader: else
    the numbers after one in a ``#`` comment would be a first point to cut from."""
    import numpy as np

    path = write(tmp_path, "p.txt", f"# measured{brk}1 2\n0 0\n10 0\n10 10\n")
    expected = [tuple(row) for row in np.loadtxt(path, encoding="utf-8").tolist()]
    assert expected == [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0)]
    assert [vertices(c) for c in read_points(path).contours] == [expected]


def test_closed_when_last_point_equals_first_and_repeats_dropped(tmp_path: Path) -> None:
    text = "0,0\n10,0\n10,0\n10,10\n0,0\n"
    contour = read_points(write(tmp_path, "sq.xy", text)).contours[0]
    assert contour.closed
    assert vertices(contour) == [(0.0, 0.0), (10.0, 0.0), (10.0, 10.0), (0.0, 0.0)]
    assert contour.signed_area() == pytest.approx(50.0)


@pytest.mark.parametrize(
    ("units", "factor"),
    [(None, 1.0), ("mm", 1.0), ("cm", 10.0), ("in", 25.4), ("um", 0.001), ("0.1mm", 0.1)],
)
def test_units(tmp_path: Path, units: str | None, factor: float) -> None:
    path = write(tmp_path, "p.csv", "0,0\n3,4\n")
    end = read_points(path, ImportOptions(units=units)).contours[0].end
    assert end == pytest.approx((3 * factor, 4 * factor), rel=1e-15)


def test_tenth_mm_is_exact_like_the_decimal_text(tmp_path: Path) -> None:
    # 151 * 0.1 != 15.1 in binary floating point; the importer divides by 10 instead
    path = write(tmp_path, "p.csv", "151,86\n400,265\n")
    contour = read_points(path, ImportOptions(units="0.1mm")).contours[0]
    assert vertices(contour) == [(15.1, 8.6), (40.0, 26.5)]


def test_constant_z_is_dropped_quietly_varying_z_warns(tmp_path: Path) -> None:
    flat = read_points(write(tmp_path, "flat.csv", "0,0,-1\n1,0,-1\n"))
    assert flat.warnings == ()
    assert vertices(flat.contours[0]) == [(0.0, 0.0), (1.0, 0.0)]
    ramp = read_points(write(tmp_path, "ramp.csv", "x,y,z\n0,0,0\n1,0,-0.5\n2,0,-1\n"))
    assert len(ramp.warnings) == 1
    assert "Z varies from -1 to 0" in ramp.warnings[0]
    assert "X and Y only" in ramp.warnings[0]


def test_single_point_stroke_is_skipped_with_a_warning(tmp_path: Path) -> None:
    drawing = read_points(write(tmp_path, "p.csv", "5,5\n\n0,0\n1,1\n"))
    assert len(drawing.contours) == 1
    assert drawing.warnings == (f"{tmp_path / 'p.csv'}: line 1: a stroke of one point was skipped",)


# ------------------------------------------------------------------ text errors


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0,0\n1,x\n", "line 2, column 3: 'x' is not a number"),
        ("x,y\n0,0\nx,y\n", "line 3, column 1: 'x' is not a number"),
        ("0,0\n1,2,3,4\n", "line 2: 4 numbers; rows are X,Y or X,Y,Z"),
        ("0,0\n1\n", "line 2: 1 numbers; rows are X,Y or X,Y,Z"),
        ("0,0\n1,2,3\n", "line 2: 3 numbers where the rows above have 2"),
        ("0,0\n1, NaN\n", "line 2, column 4: NaN in only some columns"),
        ("0,0\ninf,1\n", "line 2, column 1: 'inf' is not a number; infinity is not a"),
        # issue 14: Python's float() takes these; a point list does not
        ("0,0\n1_000,0\n", "line 2, column 1: '1_000' is not a number; write digits without"),
        ("1_000,2_000\n", "line 1, column 1: '1_000' is not a number"),  # not a header
        ("0,0\n 2.5\t-Infinity\n", "line 2, column 6: '-Infinity' is not a number; infinity"),
        ("0,0\n0x10,0\n", "line 2, column 1: '0x10' is not a number; write decimal numbers"),
        # absurd values (1e400 is inf as a float): out of range, naming the column
        ("0,0\n1e308,0\n", "line 2, column 1: '1e308' is out of range (at most 1e+09 mm)"),
        ("0,0\n1,1e400\n", "line 2, column 3: '1e400' is out of range"),
        ("0,0\n1,-1000000000\n", "line 2, column 3: '-1000000000' is out of range"),
        # decimal commas, as a spreadsheet in a German or French locale exports: refused
        ("15,1;8,6\n", "line 1, column 1: '15,1' has a decimal comma"),
        # one decimal comma a row would read as X,Y,Z = (0, 5, 0): a 10 x 0 mm "part"
        ("x;y\n0,5;0\n10,5;0\n10,5;20\n", "line 2, column 1: '0,5' has a decimal comma"),
        ("0\t0\n10\t-2,5\n", "line 2, column 4: '-2,5' has a decimal comma"),
        ("0 0\n10,25 5\n", "line 2, column 1: '10,25' has a decimal comma"),
        ('"0,5";"0"\n', "line 1, column 2: '0,5' has a decimal comma"),
        ('"0","0"\n"0,5","0"\n', "line 2, column 1: '0,5' is not a number; rows are"),
        ('"0,0\n1,1\n', """line 1, column 1: '"0' is not a number"""),  # an unclosed quote
        ("x,y\n\n", "no stroke of two or more points"),
        ("", "no stroke of two or more points"),
        ("3,3\n", "no stroke of two or more points"),
    ],
)
def test_bad_rows_name_file_and_line(tmp_path: Path, text: str, message: str) -> None:
    path = write(tmp_path, "bad.csv", text)
    with pytest.raises(InputError) as err:
        read_points(path)
    assert str(err.value).startswith(f"{path}: ")
    assert message in str(err.value)


@pytest.mark.parametrize(
    ("header", "unit", "mm"),
    [
        ("X (in),Y (in)", "in", 254.0),  # 10 in = 254 mm (25.4 mm to the inch, exactly)
        ("x[cm];y[cm]", "cm", 100.0),
        ("x_in,y_in", "in", 254.0),
        ("X inches,Y", "in", 254.0),
    ],
)
def test_a_header_naming_a_unit_other_than_mm_needs_units(
    tmp_path: Path, header: str, unit: str, mm: float
) -> None:
    """A header that says inches, read in mm, would cut the part 25.4 times too small."""
    path = write(tmp_path, "h.csv", f"{header}\n0,0\n10,0\n10,10\n")
    with pytest.raises(
        InputError, match=f"line 1: the header .* gives the unit {unit}.* give --units {unit}"
    ):
        read_points(path)
    drawing = read_points(path, ImportOptions(units=unit))
    assert vertices(drawing.contours[0])[1] == (pytest.approx(mm, abs=1e-9), 0.0)
    said = read_points(path, ImportOptions(units="mm")).warnings  # the user's word stands
    assert [w for w in said if f"names {unit}; read in --units mm, as asked" in w]


@pytest.mark.parametrize("header", ["x,y", "X (mm),Y (mm)", "x_mm;y_mm", "name,value", "mid,end"])
def test_a_header_in_mm_or_without_a_unit_is_read_as_before(tmp_path: Path, header: str) -> None:
    drawing = read_points(write(tmp_path, "h.csv", f"{header}\n0,0\n10,0\n"))
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.0, 0.0)] and not drawing.warnings


@pytest.mark.parametrize(
    ("text", "columns"),
    [
        # pandas' DataFrame.to_csv writes its index first, under an empty header cell
        (",x,y\n0,0.0,0.0\n1,10.0,0.0\n2,10.0,5.0\n", (2, 3)),
        ("y,x\n0,0\n0,10\n5,10\n", (2, 1)),
        ("id;X (mm);Y (mm)\n1;0;0\n2;10;0\n3;10;5\n", (2, 3)),
    ],
)
def test_a_header_naming_x_and_y_says_which_columns_they_are(
    tmp_path: Path, text: str, columns: tuple[int, int]
) -> None:
    """Read by position, pandas' index was X and the part 2 x 10 mm; by the names, the
    10 x 5 mm rectangle the rows hold."""
    drawing = read_points(write(tmp_path, "p.csv", text))
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0)]
    said = f"X and Y read from columns {columns[0]} and {columns[1]}, as the header names them"
    assert [w for w in drawing.warnings if said in w]


def test_a_third_column_the_header_does_not_name_is_z_as_without_a_header(
    tmp_path: Path,
) -> None:
    drawing = read_points(write(tmp_path, "p.csv", "x,y\n0,0,0\n10,0,1\n10,5,2\n"))
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0)]
    assert [w for w in drawing.warnings if "Z varies from 0 to 2" in w]


def test_a_header_naming_more_columns_than_the_rows_have_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "p.csv", "id,x,y\n0,1\n2,3\n")
    with pytest.raises(InputError, match="line 2: 2 numbers, but the header names X and Y "):
        read_points(path)


@pytest.mark.parametrize(
    ("text", "x_column"),
    [
        # a CMM's or spreadsheet's table: a point id, a name, X, Y, Z, a feed left empty
        ("id,name,x,y,z,feed\n1,P1,0,0,0,100\n2,P2,10,0,0,\n3,,10,5,-1,100\n", 3),
        ("id;X;Y;Z;feed\n1;0;0;0;100\n2;10;0;0;100\n3;10;5;-1;100\n", 2),
        ("id\tx\ty\tz\tfeed\n1\t0\t0\t0\t100\n2\t10\t0\t0\t\n3\t10\t5\t-1\t100\n", 2),
        ("id x y z feed\n1 0 0 0 100\n2 10 0 0 100\n3 10 5 -1 100\n", 2),
    ],
)
def test_a_table_of_more_columns_is_read_by_the_names_of_its_header(
    tmp_path: Path, text: str, x_column: int
) -> None:
    """The header names X, Y and Z among other columns: the rows hold the 10 x 5 mm
    corner (0,0) (10,0) (10,5); columns not named X, Y or Z are not read (text or empty)."""
    drawing = read_points(write(tmp_path, "t.csv", text))
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0)]
    assert [w for w in drawing.warnings if f"from columns {x_column} and {x_column + 1}" in w]
    assert [w for w in drawing.warnings if re.search(r"column\(s\) 'id',.* 'feed' not read", w)]
    assert [w for w in drawing.warnings if "Z varies from -1 to 0" in w]


def test_numpy_s_header_comment_names_the_columns(tmp_path: Path) -> None:
    """numpy.savetxt writes its header as a comment (``# id x y z``), which genfromtxt's
    ``names=True`` reads as the header: so does camtool."""
    np = pytest.importorskip("numpy")
    table = [[1, 0, 0, 0, 100], [2, 10.5, 0, 0, 100], [3, 10.5, 5.25, 0, 100]]
    path = tmp_path / "np.txt"
    np.savetxt(path, np.array(table), header="id x y z feed")
    assert path.read_text().startswith("# id x y z feed\n")
    drawing = read_points(path)
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.5, 0.0), (10.5, 5.25)]
    assert holds_rows(path.read_text())


def test_a_row_of_a_table_without_its_x_or_y_value_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "t.csv", "id,x,y,z,feed\n1,0,0,0,100\n2,,0,0,100\n")
    with pytest.raises(InputError, match="line 3: no value in column 2, which the header names X"):
        read_points(path)


def test_more_than_three_numbers_without_a_header_naming_x_and_y_is_refused(
    tmp_path: Path,
) -> None:
    for text in ("1,0,0,0,100\n2,10,0,0,100\n", "a,b,c,d\n1,0,0,0\n"):
        with pytest.raises(InputError, match=r"line [12]: [45] numbers; .* a header naming the X"):
            read_points(write(tmp_path, "t.csv", text))
    with pytest.raises(InputError, match="line 2: 4 numbers, but the header names 2 columns"):
        read_points(write(tmp_path, "t.csv", "x;y\n1;2;3;4\n"))


@pytest.mark.parametrize("first", ["sep=;", '"sep=;"', "SEP=;"])
def test_excel_s_line_naming_the_separator_is_not_a_row(tmp_path: Path, first: str) -> None:
    """Excel writes ``sep=;`` first so that the CSV opens the same in every locale."""
    drawing = read_points(write(tmp_path, "e.csv", f"{first}\r\nx;y\r\n0;0\r\n10;0\r\n10;5\r\n"))
    assert vertices(drawing.contours[0]) == [(0.0, 0.0), (10.0, 0.0), (10.0, 5.0)]


def test_excel_s_separator_line_naming_a_separator_camtool_does_not_read_is_refused(
    tmp_path: Path,
) -> None:
    path = write(tmp_path, "e.csv", "sep=|\nx|y\n0|0\n10|0\n")
    with pytest.raises(InputError, match=r"line 1: 'sep=\|' names the column separator '\|'"):
        read_points(path)


def test_a_header_of_two_units_is_refused(tmp_path: Path) -> None:
    path = write(tmp_path, "h.csv", "X (mm),Y (in)\n0,0\n10,0\n")
    with pytest.raises(InputError, match="names the units in and mm; camtool reads every column"):
        read_points(path)


def test_unknown_unit_is_a_usage_error_listing_units(tmp_path: Path) -> None:
    path = write(tmp_path, "p.csv", "0,0\n1,1\n")
    with pytest.raises(UsageError, match=r"unknown unit 'furlong'; use one of mm, um, cm"):
        read_points(path, ImportOptions(units="furlong"))


def test_missing_and_binary_files(tmp_path: Path) -> None:
    with pytest.raises(InputError, match="no such file"):
        read_points(tmp_path / "nope.csv")
    binary = tmp_path / "b.csv"
    binary.write_bytes(b"\x00\x81garbage")
    with pytest.raises(InputError, match="not a UTF-8 text file"):
        read_points(binary)
    binary.write_bytes(b"\xff\xfe\x00\x81garbage")  # a UTF-16 mark, then an odd byte count
    with pytest.raises(InputError, match="not a UTF-16-LE text file"):
        read_points(binary)


@pytest.mark.parametrize(
    "encoding", ["utf-16", "utf-16-be", "utf-32", "utf-8-sig", "utf-16-le no mark", "be no mark"]
)
def test_unicode_text_with_a_byte_order_mark(tmp_path: Path, encoding: str) -> None:
    """Excel's "Unicode Text (*.txt)" is UTF-16 LE with a byte-order mark, tab-separated;
    the mark names the encoding (Unicode §23.8), so the points are those of the UTF-8 file.
    Without a mark, ASCII text whose every other byte is a NUL is UTF-16 in that order."""
    text = "x\ty\r\n0\t0\r\n10\t0\r\n10\t5.5\r\n"
    if encoding.endswith("no mark"):
        data = text.encode("utf-16-le" if encoding.startswith("utf-16-le") else "utf-16-be")
    else:
        data = text.encode(encoding)
    if encoding == "utf-16-be":
        data = b"\xfe\xff" + data
    path = tmp_path / "excel.txt"
    path.write_bytes(data)
    (contour,) = read_points(path).contours
    assert [s.start for s in contour.segments] + [contour.end] == [(0, 0), (10, 0), (10, 5.5)]


# ------------------------------------------------------------------ Matlab files


def test_matlab_single_line_commas_comments_and_several_strokes(tmp_path: Path) -> None:
    text = (
        "% two strokes drawn with the thesis GUI\n"
        "xy = [10, 20, 30; 5, 5, 15];\n"
        "lxy = [10 10; 0 10];  % ignored\n"
        "xy = [ 0 10 10 0\n"
        "       0  0 10 0 ];\n"
    )
    drawing = read_points(write(tmp_path, "two.m", text))
    assert [vertices(c) for c in drawing.contours] == [
        [(1.0, 0.5), (2.0, 0.5), (3.0, 1.5)],
        [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 0.0)],
    ]
    assert [c.closed for c in drawing.contours] == [False, True]
    assert [c.source for c in drawing.contours] == ["stroke 1 (line 2)", "stroke 2 (line 4)"]


def test_matlab_units_option_overrides_tenth_mm(tmp_path: Path) -> None:
    path = write(tmp_path, "mm.m", "xy = [1 2; 3 4]\n")
    assert read_points(path, ImportOptions(units="mm")).contours[0].end == (2.0, 4.0)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("n = 10;\n", "line 1: unexpected variable 'n'; camtool reads 'xy'"),
        ("xy = [1 2; 3 4]\nplot(xy)\n", "line 2: expected 'xy = [ x ...; y ... ]', got 'plot(xy)'"),
        ("xy = xy*100;\n", "line 1: expected 'xy = [ x ...; y ... ]'"),
        ("xy = [1 2; 3 4\n", "line 1: expected 'xy = [ x ...; y ... ]'"),
        ("xy = [1 2 3]\n", "line 1: xy has 1 rows; it must have 2"),
        ("\n\nxy = [1 2; 3 4; 5 6]\n", "line 3: xy has 3 rows"),
        ("xy = [1 2 3; 4 5]\n", "xy rows have 3 and 2 numbers"),
        ("xy = [1 a; 3 4]\n", "'a' in xy is not a number"),
        ("xy = [1 NaN; 3 4]\n", "line 1, column 9: 'NaN' in xy is not a number; NaN and Inf"),
        ("xy = [1 2;\n 3 1_0]\n", "line 2, column 4: '1_0' in xy is not a number"),
        ("% c\nxy = [1 2; 3 1e400] % big\n", "line 2, column 14: '1e400' is out of range"),
        ("lxy = [1 2; 3 4]\n", "no 'xy = [ ... ]' matrix"),
        ("% nothing\n", "no 'xy = [ ... ]' matrix"),
    ],
)
def test_matlab_errors(tmp_path: Path, text: str, message: str) -> None:
    path = write(tmp_path, "bad.m", text)
    with pytest.raises(InputError) as err:
        read_points(path)
    assert str(err.value).startswith(f"{path}: ")
    assert message in str(err.value)


def test_limit_applies_in_mm_after_the_unit(tmp_path: Path) -> None:
    # 1 000 000 mm is in range; the same number in metres is 1e9 mm: out of range
    path = write(tmp_path, "p.csv", "0,0\n1000000,1\n")
    assert read_points(path).contours[0].end == (1e6, 1.0)
    with pytest.raises(InputError, match=r"line 2, column 1: '1000000' is out of range"):
        read_points(path, ImportOptions(units="m"))


def test_plain_decimals_and_exponents_still_read(tmp_path: Path) -> None:
    path = write(tmp_path, "p.csv", "x,y\n+1.,-.5\n1e1,2.5E-1\nNAN,nan\n0,0\n3,0\n")
    first, second = read_points(path).contours
    assert vertices(first) == [(1.0, -0.5), (10.0, 0.25)]
    assert vertices(second) == [(0.0, 0.0), (3.0, 0.0)]


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("0,0\n1_000,0\n", "line 2, column 1: '1_000' is not a number"),
        ("0,0\n1e308,0\n", "line 2, column 1: '1e308' is out of range"),
        ("0,0\nnan,1\n", "line 2, column 1: NaN in only some columns"),
        ("0,0\n1,inf\n", "line 2, column 3: 'inf' is not a number"),
    ],
)
def test_cli_exit_3_names_file_line_and_column(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, message: str
) -> None:
    path = write(tmp_path, "p.csv", text)
    assert main(["post", str(path), "-t", "grbl"]) == 3
    out, err = capsys.readouterr()
    assert out == ""
    assert f"camtool: error: {path}: {message}" in err


# How CamBam's programs begin (Universal G-code Sender keeps one as test_files/shapeoko.txt),
# a program without comments, and one with line numbers after the tape mark.
@pytest.mark.parametrize(
    ("text", "line", "shown"),
    [
        (
            "( Made using CamBam - http://www.cambam.co.uk )\n( Untitled )\nG20 G90 G64 G40\n"
            "G0 Z0.125\n",
            3,
            "'G20 G90 G64 G40'",
        ),
        ("G21 G90\nG0 X1 Y1\nG1 X2 F100\n", 1, "'G21 G90'"),
        (
            "\n%\nN10 G0 X1 Y2 Z3 (a long block, cut in the message)\n",
            3,
            "'N10 G0 X1 Y2 Z3 (a long block, cut in th…'",
        ),
    ],
)
def test_a_program_with_a_point_list_ending_is_named_as_one(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, line: int, shown: str
) -> None:
    path = write(tmp_path, "shapeoko.txt", text)
    assert main(["post", str(path), "-t", "grbl", "-o", str(tmp_path / "out.gcode")]) == 3
    err = capsys.readouterr().err
    assert f"camtool: error: {path}: line {line}: {shown} is a G-code block" in err
    assert "save it as shapeoko.nc" in err
    assert not (tmp_path / "out.gcode").exists()


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("x,y\n1,2\nG1,4\n", "line 3, column 1: 'G1' is not a number"),
        # a first row of words is a header: the second row is the bad one
        ("(10.0, 20.0)\n(30.0, 40.0)\n", "line 2, column 1: '(30.0' is not a number"),
    ],
)
def test_a_point_list_with_a_bad_row_keeps_its_own_message(
    tmp_path: Path, text: str, message: str
) -> None:
    path = write(tmp_path, "p.csv", text)
    with pytest.raises(InputError, match=re.escape(message)):
        read_points(path)
