"""Importers: read a drawing file into a :class:`~camtool.model.shapes.Drawing` (mm, Y up).

:func:`read_drawing` chooses the importer by the file name ending (DXF:
:mod:`camtool.importers.dxf`, SVG: :mod:`camtool.importers.svg`, point lists:
:mod:`camtool.importers.points`) and imports only that one, so reading a point list
never loads ezdxf or svgelements. The options and limits every importer takes are in
:mod:`camtool.importers.options`.
"""

from __future__ import annotations

from pathlib import Path

from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import Drawing

POINT_SUFFIXES = (".csv", ".txt", ".xy", ".m")
"""File endings of unitless point lists, the only inputs ``--units`` applies to."""

DRAWING_SUFFIXES = (".dxf", ".svg", *POINT_SUFFIXES)
"""File name endings the importers read, lowercase."""


def read_drawing(
    path: str | Path, options: ImportOptions | None = None, *, progress: Progress = no_progress
) -> Drawing:
    """Read the drawing at ``path``, choosing the importer by the file name ending.

    Args:
        path: the drawing file.
        options: importer options; ``None`` takes the defaults.
        progress: told the ``reading`` stage (:class:`~camtool.model.progress.Step`),
            and by the SVG importer its shapes and curve fits as it goes
            (:func:`camtool.importers.svg.read_svg`).

    Raises:
        InputError: the file is missing, unreadable, of an unknown kind, or holds
            no usable entity.
    """
    path = Path(path)
    options = options or ImportOptions()
    suffix = path.suffix.lower()
    if suffix == ".dxf":
        from camtool.importers.dxf import read_dxf

        progress(Step("reading", name=path.name))
        return read_dxf(path, options)
    if suffix == ".svg":
        from camtool.importers.svg import read_svg

        return read_svg(path, options, progress=progress)
    if suffix in POINT_SUFFIXES:
        from camtool.importers.points import read_points

        progress(Step("reading", name=path.name))
        return read_points(path, options)
    if suffix == "" and str(path) == "-":
        raise InputError("'-' (stdin) must be read with read_drawing_bytes")
    kind = f"{suffix!r} files" if suffix else "a file without a name ending"
    raise InputError(
        f"{path}: cannot read {kind}; camtool reads {', '.join(DRAWING_SUFFIXES)} drawings"
    )


def read_drawing_bytes(
    data: bytes,
    *,
    name: str = "<stdin>",
    suffix: str = ".dxf",
    options: ImportOptions | None = None,
) -> Drawing:
    """Read a drawing given as bytes (e.g. piped on stdin), of the kind ``suffix`` names.

    The bytes go through a temporary file so that each importer detects the
    encoding as it does for files; messages name ``name``.

    Raises:
        InputError: as :func:`read_drawing`.
    """
    import dataclasses
    import tempfile

    with tempfile.TemporaryDirectory(prefix="camtool-") as tmp:
        path = Path(tmp) / f"stdin{suffix}"
        path.write_bytes(data)
        try:
            drawing = read_drawing(path, options)
        except InputError as exc:
            raise InputError(str(exc).replace(str(path), name)) from exc
    warnings = tuple(w.replace(str(path), name) for w in drawing.warnings)
    return dataclasses.replace(drawing, source=name, warnings=warnings)
