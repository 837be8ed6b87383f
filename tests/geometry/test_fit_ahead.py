"""The compiled fitter loaded ahead in a helper (``fitpool.start_ahead``): the same fits.

The judge is the plain fit made in this process (:func:`fit_key` with the compiled fitter
off), which the compiled fitter equals bit for bit (tests/geometry/test_fit_compiled.py):
the helper may change the speed only. Whatever becomes of the helper (killed before the
curves are sent or while its parts come, stopped, without numba, never used) the fits
must come out the same, and no process may be left behind.
"""

from __future__ import annotations

import os
import signal
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from camtool.accel import cores
from camtool.geometry import fitpool
from camtool.geometry.fitpool import AHEAD_FROM_BYTES, SharedFits, fit_key, fit_shared
from camtool.importers.options import ImportOptions
from camtool.importers.svg import svg_drawing
from tests.geometry.test_fitpool import _keys
from tests.preview.test_ahead import _gone

pytest.importorskip("numba")
pytestmark = [
    pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork (Linux)"),
    pytest.mark.usefixtures("accel_on"),
]


@pytest.fixture(autouse=True)
def _unloaded(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """This process as a new one (the compiled fitter not loaded), on two cores; no helper
    left at the end. A helper is waited for as long as it takes: on a loaded machine its
    numba may take longer to load than the patience a command gives it."""
    monkeypatch.setattr(fitpool, "default_jobs", lambda: 2)
    monkeypatch.setattr(cores, "HELPER_PATIENCE_MIN_S", 3600.0)
    fitpool.FIT_KERNELS.forget()
    try:
        yield
    finally:
        fitpool.stop_ahead()
        fitpool.FIT_KERNELS.forget()


KEYS = _keys(fitpool.MIN_CURVES + 50)
"""Random Béziers and elliptical arcs; each test fits a prefix of them."""


@pytest.fixture(scope="module")
def plain() -> list[Any]:
    """The plain fits of :data:`KEYS`, made in this process."""
    with fitpool.FIT_KERNELS.off():
        return [fit_key(k, 0.01) for k in KEYS]


def _spy(monkeypatch: pytest.MonkeyPatch) -> list[bool]:
    """For each part asked of the helper, whether it came (a fallback to the fits made
    here would hide that none did)."""
    taken: list[bool] = []
    take = fitpool.FITTER.take

    def spy() -> bytes | None:
        part = take()
        taken.append(part is not None)
        return part

    monkeypatch.setattr(fitpool.FITTER, "take", spy)
    return taken


def _shared(keys: list[fitpool.CurveKey]) -> SharedFits:
    fits = SharedFits(0.01)
    for key in keys:
        fits.add(key)
    fits.close()
    return fits


def _started() -> int:
    fitpool.start_ahead(AHEAD_FROM_BYTES)
    helper = fitpool.FITTER.helper
    assert helper is not None and helper.pid is not None
    return helper.pid


def test_the_helper_fits_what_this_process_fits(
    plain: list[Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    taken = _spy(monkeypatch)
    pid = _started()
    counts: list[tuple[int, int]] = []
    assert fit_shared(KEYS, 0.01, done=lambda n, total: counts.append((n, total))) == plain
    assert taken and all(taken)
    assert counts == [(0, len(KEYS))]  # the fits are taken as they are needed
    assert fitpool.FIT_KERNELS.loaded() is None  # numba stayed out of this process
    assert fitpool.FITTER.helper is None and _gone(pid)


def test_copies_of_a_shape_take_its_fit_from_the_helper(monkeypatch: pytest.MonkeyPatch) -> None:
    keys = KEYS[: fitpool.MIN_CURVES]
    moved_copy = ("cubic", tuple((x + 7.5, y - 2.25) for x, y in keys[0][1]))
    taken = _spy(monkeypatch)
    _started()
    fits = fit_shared([*keys, moved_copy], 0.01)
    assert taken and all(taken)
    with fitpool.FIT_KERNELS.off():
        assert fits == fit_shared([*keys, moved_copy], 0.01, jobs=1)


@pytest.mark.parametrize(
    "when", ["before the curves", "between two batches of curves", "after the first part"]
)
def test_a_killed_helper_changes_nothing(
    when: str, plain: list[Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    taken = _spy(monkeypatch)
    pid = _started()
    if when == "before the curves":
        os.kill(pid, signal.SIGKILL)
    fits = SharedFits(0.01)
    for i, key in enumerate(KEYS):
        if when == "between two batches of curves" and i == fitpool._PART + 1:
            os.kill(pid, signal.SIGKILL)  # after the first batch went out
        fits.add(key)
    fits.close()
    first = fits.get(0)
    if when == "after the first part":
        os.kill(pid, signal.SIGKILL)
    assert [first] + [fits.get(i) for i in range(1, len(KEYS))] == plain
    if when == "after the first part":
        assert taken[0]
    elif when == "before the curves":
        assert True not in taken
    # between two batches: the first batch's part may have come before the kill
    assert fitpool.FITTER.helper is None and _gone(pid)


def test_a_helper_stopped_while_its_parts_come_changes_nothing(plain: list[Any]) -> None:
    pid = _started()
    fits = _shared(KEYS)
    first = fits.get(0)
    fitpool.stop_ahead()  # the reader's end, as when it failed on a later shape
    assert _gone(pid)
    assert [first] + [fits.get(i) for i in range(1, len(KEYS))] == plain


def test_a_helper_without_numba_leaves_the_fits_here(plain: list[Any]) -> None:
    with fitpool.FIT_KERNELS.off():  # the helper, forked now, cannot load it either
        pid = _started()
        assert fit_shared(KEYS, 0.01) == plain
    assert _gone(pid)


@pytest.mark.parametrize(
    "why",
    ["small file", "switched off", "one core", "already loaded", "jobs=1"],
)
def test_no_helper_fits_where_it_would_not_pay(
    why: str, plain: list[Any], monkeypatch: pytest.MonkeyPatch
) -> None:
    size = AHEAD_FROM_BYTES - 1 if why == "small file" else AHEAD_FROM_BYTES
    if why == "switched off":
        monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    if why == "one core":
        monkeypatch.setattr(fitpool, "default_jobs", lambda: 1)
    if why == "already loaded":
        assert fitpool.FIT_KERNELS.get(fitpool.KERNEL_FROM) is not None
    fitpool.start_ahead(size)
    started = fitpool.FITTER.helper is not None
    assert started == (why == "jobs=1")
    taken = _spy(monkeypatch)
    keys = KEYS[: fitpool.MIN_CURVES]
    assert fit_shared(keys, 0.01, jobs=1 if why == "jobs=1" else None) == plain[: len(keys)]
    assert taken == []
    fitpool.stop_ahead()
    assert fitpool.FITTER.helper is None


def _big_svg(path: Path, curves: int) -> None:
    """``curves`` cubic Béziers (closed petals, each of its own shape) and a description
    that makes the file big."""
    paths = []
    for i in range(curves):
        x, y, h = 10 + (i % 30) * 6, 10 + (i // 30) * 6, 2 + i / curves
        paths.append(
            f'<path d="M {x} {y} C {x + 1} {y + h} {x + 3.7} {y + 2.1} {x + 4} {y} Z" '
            'fill="none" stroke="black"/>'
        )
    pad = "x" * AHEAD_FROM_BYTES
    path.write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" width="200mm" height="200mm" '
        f'viewBox="0 0 200 200"><desc>{pad}</desc>{"".join(paths)}</svg>'
    )


def test_a_big_svg_reads_the_same_with_the_helper_and_leaves_none(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = tmp_path / "big.svg"
    _big_svg(path, 420)
    assert path.stat().st_size >= AHEAD_FROM_BYTES
    taken = _spy(monkeypatch)
    started: list[int] = []
    start = fitpool.start_ahead

    def spy_start(size: int) -> None:
        start(size)
        helper = fitpool.FITTER.helper
        started.extend([] if helper is None or helper.pid is None else [helper.pid])

    monkeypatch.setattr(fitpool, "start_ahead", spy_start)
    drawing, _ = svg_drawing(path, ImportOptions())
    assert taken and all(taken) and len(started) == 1
    assert fitpool.FITTER.helper is None and _gone(started[0])
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    plain, _ = svg_drawing(path, ImportOptions())
    assert drawing.contours == plain.contours


def test_a_real_svg_over_the_threshold_reads_the_same_with_the_helper(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """LinuxCNC's lathe-macro drawing (334 KB, Inkscape; fetched with ``rs274``)."""
    from tests.corpus.conftest import CORPUS

    path = CORPUS / "pkg/linuxcnc/usr/share/linuxcnc/ncfiles/macros/lathe/LatheMacro.svg"
    if not path.is_file():
        pytest.skip(f"{path} not fetched (python tests/corpus/fetch_corpus.py)")
    assert path.stat().st_size >= AHEAD_FROM_BYTES
    taken = _spy(monkeypatch)
    drawing, tolerance = svg_drawing(path, ImportOptions(fit=(190.0, 190.0)))
    assert taken and all(taken)
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    plain, plain_tolerance = svg_drawing(path, ImportOptions(fit=(190.0, 190.0)))
    assert (drawing.contours, tolerance) == (plain.contours, plain_tolerance)
