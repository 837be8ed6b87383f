"""The C heap's freed pages are returned only with the accelerated versions on."""

from __future__ import annotations

import pytest

from camtool.accel import SWITCH, collector


@pytest.mark.parametrize(("switch", "calls"), [("1", [0]), ("0", [])])
def test_release_free_trims_only_when_switched_on(
    switch: str, calls: list[int], monkeypatch: pytest.MonkeyPatch
) -> None:
    made: list[int] = []
    monkeypatch.setenv(SWITCH, switch)
    monkeypatch.setattr(collector, "_malloc_trim", lambda: made.append)
    collector.release_free()
    assert made == calls


def test_release_free_runs_on_this_c_library() -> None:
    """glibc's malloc_trim where there is one; nothing, and no error, elsewhere."""
    trim = collector._malloc_trim()
    assert trim is None or callable(trim)
    collector.release_free()
