"""Regenerate the generated parts of docs/ from samples/ (run: ``make docs``).

For each target page it writes the sample program between the markers
``<!-- sample:begin -->`` / ``<!-- sample:end -->`` and the preview picture
``docs/targets/<target>-<sample>.svg``; for docs/verify.md the verify summary of
the pic-mmh sample between ``<!-- verify:begin -->`` / ``<!-- verify:end -->``
and its preview ``docs/targets/pic-mmh-logo-verify.png``. ``--check`` only
reports whether the committed docs are current (exit 1 if not; the PNG, drawn
by matplotlib whose bytes vary between versions, only has to exist); the tests
run it.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from camtool.pipeline import post_file, verify_job
from camtool.preview import program_svg
from camtool.preview_trace import write_trace_preview
from camtool.verify.verifier import summary_lines

ROOT = Path(__file__).resolve().parents[1]
SAMPLES = {"pic-mmh": "logo.dxf"}
_BLOCK = re.compile(r"(<!-- sample:begin -->\n).*?(<!-- sample:end -->)", re.S)
_VERIFY = re.compile(r"(<!-- verify:begin -->\n).*?(<!-- verify:end -->)", re.S)
VERIFY_PNG = ROOT / "docs" / "targets" / "pic-mmh-logo-verify.png"


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
    job = post_file(ROOT / "samples" / "logo.dxf", "pic-mmh")
    lines = "".join(f"camtool: {line}\n" for line in summary_lines(verify_job(job)))
    page = ROOT / "docs" / "verify.md"
    text = page.read_text(encoding="utf-8")
    files[page] = _VERIFY.sub(lambda m: m[1] + f"```\n{lines}```\n" + m[2], text)
    return files


def verify_png() -> bytes:
    """The verify preview of samples/logo.dxf on pic-mmh."""
    job = post_file(ROOT / "samples" / "logo.dxf", "pic-mmh")
    return write_trace_preview(verify_job(job), VERIFY_PNG)


def main(argv: list[str]) -> int:
    """Write the generated docs, or with ``--check`` list the stale ones."""
    files = generated()
    stale = [p for p, text in files.items() if not p.exists() or p.read_text("utf-8") != text]
    if "--check" in argv:
        if not VERIFY_PNG.is_file():
            stale.append(VERIFY_PNG)
        for p in stale:
            print(f"stale: {p.relative_to(ROOT)} (run make docs)", file=sys.stderr)
        return 1 if stale else 0
    for p in stale:
        p.write_text(files[p], encoding="utf-8")
    VERIFY_PNG.write_bytes(verify_png())
    print(f"docs: wrote {len(stale) + 1} file(s)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
