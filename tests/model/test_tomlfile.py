"""Values quoted in messages as a TOML file writes them.

The judge is ``tomllib`` (Python's TOML 1.0 reader): a quoted value read back as the value
of a key is the value that was quoted.
"""

from __future__ import annotations

import datetime
import math
import tomllib

import pytest
from hypothesis import given
from hypothesis import strategies as st

from camtool.model.tomlfile import as_toml

_SCALARS = (
    st.booleans()
    | st.integers(min_value=-(2**63), max_value=2**63 - 1)
    | st.floats(allow_nan=False)
    | st.text()
    | st.datetimes(timezones=st.just(datetime.UTC))
    | st.dates()
)
_VALUES = st.recursive(
    _SCALARS,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(st.text(), inner, max_size=4),
    max_leaves=12,
)


@given(_VALUES)
def test_a_quoted_value_reads_back_as_itself(value: object) -> None:
    assert tomllib.loads(f"key = {as_toml(value)}")["key"] == value


@pytest.mark.parametrize(
    ("value", "quoted"),
    [(False, "false"), (["a", "b"], '["a", "b"]'), ("on", '"on"'), ({}, "{}")],
)
def test_values_are_quoted_as_written(value: object, quoted: str) -> None:
    assert as_toml(value) == quoted


def test_nan_is_quoted_as_toml_writes_it() -> None:
    assert math.isnan(tomllib.loads(f"key = {as_toml(math.nan)}")["key"])
    assert as_toml(-math.inf) == "-inf"
