"""Machine profile: what a target's machine can do and how it moves.

Loaded from the ``[machine]`` table of a target's TOML file (and overridable
with ``--machine FILE.toml``). Lengths in mm unless the name says otherwise.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, fields
from pathlib import Path
from typing import Any

from camtool.errors import InputError
from camtool.geometry import BBox


@dataclass(frozen=True, kw_only=True)
class Machine:
    """A machine profile.

    Attributes:
        name: profile name, e.g. ``"MMH-1 (GMM)"``.
        steps_per_mm: motor steps per mm per axis ``(x, y, z)`` as the controller
            assumes them.
        work_area_mm: ``(xmin, ymin, xmax, ymax)`` reachable by the tool, mm.
        has_z: whether programs may move Z.
        max_step_rate_hz: highest step frequency the controller sustains, Hz
            (0 = no limit known).
        source: where the numbers come from (a thesis section).
    """

    name: str
    steps_per_mm: tuple[float, float, float]
    work_area_mm: BBox
    has_z: bool = True
    max_step_rate_hz: float = 0.0
    source: str = ""

    def step_rate_hz(self, feed_mm_min: float) -> float:
        """Step frequency of the fastest axis moving alone at ``feed_mm_min``, Hz.

        seed-000 Eq. 3.1: f = d · F / 60 with d in steps/mm and F in mm/min.
        """
        return max(self.steps_per_mm[:2]) * feed_mm_min / 60.0

    def outside_work_area(self, box: BBox, eps_mm: float = 1e-9) -> bool:
        """True when ``box`` reaches beyond the work area by more than ``eps_mm``."""
        x0, y0, x1, y1 = self.work_area_mm
        return (
            box[0] < x0 - eps_mm
            or box[1] < y0 - eps_mm
            or box[2] > x1 + eps_mm
            or box[3] > y1 + eps_mm
        )


def machine_from_table(table: Mapping[str, Any], *, where: str) -> Machine:
    """Build a :class:`Machine` from a TOML ``[machine]`` table.

    Raises:
        InputError: an unknown key or a value of the wrong shape, naming ``where``.
    """
    known = {f.name for f in fields(Machine)}
    unknown = sorted(set(table) - known)
    if unknown:
        raise InputError(f"{where}: unknown machine key(s) {unknown}; known: {sorted(known)}")
    try:
        steps = tuple(float(v) for v in table["steps_per_mm"])
        area = tuple(float(v) for v in table["work_area_mm"])
        if len(steps) != 3 or len(area) != 4:
            raise ValueError("steps_per_mm needs 3 values and work_area_mm 4")
        return Machine(
            name=str(table["name"]),
            steps_per_mm=(steps[0], steps[1], steps[2]),
            work_area_mm=(area[0], area[1], area[2], area[3]),
            has_z=bool(table.get("has_z", True)),
            max_step_rate_hz=float(table.get("max_step_rate_hz", 0.0)),
            source=str(table.get("source", "")),
        )
    except (KeyError, TypeError, ValueError) as exc:
        raise InputError(f"{where}: invalid machine profile ({exc})") from exc


def load_toml(path: Path) -> dict[str, Any]:
    """Read a TOML file.

    Raises:
        InputError: the file is missing or not valid TOML.
    """
    try:
        with path.open("rb") as fh:
            return tomllib.load(fh)
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror or exc})") from exc
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{path}: not valid TOML ({exc})") from exc
