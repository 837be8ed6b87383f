"""Shared pytest options: ``--update-golden`` rewrites the golden files."""

from __future__ import annotations

import gc
import json
from typing import Any

import pytest
from hypothesis import settings

from camtool.cli.main import main

settings.register_profile("camtool", deadline=None)
settings.load_profile("camtool")
"""No property test has a deadline: how fast the machine is never decides a test (under
load, hypothesis's default 200 ms per example failed a DDA property test)."""

_CORPUS_RUNS: list[dict[str, Any]] = []
"""Under pytest-xdist (``make test``): each worker's corpus cases, as it sent them
(tests/corpus/conftest.py, ``pytest_sessionfinish``). Kept here: the controller, which
collects nothing, loads this conftest only."""


@pytest.hookimpl(optionalhook=True)
def pytest_testnodedown(node: Any, error: Any) -> None:
    """A pytest-xdist worker ended: keep the corpus cases it sent."""
    sent = getattr(node, "workeroutput", {}).get("camtool_corpus")
    if sent:
        _CORPUS_RUNS.append(json.loads(sent))


def pytest_terminal_summary(terminalreporter: Any) -> None:
    """Under pytest-xdist, the corpus summary of every worker's cases."""
    if _CORPUS_RUNS:
        from tests.corpus.conftest import print_summary

        print_summary(terminalreporter, _CORPUS_RUNS)


def pytest_collection_finish(session: pytest.Session) -> None:
    """What the collection imported and made is moved out of the cyclic collector's sight.

    A worker holds most of its objects by then (the modules of numba, OpenCASCADE,
    matplotlib, dask), and each full collection a test's allocations trigger walked them
    again. :func:`gc.freeze` leaves them alive and unscanned; what the tests make is
    collected as before (the time it saves: docs/performance.md).
    """
    gc.freeze()


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--update-golden",
        action="store_true",
        help="rewrite tests/golden/* from the current output instead of comparing",
    )


@pytest.fixture
def update_golden(request: pytest.FixtureRequest) -> bool:
    return bool(request.config.getoption("--update-golden"))


@pytest.fixture(autouse=True)
def _progress_quiet(monkeypatch: pytest.MonkeyPatch) -> None:
    """An in-process ``post`` or ``verify`` prints no progress line, however loaded the machine.

    The CLI shows its stages only for a job still running after
    :data:`camtool.cli.progress.AFTER_S` seconds; a test whose job ran that long on a busy
    machine would see lines it did not ask for. tests/cli/test_progress.py sets its own
    threshold where it tests them.
    """
    from camtool.cli import progress

    monkeypatch.setattr(progress, "AFTER_S", 1e9)


@pytest.fixture
def accel_on(monkeypatch: pytest.MonkeyPatch) -> None:
    """The accelerated versions on, whatever the suite runs (``CAMTOOL_ACCEL=0`` in CI's
    second run): for the tests of what only they do (a forked helper, a compiled kernel,
    a streamed trace's bounded memory)."""
    from camtool.accel import SWITCH

    monkeypatch.setenv(SWITCH, "1")


@pytest.fixture
def helpers_on(accel_on: None, monkeypatch: pytest.MonkeyPatch) -> None:
    """The accelerated versions on, and forked helpers allowed wherever the suite runs (one
    core, a worker process): for the tests of a helper's work and of its refusals."""
    from camtool.accel import cores

    monkeypatch.setattr(cores, "default_jobs", lambda: 2)
    monkeypatch.setattr(cores, "in_worker", lambda: False)


@pytest.fixture(params=["accel", "plain"])
def accel(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> bool:
    """Run the test twice: with the accelerated versions, then with ``CAMTOOL_ACCEL=0``.

    For the tests of a piece that :mod:`camtool.accel` speeds up: both ways must give the
    same answer. The value says which way this run is (True: accelerated).
    """
    from camtool.accel import SWITCH

    on = request.param == "accel"
    monkeypatch.setenv(SWITCH, "1" if on else "0")
    return on


FRESH_FIT_FIXTURES = frozenset({"accel_on", "helpers_on", "accel", "fit_kernels_fresh"})
"""Fixtures whose tests start with the compiled curve fitter not loaded, as a new process."""


@pytest.fixture
def fit_kernels_fresh() -> None:
    """The compiled curve fitter not yet loaded, as in a new process (see below)."""


@pytest.fixture(autouse=True)
def _fit_kernels(request: pytest.FixtureRequest) -> None:
    """Each test starts with the compiled curve fitter loaded, as a process that has fitted
    :data:`camtool.geometry.arcfit.KERNEL_FROM` curves; with ``CAMTOOL_ACCEL=0`` (CI's
    second run) every fit is the plain one.

    The fits are the same either way (tests/geometry/test_fit_compiled.py); the compiled
    ones spare the suite's thousands of small drawings the plain fit's time. A test of the
    accelerated versions (``accel_on``, ``helpers_on``, ``accel``) or one that asks for
    ``fit_kernels_fresh`` starts as a new process instead: nothing loaded, nothing counted,
    so its fits go to the pool or a helper as a user's would. Without this fixture, which
    way a test's fits went would depend on the tests run before it.
    """
    from camtool.geometry.arcfit import FIT_KERNELS

    FIT_KERNELS.forget()
    if FRESH_FIT_FIXTURES.isdisjoint(request.fixturenames):
        FIT_KERNELS.get(FIT_KERNELS.threshold)


@pytest.fixture
def run(capsys: pytest.CaptureFixture[str]) -> Any:
    """``run(*args)``: ``camtool ARGS`` in this process, its exit code and stderr."""

    def call(*args: str) -> tuple[int, str]:
        code = main(list(args))
        return code, capsys.readouterr().err

    return call
