"""The DC-servo wood router of Angel-11: Matlab-style point arrays, one job per stroke.

``matlab-router.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target
from camtool_postprocessors.matlab_router.dialect import post_processor

if TYPE_CHECKING:
    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.matlab_router.motion import MOTION

    return MOTION


def _link() -> LinkHooks:
    from camtool_postprocessors.matlab_router.link import LINK

    return LINK


TARGET = folder_target(__name__, dialect=post_processor, motion=_motion, link=_link)
"""The ``matlab-router`` target."""
