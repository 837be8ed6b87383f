"""Big programs drawn at the picture's resolution; titles rounded to the machine; labels kept in.

Memory and cost are checked by what is built (strokes, artists, a step simulation or
none) and by tracemalloc peaks compared with wide margins, never by the clock.
"""

from __future__ import annotations

import math
import tracemalloc
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from camtool.model.program import ArcMove, Linear, Program, Rapid
from camtool.post.registry import load_target
from camtool.preview import layout, render_preview
from camtool.preview.layout import Content, compose
from camtool.preview.program_layers import START_COLOUR, tab_segments
from camtool.preview.raster import scene_figure
from camtool.preview.scene import Scene, Segments
from camtool.preview.thin import DETAIL_MOVES, Strokes

NS = "{http://www.w3.org/2000/svg}"


def _passes(count: int, side: float = 40.0) -> Program:
    """``count`` moves going round one square and one circle again and again (one contour)."""
    moves: list[Rapid | Linear | ArcMove] = [Rapid(0.0, 0.0, contour=1)]
    corners = [(side, 0.0), (side, side), (0.0, side), (0.0, 0.0)]
    k = 0
    while len(moves) < count:
        if k % 5 == 4:
            moves.append(ArcMove(0.0, 0.0, side / 2, 0.0, False, 600.0, contour=1))
        else:
            x, y = corners[k % 5]
            moves.append(Linear(x, y, 600.0, contour=1))
        k += 1
    return Program(tuple(moves[:count]))


def _spiral(count: int, turns: float = 4.0, radius: float = 50.0) -> Program:
    """A spiral of ``count`` short lines: every move in a place of its own.

    About 630 mm long: from 20 000 moves on, each is shorter than a picture's pixel.
    """
    moves: list[Rapid | Linear] = [Rapid(0.0, 0.0, contour=1)]
    for i in range(1, count):
        t = i / count
        a = 2 * math.pi * turns * t
        moves.append(Linear(radius * t * math.cos(a), radius * t * math.sin(a), 600.0, contour=1))
    return Program(tuple(moves))


def _content(program: Program, **kw: object) -> Content:
    base: dict[str, object] = dict(
        program=program,
        drawing=None,
        verification=None,
        work_area=None,
        target_name="",
        time=None,
        edge_radius_mm=0.0,
        title=None,
        width_px=600,
    )
    base.update(kw)
    return Content(**base)  # type: ignore[arg-type]


def _cut_strokes(scene: Scene) -> list[Segments]:
    main = next(p for p in scene.panels if p.id == "main")
    cuts = next(layer for layer in main.layers if layer.id == "cuts")
    return [s for s in cuts.shapes if isinstance(s, Segments)]


# -- thinning ------------------------------------------------------------------------


def test_many_passes_over_one_path_draw_as_one() -> None:
    """4× the passes over the same square and circle: the same strokes, not 4× as many."""
    one = _cut_strokes(compose(_content(_passes(DETAIL_MOVES + 5))))
    four = _cut_strokes(compose(_content(_passes(4 * DETAIL_MOVES))))
    assert len(one) == len(four) == 1
    assert one[0].xy.shape == four[0].xy.shape
    # a 40 mm square and a 40 mm circle at 600 px: a few hundred strokes, not 20 000 moves
    assert len(one[0].xy) < 2_000


def test_strokes_are_bounded_by_the_picture_not_by_the_blocks() -> None:
    """A spiral of distinct moves: strokes grow with the pixels it crosses, not its moves."""
    n = DETAIL_MOVES + 1
    one = _cut_strokes(compose(_content(_spiral(n))))[0].xy
    four = _cut_strokes(compose(_content(_spiral(4 * n))))[0].xy
    assert len(four) < 1.3 * len(one)  # 4× the moves, the same spiral on the same pixels
    cells_across = 2 * 600  # half-pixel cells across the picture
    assert len(four) < cells_across * cells_across / 20


def test_thinned_strokes_stay_within_a_cell_of_the_path() -> None:
    strokes = Strokes(0.5)
    strokes.start((0.1, 0.1))
    strokes.extend([(0.2, 0.1), (10.1, 0.2), (10.1, 10.3)])
    strokes.start((3.0, 3.0))  # a polyline in one cell: a dot
    strokes.extend([(3.1, 3.1)])
    xy = strokes.thinned()
    assert xy.tolist() == [[[0.0, 0.0], [10.0, 0.0]], [[10.0, 0.0], [10.0, 10.5]], [[3.0, 3.0]] * 2]
    assert not xy.flags.writeable


