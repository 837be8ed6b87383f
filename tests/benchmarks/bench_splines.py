"""A DXF of thousands of SPLINEs: ``camtool inspect`` and the travel refusal of ``post``.

Run as ``python tests/benchmarks/bench_splines.py`` (or ``make bench``); not collected by
pytest. Needs the corpus (``make corpus``) for the Tango icon theme.

The drawing: every Tango icon of the corpus (Debian's ``tango-icon-theme``, the same 213
icons as ``bench_svg.py``), tiled as there on a 192 × 180 mm page, each outline (an SVG
subpath of Bézier curves, read with svgelements) joined into one cubic B-spline by ezdxf
(:func:`ezdxf.math.bezier_to_bspline`, knots of multiplicity 3 at the joins, as a CAD
program exports a curve drawn in pieces) and written as a SPLINE of a DXF R2000 file. The
traits of dxf2gcode's ``DRAAK.dxf`` (a 1.9 MB drawing of 1 186 SPLINEs, most of them many
spans long): thousands of multi-span splines. Built once per run into a temporary folder.

Timed (the faster of two runs, ``bench_svg.best``; wall, cached bytecode): ``camtool
inspect`` of the drawing, and ``camtool post`` of it to pic-mmh, whose 10 × 7 mm travel
refuses the page (exit 1): the time to reach the refusal. The goal is 5 s for each (no
peer: the time a user waits for a drawing of this kind). DRAAK.dxf itself (not in a package
this machine reaches) in docs/performance.md.
"""

from __future__ import annotations

import math
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_svg import CELL_H, CELL_W, COLUMNS, ICON_MM, best, icons
from table import camtool_env, row

GOAL_S = 5.0


def _along(a: tuple[float, float], b: tuple[float, float], f: float) -> tuple[float, float]:
    return (a[0] + (b[0] - a[0]) * f, a[1] + (b[1] - a[1]) * f)


def _outlines(path: Path) -> list[list[tuple[tuple[float, float], ...]]]:
    """Each subpath of the icon at ``path`` as its cubic Béziers (lines and quadratics raised)."""
    import svgelements as se

    out: list[list[tuple[tuple[float, float], ...]]] = []
    for element in se.SVG.parse(str(path)).elements():
        if not isinstance(element, se.Shape):
            continue
        for sub in se.Path(element).as_subpaths():
            curves: list[tuple[tuple[float, float], ...]] = []
            for seg in sub:
                s = (float(seg.start.x), float(seg.start.y)) if seg.start is not None else None
                e = (float(seg.end.x), float(seg.end.y)) if seg.end is not None else None
                if s is None or e is None:
                    continue
                if isinstance(seg, se.CubicBezier):
                    c1, c2 = seg.control1, seg.control2
                    curves.append((s, (float(c1.x), float(c1.y)), (float(c2.x), float(c2.y)), e))
                elif isinstance(seg, se.QuadraticBezier):
                    c = (float(seg.control.x), float(seg.control.y))
                    curves.append((s, _along(s, c, 2 / 3), _along(e, c, 2 / 3), e))
                elif isinstance(seg, se.Line | se.Close) and s != e:
                    curves.append((s, _along(s, e, 1 / 3), _along(s, e, 2 / 3), e))
            if curves:
                out.append(curves)
    return out


def build_dxf(paths: list[Path], out: Path) -> int:
    """Write the tiled drawing to ``out``; returns the number of SPLINEs."""
    import ezdxf
    from ezdxf.math import Bezier4P, Vec3, bezier_to_bspline

    doc = ezdxf.new("R2000", units=4)  # mm
    msp = doc.modelspace()
    scale = ICON_MM / 48.0
    count = 0
    for k, path in enumerate(paths):
        x0 = 0.5 + CELL_W * (k % COLUMNS)
        y0 = 180.0 - 0.5 - CELL_H * (k // COLUMNS)
        for curves in _outlines(path):
            placed = [
                Bezier4P([Vec3(x0 + scale * x, y0 - scale * y, 0.0) for x, y in c]) for c in curves
            ]
            if all(math.dist(c[0], c[-1]) < 1e-9 for c in curves):
                continue
            spline = bezier_to_bspline(placed)
            msp.add_spline(dxfattribs={"degree": 3}).apply_construction_tool(spline)
            count += 1
    doc.saveas(out)
    return count


def main() -> int:
    paths = icons()
    job = "DXF of {n} multi-span SPLINEs (Tango outlines, {size:.1f} MB): camtool {what}"
    if not paths:
        print("bench_splines: no Tango icons (make corpus)", file=sys.stderr)
        return 0
    env = camtool_env()
    camtool = [sys.executable, "-m", "camtool"]
    with tempfile.TemporaryDirectory() as tmp:
        drawing = Path(tmp) / "splines.dxf"
        n = build_dxf(paths, drawing)
        size = drawing.stat().st_size / 1e6
        subprocess.run([*camtool, "targets"], env=env, capture_output=True)  # bytecode
        for what, cmd, code in (
            ("inspect", [*camtool, "inspect", str(drawing)], 0),
            (
                "post to pic-mmh, refused on travel",
                [*camtool, "post", str(drawing), "-t", "pic-mmh", "-o", str(Path(tmp) / "o.pic")],
                1,
            ),
        ):
            got = best(cmd, env)
            wall, mb = float(got["wall"]), int(got["kib"]) * 1024 / 1e6
            ok = got["code"] == code
            row(
                job.format(n=n, size=size, what=what),
                f"{wall:.2f} s, {mb:.0f} MB" + ("" if ok else f" (exit {got['code']})"),
                "—",
                "—",
                None,
                "absolute",
                f"< {GOAL_S:g} s",
                ok and wall < GOAL_S,
                "" if ok else str(got["err"])[-300:],
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
