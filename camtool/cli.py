"""The ``camtool`` command line: thin click wrappers over the library.

stdout carries data only; messages go to stderr. Exit codes: 0 ok, 1 error,
2 usage, 3 unreadable or invalid input, 4 verified error over the limit.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from camtool import __version__
from camtool.errors import CamtoolError
from camtool.toolpath.plan import OFFSET_MODES

if TYPE_CHECKING:
    from camtool.geometry import Drawing


def _warn(messages: tuple[str, ...] | list[str]) -> None:
    for message in messages:
        click.echo(f"camtool: warning: {message}", err=True)


def _write(data: str | bytes, out: str) -> None:
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


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.version_option(__version__, prog_name="camtool")
def cli() -> None:
    """camtool: drawings to machine code for small and legacy CNC machines.

    Lengths are in mm and feeds in mm/min unless an option says otherwise.
    """


@cli.command()
@click.argument("drawing", metavar="DRAWING")
@click.option(
    "--target",
    "-t",
    required=True,
    metavar="NAME",
    help="Machine and dialect to write for (see `camtool targets`), or a target .toml file.",
)
@click.option(
    "-o",
    "--output",
    default="-",
    metavar="FILE",
    help="Where to write the program; '-' (default) is stdout.",
)
@click.option(
    "--offset",
    type=click.Choice(OFFSET_MODES),
    default="on",
    show_default=True,
    help="Tool-centre side: 'on' follows the drawing (scribing point); 'outside'/"
    "'inside' compensate by half the tool diameter.",
)
@click.option(
    "--tool-diameter",
    type=float,
    default=0.0,
    metavar="MM",
    help="Tool diameter in mm (needed by --offset outside|inside).",
)
@click.option(
    "--feed",
    "feed_mm_min",
    type=float,
    default=None,
    metavar="MM_PER_MIN",
    help="Cutting feed in mm/min [default: the target's, 0.8 for pic-mmh].",
)
@click.option(
    "--tolerance",
    type=float,
    default=0.001,
    show_default=True,
    metavar="MM",
    help="Entity ends closer than this (mm) are chained into one contour.",
)
@click.option(
    "--scale",
    type=float,
    default=1.0,
    show_default=True,
    metavar="K",
    help="Scale the drawing by K about its origin (unitless factor).",
)
@click.option(
    "--fit",
    "fit_mm",
    type=(float, float),
    default=None,
    metavar="W H",
    help="Scale the drawing uniformly to fit W x H mm, about its lower-left corner.",
)
@click.option(
    "--machine",
    "machine_file",
    type=click.Path(dir_okay=False, path_type=Path),
    default=None,
    metavar="FILE",
    help="TOML machine profile replacing the target's.",
)
def post(drawing: str, target: str, output: str, machine_file: Path | None, **options: Any) -> None:
    """Import DRAWING (a .dxf file, or '-' for stdin), plan it, write it for a target."""
    from camtool.pipeline import post_drawing
    from camtool.post.registry import load_target

    chosen = load_target(target, machine_file=machine_file)
    job = post_drawing(_read_input(drawing), chosen, **options)
    _warn(job.warnings)
    _write(job.result.code, output)
    if output != "-":
        click.echo(
            f"camtool: wrote {job.result.blocks} blocks for {chosen.name} to {output}", err=True
        )


def _read_input(name: str) -> Drawing:
    from camtool.importers import read_drawing, read_drawing_bytes

    if name == "-":
        return read_drawing_bytes(sys.stdin.buffer.read())
    return read_drawing(name)


@cli.command()
@click.option("--json", "as_json", is_flag=True, help="Write the list as JSON.")
def targets(as_json: bool) -> None:
    """List the targets camtool can write for."""
    from camtool.post.registry import load_target, target_names

    rows = [load_target(name) for name in target_names()]
    if as_json:
        data = [{"name": t.name, "description": t.description, "source": t.source} for t in rows]
        click.echo(json.dumps(data, indent=2))
        return
    width = max(len(t.name) for t in rows)
    for t in rows:
        click.echo(f"{t.name:<{width}}  {t.description}")


def main(argv: list[str] | None = None) -> int:
    """Run the CLI; turn every error into a message and an exit code, never a traceback."""
    try:
        cli.main(args=argv, prog_name="camtool", standalone_mode=False)
    except click.exceptions.Exit as exc:
        return int(exc.exit_code)
    except click.ClickException as exc:
        exc.show()
        return int(exc.exit_code)
    except click.Abort:
        click.echo("camtool: aborted", err=True)
        return 130
    except CamtoolError as exc:
        click.echo(f"camtool: error: {exc}", err=True)
        return exc.exit_code
    except Exception as exc:  # a bug: still a message, never a traceback
        click.echo(
            f"camtool: internal error: {type(exc).__name__}: {exc} (please report it)", err=True
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
