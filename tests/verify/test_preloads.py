"""Loading a comparison's kernels while the plan waits for OpenCASCADE (issue 17).

``comparison_preloads`` must name work only for a drawing whose comparison loads the
compiled search (the count of its samples is the sampler's own), and a job posted while
they run (``post_path(verifying=True)``) must be the job posted without them.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from camtool.accel import cores
from camtool.importers import read_drawing
from camtool.jobs.pipeline import post_path
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify import cutting_thin, deviations, drawing_compare, nearest_search

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

SAMPLES = Path(__file__).resolve().parents[2] / "samples"


@pytest.mark.parametrize("name", ["logo.dxf", "plate.dxf", "pocket.dxf"])
def test_the_preloads_follow_the_drawing_s_sample_count(name: str) -> None:
    drawing = read_drawing(SAMPLES / name)
    samples, _ = drawing_compare._sample_drawing_now(drawing, drawing_compare.AGAINST_SPACING_MM)
    tasks = drawing_compare.comparison_preloads(drawing)
    if len(samples) >= drawing_compare.PREPARE_KERNELS_FROM:  # prepare_comparison loads the kernels
        assert tasks == [
            nearest_search.near_kernels,
            drawing_compare._first_call,
            drawing_compare._load_kernels,
        ]
    else:  # the logo (6 911 samples) keeps the k-d tree: nothing to load ahead
        assert tasks == []


def test_the_first_call_makes_one_call_of_the_kernels(monkeypatch: pytest.MonkeyPatch) -> None:
    """It calls the search's tree builder once, on one point (numba loads its registries
    at a process's first call); without numba it does nothing."""
    import numpy as np

    calls: list[np.ndarray] = []

    class Kernels:
        @staticmethod
        def build(points: np.ndarray) -> None:
            calls.append(points)

    monkeypatch.setattr(nearest_search, "near_kernels", lambda *args: Kernels)
    drawing_compare._first_call()
    assert len(calls) == 1 and calls[0].shape == (1, 2) and calls[0].dtype == np.float64
    monkeypatch.setattr(nearest_search, "near_kernels", lambda *args: None)
    drawing_compare._first_call()
    assert len(calls) == 1


def test_a_job_posted_while_preloading_is_the_same_job() -> None:
    target = load_target("grbl")
    plan = PlanOptions(offset="outside", tool_diameter=3.0, depth=3.0, step_down=1.0)
    plain = post_path(SAMPLES / "plate.dxf", target, plan)
    loading = post_path(SAMPLES / "plate.dxf", target, plan, verifying=True)
    assert loading.result.code == plain.result.code
    assert loading.program == plain.program
    assert cores._MEANWHILE.get() is None  # the tasks no wait ran are gone with the job


def test_point_distances_in_chunks_are_the_whole_answer_bit_for_bit(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Each point's distance is its own, so measuring a few at a time changes no float."""
    import numpy as np

    from camtool.jobs.pipeline import post_drawing

    target = load_target("grbl")
    plan = PlanOptions(offset="outside", tool_diameter=3.0)
    job = post_drawing(read_drawing(SAMPLES / "plate.dxf"), target, plan)
    rng = np.random.default_rng(8)
    blocks = rng.integers(0, len(job.program.moves), size=5000)
    points = rng.uniform(-5.0, 105.0, size=(5000, 2))
    nominal = deviations.nominal_arrays(job.program)
    assert (nominal["kind"][blocks] == 1).any() and (nominal["kind"][blocks] == 0).any()
    whole = deviations.point_distances(points, blocks, nominal)
    monkeypatch.setattr(deviations, "POINT_CHUNK", 7)
    assert deviations.point_distances(points, blocks, nominal).tobytes() == whole.tobytes()


@pytest.mark.parametrize(("offset", "tool"), [("outside", 0.5), ("outside", 3.0), ("on", 0.0)])
def test_the_budget_s_distance_is_the_comparison_s_bit_for_bit(offset: str, tool: float) -> None:
    """``against_worst`` (the budget's figure) is ``against_thinned(...).max_um``.

    On ``make demo``'s plate: cut outside, its tight corners (and with 3 mm a narrow
    slot) are not cut as drawn, so those samples are measured apart in both; cut on
    the line, every sample counts.
    """
    from camtool.jobs.pipeline import post_drawing, verify_job
    from camtool.verify import streamed, trace_sources

    target = load_target("grbl")
    plan = PlanOptions(offset=offset, tool_diameter=tool, depth=1.0)
    job = post_drawing(read_drawing(SAMPLES / "plate.dxf"), target, plan)
    v = verify_job(job, budget=False)
    assert v.drawing is not None and v.against is not None
    thin = cutting_thin.thin_cutting(*streamed.cutting_rows(v.program, v.trace))
    nominal = trace_sources._nominal_lines(v.program) if v.findings else ()
    args = (thin, v.drawing, tool / 2.0)
    full = drawing_compare.against_thinned(*args, nominal=nominal, findings=v.findings)
    assert full.max_um == v.against.max_um
    worst = drawing_compare.against_worst(*args, nominal=nominal, findings=v.findings)
    assert worst == full.max_um
    assert bool(full.not_cut) == (offset == "outside")


LOADED = r"""
import json, os, sys
from pathlib import Path
os.sched_setaffinity(0, {min(os.sched_getaffinity(0))})  # one core: the budget runs here
from numba.core.registry import CPUDispatcher
from camtool.jobs.pipeline import post_path, verify_job
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions
from camtool.verify import cutting_thin, deviations, drawing_compare, nearest_search

kernels = nearest_search.near_kernels()

def loaded():
    return sorted(
        f"{name} {sig}" for name, kernel in vars(kernels).items()
        if isinstance(kernel, CPUDispatcher) for sig in kernel.signatures
    )

before = loaded()
if sys.argv[1] == "warm":
    kernels.load_cached()
warm = loaded()
plan = PlanOptions(offset="outside", tool_diameter=3.0, depth=1.0)
job = post_path(Path(sys.argv[2]), load_target("grbl"), plan)
v = verify_job(job)
v.error_budget  # its sources re-simulated and measured in this process
print(json.dumps({"before": before, "warm": warm, "used": loaded()}))
"""


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity"), reason="Linux")
def test_the_kernels_loaded_ahead_are_those_a_verification_calls() -> None:
    """``load_cached`` loads exactly the kernels and types that verifying a part against its
    drawing calls, its error budget included: none for nothing, and none left for a forked
    worker to load again. Judged by numba's own record of each kernel's signatures."""
    pytest.importorskip("numba")
    plate = str(SAMPLES / "plate.dxf")
    runs = {}
    for mode in ("cold", "warm"):
        out = subprocess.run(
            [sys.executable, "-c", LOADED, mode, plate],
            capture_output=True,
            text=True,
            check=True,
        )
        runs[mode] = json.loads(out.stdout.splitlines()[-1])
    cold, warm = runs["cold"], runs["warm"]
    assert cold["before"] == cold["warm"] == []  # a fresh process: nothing loaded yet
    assert set(warm["warm"]) == set(cold["used"])  # ahead: what the verification calls
    assert warm["used"] == warm["warm"]  # and the verification loads nothing more
