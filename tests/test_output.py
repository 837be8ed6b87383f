"""Atomic output files."""

from __future__ import annotations

import os
import stat
from pathlib import Path

from camtool.output import write_atomic


def test_written_files_get_the_permissions_open_would_give(tmp_path: Path) -> None:
    old = os.umask(0o022)
    try:
        write_atomic(tmp_path / "a.nc", "G0 X1\n")
        write_atomic(tmp_path / "b.bin", b"\x13\x54")
    finally:
        os.umask(old)
    for name in ("a.nc", "b.bin"):
        assert stat.S_IMODE((tmp_path / name).stat().st_mode) == 0o644
    assert (tmp_path / "b.bin").read_bytes() == b"\x13\x54"
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []
