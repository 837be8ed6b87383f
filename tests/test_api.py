"""The public API in ``camtool/__init__.py``: every name imports, nothing heavy up front.

docs/api.md's example runs here as written, and what it produced is checked: the
first move of a Z program rises before it travels, the depth passes are the
requested ones, and the predicted deviation stays within what GRBL's interpolator
allows (see :func:`test_docs_example_posts_and_verifies_plate_for_grbl`).
"""

from __future__ import annotations

import ast
import math
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

import camtool
from camtool.model.program import ArcMove, Linear, Rapid

ROOT = Path(__file__).parents[1]
HEAVY = ("build123d", "OCP", "matplotlib", "numpy", "shapely", "ezdxf")
"""Packages ``import camtool`` must not load (OCCT, plotting, numerics, DXF)."""


def test_every_public_name_imports() -> None:
    assert "__version__" in camtool.__all__
    for name in camtool.__all__:
        assert getattr(camtool, name) is not None, name
    assert set(dir(camtool)) >= set(camtool.__all__)
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        camtool.nothing  # noqa: B018


def _loaded_after(code: str) -> set[str]:
    """Top-level packages loaded by a fresh interpreter after running ``code``."""
    probe = f"{code}\nimport sys\nprint(' '.join(sorted({{m.split('.')[0] for m in sys.modules}})))"
    paths = [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])]  # a checkout's own first
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(paths)}
    proc = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, env=env
    )
    return set(proc.stdout.split())


def test_import_camtool_loads_nothing_heavy() -> None:
    loaded = _loaded_after("import camtool\ncamtool.__version__")
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def test_targets_through_the_api_load_no_occt() -> None:
    loaded = _loaded_after("import camtool\ncamtool.list_targets()\ncamtool.load_target('grbl')")
    assert not loaded & {"build123d", "OCP", "matplotlib"}


def test_listing_targets_loads_no_numpy() -> None:
    # `camtool targets` builds every dialect: the matlab-router one imports numpy on use
    loaded = _loaded_after("import camtool\ncamtool.list_targets()")
    assert not loaded & set(HEAVY), sorted(loaded & set(HEAVY))


def _docs_example() -> dict[str, Any]:
    """Run the python block of docs/api.md from the repository root; its names."""
    text = (ROOT / "docs" / "api.md").read_text(encoding="utf-8")
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    assert len(blocks) == 1
    namespace: dict[str, Any] = {}
    cwd = Path.cwd()
    os.chdir(ROOT)
    try:
        exec(compile(blocks[0], "docs/api.md", "exec"), namespace)
    finally:
        os.chdir(cwd)
    return namespace


def test_docs_example_posts_and_verifies_plate_for_grbl(
    capsys: pytest.CaptureFixture[str],
) -> None:
    ns = _docs_example()
    out = capsys.readouterr().out
    job, target, v = ns["job"], ns["target"], ns["verification"]
    assert isinstance(job, camtool.PostJob) and isinstance(v, camtool.Verification)
    assert "refused: --offset outside needs --tool-diameter" in out

    # The first move rises to the clearance height where the machine stands (Z only),
    # and the code says so before any XY travel.
    first = job.program.moves[0]
    assert isinstance(first, Rapid) and (first.x, first.y) == job.program.origin
    assert first.z == pytest.approx(5.0)  # clearance: max(5 mm, --safe-z 2 mm)
    motion = [line for line in ns["code"].splitlines() if re.match(r"G[0-3] [XYZ]", line)]
    assert motion[:2] == ["G0 Z5.000", "G0 X6.000 Y6.500"]

    # 3 mm in 1 mm passes: cuts at exactly Z -1, -2, -3.
    cut_z = {
        round(m.z, 6)
        for m in job.program.moves
        if isinstance(m, Linear | ArcMove) and m.z is not None and m.z < 0
    }
    assert cut_z == {-1.0, -2.0, -3.0}

    # --offset outside: the tool centre runs one radius (1.5 mm) outside the 40 × 30 mm
    # plate; --origin lower-left: the toolpath's lower-left corner is X0 Y0.
    r = 1.5
    assert job.program.bbox(cutting_only=True) == pytest.approx((0, 0, 40 + 2 * r, 30 + 2 * r))
    assert job.placed.bbox() == pytest.approx((r, r, 40 + r, 30 + r))

    # GRBL cuts arcs as chords within 0.002 mm (its arc_tolerance) and moves in steps
    # of 1/250 mm on each axis: the simulated path leaves the programmed one by at most
    # the chord sagitta plus one step on both axes, and by something (it is stepped).
    machine = target.machine
    step_mm = 1.0 / machine.steps_per_mm[0]
    bound_um = 1000.0 * (machine.motion.chord_tolerance_mm + math.sqrt(2.0) * step_mm)
    assert 0.0 < v.deviation.max_um <= bound_um
    again = camtool.verify_code(ns["code"], target)
    assert again.deviation.max_um == pytest.approx(v.deviation.max_um)
    assert v.time_s > 0 and job.result.blocks > 0


def test_the_type_checking_imports_are_the_public_names() -> None:
    # __all__ derives from _HOMES; the TYPE_CHECKING block must name the same homes
    tree = ast.parse((ROOT / "camtool" / "__init__.py").read_text(encoding="utf-8"))
    block = next(n for n in tree.body if isinstance(n, ast.If))
    seen = {
        alias.name: node.module
        for node in block.body
        if isinstance(node, ast.ImportFrom)
        for alias in node.names
        if alias.asname == alias.name
    }
    assert seen == camtool._HOMES
