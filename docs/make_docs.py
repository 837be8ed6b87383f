"""Regenerate the generated parts of docs/ from samples/ (run: ``make docs``).

Every target page ``docs/targets/<target>.md`` names its bundled sample in
its marker, with optional ``post`` options::

    <!-- sample:begin logo.dxf scale=2 format=dump -->
    (generated)
    <!-- sample:end -->

(options: ``scale``, ``feed``, ``format``, ``offset``, ``tool_diameter``,
``fit=WxH``). The page gets the posted program between the markers (at most
:data:`MAX_LINES` lines) and the preview picture
``docs/targets/<target>-<sample>.svg``; for docs/verify.md the verify summary of
the pic-mmh sample between ``<!-- verify:begin -->`` / ``<!-- verify:end -->``
and its preview ``docs/targets/pic-mmh-logo-verify.png``; docs/gallery.md and
its verified pictures (``make_gallery.py``); the planning examples of
docs/toolpaths.md and their pictures (``make_toolpaths.py``). ``--check`` only
reports whether the committed docs are current (exit 1 if not; the PNG, drawn
by matplotlib whose bytes vary between versions, only has to exist); the tests
run it with ``--without-gallery-pictures`` (the gallery page is checked, its
pictures are not made), and compare the pictures the gallery page's own commands
write with the committed ones (tests/docs/test_documented_commands.py).
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

from camtool.jobs.pipeline import OutputOptions, PostJob, post_file, verify_job
from camtool.post.registry import load_target, target_names
from camtool.preview import render_preview
from camtool.toolpath.options import PlanOptions
from camtool.verify.report import summary_lines

ROOT = Path(__file__).resolve().parents[1]
MAX_LINES = 60
"""Longest example shown on a target page; longer ones are cut with a note."""
_BLOCK = re.compile(r"(<!-- sample:begin ([^>]*?) -->\n).*?(<!-- sample:end -->)", re.S)
_TARGETS = re.compile(r"(<!-- targets:begin -->\n).*?(<!-- targets:end -->)", re.S)
_VERIFY = re.compile(r"(<!-- verify:begin -->\n).*?(<!-- verify:end -->)", re.S)
VERIFY_PNG = ROOT / "docs" / "targets" / "pic-mmh-logo-verify.png"


def generated(gallery_pictures: bool = True) -> dict[Path, str]:
    """Every generated docs file with its current content.

    The gallery's pictures only while ``gallery_pictures`` (:func:`make_gallery.gallery_files`).
    """
    files: dict[Path, str] = {}
    for target in target_names():
        found = page_sample(target)
        if found is None:
            raise SystemExit(f"docs/targets/{target}.md: no <!-- sample:begin SAMPLE --> marker")
        page, text, marker = found
        sample = marker[2].split()[0]
        job = post_sample(target, marker[2])
        stem = Path(sample).stem
        title = f"samples/{sample} → {target}"
        svg = render_preview(".svg", program=job.program, target=job.target, title=title)
        files[ROOT / "docs" / "targets" / f"{target}-{stem}.svg"] = svg.decode("utf-8")
        block = f"```\n{_shown(job.result.code)}```\n"
        files[page] = text[: marker.start()] + marker[1] + block + marker[3] + text[marker.end() :]
    index = ROOT / "docs" / "targets" / "index.md"
    table = targets_table()
    text = index.read_text(encoding="utf-8")
    files[index] = _TARGETS.sub(lambda m: m[1] + table + m[2], text)
    job = post_file(ROOT / "samples" / "logo.dxf", "pic-mmh")
    lines = "".join(f"camtool: {line}\n" for line in summary_lines(verify_job(job)))
    page = ROOT / "docs" / "verify.md"
    text = page.read_text(encoding="utf-8")
    files[page] = _VERIFY.sub(lambda m: m[1] + f"```\n{lines}```\n" + m[2], text)
    files.update(job_files())
    from make_gallery import gallery_files

    files.update(gallery_files(gallery_pictures))
    from make_toolpaths import toolpath_files

    files.update(toolpath_files())
    return files


_JOB = re.compile(r"(<!-- job:begin -->\n).*?(<!-- job:end -->)", re.S)


def job_files() -> dict[Path, str]:
    """docs/jobs.md's sample program (its head) and the picture of the sample job."""
    from camtool.importers import read_drawing
    from camtool.jobs.jobfile import load_job
    from camtool.jobs.run import run_job

    drawing = read_drawing(ROOT / "samples" / "part.dxf")
    job = run_job(drawing, load_target("linuxcnc"), load_job(ROOT / "samples" / "part.toml"))
    title = "samples/part.dxf + samples/part.toml → linuxcnc"
    svg = render_preview(".svg", program=job.program, target=job.target, title=title)
    page = ROOT / "docs" / "jobs.md"
    text = page.read_text(encoding="utf-8")
    head = "".join(str(job.result.code).splitlines(keepends=True)[:40]) + "…\n"
    return {
        ROOT / "docs" / "jobs-part.svg": svg.decode("utf-8"),
        page: _JOB.sub(lambda m: m[1] + f"```\n{head}```\n" + m[2], text),
    }


