"""GRBL 1.1 with its default settings: RS-274 G-code, sent by its character-counting protocol.

``grbl.toml`` holds its dialect and machine; the Python it needs is named here.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from camtool.post.registry import folder_target

if TYPE_CHECKING:
    from camtool.link.spec import LinkHooks
    from camtool.verify.motion import MotionHooks


def _motion() -> MotionHooks:
    from camtool_postprocessors.grbl.motion import MOTION

    return MOTION


def _link() -> LinkHooks:
    from camtool_postprocessors.grbl.link import LINK

    return LINK


TARGET = folder_target(__name__, motion=_motion, link=_link)
"""The ``grbl`` target."""
