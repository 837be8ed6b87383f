"""LinuxCNC's rs274ngc interpreter on a stepgen machine: RS-274/NGC G-code.

``linuxcnc.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target

if TYPE_CHECKING:
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.linuxcnc.motion import MOTION

    return MOTION


TARGET = folder_target(__name__, motion=_motion)
"""The ``linuxcnc`` target."""
