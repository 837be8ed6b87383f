"""Loading a comparison's kernels while the plan waits for OpenCASCADE (issue 17).

``comparison_preloads`` must name work only for a drawing whose comparison loads the
compiled search (the count of its samples is the sampler's own), and a job posted while
they run (``post_path(verifying=True)``) must be the job posted without them.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.importers import read_drawing
from camtool.jobs.pipeline import post_path
from camtool.model import cores
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify import metrics

SAMPLES = Path(__file__).resolve().parents[2] / "samples"


@pytest.mark.parametrize("name", ["logo.dxf", "plate.dxf", "pocket.dxf"])
def test_the_preloads_follow_the_drawing_s_sample_count(name: str) -> None:
    drawing = read_drawing(SAMPLES / name)
    samples, _ = metrics._sample_drawing_now(drawing, metrics.AGAINST_SPACING_MM)
    tasks = metrics.comparison_preloads(drawing)
    if len(samples) >= metrics.PREPARE_KERNELS_FROM:  # prepare_comparison loads the kernels
        assert tasks == [metrics.near_kernels, metrics._first_call]
    else:  # the logo (6 911 samples) keeps the k-d tree: nothing to load ahead
        assert tasks == []


def test_the_first_call_loads_the_kernels() -> None:
    pytest.importorskip("numba")
    metrics._first_call()
    assert metrics.near_kernels(0) is not None


def test_a_job_posted_while_preloading_is_the_same_job() -> None:
    target = load_target("grbl")
    plan = PlanOptions(offset="outside", tool_diameter=3.0, depth=3.0, step_down=1.0)
    plain = post_path(SAMPLES / "plate.dxf", target, plan)
    loading = post_path(SAMPLES / "plate.dxf", target, plan, verifying=True)
    assert loading.result.code == plain.result.code
    assert loading.program == plain.program
    assert cores._MEANWHILE == []  # the tasks no wait ran are gone with the job