def targets_table() -> str:
    """The Markdown table of the built-in targets for docs/targets/index.md."""
    rows = [
        "| target | machine | formats | from |",
        "|---|---|---|---|",
    ]
    for name in target_names():
        t = load_target(name)
        formats = ", ".join(f"`{f}` ({suffix})" for f, suffix in t.post.formats.items())
        rows.append(f"| [`{name}`]({name}.md) | {t.machine.name} | {formats} | {t.source} |")
    return "\n".join(rows) + "\n"


def page_sample(target: str) -> tuple[Path, str, re.Match[str]] | None:
    """A target's page, its text and its sample marker; ``None`` when either is missing."""
    page = ROOT / "docs" / "targets" / f"{target}.md"
    if not page.is_file():
        return None
    text = page.read_text(encoding="utf-8")
    marker = _BLOCK.search(text)
    return None if marker is None else (page, text, marker)


def post_sample(target: str, spec: str) -> PostJob:
    """Post the sample a marker names (``SAMPLE key=value ...``) for ``target``."""
    sample, *words = spec.split()
    options = dict(word.split("=", 1) for word in words)
    fmt = options.pop("format", None)
    return post_file(
        ROOT / "samples" / sample, target, PlanOptions(**_options(options)), OutputOptions(fmt=fmt)
    )


def _options(words: dict[str, str]) -> dict[str, object]:
    """:class:`PlanOptions` fields from a marker's ``key=value`` words."""
    out: dict[str, object] = {}
    for key, value in words.items():
        if key == "fit":
            w, h = value.lower().split("x")
            out["fit"] = (float(w), float(h))
        elif key == "offset":
            out[key] = value
        elif key in ("scale", "tool_diameter"):
            out[key] = float(value)
        elif key == "feed":
            out["feed_mm_min"] = float(value)
        else:
            raise SystemExit(f"unknown sample option {key!r}")
    return out


def _shown(code: str | bytes) -> str:
    """The example as shown on a page: text, cut after :data:`MAX_LINES` lines."""
    if isinstance(code, bytes):
        raise SystemExit("a binary format cannot be shown on a page: use format=dump")
    lines = code.splitlines(keepends=True)
    if len(lines) <= MAX_LINES:
        return code
    rest = len(lines) - MAX_LINES
    return "".join(lines[:MAX_LINES]) + f"… ({rest} more lines)\n"


def verify_png() -> bytes:
    """The verify preview of samples/logo.dxf on pic-mmh."""
    job = post_file(ROOT / "samples" / "logo.dxf", "pic-mmh")
    return render_preview(VERIFY_PNG, verification=verify_job(job))


def main(argv: list[str]) -> int:
    """Write the generated docs, or with ``--check`` list the stale ones."""
    files = generated(gallery_pictures="--without-gallery-pictures" not in argv)
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
