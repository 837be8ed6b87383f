"""A drawing too small for any tool to cut (a unit set wrong) is refused, not cut as a dot.

A 1 × 1 unit square with a circle inside, in a DXF whose ``$INSUNITS`` says µm (13) or
microinches (8), is 0.001 mm or 25.4 nm across (DXF reference, ``$INSUNITS``): its lines lie
within the 0.001 mm tolerance and the 0.01 mm chaining distance of each other, and a program
of it would plunge at one point where a part was drawn.
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path
from typing import Any

import pytest

from camtool.cli.main import main
from tests.shapes import write_dxf


def _part(msp: Any) -> None:
    msp.add_lwpolyline([(0, 0), (1, 0), (1, 1), (0, 1)], close=True)
    msp.add_circle((0.5, 0.5), 0.2)


def _run(*args: str) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            code = main(list(args))
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else 1
    return code or 0, err.getvalue()


@pytest.mark.parametrize(("insunits", "span"), [(13, "0.001 × 0.001"), (8, "2.54e-05 × 2.54e-05")])
def test_a_part_in_micrometres_is_refused_naming_its_span_and_units(
    tmp_path: Path, insunits: int, span: str
) -> None:
    drawing = write_dxf(tmp_path / "part.dxf", _part, insunits=insunits)
    out = tmp_path / "part.nc"
    code, err = _run("post", str(drawing), "-t", "grbl", "-o", str(out))
    assert code == 3 and not out.exists()
    assert f"part.dxf: its cuts span only {span} mm, under 0.02 mm" in err
    assert "$INSUNITS" in err and "--scale" in err and "--tolerance" in err


def test_scaled_fitted_or_at_finer_tolerances_it_is_cut(tmp_path: Path) -> None:
    drawing = write_dxf(tmp_path / "part.dxf", _part, insunits=13)
    for i, extra in enumerate(
        (
            ["--scale", "1000"],
            ["--fit", "10", "10"],
            ["--tolerance", "0.00005", "--chain-tolerance", "0.0001"],
        )
    ):
        out = tmp_path / f"part{i}.nc"
        code, err = _run("post", str(drawing), "-t", "grbl", "-o", str(out), *extra)
        assert code == 0, err
        assert "G1 X" in out.read_text()


def test_a_job_of_it_and_job_init_are_refused_alike(tmp_path: Path) -> None:
    drawing = write_dxf(tmp_path / "part.dxf", _part, insunits=13)
    job = tmp_path / "part.toml"
    code, err = _run("job", "init", str(drawing), "-o", str(job))
    assert code == 3 and not job.exists()
    assert "its cuts span only 0.001 × 0.001 mm" in err
    job.write_text(
        '[[tools]]\nid = 1\ndiameter = 1.0\n\n[[operations]]\ntype = "engrave"\ntool = 1\n'
        "depth = 0.1\n",
        encoding="utf-8",
    )
    code, err = _run(
        "post", str(drawing), "-t", "grbl", "--job", str(job), "-o", str(tmp_path / "o.nc")
    )
    assert code == 3 and "its cuts span only 0.001 × 0.001 mm" in err


def test_a_drawing_of_one_point_to_drill_is_not_refused(tmp_path: Path) -> None:
    """A POINT spans nothing, and is no cut to span: one hole is drilled there."""

    def hole(msp: Any) -> None:
        msp.add_point((20, 20))

    drawing = write_dxf(tmp_path / "hole.dxf", hole)
    job = tmp_path / "hole.toml"
    job.write_text(
        '[[tools]]\nid = 1\ntype = "drill"\ndiameter = 3.0\n\n[[operations]]\ntype = "drill"\n'
        "tool = 1\ndepth = 2\n",
        encoding="utf-8",
    )
    out = tmp_path / "hole.nc"
    code, err = _run("post", str(drawing), "-t", "grbl", "--job", str(job), "-o", str(out))
    assert code == 0, err
    assert "X20.000 Y20.000" in out.read_text()


def test_job_init_drills_no_circle_that_rounds_to_a_0_mm_drill(tmp_path: Path) -> None:
    """A dot drawn as a circle of ø0.4 µm in a part is no hole: no drill of diameter 0."""

    def part(msp: Any) -> None:
        msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True)
        msp.add_circle((10, 10), 0.0002)
        msp.add_circle((20, 10), 1.5)

    drawing = write_dxf(tmp_path / "dot.dxf", part)
    job = tmp_path / "dot.toml"
    code, err = _run("job", "init", str(drawing), "-o", str(job))
    assert code == 0, err
    text = job.read_text()
    assert "diameter = 0 " not in text and "holes 0" not in text
    code, err = _run(
        "post", str(drawing), "-t", "grbl", "--job", str(job), "-o", str(tmp_path / "dot.nc")
    )
    assert code == 0, err
