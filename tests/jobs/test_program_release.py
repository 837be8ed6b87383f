"""Nothing at module level keeps a posted program alive once its caller lets it go.

A batch or a long-lived API user posts one big program after another; a module-level
cache holding the last program's moves would keep hundreds of MB alive after the job.
Counted, not timed: the live :class:`Linear` objects after ``del`` and a collection.
"""

from __future__ import annotations

import gc
import weakref

from camtool.model.program import Linear
from camtool.model.shapes import Contour, Drawing, Line
from camtool.post.registry import load_target
from camtool.toolpath.options import PlanOptions


def _live_linears() -> int:
    gc.collect()
    return sum(1 for o in gc.get_objects() if type(o) is Linear)


def test_no_move_of_a_posted_program_outlives_it() -> None:
    from camtool.jobs.pipeline import post_drawing

    lines = [Contour((Line((0.5 * k, 0.0), (0.5 * k, 10.0 + k % 7)),), False) for k in range(300)]
    drawing = Drawing(tuple(lines), "lines")
    target = load_target("grbl")
    before = _live_linears()
    done = post_drawing(drawing, target, PlanOptions(feed_mm_min=500.0))
    program = weakref.ref(done.program)
    assert sum(1 for m in done.program.moves if type(m) is Linear) >= 300
    del done
    assert _live_linears() == before
    assert program() is None
