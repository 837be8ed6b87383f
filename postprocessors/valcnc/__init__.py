"""ValCNC (Munoz-22): a PIC18F4550 fed one block at a time, G00-G03 with X Y Z I J only.

``valcnc.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target

if TYPE_CHECKING:
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.valcnc.motion import MOTION

    return MOTION


TARGET = folder_target(__name__, motion=_motion)
"""The ``valcnc`` target."""
