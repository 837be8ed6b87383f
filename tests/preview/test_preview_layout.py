"""Previews that say what matters: titles, labels that never pile up, round PNG arcs, tabs, zero."""

from __future__ import annotations

import io
import math
import xml.etree.ElementTree as ET
from typing import Any

import numpy as np
import pytest

from camtool.model.program import Linear, Program, Rapid
from camtool.model.shapes import Arc, Contour, Drawing, Line
from camtool.preview import render_preview
from camtool.preview.program_layers import tab_segments
from camtool.preview.raster import scene_png
from camtool.preview.scene import (
    MAX_LABELS,
    Layer,
    Panel,
    Path,
    Rect,
    Scene,
    Style,
    Text,
    place_labels,
    text_box,
)

NS = "{http://www.w3.org/2000/svg}"


def _groups(svg: bytes) -> dict[str, ET.Element]:
    root = ET.fromstring(svg)
    return {g.get("id", ""): g for g in root.iter() if g.get("id")}


def _title(svg: bytes) -> list[str]:
    return [t.text or "" for t in _groups(svg)["title"]]


def _rectangle(x0: float, y0: float, x1: float, y1: float) -> Contour:
    pts = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    return Contour(tuple(Line(a, b) for a, b in zip(pts, [*pts[1:], pts[0]], strict=True)), True)


def test_title_gives_part_size_and_toolpath_extent_apart() -> None:
    # a 100 × 60 mm part cut on its outside with a 3 mm tool: the path is 1.5 mm outside it
    part = Drawing((_rectangle(0.0, 0.0, 100.0, 60.0),))
    corners = [(-1.5, -1.5), (101.5, -1.5), (101.5, 61.5), (-1.5, 61.5), (-1.5, -1.5)]
    path = Program((Rapid(-1.5, -1.5), *(Linear(x, y, 600.0, contour=1) for x, y in corners[1:])))
    title = _title(render_preview(".svg", program=path, drawing=part))
    assert title[0].startswith("part 100 × 60 mm, toolpath X −1.5…101.5 Y −1.5…61.5 mm · ")
    alone = _title(render_preview(".svg", program=path))
    assert alone[0].startswith("toolpath 103 × 63 mm, X −1.5…101.5 Y −1.5…61.5 mm · ")
    drawing_only = _title(render_preview(".svg", drawing=part))
    assert drawing_only == ["part 100 × 60 mm"]


def test_500_labels_are_thinned_and_never_overlap() -> None:
    labels = [Text((0.01 * i, 0.0), str(i + 1), 1.0) for i in range(500)]
    placed = place_labels(labels)
    assert 0 < len(placed) <= MAX_LABELS
    boxes = [text_box(t) for t in placed]
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not (a[0] < b[2] and b[0] < a[2] and a[1] < b[3] and b[1] < a[3])
    assert placed[0].text == "1"  # the first run's number is kept


def test_colliding_labels_are_moved_not_stacked() -> None:
    two = place_labels([Text((0.0, 0.0), "12", 1.0), Text((0.0, 0.0), "13", 1.0)])
    assert [t.text for t in two] == ["12", "13"]
    assert two[0].at != two[1].at


