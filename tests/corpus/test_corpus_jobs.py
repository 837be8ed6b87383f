"""Every LibreCAD part of the corpus as a job: ``job init``'s job posts on grbl and linuxcnc.

A new user's first run on a real drawing: ``camtool job init PART.dxf``, then ``camtool post
PART.dxf --job`` that job. It must post on GRBL and LinuxCNC with no edit, and LinuxCNC's own
interpreter (``rs274``) must accept the linuxcnc program (with a tool table holding every
tool the job names). The drawings are LibreCAD's parts library (``make corpus``).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.init import initial_job
from camtool.jobs.jobfile import job_from_dict
from camtool.jobs.run import run_job
from camtool.model.errors import InputError
from camtool.post.registry import load_target
from tests.corpus.conftest import (
    CORPUS,
    EMPTY,
    case_id,
    corpus_files,
    load_manifest,
    skip_reason,
)
from tests.corpus.test_rs274 import rs274, rs274_problem

MANIFEST = load_manifest()
FILES = [f for f in corpus_files(MANIFEST) if "librecad" in f and f.endswith(".dxf")]


@pytest.mark.parametrize("rel", FILES or ["<none>"], ids=case_id)
def test_job_init_then_post_on_grbl_and_linuxcnc(rel: str, tmp_path: Path) -> None:
    if MANIFEST is None or not FILES:
        pytest.skip(skip_reason())
    try:
        drawing = read_drawing(CORPUS / rel)
    except InputError as exc:
        assert any(text in str(exc) for text in EMPTY), str(exc)  # nothing to make a job of
        return
    grbl = load_target("grbl")
    data = tomllib.loads(initial_job(drawing, travel_mm=grbl.machine.travel_mm))
    job = job_from_dict(data, source="init.toml")
    run_job(drawing, grbl, job)
    done = run_job(drawing, load_target("linuxcnc"), job)
    if rs274_problem() is not None:
        return
    program = tmp_path / "job.ngc"
    program.write_text(str(done.result.code))
    table = tmp_path / "tool.tbl"
    table.write_text("".join(f"T{t.id} P{t.id} D{t.diameter:g} Z0 ;{t.type}\n" for t in job.tools))
    judged = rs274(program, table)
    assert judged.returncode == 0, judged.stderr[-500:]


def test_openscad_fan_parts_are_cut_and_its_dimensions_are_not() -> None:
    """OpenSCAD's example009 (a fan) keeps one layer per extruded part; ``fan_side_center``
    is a part (its circle is the hub's bore), ``dim`` holds dimension lines. The circles
    come from ezdxf, not from camtool."""
    full = (MANIFEST or {}).get("dxf", {}).get("full", [])
    rel = next((f for f in full if f.endswith("example009.dxf")), None)
    if rel is None:
        pytest.skip(skip_reason())
    import ezdxf

    msp = ezdxf.readfile(CORPUS / rel).modelspace()
    bores = sorted(2 * c.dxf.radius for c in msp.query('CIRCLE[layer=="fan_side_center"]'))
    assert bores == [6.0]
    assert msp.query('LINE[layer=="dim"]')
    drawing = read_drawing(CORPUS / rel)
    grbl = load_target("grbl")
    text = initial_job(drawing, travel_mm=grbl.machine.travel_mm)
    job = job_from_dict(tomllib.loads(text), source="init.toml")
    drills = [op for op in job.operations if op.type == "drill"]
    assert any(
        op.select.layers == ("fan_side_center",) and op.select.diameter == (6.0, 6.0)
        for op in drills
    )
    assert "layer 'dim': construction layer 'dim'" in text
    done = run_job(drawing, grbl, job)
    assert not any("fan_side_center" in w and "construction" in w for w in done.warnings)
