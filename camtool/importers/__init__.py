"""Importers: read a drawing file into a :class:`~camtool.geometry.Drawing` (mm, Y up)."""

from __future__ import annotations

from pathlib import Path

from camtool.errors import InputError
from camtool.geometry import Drawing

DRAWING_SUFFIXES = (".dxf",)
"""File name endings the importers read, lowercase."""


def read_drawing(path: str | Path) -> Drawing:
    """Read the drawing at ``path``, choosing the importer by the file name ending.

    Raises:
        InputError: the file is missing, unreadable, of an unknown kind, or holds
            no usable entity.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".dxf":
        from camtool.importers.dxf import read_dxf

        return read_dxf(path)
    raise InputError(
        f"{path}: cannot read {suffix or 'files without an ending'!r}; "
        f"camtool reads {', '.join(DRAWING_SUFFIXES)}"
    )
