"""DXF entities written without their subclass markers, as small DXF writers write them.

Since DXF R13 an entity's group codes come in subclasses, each opened by a ``100``
marker: ``AcDbEntity`` for the layer and colour, ``AcDbPolyline`` for an LWPOLYLINE's
vertices, ``AcDbSpline`` for a SPLINE's knots and control points (AutoCAD DXF
Reference, "Common Group Codes for Entities", LWPOLYLINE, SPLINE). Small writers (a gear
template generator, JavaScript and Python DXF writers) write these two entities as a
flat list of group codes, the way DXF R12 wrote its entities. LibreCAD and Inkscape read
them by their group codes; ezdxf, in normal and in recover mode, refuses the file
("missing 'AcDbPolyline' subclass in LWPOLYLINE"). :func:`with_subclass_markers` puts
the markers in, so that ezdxf reads every group code as the writer meant it.
"""

from __future__ import annotations

import re
from collections import Counter
from dataclasses import dataclass

SUBCLASSES = {b"LWPOLYLINE": b"AcDbPolyline", b"SPLINE": b"AcDbSpline"}
"""The entities ezdxf cannot read without their subclass, and that subclass's marker."""

_BASE = frozenset({5, 105, 330, 360})
"""Group codes of the base class: the handle and the owners."""

_ENTITY = frozenset({6, 8, 48, 60, 62, 67, 92, 160, 284, 310, 347, 348, 370, 380, 390})
_ENTITY |= frozenset({410, 420, 430, 440})
"""Group codes of ``AcDbEntity`` (layer, linetype, colour, space, lineweight...)."""

_MISSING = re.compile(r"missing '(AcDbPolyline|AcDbSpline)' subclass")


def missing_subclass(reason: str) -> bool:
    """Whether ezdxf's ``reason`` for refusing a file is an entity without its subclass."""
    return _MISSING.search(reason) is not None


@dataclass(frozen=True)
class Marked:
    """A DXF file's text with the subclass markers put in.

    Attributes:
        data: the file, one tag per two lines (newline line ends).
        counts: how many entities of each type got their markers.
        inserted: the 1-based lines of ``data`` that are markers, in order.
    """

    data: bytes
    counts: Counter[str]
    inserted: tuple[int, ...]

    def original_line(self, line: int) -> int:
        """A line of :attr:`data` as a line of the file (markers before it taken away)."""
        return line - sum(1 for n in self.inserted if n < line)


def with_subclass_markers(data: bytes) -> Marked:
    """An ASCII DXF file with markers in each entity of :data:`SUBCLASSES` that has none.

    The entity's group codes are sorted into the base class (handle, owners and ``102``
    groups), ``AcDbEntity`` (:data:`_ENTITY`) and the entity's own subclass (every other
    code, in the file's order: an LWPOLYLINE's vertices stay in order); extended data
    (codes 1000 and above) stays last. An entity with any ``100`` marker is left as it
    is, as is every other entity.

    Args:
        data: the file's bytes (ASCII DXF; a binary DXF is returned unchanged).

    Returns:
        The file with the markers, the counts by entity type and the inserted lines.
    """
    lines = data.splitlines()
    if data.startswith(b"AutoCAD Binary DXF") or len(lines) < 2:
        return Marked(data, Counter(), ())
    pairs = [(lines[k].strip(), lines[k + 1]) for k in range(0, len(lines) - 1, 2)]
    out: list[_Tag] = []
    counts: Counter[str] = Counter()
    k = 0
    while k < len(pairs):
        code, value = pairs[k]
        end = k + 1
        while end < len(pairs) and pairs[end][0] != b"0":
            end += 1
        body = pairs[k + 1 : end]
        kind = value.strip().upper()
        out.append((code, value, False))
        if code == b"0" and kind in SUBCLASSES and all(c != b"100" for c, _ in body):
            counts[kind.decode()] += 1
            out.extend(_marked(body, SUBCLASSES[kind]))
        else:
            out.extend((c, v, False) for c, v in body)
        k = end
    if not counts:
        return Marked(data, counts, ())
    _declare_version(out)
    text = b"\n".join(line for code, value, _ in out for line in (code, value)) + b"\n"
    inserted = tuple(n for k, tag in enumerate(out) if tag[2] for n in (2 * k + 1, 2 * k + 2))
    return Marked(text, counts, inserted)


_Tag = tuple[bytes, bytes, bool]
"""A group code, its value and whether it was put in (not in the file)."""


def _declare_version(out: list[_Tag]) -> None:
    """Give the file the version of its markers (R2000, ``AC1015``) where it says less.

    Without it (no ``$ACADVER``, or one before R2000, which has no LWPOLYLINE) ezdxf
    reads the file as DXF R12, whose entities have no subclasses, and takes the markers
    out again. ``$INSUNITS`` is not added: the file's unit stays unsaid.
    """
    codes = [(code, value.strip().upper()) for code, value, _ in out]
    if (b"9", b"$ACADVER") in codes:
        at = codes.index((b"9", b"$ACADVER")) + 1
        if at < len(out) and out[at][0] == b"1" and codes[at][1] < b"AC1015":
            out[at] = (b"1", b"AC1015", False)  # a changed value: no line moves
        return
    version = [(b"9", b"$ACADVER", True), (b"1", b"AC1015", True)]
    for k in range(1, len(codes)):
        if codes[k] == (b"2", b"HEADER") and codes[k - 1] == (b"0", b"SECTION"):
            out[k + 1 : k + 1] = version
            return
    section = [(b"0", b"SECTION", True), (b"2", b"HEADER", True)]
    out[0:0] = [*section, *version, (b"0", b"ENDSEC", True)]


def _marked(body: list[tuple[bytes, bytes]], subclass: bytes) -> list[_Tag]:
    """An entity's tags (after its ``0`` tag) sorted into subclasses, with markers."""
    base: list[_Tag] = []
    entity: list[_Tag] = []
    own: list[_Tag] = []
    extended: list[_Tag] = []
    in_group = False
    for code, value in body:
        try:
            number = int(code)
        except ValueError:
            number = -1  # not a group code: left where ezdxf will say so
        tag = (code, value, False)
        if number == 102:
            in_group = value.strip().startswith(b"{")
            base.append(tag)
        elif in_group or number in _BASE:
            base.append(tag)
        elif number >= 1000:
            extended.append(tag)
        elif number in _ENTITY:
            entity.append(tag)
        else:
            own.append(tag)
    return [
        *base,
        (b"100", b"AcDbEntity", True),
        *entity,
        (b"100", subclass, True),
        *own,
        *extended,
    ]
