"""The SVG importer frees svgelements' XML tree at once, and the CLI's collector thresholds.

svgelements' parse leaves the XML elements it read in reference cycles (its id table holds
``(element, children)`` tuples that point back), so reference counting never frees them;
with the CLI's raised collector thresholds (:data:`camtool.accel.collector.THRESHOLD`) they would
wait for a rare full collection. The importer collects the young generations right after
the parse.
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

import camtool.__main__ as entry
from camtool.accel import collector
from camtool.importers.svg import read_svg

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture
def paused_gc() -> Iterator[None]:
    """The collector paused for the test (only explicit collections run)."""
    enabled = gc.isenabled()
    gc.disable()
    gc.collect()
    try:
        yield
    finally:
        if enabled:
            gc.enable()


def _xml_elements() -> int:
    """Live XML elements the collector tracks."""
    return sum(
        type(o).__name__ == "Element" and "etree" in type(o).__module__ for o in gc.get_objects()
    )


@pytest.mark.usefixtures("paused_gc")
def test_svgelements_really_leaves_cycles() -> None:
    """The premise: after a parse, XML elements stay alive until the collector runs."""
    import io

    import svgelements as se

    data = (DATA / "inkscape-source.svg").read_bytes()
    se.SVG.parse(io.BytesIO(data), reify=False)
    assert _xml_elements() > 0
    gc.collect()
    assert _xml_elements() == 0


@pytest.mark.usefixtures("paused_gc", "accel_on")
def test_reading_an_svg_leaves_no_xml_tree_behind() -> None:
    """With the accel layer's collector thresholds the importer collects the tree itself."""
    drawing = read_svg(DATA / "inkscape-source.svg")
    assert drawing.contours
    assert _xml_elements() == 0


def test_the_console_script_raises_the_collector_thresholds(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``run()`` sets the accel layer's thresholds before the CLI runs (when switched on)."""
    seen: list[tuple[int, int, int]] = []

    def fake_main() -> int:
        seen.append(gc.get_threshold())
        return 3

    monkeypatch.setattr("camtool.cli.main.main", fake_main)
    monkeypatch.setattr(entry, "leave", sys.exit)  # not os._exit: this is pytest's process
    monkeypatch.setenv("CAMTOOL_ACCEL", "1")
    old = gc.get_threshold()
    try:
        with pytest.raises(SystemExit) as exited:
            entry.run()
    finally:
        gc.set_threshold(*old)
    assert seen == [collector.THRESHOLD]
    assert exited.value.code == 3
    assert collector.THRESHOLD[0] > old[0]


def test_switched_off_the_collector_keeps_python_s_thresholds(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    seen: list[tuple[int, int, int]] = []
    monkeypatch.setattr("camtool.cli.main.main", lambda: seen.append(gc.get_threshold()) or 0)
    monkeypatch.setattr(entry, "leave", sys.exit)
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    old = gc.get_threshold()
    with pytest.raises(SystemExit):
        entry.run()
    assert seen == [old]
