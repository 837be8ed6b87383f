"""Fixtures of the CLI tests: the link simulators (tests/link/conftest.py)."""

from tests.link.conftest import simulate  # noqa: F401 (a fixture)
