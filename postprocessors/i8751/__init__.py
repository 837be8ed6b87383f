"""The Intel 8751 serial stepper interface (Intf8751): binary packets over RS-232.

``i8751.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target
from camtool_postprocessors.i8751.dialect import post_processor

if TYPE_CHECKING:
    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.i8751.motion import MOTION

    return MOTION


def _link() -> LinkHooks:
    from camtool_postprocessors.i8751.link import LINK

    return LINK


TARGET = folder_target(__name__, dialect=post_processor, motion=_motion, link=_link)
"""The ``i8751`` target."""
