"""Regenerate the examples of docs/toolpaths.md and their pictures (run by ``make docs``).

Each ``<!-- plan:begin NAME -->`` … ``<!-- plan:end -->`` block of docs/toolpaths.md
gets the command of the example :data:`EXAMPLES` names, what camtool says on stderr
when it plans it (warnings and the ordering/arc-fit notes) and the preview
``docs/toolpaths/NAME.svg`` (the program over the drawing, the tool width of an
offset). The SVGs are deterministic, so ``make_docs.py --check`` compares them byte
for byte.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

from make_docs import ROOT

from camtool.jobs.pipeline import post_file
from camtool.preview import render_preview
from camtool.toolpath.options import PlanOptions

PAGE = ROOT / "docs" / "toolpaths.md"
PICTURES = ROOT / "docs" / "toolpaths"
_BLOCK = re.compile(r"(<!-- plan:begin (\S+) -->\n).*?(<!-- plan:end -->)", re.S)

EXAMPLES: dict[str, tuple[str, str, dict[str, Any]]] = {
    "plate-outside": (
        "plate.dxf",
        "grbl",
        {
            "offset": "outside",
            "tool_diameter": 3.0,
            "depth": 3.0,
            "step_down": 1.0,
            "tabs": 3,
            "lead_in": 2.0,
            "placement": "lower-left",
        },
    ),
    "pocket-concentric": ("pocket.dxf", "grbl", {"offset": "pocket", "tool_diameter": 2.0}),
    "pocket-zigzag": (
        "pocket.dxf",
        "linuxcnc",
        {"offset": "pocket", "tool_diameter": 2.0, "pocket": "zigzag", "pocket_angle_deg": 30.0},
    ),
    "logo-reversals": ("logo.dxf", "pic-mmh", {"order": "reversals"}),
}
"""Example name → (sample, target, :class:`PlanOptions` fields)."""


def toolpath_files() -> dict[Path, str]:
    """docs/toolpaths.md with its example blocks filled in, and each example's SVG."""
    files: dict[Path, str] = {}
    text = PAGE.read_text(encoding="utf-8")

    def fill(marker: re.Match[str]) -> str:
        name = marker[2]
        if name not in EXAMPLES:
            raise SystemExit(f"docs/toolpaths.md: unknown example {name!r}")
        sample, target, options = EXAMPLES[name]
        job = post_file(ROOT / "samples" / sample, target, PlanOptions(**options))
        svg = render_preview(
            ".svg",
            program=job.program,
            drawing=job.placed,
            target=job.target,
            edge_radius_mm=job.edge_radius_mm,
            title=f"samples/{sample} → {target}: {name}",
        )
        files[PICTURES / f"{name}.svg"] = svg.decode("utf-8")
        said = [f"camtool: warning: {w}" for w in job.warnings]
        said += [f"camtool: {line}" for line in job.plan.notes()] if job.plan else []
        command = " ".join(
            ["camtool post", f"samples/{sample}", f"-t {target}", *_flags(options), "-o OUT"]
        )
        body = f"```sh\n{command}\n```\n\n```\n" + "\n".join(said) + "\n```\n\n"
        body += f"![{name}](toolpaths/{name}.svg)\n"
        return marker[1] + body + marker[3]

    files[PAGE] = _BLOCK.sub(fill, text)
    return files


def _flags(options: dict[str, Any]) -> list[str]:
    from camtool.toolpath.options import flag

    out = []
    for key, value in options.items():
        shown = f"{value:g}" if isinstance(value, float) else str(value)
        out.append(f"{flag(key)} {shown}")
    return out
