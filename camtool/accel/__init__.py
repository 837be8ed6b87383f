"""Speed behind one switch: compiled kernels, forked workers and helpers, collector tuning.

Every stage of camtool has one plain version, the reference that says what it computes.
What only makes a stage faster lives here, and a stage asks :func:`enabled` before it uses
it. ``CAMTOOL_ACCEL=0`` (or ``off``, ``false``, ``no``) in the environment runs every
stage's plain version: the same programs, reports and pictures, only slower. The test
suite runs each accelerated piece both ways (the ``accel`` fixture of tests/conftest.py).
"""

from __future__ import annotations

import os

SWITCH = "CAMTOOL_ACCEL"
"""The environment variable that switches the accelerated versions off."""

_OFF = frozenset({"0", "off", "false", "no"})


def enabled() -> bool:
    """Whether the accelerated versions may run (``CAMTOOL_ACCEL`` is not ``0``/``off``).

    Read from the environment at each call, so a test or an embedding program can switch
    it for one job; a stage asks once per job, not in its inner loops.
    """
    return os.environ.get(SWITCH, "1").strip().lower() not in _OFF
