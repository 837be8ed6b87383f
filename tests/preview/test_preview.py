"""Previews: layers, colours, exact arcs, tool width, times, the worst point, determinism."""

from __future__ import annotations

import dataclasses
import math
import re
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from camtool.model.errors import UsageError
from camtool.model.machine import Backlash
from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.model.shapes import Contour, Drawing, Line
from camtool.post.registry import load_target
from camtool.preview import CUT_COLOUR, RAPID_COLOUR, program_svg, render_preview
from camtool.preview.layout import zoom_text
from camtool.verify.verifier import Verification, verify_program

NS = "{http://www.w3.org/2000/svg}"
GOLDEN_PNG = Path(__file__).parents[1] / "golden" / "preview-small.png"

# An X reversal of exactly the injected backlash (0.1 mm) while Y travels 2 mm:
# the X motor turns but the carriage stays at X = 4, so the tool leaves the
# programmed diagonal (4, 0) → (3.9, 2) and is farthest from it at the end.
INJECTED_CODE = (
    "G54;\nG90;\nG00X02000.00Y00000.00;\nG01X04000.00Y00000.00F08;\nG01X03900.00Y02000.00F08;\n"
)
INJECTED_LINE = 5  # the diagonal's line in INJECTED_CODE
BACKLASH_UM = 100.0


def _program() -> Program:
    return Program(
        (
            Rapid(1, 1, contour=1),
            Linear(3, 1, 1.0, contour=1),
            ArcMove(1, 1, 2, 1, True, 1.0, contour=1),  # CW half circle back, below the line
            Rapid(5, 5, contour=2),
            ArcMove(5, 5, 6, 5, False, 1.0, contour=2),  # full CCW circle
        )
    )


def _groups(svg: str | bytes) -> dict[str, ET.Element]:
    root = ET.fromstring(svg)
    return {g.get("id", ""): g for g in root.iter() if g.get("id")}


def _injected() -> Verification:
    """The pic-mmh program above on a GMM machine with 100 µm of uncompensated X backlash."""
    target = load_target("pic-mmh")
    program = target.post.parse(INJECTED_CODE, source="injected.pic")
    lash = Backlash(true_um=(BACKLASH_UM, 0.0, 0.0), compensation_um=(0.0, 0.0, 0.0))
    machine = dataclasses.replace(target.machine, backlash=lash)
    return verify_program(program, machine, name="pic-mmh")


def test_layers_colours_and_markers() -> None:
    groups = _groups(program_svg(_program(), work_area=(0, 0, 10, 7), title="t"))
    assert {"cuts", "rapids", "starts", "order", "work-area", "scale-bar", "title"} <= set(groups)
    assert [p.get("stroke") for p in groups["cuts"]] == [CUT_COLOUR]
    rapid = next(iter(groups["rapids"]))
    assert rapid.get("stroke") == RAPID_COLOUR and rapid.get("stroke-dasharray")
    area = next(iter(groups["work-area"]))
    assert (area.get("x"), area.get("y"), area.get("width"), area.get("height")) == (
        "0",
        "-7",
        "10",
        "7",
    )
    assert [t.text for t in groups["order"]] == ["1", "2"]
    assert "t" in [t.text for t in groups["title"]]
    assert "tool-width" not in groups and "trace" not in groups and "drawing" not in groups


def test_arcs_are_exact_svg_arcs_with_the_right_sweep() -> None:
    d = next(iter(_groups(program_svg(_program()))["cuts"])).get("d")
    arcs = re.findall(r"A([\d.]+) [\d.]+ 0 (\d) (\d)", d or "")
    # CW half circle: sweep-flag 1 on the page (Y down); the full circle is two CCW halves.
    assert arcs == [("1", "0", "1"), ("1", "0", "0"), ("1", "0", "0")]


def test_one_start_marker_per_contour_at_its_start() -> None:
    squares = tuple(
        move
        for i, x in enumerate((0.0, 3.0, 6.0))
        for move in (
            Rapid(x, 0.0, contour=i + 1),
            Linear(x + 1, 0.0, 60.0, contour=i + 1),
            Linear(x + 1, 1.0, 60.0, contour=i + 1),
            Linear(x, 0.0, 60.0, contour=i + 1),
        )
    )
    starts = _groups(render_preview(".svg", program=Program(squares)))["starts"]
    dots = [(float(c.get("cx", "")), -float(c.get("cy", ""))) for c in starts.iter(f"{NS}circle")]
    assert dots == [(0.0, 0.0), (3.0, 0.0), (6.0, 0.0)]
    assert len(list(starts.iter(f"{NS}path"))) == 3  # one direction arrow each


