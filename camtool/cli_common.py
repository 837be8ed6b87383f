"""Options and helpers every ``camtool`` command shares (post, verify, preview, batch).

Click options are defined once here so that the same option reads the same in
every command; the helpers keep stdout for data and stderr for messages.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from camtool.errors import CamtoolError, InputError
from camtool.toolpath.options import DIRECTIONS, OFFSET_MODES, ORDERS, POCKET_STYLES

if TYPE_CHECKING:
    from camtool.geometry import Drawing
    from camtool.importers import ImportOptions


def warn(messages: tuple[str, ...] | list[str]) -> None:
    """Each message to stderr as ``camtool: warning: …``."""
    for message in messages:
        click.echo(f"camtool: warning: {message}", err=True)


def write_output(data: str | bytes, out: str) -> None:
    """``data`` to the file ``out`` atomically, or to stdout for ``-``.

    Raises:
        CamtoolError: the file cannot be written (nothing is left behind).
    """
    if out == "-":
        if isinstance(data, bytes):
            sys.stdout.buffer.write(data)
        else:
            click.echo(data, nl=False)
        return
    from camtool.output import write_atomic

    try:
        write_atomic(out, data)
    except OSError as exc:
        raise CamtoolError(f"{out}: cannot write ({exc.strerror or exc})") from exc


MACHINE = click.option(
    "--machine",
    "machine_file",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    metavar="FILE|NAME",
    help="Machine profile (a TOML file or a built-in name) laid over the target's, key by "
    "key, e.g. a measured backlash.",
)


def import_options(command: Callable[..., None]) -> Callable[..., None]:
    """Options of the importers: --layers, --units, --hatch-boundaries, --max-entities."""
    from camtool.units import LENGTH_UNITS

    command = click.option(
        "--max-entities",
        type=click.IntRange(min=1),
        default=None,
        metavar="N",
        help="Refuse a drawing that expands to more than N entities (DXF blocks and "
        "MINSERT grids, SVG <use> clones, counted before expanding) [default: 5000000].",
    )(command)
    command = click.option(
        "--hatch-boundaries",
        is_flag=True,
        help="Use DXF HATCH boundary paths as contours (skipped otherwise).",
    )(command)
    command = click.option(
        "--units",
        type=click.Choice(list(LENGTH_UNITS)),
        default=None,
        help="Unit of unitless inputs (point lists; default mm, Matlab xy files 0.1mm).",
    )(command)
    return click.option(
        "--layers",
        default=None,
        metavar="A,B",
        help="Only these layers (DXF layers, Inkscape layers), comma-separated.",
    )(command)


def import_settings(options: dict[str, Any]) -> ImportOptions:
    """Pop the importer options out of a command's keyword options."""
    from camtool.importers import ImportOptions

    layers = options.pop("layers", None)
    names = tuple(n.strip() for n in layers.split(",") if n.strip()) if layers else None
    return ImportOptions(
        layers=names,
        tolerance=options.get("tolerance", 0.001),
        units=options.pop("units", None),
        hatch_boundaries=options.pop("hatch_boundaries", False),
        **_given(max_entities=options.pop("max_entities", None)),
    )


def _given(**values: Any) -> dict[str, Any]:
    """The keyword options that were given (not ``None``), so defaults stay in one place."""
    return {k: v for k, v in values.items() if v is not None}


def post_options(command: Callable[..., None]) -> Callable[..., None]:
    """The options that shape how a drawing is posted (``post`` and ``batch``)."""
    for decorator in reversed(_POST_OPTIONS):
        command = decorator(command)
    return command


