"""Canned drilling cycles as moves: what G81, G82, G83 and G73 do, by LinuxCNC's rules.

One expansion serves the planner (a drill operation's holes), the G-code reader (another
CAM's cycles) and every dialect without canned cycles (which writes the moves), so a
hole is the same rapids and feeds wherever it comes from. The rules are LinuxCNC's
(G-code reference, "G81", "G83", "G73"; ``rs274`` gives the same canonical moves):

Design notes: docs/internals.md, ``camtool/model/drilling.py``.
"""

from __future__ import annotations

from camtool.model.program import DrillCycle, Dwell, Linear, Move, Rapid

RAPID_DELTA_MM = 0.254
"""How far above the depth already drilled a peck cycle's rapid stops (LinuxCNC's
``G83_RAPID_DELTA`` and ``G73_RETRACT``: 0.010 in, 0.254 mm in a G21 program)."""


def retract_z(cycle: DrillCycle, start_z: float) -> float:
    """The height the tool ends at after ``cycle``, begun at ``start_z``, mm."""
    if cycle.retract == "initial":
        return max(start_z, cycle.r_z)
    return cycle.r_z


def expand(cycle: DrillCycle, here: tuple[float, float, float]) -> list[Move | Dwell]:
    """The moves (and the G82 dwell) of ``cycle`` for a tool standing at ``here``.

    Args:
        cycle: the cycle; its ``moves`` is not read.
        here: the tool's position ``(x, y, z)`` before the cycle, mm.

    Returns:
        Rapids and feeds in order, each with its Z where it moves Z (``None`` where it
        keeps it); a :class:`~camtool.model.program.Dwell` where a G82 waits at the bottom.

    Raises:
        ValueError: the bottom is not below the R plane, or a peck cycle has no peck
            depth > 0.
    """
    if not cycle.bottom_z < cycle.r_z:
        raise ValueError(f"the hole's bottom Z{cycle.bottom_z:g} is not below R{cycle.r_z:g}")
    if cycle.kind != "drill" and not (cycle.peck_mm is not None and cycle.peck_mm > 0):
        raise ValueError(f"a {cycle.kind} cycle needs a peck depth > 0")
    x, y, feed = cycle.x, cycle.y, cycle.feed_mm_min
    out: list[Move | Dwell] = []
    z = here[2]
    if z < cycle.r_z:
        out.append(Rapid(here[0], here[1], cycle.r_z))
        z = cycle.r_z
    if (x, y) != (here[0], here[1]):
        out.append(Rapid(x, y))
    if z > cycle.r_z:
        out.append(Rapid(x, y, cycle.r_z))
    if cycle.kind == "drill":
        out.append(Linear(x, y, feed, cycle.bottom_z))
        if cycle.dwell_s > 0:
            out.append(Dwell(cycle.dwell_s))
    else:
        out.extend(_pecks(cycle))
    out.append(Rapid(x, y, retract_z(cycle, here[2])))
    return out


def _pecks(cycle: DrillCycle) -> list[Move]:
    """The pecks of a G83 or G73 cycle from the R plane to the bottom."""
    assert cycle.peck_mm is not None
    x, y, feed = cycle.x, cycle.y, cycle.feed_mm_min
    out: list[Move] = []
    depth = cycle.r_z
    while True:
        depth = max(depth - cycle.peck_mm, cycle.bottom_z)
        out.append(Linear(x, y, feed, depth))
        if depth <= cycle.bottom_z:
            return out
        if cycle.kind == "peck":
            out.append(Rapid(x, y, cycle.r_z))
        out.append(Rapid(x, y, depth + RAPID_DELTA_MM))
