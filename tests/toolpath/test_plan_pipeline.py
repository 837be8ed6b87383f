"""The planner end to end: options a target cannot carry out, arc-fit savings, depth on Z targets.

Stage-level tests live beside this file (test_compensate, test_pocket, test_order,
test_passes); here the stages run together through :func:`camtool.jobs.pipeline.post_drawing`.
"""

from __future__ import annotations

import itertools
import math
from pathlib import Path
from typing import Any

import pytest

from camtool.jobs.pipeline import post_drawing, post_file
from camtool.model.errors import UsageError
from camtool.model.program import ArcMove, Linear, Rapid
from camtool.model.shapes import Arc, Contour, Drawing, Line
from camtool.post.registry import load_target
from camtool.toolpath.plan import MIN_FIT_RUN, PlanOptions, fit_dense, plan_drawing
from tests.shapes import STAR_XY_01MM
from tests.toolpath.contours import rect


def _plate() -> Drawing:
    """A 30 × 20 mm plate with a ø6 mm hole."""
    hole = Contour((Arc((18.0, 10.0), (18.0, 10.0), (15.0, 10.0), False),), True)
    return Drawing((rect(0, 0, 30, 20), hole), "plate").transformed(1.0, 5.0, 5.0)


@pytest.mark.parametrize("target", ["pic-mmh", "matlab-router"])
@pytest.mark.parametrize("option", [{"depth": 1.0}, {"depth": 1.0, "step_down": 0.5}])
def test_2d_targets_refuse_depth_options(target: str, option: dict[str, Any]) -> None:
    # Issue 4 "Depth": for 2D-only targets depth options are a clear error, not ignored.
    with pytest.raises(UsageError, match=r"--depth.*no programmable Z"):
        post_drawing(_plate(), load_target(target), PlanOptions(**option))


def test_depth_sub_options_need_a_depth() -> None:
    with pytest.raises(UsageError, match=r"--step-down.*need"):
        PlanOptions(feed_mm_min=100.0, step_down=0.5)


def test_lead_in_refused_on_a_chord_only_target() -> None:
    with pytest.raises(UsageError, match="--lead-in: i8751 writes arcs as chords"):
        post_drawing(
            _plate(),
            load_target("i8751"),
            PlanOptions(offset="outside", tool_diameter=1.0, lead_in=1.0),
        )


def test_ramp_refused_where_z_has_its_own_block() -> None:
    # flashcut writes "G01 Z…" alone (Yanez-07 R7): it cannot descend along the path.
    with pytest.raises(UsageError, match="--ramp: flashcut moves Z in a block of its own"):
        post_drawing(_plate(), load_target("flashcut"), PlanOptions(depth=0.2, ramp_deg=5.0))


def test_gcode_input_refuses_planning_options(tmp_path: Path) -> None:
    code = tmp_path / "p.ngc"
    code.write_text("G21 G90\nG0 X0 Y0\nG1 X5 Y0 F100\nM2\n")
    with pytest.raises(UsageError, match="--depth, --order only apply to drawings"):
        post_file(code, "grbl", PlanOptions(depth=1.0, order="reversals"))


def test_dense_polyline_becomes_arcs_and_the_saving_is_reported() -> None:
    # A circle of radius 10 drawn as a 360-gon: sagitta 10·(1 − cos 0.5°) = 0.38 µm, well
    # inside the 1 µm tolerance, so a few arcs replace the 360 lines.
    n = 360
    pts = [
        (10 * math.cos(2 * math.pi * k / n), 10 * math.sin(2 * math.pi * k / n)) for k in range(n)
    ]
    gon = Contour(tuple(Line(pts[k], pts[(k + 1) % n]) for k in range(n)), True)
    (fitted,), stats = fit_dense([gon], 0.001)
    assert stats.replaced == n
    marked = Contour(gon.segments, True, "holes", "circle#c", "#ff0000", "DASHED")
    ((refitted,), _) = fit_dense([marked], 0.001)  # what the contour was stays
    assert (refitted.layer, refitted.source, refitted.colour, refitted.linetype) == (
        "holes",
        "circle#c",
        "#ff0000",
        "DASHED",
    )
    assert stats.arcs >= 1 and stats.segments == len(fitted.segments) < 10
    for seg in fitted.segments:
        assert isinstance(seg, Arc) and seg.radius == pytest.approx(10.0, abs=1e-3)
    planned = plan_drawing(Drawing((gon,)), PlanOptions(feed_mm_min=100.0))
    assert planned.report.fit is not None and planned.report.fit.replaced == n
    assert any("arc fitting replaced 360 segments" in line for line in planned.report.notes())
    off = plan_drawing(Drawing((gon,)), PlanOptions(feed_mm_min=100.0, fit_arcs=False))
    assert sum(isinstance(m, Linear) for m in off.program.moves) == n


