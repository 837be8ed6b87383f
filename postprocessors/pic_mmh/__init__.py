"""The GMM micro machine tool's PIC18F8720 controller (UNAM-GMM): fixed-width µm G-code.

``pic-mmh.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target
from camtool_postprocessors.pic_mmh.dialect import post_processor

if TYPE_CHECKING:
    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.pic_mmh.motion import MOTION

    return MOTION


def _link() -> LinkHooks:
    from camtool_postprocessors.pic_mmh.link import LINK

    return LINK


TARGET = folder_target(__name__, dialect=post_processor, motion=_motion, link=_link)
"""The ``pic-mmh`` target."""
