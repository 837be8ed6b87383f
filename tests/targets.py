"""The built-in targets and their default file endings, from the registry (not a copy)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from camtool.post.registry import list_targets

_BUILTIN = [e for e in list_targets() if e.origin == "builtin" and e.target is not None]

TARGETS: tuple[str, ...] = tuple(e.name for e in _BUILTIN)
"""Every built-in target name, in `camtool targets` order."""

EXTENSIONS: dict[str, str] = {e.name: e.target.post.suffix for e in _BUILTIN if e.target}
"""The default output format's file ending of each built-in target."""


def post_cli(source: Path, target: str, out: Path) -> subprocess.CompletedProcess[str]:
    """``camtool post SOURCE -t TARGET -o OUT`` as a user runs it (a process of its own)."""
    return subprocess.run(
        [sys.executable, "-m", "camtool", "post", str(source), "-t", target, "-o", str(out)],
        capture_output=True,
        text=True,
        check=False,
    )


def repost_cli(folder: Path, name: str, code: str, target: str) -> tuple[Path, Path]:
    """Write ``code`` to ``FOLDER/NAME`` and post it for ``target`` (:func:`post_cli`), which
    must succeed: the original and the posted program's paths."""
    original = folder / name
    original.write_text(code)
    out = folder / f"{original.stem}-{target}.ngc"
    done = post_cli(original, target, out)
    assert done.returncode == 0, done.stderr
    return original, out
