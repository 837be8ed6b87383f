"""Importers: read a drawing file into a :class:`~camtool.model.shapes.Drawing` (mm, Y up).

:func:`read_drawing` chooses the importer by the file name ending (DXF:
:mod:`camtool.importers.dxf`, SVG: :mod:`camtool.importers.svg`, point lists:
:mod:`camtool.importers.points`) and imports only that one, so reading a point list
never loads ezdxf or svgelements. The options and limits every importer takes are in
:mod:`camtool.importers.options`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import NoReturn

from camtool.importers.options import ImportOptions
from camtool.model.construction import fit_extent
from camtool.model.errors import CamtoolError, InputError, not_a_file
from camtool.model.progress import Progress, Step, no_progress
from camtool.model.shapes import BBox, Drawing, fit_factor

POINT_SUFFIXES = (".csv", ".txt", ".xy", ".m")
"""File endings of unitless point lists, the only inputs ``--units`` applies to."""

DRAWING_SUFFIXES = (".dxf", ".svg", ".svgz", *POINT_SUFFIXES)
"""File name endings the importers read, lowercase (``.svgz``: an SVG compressed by gzip,
as Inkscape saves "Compressed Inkscape SVG")."""

MAX_SVGZ_BYTES = 256 << 20
"""Most bytes a ``.svgz`` may expand to (256 MiB, 50 times the 5 MB page of the SVG
benchmark): a gzip bomb (a few MB expanding to gigabytes) is refused before memory runs out."""


def read_drawing(
    path: str | Path,
    options: ImportOptions | None = None,
    *,
    progress: Progress = no_progress,
    check: Callable[[BBox], None] | None = None,
) -> Drawing:
    """Read the drawing at ``path``, choosing the importer by the file name ending.

    Curves (Béziers, ellipses, splines) are fitted within ``options.tolerance`` at the
    size planning will give the drawing (``options.scale`` or ``options.fit``:
    :meth:`~camtool.importers.options.ImportOptions.curve_tolerance`). For ``--fit`` the
    factor depends on the extent of the drawing read: the SVG importer fits for the
    extent of its segments' ends (as a rule within the drawing's, so not coarser), the
    others for the drawing as drawn; then the factor of the drawing read is checked, and
    where its curves would be further than ``tolerance`` from the arcs once scaled (a DXF
    scaled up, an SVG with a path of zero length far off), the file is read again with
    the finer tolerance that factor asks.

    Args:
        path: the drawing file.
        options: importer options; ``None`` takes the defaults.
        progress: told the ``reading`` stage (:class:`~camtool.model.progress.Step`),
            and by the SVG importer its shapes and curve fits as it goes
            (:func:`camtool.importers.svg.read_svg`).
        check: called with a box (mm, as drawn) within the drawing's extent as soon as
            there is one: by the SVG importer before it fits curves (the extent of its
            segments' ends), by the DXF importer as its contours are read (the extent so
            far), and with the extent of the drawing read. What it raises
            stops the reading; ``camtool post`` refuses there a drawing too large for the
            machine (:func:`camtool.jobs.pipeline.post_path`).

    Raises:
        InputError: the file is missing, unreadable, of an unknown kind, or holds
            no usable entity; or (``--fit``) a drawing so small against the tolerance
            that no fit holds it once scaled.
        Whatever ``check`` raises.
    """
    path = Path(path)
    options = options or ImportOptions()
    drawing, used = _read(path, options, progress, check)
    if options.fit is None:
        return drawing
    for margin in _REFIT_MARGINS:
        # as planning will scale it, or larger (it counts only the marks a job drills)
        k = fit_factor(fit_extent(drawing, marks=False), options.fit)
        k = 1.0 if math.isinf(k) else k
        if used * k <= options.tolerance:
            return drawing
        used = options.tolerance / k * (1.0 - margin)
        del drawing  # not held while the finer one is read
        drawing = _read(path, options.at_tolerance(used), progress)[0]  # noqa: F841 (read above)
    raise InputError(
        f"{path}: its curves cannot be fitted within --tolerance {options.tolerance:g} mm at "
        "the --fit size (the drawing is hardly larger than the tolerance); raise --tolerance"
    )


_REFIT_MARGINS = (1e-6, 1e-3, 0.1, 0.5)
"""Each new fit of a drawing read again for ``--fit`` asks this much finer than the factor
of the drawing before it (a finer fit moves the extent, so the factor, by a few tolerances)."""


def _read(
    path: Path,
    options: ImportOptions,
    progress: Progress,
    check: Callable[[BBox], None] | None = None,
) -> tuple[Drawing, float]:
    """The drawing at ``path`` and the tolerance its curves were fitted within (mm, as drawn).

    0.0 for a drawing without fitted curves (a point list, a DXF of LINEs only). ``check``: see
    :func:`read_drawing`.
    """
    suffix = path.suffix.lower()
    if suffix == ".svgz":
        return _read_svgz(path, options, progress, check)
    if suffix == ".svg":
        from camtool.importers.svg import svg_drawing

        return svg_drawing(path, options, progress=progress, check=check)
    if suffix == ".dxf":
        from camtool.importers.dxf import import_dxf

        progress(Step("reading", name=path.name))
        used = options.curve_tolerance()
        imported = import_dxf(path, options.at_tolerance(used), check=check)
        drawing = imported.drawing
        if not imported.converted:  # only LINEs: the same drawing at any tolerance
            used = 0.0
    elif suffix in POINT_SUFFIXES:
        from camtool.importers.points import read_points

        progress(Step("reading", name=path.name))
        drawing, used = read_points(path, options), 0.0
    else:
        _unknown(path, suffix)
    if check is not None and drawing.contours:  # a point is cut only by a job's drill
        check(Drawing(drawing.contours).bbox())
    return drawing, used


def _read_svgz(
    path: Path,
    options: ImportOptions,
    progress: Progress,
    check: Callable[[BBox], None] | None,
) -> tuple[Drawing, float]:
    """The SVG that ``path`` holds compressed, read as a ``.svg``; messages name ``path``."""
    from camtool.importers.svg import svg_drawing

    with bytes_as_file(gunzipped(path), ".svg", str(path)) as plain:  # held while written only

        def named(step: Step) -> None:  # "reading penguins.svgz", not the temporary file
            progress(dataclasses.replace(step, name=path.name) if step.name == plain.name else step)

        drawing, used = svg_drawing(plain, options, progress=named, check=check)
    return renamed(drawing, plain, str(path)), used


def renamed(drawing: Drawing, path: Path, name: str) -> Drawing:
    """``drawing``, read from the temporary file ``path``, named ``name`` instead.

    Its source, warnings and size note (``<stdin>``, or the ``.svgz`` it was decompressed from).
    """
    return dataclasses.replace(
        drawing,
        source=name,
        warnings=tuple(w.replace(str(path), name) for w in drawing.warnings),
        size_note=drawing.size_note.replace(str(path), name),
    )


def gunzipped(path: Path) -> bytes:
    """The bytes of the gzip file at ``path`` decompressed (a file not in gzip: as it is).

    Raises:
        InputError: the file is missing or unreadable, damaged, or expands past
            :data:`MAX_SVGZ_BYTES`.
    """
    import gzip
    import zlib

    try:
        with path.open("rb") as file:
            if file.read(2) != b"\x1f\x8b":  # no gzip header: an uncompressed SVG so named
                file.seek(0)
                return file.read()
        with gzip.open(path, "rb") as packed:
            data = packed.read(MAX_SVGZ_BYTES + 1)
    except FileNotFoundError:
        raise not_a_file(path) from None
    except (gzip.BadGzipFile, EOFError, zlib.error) as exc:
        raise InputError(
            f"{path}: damaged gzip data ({exc}); save the drawing again as .svg"
        ) from None
    except OSError as exc:
        raise InputError(f"{path}: cannot read it ({exc.strerror or exc})") from None
    if len(data) > MAX_SVGZ_BYTES:
        raise InputError(
            f"{path}: expands to more than {MAX_SVGZ_BYTES >> 20} MiB once decompressed (a "
            "gzip bomb, or an SVG larger than camtool reads compressed); if it is a real "
            "drawing, decompress it (gunzip -S .svgz) and post the .svg"
        )
    return data


def _unknown(path: Path, suffix: str) -> NoReturn:
    """Refuse a file of a kind no importer reads (InputError)."""
    if suffix == "" and str(path) == "-":
        raise InputError("'-' (stdin) must be read with read_drawing_bytes")
    kind = f"{suffix!r} files" if suffix else "a file without a name ending"
    raise InputError(
        f"{path}: cannot read {kind}; camtool reads {', '.join(DRAWING_SUFFIXES)} drawings"
    )


@contextmanager
def bytes_as_file(data: bytes, suffix: str, name: str) -> Iterator[Path]:
    """``data`` as a temporary file ending in ``suffix``, removed on leaving.

    The importers read files (each detects the encoding as it does for a file on disk); a
    :class:`~camtool.model.errors.CamtoolError` raised inside names ``name`` (``<stdin>``)
    instead of the temporary file (its type kept). What else the caller shows should replace
    ``str(path)`` with ``name`` likewise (:func:`renamed`).
    """
    import tempfile

    with tempfile.TemporaryDirectory(prefix="camtool-") as tmp:
        path = Path(tmp) / f"stdin{suffix}"
        path.write_bytes(data)
        del data  # the importer reads the file: a large input is not held twice
        try:
            yield path
        except CamtoolError as exc:  # an InputError, or a TooLargeError from ``check``
            raise type(exc)(str(exc).replace(str(path), name)) from exc


def read_drawing_bytes(
    data: bytes,
    *,
    name: str = "<stdin>",
    suffix: str = ".dxf",
    options: ImportOptions | None = None,
    check: Callable[[BBox], None] | None = None,
) -> Drawing:
    """Read a drawing given as bytes (e.g. piped on stdin), of the kind ``suffix`` names.

    Through a temporary file (:func:`bytes_as_file`); messages name ``name``. ``check``:
    as for :func:`read_drawing`.

    Raises:
        InputError: as :func:`read_drawing`.
    """
    with bytes_as_file(data, suffix, name) as path:
        drawing = read_drawing(path, options, check=check)
    return renamed(drawing, path, name)
