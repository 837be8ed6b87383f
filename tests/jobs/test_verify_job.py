"""Verifying a job: the whole program, then each operation alone against its own drawing."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.jobfile import load_job
from camtool.jobs.pipeline import report_json, verify_job
from camtool.jobs.run import run_job
from camtool.post.registry import load_target

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def verified() -> object:
    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    job = run_job(drawing, load_target("linuxcnc"), load_job(ROOT / "samples" / "part.toml"))
    return verify_job(job, budget=False)


def test_each_operation_is_compared_with_its_own_drawing_and_tool(verified: object) -> None:
    v = verified
    assert v.against is None and len(v.parts) == 4  # type: ignore[attr-defined]
    labels = [p.label for p in v.parts]  # type: ignore[attr-defined]
    assert labels[0] == "operation 1 (drill 'holes') T2"
    for part in v.parts:  # type: ignore[attr-defined]
        pv = part.verification
        assert pv.against is not None, part.label
        # linuxcnc writes 1 µm and steps 5 µm (200 steps/mm): every cut lies within a few
        # steps of its drawing once each operation is compared with its own tool
        assert pv.against.max_um < 10.0, (part.label, pv.against.max_um)
    drill = v.parts[0].verification  # type: ignore[attr-defined]
    assert drill.tool_diameter == 3.2  # the hole is the drill's diameter about its centre


def test_the_report_has_a_section_per_operation(verified: object) -> None:
    report = json.loads(report_json(verified))  # type: ignore[arg-type]
    ops = report["operations"]
    assert [op["operation"] for op in ops][-1] == "operation 4 (profile outside 'outline') T1"
    assert all(op["against"] is not None and op["time_s"] > 0 for op in ops)
    assert report["max_error_um"] == max(op["max_error_um"] for op in [*ops, report])


def test_the_limit_judges_every_operation(verified: object) -> None:
    worst = max(p.verification.max_error_um for p in verified.parts)  # type: ignore[attr-defined]
    assert verified.over_limit(worst + 0.01) is None  # type: ignore[attr-defined]
    assert verified.over_limit(worst / 2) is not None  # type: ignore[attr-defined]
