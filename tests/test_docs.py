"""The docs show what camtool does today: generated parts are current, pages exist."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).parents[1]


def test_generated_docs_are_current() -> None:
    proc = subprocess.run(
        [
            sys.executable,
            str(ROOT / "docs" / "make_docs.py"),
            "--check",
            "--without-gallery-pictures",
        ],
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr


def test_every_target_has_a_page_with_a_preview() -> None:
    from camtool.post.registry import target_names

    for name in target_names():
        page = ROOT / "docs" / "targets" / f"{name}.md"
        assert page.is_file(), f"docs/targets/{name}.md is missing"
        assert ".svg)" in page.read_text(encoding="utf-8")
