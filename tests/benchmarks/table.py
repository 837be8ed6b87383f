"""One table of benchmark results against named peers (imported by the ``bench_*.py`` scripts).

Each benchmark script measures camtool and its peer in the same run and calls :func:`row`
once per job. A row is printed to stdout as one line ``BENCH-ROW {json}``;
``tests/benchmarks/run_all.py`` (``make bench``) runs every ``bench_*.py``, collects these
lines and prints them as one table. Run alone, a script prints its own rows the same way.

A ratio is always *camtool's speed over the peer's* (``> 1`` means camtool is faster) or,
for wall times, *camtool's time over the peer's* (``< 1`` means camtool is faster): the
``kind`` field says which, and ``goal`` is the bound the issue sets in the same sense.
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
from pathlib import Path
from typing import Literal

PREFIX = "BENCH-ROW "
"""Start of a result line on stdout."""

Kind = Literal["time", "speed", "absolute"]

ROOT = Path(__file__).resolve().parents[2]

PYCACHE = Path(tempfile.gettempdir()) / "camtool-bench-pycache"
"""Where camtool's bytecode is cached for the benchmarks' runs (``PYTHONPYCACHEPREFIX``)."""


def camtool_env(tree: Path = ROOT, pycache: Path = PYCACHE) -> dict[str, str]:
    """The environment camtool runs in, as a user's: ``tree`` first, from cached bytecode.

    ``PYTHONPATH`` is the tree's root and its ``.pp`` (the target plug-ins). An installed
    camtool runs from bytecode (pip compiles it), and so do its libraries here; a shell with
    ``PYTHONDONTWRITEBYTECODE`` set would compile every camtool module from source on every
    run. That variable is dropped and the bytecode goes to ``pycache``, written by the
    first run (each script times the best of several runs, or makes an untimed one first).
    """
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(tree), str(tree / ".pp")]))
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["PYTHONPYCACHEPREFIX"] = str(pycache)
    return env


def row(
    job: str,
    camtool: str,
    peer: str,
    peer_value: str,
    ratio: float | None,
    kind: Kind,
    goal: str,
    met: bool,
    note: str = "",
) -> None:
    """Print one result line for the collected table.

    Args:
        job: what was run, e.g. ``"SVG → GRBL, 229 Tango icons"``.
        camtool: camtool's figure with its unit, e.g. ``"2.1 s"`` or ``"120 M steps/s"``.
        peer: the peer's name and version, e.g. ``"vpype 1.14.0 + vpype-gcode 0.11"``;
            ``"—"`` when the goal is absolute (a time or memory bound, no peer).
        peer_value: the peer's figure with its unit (``"—"`` when none).
        ratio: camtool over peer (see ``kind``); ``None`` for an absolute goal.
        kind: ``"time"`` (ratio of wall times, smaller is better), ``"speed"`` (ratio of
            rates, larger is better) or ``"absolute"`` (no peer).
        goal: the issue's bound, e.g. ``"≤ 1.0×"``, ``"≥ 0.3×"``, ``"< 3 s, < 300 MB"``.
        met: whether the goal is met in this run.
        note: anything the reader needs (output identical, sizes, …).
    """
    record = {
        "job": job,
        "camtool": camtool,
        "peer": peer,
        "peer_value": peer_value,
        "ratio": ratio,
        "kind": kind,
        "goal": goal,
        "met": bool(met),
        "note": note,
    }
    sys.stdout.write(PREFIX + json.dumps(record, ensure_ascii=False) + "\n")
    sys.stdout.flush()
