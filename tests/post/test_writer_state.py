"""The writer state every dialect writer shares (camtool.post.base.WriterState)."""

from camtool.model.program import Dwell, Home, Spindle
from camtool.post.base import WriterState


def test_where_names_the_contour_and_the_next_block() -> None:
    w: WriterState[str] = WriterState(["G54;", "G90;"])
    assert w.where() == "block 3"
    w.contour = 2
    assert w.where() == "contour 2, block 3"
    assert w.where(0) == "block 3"
    assert w.where(4, 7) == "contour 4, block 7"


def test_warn_says_a_message_once() -> None:
    w: WriterState[str] = WriterState()
    w.warn("feed 101 mm/min rounded")
    w.warn("feed 101 mm/min rounded")
    w.warn("feed 99 mm/min rounded")
    assert w.warnings == ["feed 101 mm/min rounded", "feed 99 mm/min rounded"]


def test_notes_keep_the_first_message_and_count_by_kind() -> None:
    w: WriterState[str] = WriterState()
    w.note("dwell", "block 3: dwell rounded")
    w.note("rpm", "speed rounded")
    w.note("dwell", "block 9: dwell rounded")
    assert w.noted() == ["block 3: dwell rounded (2 times)", "speed rounded"]


def test_dropped_commands_by_class_name_apart_from_other_counts() -> None:
    w: WriterState[str] = WriterState()
    w.drop(Spindle("cw", 1000.0))
    w.drop(Home("XY"))
    w.drop(Dwell(1.0))
    w.drop(Spindle("off"))
    w.counts["tiny"] += 3
    assert w.dropped() == [("Dwell", 1), ("Home", 1), ("Spindle", 2)]


def test_chorded_counts_arcs_chords_and_the_largest_error() -> None:
    w: WriterState[str] = WriterState(here=(1.0, 2.0))
    assert w.here == (1.0, 2.0)
    w.chorded(8, 0.01)
    w.chorded(4, 0.004)
    assert (w.arcs, w.chords, w.chord_error_mm) == (2, 12, 0.01)
