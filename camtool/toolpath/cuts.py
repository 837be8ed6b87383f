"""The planner's intermediate forms: cuts before ordering, and what planning found.

Design notes: docs/internals.md, ``camtool/toolpath/cuts.py``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from camtool.model.shapes import Contour, Point

CUT_KINDS = ("profile", "open", "pocket")
"""Kinds of :class:`Cut`: a closed profile, an open contour cut on the line, a pocket path."""

SIDES = ("left", "right")
"""Values of :attr:`Cut.material_side`."""


@dataclass(frozen=True)
class Cut:
    """One continuous tool-centre path, cut at one depth before ordering and passes.

    Attributes:
        path: the tool-centre path, mm. Closed for profiles and pocket rings; a
            pocket's linked rings form one open path.
        group: index of the (chained) drawing contour the cut comes from; the
            ordering keeps "inside before outside" by the nesting of groups.
        kind: one of :data:`CUT_KINDS`.
        may_reverse: the ordering may traverse the path backwards (the direction
            was not fixed by ``--direction`` on a compensated contour).
        may_rotate: the ordering may start the (closed) path at another vertex.
        outside_profile: an outer boundary of material cut on its outside: tabs
            and lead-ins go on these.
        material_side: ``"left"``/``"right"`` of the travel direction on which the
            material that stays lies, ``None`` when unknown (paths on the line).
            Reversing the path swaps it.
    """

    path: Contour
    group: int
    kind: str = "profile"
    may_reverse: bool = True
    may_rotate: bool = True
    outside_profile: bool = False
    material_side: str | None = None

    def __post_init__(self) -> None:
        if self.kind not in CUT_KINDS:
            raise ValueError(f"unknown cut kind {self.kind!r}")
        if self.material_side is not None and self.material_side not in SIDES:
            raise ValueError(f"unknown material side {self.material_side!r}")
        if self.may_rotate and not self.path.closed:
            raise ValueError("only a closed path may start at another vertex")

    def reversed(self) -> Cut:
        """The same cut traversed the other way (material side swapped)."""
        side = {"left": "right", "right": "left"}.get(self.material_side or "")
        return Cut(
            self.path.reversed(),
            self.group,
            self.kind,
            self.may_reverse,
            self.may_rotate,
            self.outside_profile,
            side,
        )


FINDING_KINDS = (
    "closed-gap",
    "offset-fallback",
    "offset-vanished",
    "self-crossing",
    "crossing",
    "overlap",
    "tight-corner",
    "uncut",
    "gouge",
    "open-left-out",
    "open-gap",
    "lead-in",
    "option",
    "arc-fit",
    "ordering",
    "copy",
)
"""Kinds of :class:`Finding`, the keys of the plan report's ``findings`` counts."""


@dataclass(frozen=True)
class Finding:
    """Something planning found that the user must know: where, what, how much.

    Attributes:
        kind: one of :data:`FINDING_KINDS`.
        message: one line for the user, naming the contour (its source entity
            and a location in mm) and what to do.
        at: a representative location, mm (a corner, a gap, an uncut region's
            centroid), ``None`` when the finding has no single place.
        value: the finding's size in the unit its kind implies (gap mm, corner
            radius mm, area mm², ...), ``None`` when it has none.
    """

    kind: str
    message: str
    at: Point | None = None
    value: float | None = None

    def __post_init__(self) -> None:
        if self.kind not in FINDING_KINDS:
            raise ValueError(f"unknown finding kind {self.kind!r}")


@dataclass(frozen=True)
class Stage:
    """A stage's output: cuts and what it found."""

    cuts: tuple[Cut, ...]
    findings: tuple[Finding, ...] = field(default=())


def where(contour: Contour) -> str:
    """``"contour LINE #2A at (x, y) mm"``: how messages name a contour."""
    from camtool.model.units import fmt_point

    src = f"{contour.source} " if contour.source else ""
    return f"contour {src}at {fmt_point(contour.start)} mm"


MAX_LISTED = 10
"""Most contours one kind of finding names one by one; the rest are counted in one line."""

