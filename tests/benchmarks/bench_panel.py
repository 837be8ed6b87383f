"""A panelised laser-cut SVG of tens of thousands of curves, posted with tool offsets.

Run as ``python tests/benchmarks/bench_panel.py`` (or ``make bench``); not collected by
pytest. Needs the corpus (``make corpus``) for Inkscape's examples.

The drawing: Inkscape's ``live-path-effects-gears.svg`` (Debian's ``inkscape`` package: a
sheet of gears, each outline a path of Bézier curves), its paths copied side by side in a
grid until the page holds at least :data:`CURVES` curves, as a nesting program lays out
one part many times for a laser. The traits of the issue's panel (55 542 curves, the same
parts repeated). Built once per run into a temporary folder.

Timed (the faster of two runs, ``bench_svg.best``; wall, cached bytecode):
``camtool post PANEL.svg -t grbl --fit 100 100 --offset outside --tool-diameter 1``,
the command of the issue (its stages are told on stderr as it runs). The goal is 30 s
(no peer: the time a user waits).
"""

from __future__ import annotations

import re
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_svg import best, corpus_dirs
from table import camtool_env, row

GEARS = Path("pkg/inkscape/usr/share/inkscape/examples/live-path-effects-gears.svg")
"""The part, relative to a corpus directory."""
CURVES = 55_000
"""Fewest curves on the page."""
GOAL_S = 30.0
SVG_NS = "http://www.w3.org/2000/svg"
_CURVE = re.compile(r"[CcSsQqTtAa]")
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def _part() -> Path | None:
    for folder in corpus_dirs():
        if (folder / GEARS).is_file():
            return folder / GEARS
    return None


def _curves(d: str) -> int:
    """Curves in path data ``d``: each curve command's coordinate groups."""
    count = 0
    for cmd, args in re.findall(r"([A-Za-z])([^A-Za-z]*)", d):
        if _CURVE.fullmatch(cmd):
            per = {"c": 6, "s": 4, "q": 4, "t": 2, "a": 7}[cmd.lower()]
            count += max(1, len(_NUMBER.findall(args)) // per)
    return count


def build_panel(part: Path, out: Path) -> tuple[int, int]:
    """The panel SVG at ``out`` from the part's paths; returns (copies, curves)."""
    root = ET.parse(part).getroot()
    paths = [p for p in root.iter(f"{{{SVG_NS}}}path") if p.get("d")]
    per_copy = sum(_curves(p.get("d", "")) for p in paths)
    copies = -(-CURVES // per_copy)
    columns = int(copies**0.5) + 1
    ET.register_namespace("", SVG_NS)
    page = ET.Element(f"{{{SVG_NS}}}svg", {"width": "800mm", "height": "800mm"})
    for k in range(copies):
        x, y = (k % columns) * 800.0, (k // columns) * 1000.0
        group = ET.SubElement(page, f"{{{SVG_NS}}}g", {"transform": f"translate({x},{y})"})
        for p in paths:
            attrs = {"d": p.get("d", ""), "style": "fill:none;stroke:#000000"}
            if p.get("transform"):
                attrs["transform"] = p.get("transform", "")
            ET.SubElement(group, f"{{{SVG_NS}}}path", attrs)
    tmp = out.with_suffix(".tmp")
    ET.ElementTree(page).write(tmp, encoding="utf-8", xml_declaration=True)
    tmp.replace(out)
    return copies, copies * per_copy


def main() -> int:
    """Build the panel, time the post, print the row."""
    job = "panel SVG (gears, ≥ 55 000 curves) --fit 100 100 --offset outside --tool-diameter 1"
    part = _part()
    if part is None:
        row(job, "—", "—", "—", None, "absolute", "< 30 s", False, "no corpus: inkscape missing")
        return 0
    folder = Path(tempfile.gettempdir()) / "camtool-bench-panel"
    folder.mkdir(exist_ok=True)
    panel = folder / "panel.svg"
    copies, curves = build_panel(part, panel)
    out = folder / "panel.gcode"
    cmd = [sys.executable, "-m", "camtool", "post", str(panel), "-t", "grbl", "-o", str(out)]
    cmd += ["--fit", "100", "100", "--offset", "outside", "--tool-diameter", "1"]
    got = best(cmd, camtool_env())
    wall = float(got["wall"])  # type: ignore[arg-type]
    ok = got["code"] == 0
    note = (
        f"{copies} copies, {curves} curves, {panel.stat().st_size // 1024} KiB; "
        f"exit {got['code']}; peak {int(got['kib']) // 1024} MiB"  # type: ignore[call-overload]
    )
    print(f"bench_panel: {wall:.2f} s, {note}", file=sys.stderr)
    row(job, f"{wall:.2f} s", "—", "—", None, "absolute", "< 30 s", ok and wall < GOAL_S, note)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