def test_strokes_flush_keeps_every_stroke_once(monkeypatch: pytest.MonkeyPatch) -> None:
    """Thinning in pieces (a small flush size) gives the strokes of thinning at once."""
    from camtool.preview import thin

    def collect() -> list[list[list[float]]]:
        strokes = Strokes(0.25)
        for k in range(30):
            strokes.start((0.0, float(k % 7)))
            strokes.extend([(float(i) * 0.3, float(k % 7) + 0.1 * i) for i in range(1, 40)])
        return sorted(strokes.thinned().tolist())

    whole = collect()
    monkeypatch.setattr(thin, "FLUSH_POINTS", 50)
    assert collect() == whole


def test_a_big_program_has_one_artist_per_layer_in_the_png() -> None:
    scene = compose(_content(_passes(4 * DETAIL_MOVES)))
    fig = scene_figure(scene)
    main = fig.axes[1]  # page first, then the main panel
    assert len(main.collections) <= 4  # rapids, cuts, starts' arrows...
    assert sum(len(c.get_paths()) for c in main.collections) < 3_000


def test_preview_memory_does_not_grow_with_the_program(monkeypatch: pytest.MonkeyPatch) -> None:
    """tracemalloc peak of drawing a program (built beforehand) at N and 4N moves.

    The points held before thinning are bounded by ``FLUSH_POINTS``, made small here so
    that both programs reach the bound, and the programs are drawn as strokes from
    ``DETAIL_MOVES`` = 4 000 moves (20 000 by default): two fifths of a spiral's turn, each
    move a twentieth of a pixel. Drawn move by move (``FLUSH_POINTS`` never reached) the
    peak grows 2.3×; thinned, 1.02×.
    """
    from camtool.preview import program_layers, thin

    monkeypatch.setattr(thin, "FLUSH_POINTS", 1024)
    monkeypatch.setattr(program_layers, "DETAIL_MOVES", 4_000)

    def peak(program: Program) -> int:
        tracemalloc.start()
        try:
            render_preview(".svg", program=program, width_px=300)
            return tracemalloc.get_traced_memory()[1]
        finally:
            tracemalloc.stop()

    small, big = _spiral(4_001, turns=0.4), _spiral(4 * 4_001, turns=0.4)
    peak(small)  # imports and caches first
    assert peak(big) < 1.6 * peak(small)


