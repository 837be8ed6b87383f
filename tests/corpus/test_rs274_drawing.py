"""Where LinuxCNC's interpreter moves the tool lies on the curves ezdxf draws: the whole chain.

The corpus DXFs (LibreCAD's parts and symbols, OpenSCAD's examples) that post to linuxcnc or
grbl at the first try, as a new user posts them (``camtool post FILE -t TARGET -o OUT``: the
tool centre on the drawing, work zero at the drawing's origin), are read back by ``rs274``
(test_rs274.py; the grbl dialect writes RS-274 words it reads as GRBL does) and every feed
move is sampled along its line or arc. Each point must lie near the drawing as ezdxf itself
evaluates it (test_dxf_reference.py's reference: its
``ARC``/``CIRCLE``/``ELLIPSE``/``SPLINE`` evaluators, polylines' bulge arcs, blocks exploded),
not as camtool reads it: one judge for reading, chaining, ordering, arc fitting, the
writer's words and its arc check at once. A mirrored OCS arc, a lost block transform, a
G2 written for a G3, a swapped I/J or a misplaced program moves points by far more than
:data:`LIMIT_MM`.

:data:`LIMIT_MM` adds what the program may lawfully differ from the drawing by: the fit's
tolerance (0.001 mm), an arc the controller's check refuses written as chords (within
0.002 mm of it), the 3 decimals (half of 0.001 mm on each axis) and a gap of up to
``--close-gap`` (0.02 mm) closed by a line, whose points lie within half of it of the
drawing; plus the reference's sampling step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from camtool.importers.dxf import import_dxf
from camtool.importers.options import ImportOptions
from tests.corpus.conftest import CORPUS, case_id, corpus_files, load_manifest, outcome_for
from tests.corpus.test_dxf_reference import _reference
from tests.corpus.test_rs274 import arc_points, canon_moves, needs_rs274, rs274

MANIFEST = load_manifest()
DXF = [f for f in corpus_files(MANIFEST) if f.lower().endswith(".dxf")]
STEP_MM = 0.002
"""Spacing of the points sampled along the reference and along each feed move, mm."""
LIMIT_MM = 0.001 + 0.002 + 0.0005 * math.sqrt(2) + 0.01 + STEP_MM
"""Farthest a fed point may lie from the drawing (see the module), mm: about 0.016."""


def fed_points(stdout: str) -> np.ndarray:
    """``(N, 2)`` points along rs274's feed moves (lines and arcs), mm, sampled every STEP_MM."""
    pts: list[tuple[float, float]] = []
    here: tuple[float, float] | None = None
    for kind, v in canon_moves(stdout):
        end = (v[0], v[1])
        if here is not None and kind == "arc":
            pts.extend(arc_points(here, end, (v[2], v[3]), v[4], STEP_MM))
        elif here is not None and kind == "line":
            n = max(1, int(math.dist(here, end) / STEP_MM))
            for t in np.linspace(0.0, 1.0, n + 1):
                pts.append((here[0] + (end[0] - here[0]) * t, here[1] + (end[1] - here[1]) * t))
        here = end
    return np.array(pts).reshape(-1, 2)


@needs_rs274
@pytest.mark.parametrize("target", ["linuxcnc", "grbl"])
@pytest.mark.parametrize("rel", DXF or ["<none>"], ids=case_id)
def test_rs274_feeds_lie_on_ezdxf_s_curves(rel: str, target: str) -> None:
    from scipy.spatial import cKDTree

    outcome = outcome_for(rel, target)
    if outcome.status != "first-try":
        pytest.skip(f"not posted as drawn (see test_corpus): {outcome.status}")
    done = rs274(outcome.final.output)
    assert done.returncode == 0, done.stderr
    fed = fed_points(done.stdout)
    assert len(fed), f"{rel}: rs274 saw no feed move"
    mm = import_dxf(str(CORPUS / rel), ImportOptions()).mm_per_unit
    theirs = _reference(str(CORPUS / rel), mm, STEP_MM)
    off, _ = cKDTree(theirs).query(fed)
    worst = int(np.argmax(off))
    assert off[worst] <= LIMIT_MM, (
        f"{rel}: rs274 feeds the tool through {fed[worst]}, {off[worst]:.4f} mm from the "
        f"drawing as ezdxf draws it (limit {LIMIT_MM:.4f} mm): {outcome.final.command()}"
    )
