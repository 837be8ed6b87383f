"""The ``xy-then`` test machine: ``xy-then.toml`` and the motion model of ``motion.py``."""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target

if TYPE_CHECKING:
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from tests.plugins.xythen_plugin.xy_then.motion import MOTION

    return MOTION


TARGET = folder_target(__name__, motion=_motion)
"""The ``xy-then`` target."""
