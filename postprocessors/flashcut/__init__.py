"""The LMM micro machine tool run by a VB6 application (Yanez-07): FlashCut-style G-code.

``flashcut.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target

if TYPE_CHECKING:
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.flashcut.motion import MOTION

    return MOTION


TARGET = folder_target(__name__, motion=_motion)
"""The ``flashcut`` target."""