_COUNTED = {
    "gouge": "place(s) where the tool cuts into the part",
    "offset-fallback": "contour(s) OpenCASCADE could not offset (shapely's buffer used)",
    "offset-vanished": "contour(s) the offset left nothing of",
    "self-crossing": "self-crossing contour(s)",
    "crossing": "pair(s) of contours that cross each other",
    "tight-corner": "contour(s) with inside corners tighter than the tool radius",
    "uncut": "region(s) narrower than the tool, not cut",
    "closed-gap": "gap(s) closed with a straight line",
    "open-gap": "open contour(s) or open end(s)",
    "copy": "contour(s) that repeat another on its path, each cut once",
}
"""How the line that counts a kind's unlisted findings names them (others: by the kind)."""


def finding_warnings(findings: Sequence[Finding]) -> list[str]:
    """The findings' messages as warnings: at most :data:`MAX_LISTED` + 1 lines per kind.

    A kind with more than that keeps its first :data:`MAX_LISTED` messages (repeats
    dropped), in place, and one line counting the rest; the findings themselves, all of
    them, stay in the plan report (``--report R.json``: ``plan.findings``). Parts closer
    than the tool would otherwise print a line per overlap.
    """
    by_kind: dict[str, dict[str, None]] = {}  # distinct messages, in order (dict: linear)
    for f in findings:
        by_kind.setdefault(f.kind, {})[f.message] = None
    listed = {kind: list(messages)[:MAX_LISTED] for kind, messages in by_kind.items()}
    out: list[str] = []
    for f in findings:
        rest = len(by_kind[f.kind]) - MAX_LISTED
        if rest <= 1:
            out.append(f.message)
        elif f.message in listed[f.kind]:
            out.append(f.message)
            if f.message == listed[f.kind][-1]:  # the last one listed: the count follows
                what = _COUNTED.get(f.kind, f"finding(s) of kind '{f.kind}'")
                out.append(
                    f"{rest} more {what}, not listed here "
                    "(the report of --report R.json lists each one)"
                )
    return list(dict.fromkeys(out))


def open_left_out(contours: Sequence[Contour], side: str) -> list[Finding]:
    """An ``open-left-out`` finding per open contour of ``contours`` (the first :data:`MAX_LISTED`).

    An open contour has no inside or outside: under ``side`` (``outside``, ``inside`` or
    ``pocket``) it is not cut at all (cutting it on its line would cut through the part:
    the diameter lines of a disc, a construction line across it). Each finding names the
    contour, its layer and where it runs; past :data:`MAX_LISTED`, one more counts the rest.
    """
    from camtool.model.units import fmt_point

    opened = [c for c in contours if not c.closed]
    out = [
        Finding(
            "open-left-out",
            f"not cut: open {where(c)} to {fmt_point(c.end)} mm on layer {c.layer!r}: "
            f"{side} needs a closed contour (an engrave operation or --offset on cuts it on "
            "its line)",
            c.start,
            c.length,
        )
        for c in opened[:MAX_LISTED]
    ]
    if len(opened) > MAX_LISTED:
        rest = len(opened) - MAX_LISTED
        out.append(
            Finding(
                "open-left-out",
                f"not cut: {rest} more open contour(s) (`camtool inspect` lists them)",
                value=float(rest),
            )
        )
    return out


def self_crossing(contour: Contour, tolerance: float, what: str) -> Finding | None:
    """A ``self-crossing`` finding when the closed ``contour`` crosses itself, else ``None``.

    ``what`` (``"outside offset"``, ``"pocket"``) is made from shapely's buffer of the
    area the contour encloses: an offset follows the boundary of that area (the loops of
    the drawn line inside it are not cut), a pocket clears all of it (through them).
    Located where it crosses (shapely's validity check, GEOS), mm; arcs are chords
    within ``tolerance / 4``.
    """
    from shapely import Polygon, is_valid_reason

    reason = is_valid_reason(Polygon(contour.points(tolerance / 4)))
    if not reason.startswith(("Self-intersection", "Ring Self-intersection")):
        return None
    x, y = (float(v) for v in reason[reason.index("[") + 1 : reason.index("]")].split()[:2])
    effect = (
        "clears the whole area it encloses, through its loops inside"
        if what == "pocket"
        else "follows the boundary of the area it encloses, and its loops inside are not cut"
    )
    return Finding(
        "self-crossing",
        f"{where(contour)}: the contour crosses itself (at ({x:.4f}, {y:.4f}) mm): the "
        f"{what} {effect}; cut it on its line (--offset on, or an engrave operation) to "
        "follow every loop",
        (x, y),
    )
