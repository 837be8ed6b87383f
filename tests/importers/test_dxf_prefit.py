"""A drawing's SPLINEs fitted ahead on forked workers read as the ones fitted in order.

The fits made ahead (:mod:`camtool.importers.dxf_prefit`) must be the reader's own: the
same contours (every float), the same warnings for a spline that cannot be fitted, and
the fits of a block's splines (transformed copies) made as they are read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from camtool.importers import dxf, dxf_prefit
from camtool.importers.dxf import import_dxf
from camtool.importers.options import ImportOptions
from tests.shapes import write_dxf


def _splines(msp: Any) -> None:
    rng = np.random.default_rng(11)
    for k in range(90):  # more than MIN_SPLINES, several spans each
        offset = np.array([k % 10 * 30.0, k // 10 * 30.0])
        cps = np.cumsum(rng.uniform(-3, 3, (9, 2)), axis=0) + offset
        msp.add_open_spline([(x, y, 0.0) for x, y in cps], degree=3)
    bad = msp.add_open_spline([(0, 0, 0), (0, 0, 0), (0, 0, 0), (0, 0, 0)], degree=3)
    bad.dxf.layer = "POINTLIKE"  # a spline that is one point: skipped with a warning
    block = msp.doc.blocks.new("CURL")
    block.add_open_spline([(0, 0, 0), (2, 4, 0), (5, -1, 0), (8, 3, 0)], degree=3)
    msp.add_blockref("CURL", (400, 0), dxfattribs={"xscale": 2.0, "rotation": 30})


@pytest.mark.usefixtures("fit_kernels_fresh")  # the splines go to the pool, as a new process's
def test_splines_fitted_ahead_read_as_fitted_in_order(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    path = write_dxf(tmp_path / "curves.dxf", _splines)
    taken: list[bool] = []
    take = dxf_prefit.take

    def counted(entity: Any) -> Any:
        got = take(entity)
        taken.append(got is not None)
        return got

    monkeypatch.setattr("camtool.importers.dxf_entities.take", counted)
    ahead = import_dxf(path, ImportOptions())
    if not any(taken):
        pytest.skip("no pool here (CAMTOOL_ACCEL=0, one core, or a batch worker)")
    assert taken.count(True) == 90  # the model space's splines that fit; not the block's
    monkeypatch.setattr(dxf, "MIN_SPLINES", 10**9)  # every spline fitted as it is read
    taken.clear()
    in_order = import_dxf(path, ImportOptions())
    assert not any(taken)
    assert ahead.drawing.contours == in_order.drawing.contours
    assert ahead.drawing.warnings == in_order.drawing.warnings
    assert any("SPLINE" in w and "skipped 1" in w for w in in_order.drawing.warnings)
    assert len(in_order.drawing.contours) == 91  # 90 and the block's


def test_no_pool_fits_nothing_ahead() -> None:
    assert dxf_prefit.fit_ahead([object()] * 3, 0.01, lambda e, t: ([], False), print) == {}
