"""Regenerate the generated parts of docs/ from samples/ (run: ``make docs``).

For each target page it writes the sample program between the markers
``<!-- sample:begin -->`` / ``<!-- sample:end -->`` and the preview picture
``docs/targets/<target>-<sample>.svg``. ``--check`` only reports whether the
committed docs are current (exit 1 if not); the tests run it.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from camtool.pipeline import post_file
from camtool.preview import program_svg

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = {"pic-mmh": "logo.dxf"}
_BLOCK = re.compile(r"(<!-- sample:begin -->\n).*?(<!-- sample:end -->)", re.S)


def generated() -> dict[Path, str]:
    """Every generated docs file with its current content."""
    files: dict[Path, str] = {}
    for target, sample in SAMPLES.items():
        job = post_file(ROOT / "samples" / sample, target)
        stem = Path(sample).stem
        svg = program_svg(
            job.program,
            work_area=job.target.machine.work_area_mm,
            title=f"samples/{sample} → {target}",
        )
        files[ROOT / "docs" / "targets" / f"{target}-{stem}.svg"] = svg
        page = ROOT / "docs" / "targets" / f"{target}.md"
        block = f"```\n{job.result.code}```\n"
        text = page.read_text(encoding="utf-8")
        files[page] = _BLOCK.sub(lambda m, block=block: m[1] + block + m[2], text)
    return files


def main(argv: list[str]) -> int:
    """Write the generated docs, or with ``--check`` list the stale ones."""
    files = generated()
    stale = [p for p, text in files.items() if not p.exists() or p.read_text("utf-8") != text]
    if "--check" in argv:
        for p in stale:
            print(f"stale: {p.relative_to(ROOT)} (run make docs)", file=sys.stderr)
        return 1 if stale else 0
    for p in stale:
        p.write_text(files[p], encoding="utf-8")
    print(f"docs: wrote {len(stale)} changed file(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