def test_sharp_polygons_are_not_fitted() -> None:
    # The Angel-11 star (§3, L3196–L3200) keeps its ten straight edges: ten lines are a run
    # long enough to be tried, but every vertex turns far more than the corner angle, and
    # its lxy arrays (L3212–L3228) are golden values of the matlab-router tests.
    xs, ys = STAR_XY_01MM
    pts = [(x / 10.0, y / 10.0) for x, y in zip(xs, ys, strict=True)]
    star = Contour(tuple(Line(a, b) for a, b in itertools.pairwise(pts)), True)
    assert len(star.segments) >= MIN_FIT_RUN
    (fitted,), stats = fit_dense([star], 0.001)
    assert stats.replaced == 0 and fitted.segments == star.segments


def test_grbl_depth_passes_and_tabs_verify(tmp_path: Path) -> None:
    # 1.5 mm deep in 0.5 mm passes (3 levels), 2 tabs on the outside profile, verified on grbl.
    from camtool.jobs.pipeline import verify_job

    job = post_drawing(
        _plate(),
        load_target("grbl"),
        PlanOptions(
            offset="outside",
            tool_diameter=2.0,
            depth=1.5,
            step_down=0.5,
            tabs=2,
            tab_width=3.0,
            tab_height=0.5,
            feed_mm_min=300.0,
        ),
    )
    moves = job.program.moves
    cutting_z = {
        round(m.z, 6) for m in moves if isinstance(m, Linear | ArcMove) and m.z is not None
    }
    assert {-0.5, -1.0, -1.5} <= cutting_z
    assert -1.0 in cutting_z  # the tab top: −1.5 + 0.5
    # rapids at safe Z (2 mm) or at the 5 mm clearance (start, end, between parts)
    assert {m.z for m in moves if isinstance(m, Rapid) and m.z is not None} == {2.0, 5.0}
    from camtool.verify.report import report_dict

    report = report_dict(verify_job(job))
    # Z travel: 2 mm down to the top and 1.5 mm on into the part, and back, at least.
    assert report["steps"]["z"] >= 2 * 3.5 * job.target.machine.steps_per_mm[2]
    assert job.plan is not None
    assert job.plan.to_json()["cuts"] == 2


def test_cli_reports_what_planning_found(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # samples/plate.dxf with a 3 mm tool outside: the notch's two inside corners keep the
    # 1.5 mm tool radius, and the 2 × 2 mm square hole is narrower than the tool.
    import json

    from camtool.cli.main import main

    root = Path(__file__).parents[2]
    report = tmp_path / "r.json"
    args = ["post", str(root / "samples" / "plate.dxf"), "-t", "grbl", "--offset", "outside"]
    args += ["--tool-diameter", "3", "-o", str(tmp_path / "p.gcode"), "--report", str(report)]
    assert main(args) == 0
    err = capsys.readouterr().err
    assert "2 inside corners tighter than the 1.5 mm tool radius" in err
    assert "about 2 mm wide, narrower than the 3 mm tool" in err
    assert "order travel: rapids" in err
    plan = json.loads(report.read_text())["plan"]
    assert plan["counts"] == {"tight-corner": 1, "offset-vanished": 1}
    vanished = next(f for f in plan["findings"] if f["kind"] == "offset-vanished")
    assert vanished["at"] == pytest.approx([9.0, 15.0])
    assert plan["order"]["mode"] == "travel"
