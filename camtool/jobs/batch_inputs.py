"""Which files a batch posts: files, directories and shell-style globs, expanded.

An input is, in this order:

- an existing directory: every file below it (recursively) whose ending camtool
  reads (:data:`READABLE_SUFFIXES`: drawings and G-code programs); hidden files
  and directories (``.git``, ``.venv`` ...) and the batch's own output directory
  are skipped, so re-running a batch never posts its previous outputs;
- an existing file: taken as it is, whatever its ending (a wrong ending is that
  file's error when it is posted);
- a glob (``*``, ``?``, ``[...]``; ``**`` matches any number of directories):
  matching files with a readable ending, and matching directories expanded as
  above. Quote globs on the command line so camtool, not the shell, expands
  them (the shell's ``**`` is not recursive in POSIX sh).

Every found file keeps its path relative to its input's root — the directory,
the glob's leading part without wildcards, or the file's own directory — so
``drawings/a/b.dxf`` found through ``drawings`` is ``a/b.dxf`` in the output
directory. A glob whose ``..`` climbs above its leading part (``a/*/../../x/*.dxf``)
names its files below the deepest folder that holds them all, never with ``..``.
The result is sorted by path and free of repeats (the same file found twice keeps
its first relative path).
"""

from __future__ import annotations

import glob
import os
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from camtool.importers import DRAWING_SUFFIXES
from camtool.model.errors import InputError, UsageError

_MAGIC = re.compile(r"[*?[]")


def readable_suffixes() -> tuple[str, ...]:
    """File endings a batch picks up in directories and globs, lowercase.

    The drawing endings of :data:`camtool.importers.DRAWING_SUFFIXES` and the
    G-code endings of :data:`camtool.jobs.pipeline.PROGRAM_SUFFIXES`.
    """
    from camtool.jobs.pipeline import PROGRAM_SUFFIXES

    return DRAWING_SUFFIXES + PROGRAM_SUFFIXES


@dataclass(frozen=True)
class BatchInput:
    """One file a batch posts.

    Attributes:
        path: the file, as found (relative to the working directory when the
            input was).
        relative: its path below its input's root (e.g. ``a/b.dxf``); outputs
            keep it.
    """

    path: Path
    relative: Path


def expand_inputs(inputs: Sequence[str], *, exclude: Path | None = None) -> tuple[BatchInput, ...]:
    """Expand files, directories and globs into the files to post (see the module docstring).

    Args:
        inputs: what the user gave, in order.
        exclude: a directory (the batch's output directory) never searched by
            directories and globs; explicitly named files are kept.

    Returns:
        The files, sorted by path, each once.

    Raises:
        UsageError: an input is ``-`` (a batch reads files, not stdin).
        InputError: an input matches nothing camtool reads (the message names it
            and lists the readable endings); checked for every input before any
            work starts.
    """
    skip = exclude.resolve() if exclude is not None else None
    found: dict[Path, BatchInput] = {}
    for text in inputs:
        for item in _expand_one(text, skip):
            found.setdefault(item.path.resolve(), item)
    return tuple(sorted(found.values(), key=lambda item: item.path.as_posix()))


def _expand_one(text: str, skip: Path | None) -> list[BatchInput]:
    """The files one input names (see :func:`expand_inputs`)."""
    if text == "-":
        raise UsageError("a batch reads files, not stdin ('-'); use `camtool post -` for a pipe")
    path = Path(text)
    if path.is_dir():
        items = _walk(path, path, skip)
    elif path.exists():
        return [BatchInput(path, Path(path.name))]
    elif not _MAGIC.search(text):
        raise InputError(f"{text}: no such file or directory")
    else:
        items = _rebase(_glob(text, skip))
    if not items:
        endings = ", ".join(readable_suffixes())
        what = "holds" if path.is_dir() else "matches"
        raise InputError(f"{text}: {what} no file camtool reads ({endings})")
    return items


def _rebase(items: list[BatchInput]) -> list[BatchInput]:
    """Relative paths below the files' common folder when one would climb out with ``..``.

    A glob such as ``a/*/../../x/*.dxf`` matches ``a/s/../../x/f.dxf``, which is
    ``../x/f.dxf`` below the glob's leading part ``a``: written below ``-o`` as it is,
    it would land outside. Such a glob's files are named below the deepest folder
    that holds them all instead (``f.dxf``); :func:`camtool.jobs.batch.plan_batch` still
    checks every output resolves inside ``-o``.
    """
    if not any(item.relative.parts[:1] == ("..",) for item in items):
        return items
    absolute = [os.path.normpath(os.path.abspath(item.path)) for item in items]
    common = os.path.commonpath([os.path.dirname(a) for a in absolute])
    return [
        BatchInput(item.path, Path(os.path.relpath(a, common)))
        for item, a in zip(items, absolute, strict=True)
    ]


def _glob(pattern: str, skip: Path | None) -> list[BatchInput]:
    """Files a glob matches, relative to its leading part without wildcards."""
    parts = Path(pattern).parts
    fixed = next((i for i, part in enumerate(parts) if _MAGIC.search(part)), len(parts))
    root = Path(*parts[:fixed]) if fixed else Path()
    if skip is not None and _below(root.resolve(), skip):
        skip = None  # the user globbed inside the output directory on purpose
    items: list[BatchInput] = []
    for match in sorted(glob.glob(pattern, recursive=True)):
        path = Path(match)
        if skip is not None and _below(path.resolve(), skip):
            continue
        if path.is_dir():
            items.extend(_walk(path, root, skip))
        elif _readable(path):
            items.append(BatchInput(path, Path(os.path.relpath(path, root))))
    return items


def _walk(directory: Path, root: Path, skip: Path | None) -> list[BatchInput]:
    """Readable, non-hidden files below ``directory``, relative to ``root``, sorted."""
    items: list[BatchInput] = []
    for here, dirs, files in os.walk(directory):
        dirs[:] = sorted(
            d
            for d in dirs
            if not d.startswith(".") and (skip is None or (Path(here) / d).resolve() != skip)
        )
        for name in sorted(files):
            path = Path(here) / name
            if not name.startswith(".") and _readable(path):
                items.append(BatchInput(path, Path(os.path.relpath(path, root))))
    return items


def _readable(path: Path) -> bool:
    return path.suffix.lower() in readable_suffixes()


def _below(path: Path, directory: Path) -> bool:
    """True when resolved ``path`` is ``directory`` or inside it."""
    return path == directory or directory in path.parents