def test_direction_arrow_points_along_the_first_cut() -> None:
    up = Program((Linear(0.0, 5.0, 60.0, contour=1),))
    arrow = next(iter(_groups(render_preview(".svg", program=up))["starts"].iter(f"{NS}path")))
    numbers = [float(v) for v in re.findall(r"-?[\d.]+", arrow.get("d", ""))]
    tip_y = max(-y for y in numbers[1::2])
    assert tip_y > 0 and all(abs(x) < 0.2 for x in numbers[0::2])  # it points up the Y axis


def test_tool_width_only_with_an_offset_and_as_wide_as_the_tool() -> None:
    line = Program((Linear(10.0, 0.0, 60.0, contour=1),))
    assert "tool-width" not in _groups(render_preview(".svg", program=line))
    band = _groups(render_preview(".svg", program=line, edge_radius_mm=0.5))["tool-width"]
    path = next(iter(band))
    assert float(path.get("opacity", "1")) < 1  # translucent
    xy = np.array([float(v) for v in re.findall(r"-?[\d.]+", path.get("d", ""))]).reshape(-1, 2)
    x, y = xy[:, 0], xy[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, 1)) - np.dot(y, np.roll(x, 1)))  # shoelace
    # a 10 mm cut swept by a 0.5 mm radius: a 10 x 1 mm band and two half discs
    assert area == pytest.approx(10 * 1.0 + math.pi * 0.25, rel=2e-3)
    assert xy[:, 1].max() == pytest.approx(0.5, abs=1e-3)


def test_title_gives_size_and_time_at_programmed_feeds() -> None:
    line = Program((Linear(10.0, 0.0, 60.0, contour=1), Linear(10.0, 5.0, 60.0, contour=1)))
    texts = [t.text for t in _groups(render_preview(".svg", program=line))["title"]]
    # 15 mm at 60 mm/min = 15 s
    assert texts == ["toolpath 10 × 5 mm, X 0…10 Y 0…5 mm · ≈ 15 s at programmed feeds, cuts only"]


def test_title_time_by_the_pic_mmh_timing_model() -> None:
    # UNAM-GMM S000-17: f = d·F/60 = 7142.857 · 0.8 / 60 = 95.24 Hz, one DDA iteration per
    # step: a 1 mm X line (7143 steps) at F08 takes 7143 / 95.24 = 75.0 s.
    one_mm = Program((Linear(1.0, 0.0, 0.8, contour=1),))
    svg = render_preview(".svg", program=one_mm, target=load_target("pic-mmh"))
    texts = [t.text for t in _groups(svg)["title"]]
    assert texts == [
        "pic-mmh · toolpath 1 × 0 mm, X 0…1 Y 0…0 mm · ≈ 1 min 15 s by the pic-mmh timing model"
    ]


def test_drawing_alone_and_program_over_drawing() -> None:
    square = Drawing(
        (
            Contour(
                (
                    Line((0, 0), (4, 0)),
                    Line((4, 0), (4, 4)),
                    Line((4, 4), (0, 4)),
                    Line((0, 4), (0, 0)),
                ),
                closed=True,
            ),
        )
    )
    alone = _groups(render_preview(".svg", drawing=square))
    assert "drawing" in alone and "cuts" not in alone and "starts" not in alone
    both = _groups(render_preview(".svg", drawing=square, program=_program()))
    assert {"drawing", "cuts", "starts"} <= set(both)


def test_verified_program_has_trace_colour_scale_worst_point_and_inset() -> None:
    v = _injected()
    groups = _groups(render_preview(".svg", verification=v))
    for layer in ("trace", "cuts", "worst", "inset", "inset-trace", "colour-scale", "legend"):
        assert layer in groups, layer
    colours = {p.get("stroke") for p in groups["trace"]}
    assert len(colours) > 3 and CUT_COLOUR not in colours
    ticks = [t.text for t in groups["colour-scale"] if t.text and t.text[0].isdigit()]
    assert ticks[-1] == f"{v.deviation.max_um:.3g}"