_POST_OPTIONS = (
    click.option(
        "--offset",
        type=click.Choice(OFFSET_MODES),
        default="on",
        show_default=True,
        help="Tool-centre side: 'on' follows the drawing (scribing point); 'outside'/"
        "'inside' compensate by half the tool diameter (holes to their correct side); "
        "'pocket' clears the inside of closed contours around their islands.",
    ),
    click.option(
        "--tool-diameter",
        type=float,
        default=0.0,
        metavar="MM",
        help="Tool diameter in mm (needed by every --offset but 'on').",
    ),
    click.option(
        "--direction",
        type=click.Choice(DIRECTIONS),
        default=None,
        help="Cutting direction of closed contours for a clockwise (M03) spindle "
        "[default: climb when compensating; the drawn direction with --offset on].",
    ),
    click.option(
        "--stepover",
        type=float,
        default=0.4,
        show_default=True,
        metavar="FRACTION",
        help="Pocket step-over as a fraction of the tool diameter.",
    ),
    click.option(
        "--pocket",
        type=click.Choice(POCKET_STYLES),
        default="concentric",
        show_default=True,
        help="Pocket style: concentric offsets (wall first, innermost last) or zigzag lines.",
    ),
    click.option(
        "--pocket-angle",
        "pocket_angle_deg",
        type=float,
        default=0.0,
        show_default=True,
        metavar="DEG",
        help="Angle of the zigzag lines, degrees counter-clockwise from +X.",
    ),
    click.option(
        "--depth",
        type=float,
        default=None,
        metavar="MM",
        help="Cut depth below the top (Z 0), mm; Z targets only. Without it no Z is written.",
    ),
    click.option(
        "--step-down",
        type=float,
        default=None,
        metavar="MM",
        help="Depth of each pass, mm [default: one pass at --depth].",
    ),
    click.option(
        "--safe-z",
        type=float,
        default=2.0,
        show_default=True,
        metavar="MM",
        help="Height of every rapid when --depth is given, mm above the top.",
    ),
    click.option(
        "--plunge-feed",
        "plunge_feed_mm_min",
        type=float,
        default=None,
        metavar="MM_PER_MIN",
        help="Feed of Z moves into the material [default: half the cutting feed].",
    ),
    click.option(
        "--ramp",
        "ramp_angle_deg",
        type=float,
        default=None,
        metavar="DEG",
        help="Enter each pass descending along the path at DEG from the horizontal, "
        "instead of plunging (targets that move X, Y and Z together).",
    ),
    click.option(
        "--tabs",
        type=click.IntRange(min=0),
        default=0,
        show_default=True,
        metavar="N",
        help="Holding tabs per outside profile (needs --depth and --offset outside).",
    ),
    click.option(
        "--tab-width",
        type=float,
        default=2.0,
        show_default=True,
        metavar="MM",
        help="Tab length along the part edge, mm.",
    ),
    click.option(
        "--tab-height",
        type=float,
        default=0.5,
        show_default=True,
        metavar="MM",
        help="Tab height above the final depth, mm.",
    ),
    click.option(
        "--order",
        type=click.Choice(ORDERS),
        default="travel",
        show_default=True,
        help="Cutting order (holes always before the contour around them): 'travel' "
        "shortens rapids; 'reversals' minimises axis reversals weighted by the machine's "
        "backlash; 'mirror' cuts a symmetric part half by half from one shared point.",
    ),
    click.option(
        "--lead-in",
        "lead_in_mm",
        type=float,
        default=0.0,
        show_default=True,
        metavar="MM",
        help="Radius of tangent lead-in/lead-out arcs on closed profiles (targets with arcs).",
    ),
    click.option(
        "--close-gap",
        type=float,
        default=0.02,
        show_default=True,
        metavar="MM",
        help="Close contours whose ends are at most this far apart (with a warning); 0: never.",
    ),
    click.option(
        "--fit-arcs/--no-fit-arcs",
        default=True,
        show_default=True,
        help="Fit arcs to dense polylines within --tolerance (G02/G03 instead of many G01).",
    ),
    click.option(
        "--feed",
        "feed_mm_min",
        type=float,
        default=None,
        metavar="MM_PER_MIN",
        help="Cutting feed in mm/min [default: the target's, 0.8 for pic-mmh].",
    ),
    click.option(
        "--tolerance",
        type=float,
        default=0.001,
        show_default=True,
        metavar="MM",
        help="Entity ends closer than this (mm) are chained into one contour; fitted arcs "
        "stay this close to what they replace.",
    ),
    click.option(
        "--scale",
        type=float,
        default=1.0,
        show_default=True,
        metavar="K",
        help="Scale the drawing by K about its origin (unitless factor).",
    ),
    click.option(
        "--fit",
        "fit_mm",
        type=(float, float),
        default=None,
        metavar="W H",
        help="Scale the drawing uniformly to fit W x H mm, about its lower-left corner.",
    ),
    click.option(
        "--format",
        "fmt",
        default=None,
        metavar="NAME",
        help="Output format of the target's dialect (e.g. matlab-router 'wire', i8751 'dump'); "
        "see `camtool targets`.",
    ),
    click.option(
        "--spindle-rpm",
        type=click.FloatRange(min=0),
        default=None,
        metavar="RPM",
        help="Spindle on (M03) at RPM before the first move and off (M05) after the last; "
        "0 writes no spindle commands [default: the target's].",
    ),
)


def read_code(name: str, *, binary: bool = False) -> str | bytes:
    """A code file (``-``: stdin): bytes for a binary dialect, else ASCII text.

    Raises:
        InputError: missing, unreadable, or (text) not ASCII, naming the file.
    """
    if binary:
        try:
            return sys.stdin.buffer.read() if name == "-" else Path(name).read_bytes()
        except FileNotFoundError as exc:
            raise InputError(f"{name}: no such file") from exc
        except OSError as exc:
            raise InputError(f"{name}: cannot read ({exc.strerror or exc})") from exc
    if name == "-":
        return sys.stdin.read()
    try:
        return Path(name).read_text(encoding="ascii", errors="strict")
    except FileNotFoundError as exc:
        raise InputError(f"{name}: no such file") from exc
    except UnicodeDecodeError as exc:
        raise InputError(f"{name}: not a text program (byte {exc.start} is not ASCII)") from exc
    except OSError as exc:
        raise InputError(f"{name}: cannot read ({exc.strerror or exc})") from exc


def read_input(name: str, settings: ImportOptions | None = None) -> Drawing:
    """The drawing at ``name`` (``-``: stdin), read by its ending.

    Raises:
        InputError: the drawing cannot be read (see :mod:`camtool.importers`).
    """
    from camtool.importers import read_drawing, read_drawing_bytes

    if name == "-":
        return read_drawing_bytes(sys.stdin.buffer.read(), options=settings)
    return read_drawing(name, settings)