def test_a_big_program_is_timed_at_its_feeds_not_simulated(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    def simulate(*_: object) -> object:
        raise AssertionError("a picture simulated the steps of a big program")

    monkeypatch.setattr(layout, "machine_time", simulate)
    program = _passes(layout.TIMED_MOVES + 1)
    svg = render_preview(".svg", program=program, target=load_target("grbl"))
    title = " ".join(t.text or "" for t in _groups(svg)["title"])
    assert "at programmed feeds, cuts only" in title and "not simulated" in title


def test_tab_segments_of_one_long_run_match_the_rule() -> None:
    """The linear tab search gives what the rule says on a run with tabs at two heights."""
    moves: list[Rapid | Linear] = [
        Rapid(0.0, 0.0, z=5.0, contour=1),
        Linear(0.0, 0.0, 100.0, z=-3.0, contour=1),
    ]
    x = 0.0
    for k in range(50):
        x += 1.0
        moves.append(Linear(x, 0.0, 100.0, contour=1))  # at -3
        moves.append(Linear(x, 0.0, 100.0, z=-1.0 if k % 2 else -2.0, contour=1))  # up a tab
        x += 1.0
        moves.append(Linear(x, 0.0, 100.0, contour=1))  # across the tab
        moves.append(Linear(x, 0.0, 100.0, z=-3.0, contour=1))  # down again
    tabs = tab_segments(Program(tuple(moves)))
    # each of the 50 tab crossings, and nothing else: the last one too (a cut follows it)
    assert len(tabs) == 50
    assert all(t.end[0] - t.start[0] == 1.0 and t.start[0] % 2 == 1.0 for t in tabs)


# -- titles and labels ---------------------------------------------------------------


def _groups(svg: bytes) -> dict[str, ET.Element]:
    root = ET.fromstring(svg)
    return {g.get("id", ""): g for g in root.iter() if g.get("id")}


def test_title_is_rounded_to_the_machine_resolution() -> None:
    """An extent of −0.001…34.999 mm on GRBL (250 steps/mm: 4 µm) is 0…35 and 35 wide."""
    program = Program(
        (
            Rapid(-0.001, -0.001, contour=1),
            Linear(34.999, -0.001, 600.0, contour=1),
            Linear(34.999, 34.999, 600.0, contour=1),
        )
    )
    svg = render_preview(".svg", program=program, target=load_target("grbl"))
    title = " ".join(t.text or "" for t in _groups(svg)["title"])
    assert "toolpath 35 × 35 mm, X 0…35 Y 0…35 mm" in title
    assert "34.999" not in title and "0.001" not in title and "−0" not in title


def test_title_keeps_digits_the_machine_can_tell_apart() -> None:
    program = Program((Rapid(0.0, 0.0, contour=1), Linear(12.345, 0.5, 600.0, contour=1)))
    svg = render_preview(".svg", program=program, target=load_target("grbl"))
    title = " ".join(t.text or "" for t in _groups(svg)["title"])
    assert "X 0…12.345 Y 0…0.5 mm" in title


def _edge_program() -> Program:
    """Contours close together on the edges of a 60 mm square, numbers on the outside.

    A number goes on the left of the direction of travel: along the top edge going +X
    it is above the edge, along the bottom going −X below it, and so on; neighbours
    2.5 mm apart collide, and a number moved away from its neighbour leaves the picture
    unless it is kept in.
    """
    moves: list[Rapid | Linear] = []
    c = 0
    for i in range(24):
        t = 2.5 * i
        for (x, y), (dx, dy) in (
            ((t, 60.0), (1.0, 0.0)),
            ((60.0 - t, 0.0), (-1.0, 0.0)),
            ((0.0, t), (0.0, -1.0)),
            ((60.0, 60.0 - t), (0.0, 1.0)),
        ):
            c += 1
            moves.append(Rapid(x, y, contour=c))
            moves.append(Linear(x + 0.5 * dx, y + 0.5 * dy, 600.0, contour=c))
    return Program(tuple(moves))


def test_order_numbers_are_inside_the_picture_and_apart() -> None:
    """Measured by matplotlib's renderer on the PNG's own figure, not by camtool's estimate."""
    scene = compose(_content(_edge_program(), width_px=500))
    fig = scene_figure(scene)
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    main = fig.axes[1]
    numbers = [t for t in main.texts if t.get_color() == START_COLOUR]
    assert len(numbers) >= 20
    page = fig.bbox
    frame = main.bbox
    boxes = [t.get_window_extent(renderer) for t in numbers]
    for b in boxes:
        assert page.x0 <= b.x0 and b.x1 <= page.x1 and page.y0 <= b.y0 and b.y1 <= page.y1
        assert frame.x0 - 0.5 <= b.x0 and b.x1 <= frame.x1 + 0.5  # not clipped by its panel
        assert frame.y0 - 0.5 <= b.y0 and b.y1 <= frame.y1 + 0.5
    for i, a in enumerate(boxes):
        for b in boxes[i + 1 :]:
            assert not a.overlaps(b), (a, b)


def test_a_long_preview_tells_its_stages_on_stderr(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Threshold 0 (every job "long"): reading and drawing on stderr; quiet otherwise."""
    from camtool.cli import progress as progress_module
    from camtool.cli.main import main

    code = tmp_path / "part.ngc"
    code.write_text("G21 G90\nG0 X0 Y0\nG1 X10 Y0 F600\nG1 X10 Y10\nM2\n")
    args = ["preview", str(code), "-o", str(tmp_path / "p.svg")]

    def run() -> str:
        assert main(args) == 0
        return capsys.readouterr().err

    quiet = run()
    monkeypatch.setattr(progress_module, "AFTER_S", 0.0)
    told = run()
    stages = [ln for ln in told.splitlines() if ln.endswith("…")]
    assert stages == ["camtool: reading part.ngc…", "camtool: drawing 3 moves…"]
    assert [ln for ln in told.splitlines() if ln not in stages] == quiet.splitlines()
