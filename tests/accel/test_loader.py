"""A kernel module is imported once the work asked for reaches its threshold, and only then.

The module here is the standard library's ``json`` (any importable module will do): what
is checked is when :class:`~camtool.accel.loader.KernelsOnDemand` answers it.
"""

from __future__ import annotations

import json

import pytest

from camtool.accel.loader import KernelsOnDemand


@pytest.mark.usefixtures("accel_on")
def test_the_module_comes_once_the_work_reaches_the_threshold() -> None:
    kernels = KernelsOnDemand("json", 1000)
    assert kernels.get(400) is None and kernels.get(599) is None  # 999: not yet
    assert kernels.loaded() is None
    assert kernels.get(1) is json  # 1000
    assert kernels.get(0) is json  # then for every caller, whatever it asks
    with kernels.off():
        assert kernels.get(10**9) is None
    assert kernels.get(0) is json
    kernels.forget()
    assert kernels.get(999) is None


@pytest.mark.usefixtures("accel_on")
def test_a_module_that_cannot_be_imported_leaves_the_plain_path() -> None:
    kernels = KernelsOnDemand("camtool.accel.no_such_kernels", 0)
    assert kernels.get(1) is None
    assert kernels.get(1) is None  # tried once, not again


def test_switched_off_nothing_is_loaded(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CAMTOOL_ACCEL", "0")
    kernels = KernelsOnDemand("json", 0)
    assert kernels.get(10**9) is None and kernels.loaded() is None