def test_worst_point_marker_is_where_the_backlash_left_the_tool() -> None:
    v = _injected()
    steps_per_mm = v.machine.steps_per_mm[0]

    def on_grid(mm: float) -> float:  # where the controller's steps put the carriage
        return round(mm * steps_per_mm) / steps_per_mm

    # The X play (100 µm = 714.3 steps) swallows the whole 0.1 mm X travel (714 steps):
    # the carriage stays at X = 4 while Y reaches 2, farthest from the diagonal at its end.
    at = (on_grid(4.0), on_grid(2.0))
    (ax, ay), (bx, by) = (4.0, 0.0), (3.9, 2.0)
    expected_um = abs((bx - ax) * (at[1] - ay) - (by - ay) * (at[0] - ax)) / math.hypot(
        bx - ax, by - ay
    )
    expected_um *= 1000.0
    assert expected_um == pytest.approx(BACKLASH_UM * 2 / math.hypot(0.1, 2), abs=0.1)
    assert v.deviation.max_um == pytest.approx(expected_um, abs=0.01)
    groups = _groups(render_preview(".svg", verification=v))
    for layer in ("worst", "inset-worst"):
        ring = next(iter(groups[layer].iter(f"{NS}circle")))
        centre = (float(ring.get("cx", "")), -float(ring.get("cy", "")))
        assert centre == pytest.approx(at, abs=1e-4), layer
    label = [t.text for t in groups["worst"].iter(f"{NS}text")]
    assert label == [f"max {expected_um:.2f} µm, line {INJECTED_LINE}"]
    window = next(iter(groups["inset"].iter(f"{NS}svg"))).get("viewBox", "")
    x, y, w, h = (float(s) for s in window.split())
    assert (x + w / 2, -(y + h / 2)) == pytest.approx(at, abs=1e-4)


def test_unknown_ending_and_nothing_to_draw_are_usage_errors() -> None:
    with pytest.raises(UsageError, match=r"\.png or \.svg"):
        render_preview("out.jpg", program=_program())
    with pytest.raises(UsageError, match="nothing to preview"):
        render_preview(".svg", program=Program(()))


def test_same_input_same_svg_bytes() -> None:
    assert program_svg(_program(), title="x") == program_svg(_program(), title="x")
    v = _injected()
    assert render_preview("a.svg", verification=v) == render_preview("b.svg", verification=v)


def test_png_is_stable_and_matches_the_golden(update_golden: bool) -> None:
    from matplotlib.image import imread

    png = render_preview(".png", program=_program(), work_area=(0, 0, 10, 7), width_px=240)
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and b"Software" not in png
    again = render_preview(".png", program=_program(), work_area=(0, 0, 10, 7), width_px=240)
    assert png == again
    if update_golden:
        GOLDEN_PNG.write_bytes(png)
    import io

    now = imread(io.BytesIO(png))
    golden = imread(GOLDEN_PNG)
    assert now.shape == golden.shape
    # Text is rasterised by FreeType: allow small pixel shifts between machines. For scale:
    # leaving out the second contour (a 2 mm circle) makes this 0.0058, a 1.3 mm one 0.0075.
    assert float(np.abs(now[..., :3] - golden[..., :3]).mean()) < 0.002


def _texts(svg: str | bytes, group: str) -> list[str]:
    return ["".join(t.itertext()) for t in _groups(svg)[group].iter(f"{NS}text")]


def test_a_part_under_1_mm_is_labelled_in_um() -> None:
    """A 7-step line on the GMM (7 × 140 nm = 0.98 µm): no "0 × 0.001 mm", no "zoom × 0"."""
    target = load_target("pic-mmh")
    step = 1.0 / target.machine.steps_per_mm[0]
    program = Program((Rapid(1.0, 1.0, contour=1), Linear(1.0 + 7 * step, 1.0, 0.8, contour=1)))
    v = verify_program(program, target.machine, name="pic-mmh")
    svg = render_preview(".svg", verification=v)
    title = " ".join(_texts(svg, "title"))
    # 0.98 µm is written as the shortest decimal within half a step (0.07 µm) of it: 1 µm
    assert "1 × 0 µm" in title and "0.001 mm" not in title
    assert "X 1000…1001 Y 1000…1000 µm" in title
    assert " µm" in " ".join(_texts(svg, "scale-bar"))
    # an inset window wider than the main view (an error larger than the part) zooms out
    assert (zoom_text(0.06), zoom_text(0.5), zoom_text(9.6), zoom_text(48.2)) == (
        "0.06",
        "0.5",
        "9.6",
        "48",
    )


def test_title_names_the_dominant_error_source() -> None:
    svg = render_preview(".svg", verification=_injected())
    title = _texts(svg, "title")
    budget = [line for line in title if line.startswith("error budget:")]
    assert len(budget) == 1 and "dominant backlash residual" in budget[0]
    assert "one source off at a time" in budget[0]
    assert "shortfall along the path" in " ".join(title)
    assert "error budget" not in " ".join(_texts(svg, "legend"))