def test_500_contours_show_at_most_max_labels_order_numbers() -> None:
    moves = []
    for i in range(500):
        x, y = float(i % 25) * 2.0, float(i // 25) * 2.0
        moves += [Rapid(x, y), Linear(x + 1.0, y, 100.0, contour=i + 1)]
    svg = render_preview(".svg", program=Program(tuple(moves)))
    numbers = list(_groups(svg)["order"].iter(f"{NS}text"))
    assert 0 < len(numbers) <= MAX_LABELS


@pytest.mark.parametrize(("runs", "marked"), [(40, 40), (MAX_LABELS, MAX_LABELS), (500, 57)])
def test_start_markers_go_where_the_numbers_are(runs: int, marked: int) -> None:
    """Every run's start is marked up to MAX_LABELS runs; past it the numbered ones only.

    (500 runs: every ⌈500/59⌉ = 9th, 56 of them, and the last; the 4 634 runs of a
    213-icon SVG job buried its picture under markers.)
    """
    moves = []
    for i in range(runs):
        x, y = float(i % 25) * 2.0, float(i // 25) * 2.0
        moves += [Rapid(x, y), Linear(x + 1.0, y, 100.0, contour=i + 1)]
    svg = render_preview(".svg", program=Program(tuple(moves)))
    dots = list(_groups(svg)["starts"].iter(f"{NS}circle"))
    assert len(dots) == marked
    numbers = {int(t.text or "0") for t in _groups(svg)["order"].iter(f"{NS}text")}
    centres = {(float(d.get("cx", "nan")), -float(d.get("cy", "nan"))) for d in dots}
    starts = {(float(i % 25) * 2.0, float(i // 25) * 2.0) for i in range(runs)}
    assert centres <= starts
    if runs > MAX_LABELS:  # the numbered runs are the marked ones (numbers are 1-based)
        assert numbers <= {i + 1 for i in range(0, runs, 9)} | {runs}


def test_png_circle_is_round() -> None:
    # A circle of radius 90 mm on a 200 mm page 2000 px wide: 900 px radius. Every inked
    # pixel must lie within half the line (1 px) and a pixel's diagonal of the true circle.
    r, width_px = 90.0, 2000
    page = (-100.0, -100.0, 100.0, 100.0)
    circle = Arc((r, 0.0), (r, 0.0), (0.0, 0.0), False)
    line_mm = 0.1  # 1 px
    layers = (
        Layer("bg", (Rect(page, Style(fill="#ffffff")),)),
        Layer("c", (Path(((circle,),), Style("#000000", line_mm)),)),
    )
    png = scene_png(Scene(page, width_px, (Panel("main", page, page, layers),)))
    from matplotlib.image import imread

    img = imread(io.BytesIO(png))[..., :3].mean(axis=2)
    rows, cols = np.nonzero(img < 0.5)
    px_per_mm = width_px / 200.0
    x = (cols + 0.5) - width_px / 2
    y = (rows + 0.5) - img.shape[0] / 2
    error_px = np.abs(np.hypot(x, y) - r * px_per_mm)
    assert len(rows) > 2 * math.pi * r * px_per_mm * 0.9  # the whole circle is there
    assert float(error_px.max()) <= line_mm * px_per_mm / 2 + math.sqrt(0.5) + 0.05


def _tabbed() -> Program:
    # one run: plunge to -1, a first pass, down to -3, rise to -2.5 over a tab (x 4…6), down
    return Program(
        (
            Rapid(0.0, 0.0, 5.0),
            Linear(0.0, 0.0, 300.0, z=-1.0, contour=1),
            Linear(10.0, 0.0, 300.0, z=-1.0, contour=1),
            Linear(10.0, 0.0, 300.0, z=-3.0, contour=1),
            Linear(6.0, 0.0, 300.0, z=-3.0, contour=1),
            Linear(6.0, 0.0, 300.0, z=-2.5, contour=1),
            Linear(4.0, 0.0, 300.0, z=-2.5, contour=1),
            Linear(4.0, 0.0, 300.0, z=-3.0, contour=1),
            Linear(0.0, 0.0, 300.0, z=-3.0, contour=1),
            Rapid(0.0, 0.0, 5.0),
        )
    )


def test_tab_crossings_are_found_and_drawn() -> None:
    tabs = tab_segments(_tabbed())
    assert [(s.start, s.end) for s in tabs] == [((6.0, 0.0), (4.0, 0.0))]  # not the -1 pass
    groups = _groups(render_preview(".svg", program=_tabbed()))
    assert "tabs" in groups
    assert "tab" in [t.text for t in groups["legend"].iter(f"{NS}text")]


def test_no_tabs_on_a_plain_multi_pass_cut() -> None:
    plain = Program(
        (
            Rapid(0.0, 0.0, 5.0),
            Linear(0.0, 0.0, 300.0, z=-1.0, contour=1),
            Linear(10.0, 0.0, 300.0, z=-1.0, contour=1),
            Linear(10.0, 0.0, 300.0, z=-2.0, contour=1),
            Linear(0.0, 0.0, 300.0, z=-2.0, contour=1),
        )
    )
    assert tab_segments(plain) == []


def test_no_tabs_in_a_v_carve() -> None:
    """A V-carve (Carbide Create's, every move X, Y and Z together) that holds its depth
    for a stretch between deeper moves has no tab: nothing rose onto it by Z alone."""
    carve = Program(
        (
            Rapid(0.0, 0.0, 2.0),
            Linear(0.0, 0.0, 150.0, z=0.0, contour=1),
            Linear(1.0, 1.0, 300.0, z=-0.6, contour=1),
            Linear(2.0, 1.0, 300.0, z=-0.4, contour=1),
            Linear(3.0, 1.0, 300.0, z=-0.4, contour=1),  # at one height, between deeper
            Linear(4.0, 1.0, 300.0, z=-0.7, contour=1),
            Linear(4.0, 1.0, 300.0, z=-0.4, contour=1),  # Z alone up, then a ramp down
            Linear(5.0, 1.0, 300.0, z=-0.4, contour=1),
            Linear(6.0, 2.0, 300.0, z=-0.8, contour=1),
        )
    )
    assert tab_segments(carve) == []


def test_work_zero_is_marked_when_in_view() -> None:
    near = Program((Rapid(1.0, 1.0), Linear(5.0, 1.0, 100.0, contour=1)))
    assert "zero" in _groups(render_preview(".svg", program=near))
    far = Program((Linear(105.0, 100.0, 100.0, contour=1),), origin=(100.0, 100.0))
    assert "zero" not in _groups(render_preview(".svg", program=far))


@pytest.mark.parametrize("suffix", [".svg", ".png"])
def test_not_cut_features_are_marked(suffix: str) -> None:
    from camtool.jobs.pipeline import post_drawing, verify_job
    from camtool.post.registry import load_target
    from camtool.toolpath.options import PlanOptions
    from tests.verify.test_metrics_not_cut import R, plate

    job = post_drawing(
        plate(), load_target("grbl"), PlanOptions(offset="outside", tool_diameter=2 * R)
    )
    v = verify_job(job)
    data = render_preview(suffix, verification=v, drawing=job.placed, edge_radius_mm=R)
    if suffix == ".png":
        assert data[:4] == b"\x89PNG"
        return
    groups = _groups(data)
    labels = sorted(t.text or "" for t in groups["not-cut"].iter(f"{NS}text"))
    assert labels == ["2 mm wide region", "tight corner", "tight corner"]
    title = _title(data)
    assert any("3 features not cut as drawn with this tool (max 12.0 mm)" in t for t in title)


def test_order_numbers_keep_clear_of_the_worst_points_label() -> None:
    # 40 short cuts on a 2 mm grid: their numbers sit by their starts. A box over the
    # middle of the grid (where the worst point's ring and label are drawn) must hold
    # none of them when it is given to keep clear of (each is moved aside, or hidden where
    # no place near its start is free); without it some sit there. The numbers that were
    # clear of it stay.
    from camtool.preview.program_layers import program_layers

    moves = []
    for i in range(40):
        x, y = float(i % 8) * 2.0, float(i // 8) * 2.0
        moves += [Rapid(x, y), Linear(x + 1.0, y, 100.0, contour=i + 1)]
    program = Program(tuple(moves))
    worst = (4.0, 3.0, 12.0, 6.0)

    def numbers(layers: list[Layer]) -> tuple[set[str], set[str]]:
        """The order numbers shown, and those whose box meets ``worst``."""
        order = next(layer for layer in layers if layer.id == "order")
        texts = [t for t in order.shapes if isinstance(t, Text)]
        meets = {
            t.text
            for t in texts
            if (b := text_box(t))[0] < worst[2]
            and worst[0] < b[2]
            and b[1] < worst[3]
            and worst[1] < b[3]
        }
        return {t.text for t in texts}, meets

    shown, meets = numbers(program_layers(program, 0.2))
    assert len(shown) == 40 and meets
    shown_clear, meets_clear = numbers(program_layers(program, 0.2, clear=[worst]))
    assert not meets_clear
    assert shown - meets <= shown_clear


def test_not_cut_labels_keep_clear_of_the_order_numbers_and_the_worst_point() -> None:
    # Five tight corners 3 mm apart along a line: each label is asked for just up and to
    # the right of its diamond. A box over that strip (standing for the worst point's
    # ring and label, or an order number) must hold none of them when it is given to keep
    # clear of; without it every one sits there. Each is moved aside or hidden, never
    # written over it.
    from camtool.preview.trace_layers import not_cut_layer
    from camtool.verify.not_cut import NotCut

    features = [NotCut("tight-corner", (3.0 * k, 0.0), 100.0, 10) for k in range(5)]
    box = (-1.0, 0.05, 16.0, 1.0)

    def meets(layer: Layer) -> int:
        texts = [t for t in layer.shapes if isinstance(t, Text)]
        return sum(
            1
            for t in texts
            if (b := text_box(t))[0] < box[2] and box[0] < b[2] and b[1] < box[3] and box[1] < b[3]
        )

    assert meets(not_cut_layer("not-cut", features, 0.2)) == 5
    clear = not_cut_layer("not-cut", features, 0.2, clear=[box])
    assert meets(clear) == 0
    assert sum(isinstance(s, Text) for s in clear.shapes) == 5  # moved aside, none hidden


def test_the_preview_keeps_its_labels_clear_of_the_worst_point(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # A verified job's picture (the plate with tight corners and a narrow region): the
    # order numbers are placed clear of the worst point's ring, dot and label ("max … µm,
    # line N"), which a number written over it misread; the not-cut labels clear of those
    # and of every order number.
    from camtool.jobs.pipeline import post_drawing, verify_job
    from camtool.post.registry import load_target
    from camtool.preview import program_layers as pl
    from camtool.preview import trace_layers as tl
    from camtool.toolpath.options import PlanOptions
    from tests.verify.test_metrics_not_cut import R, plate

    job = post_drawing(
        plate(), load_target("grbl"), PlanOptions(offset="outside", tool_diameter=2 * R)
    )
    v = verify_job(job)
    asked: dict[str, list[object]] = {"program": [], "not-cut": []}

    def spy(name: str, plain: Any) -> Any:
        def call(*args: object, **kwargs: object) -> object:
            asked[name].append(kwargs.get("clear"))
            return plain(*args, **kwargs)

        return call

    monkeypatch.setattr(pl, "program_layers", spy("program", pl.program_layers))
    monkeypatch.setattr(tl, "not_cut_layer", spy("not-cut", tl.not_cut_layer))
    groups = _groups(render_preview(".svg", verification=v, drawing=job.placed, edge_radius_mm=R))
    (clear,), (clear_too,) = asked["program"], asked["not-cut"]
    wx, wy = v.deviation.at_mm
    assert isinstance(clear, list) and len(clear) == 3  # the ring, its dot, the label
    assert all(b[0] <= wx <= b[2] and b[1] <= wy <= b[3] for b in clear[:2])
    numbers = list(groups["order"].iter(f"{NS}text"))
    assert numbers and isinstance(clear_too, list)
    assert clear_too[:3] == clear and len(clear_too) == 3 + len(numbers)
