"""A helper that will draw this job's PNG, started ahead so matplotlib loads on an idle core.

The helper is the accel layer's (:class:`camtool.accel.ahead.HelperAhead`): here is what it
loads (:func:`camtool.preview.raster.preload`) and draws (:func:`~camtool.preview.raster.
scene_png`, the same bytes as drawn in this process). Design notes: docs/internals.md,
``camtool/preview/ahead.py``.
"""

from __future__ import annotations

import pickle
from typing import TYPE_CHECKING

from camtool.accel.ahead import HelperAhead

if TYPE_CHECKING:
    from camtool.preview.scene import Scene

__all__ = ["DRAWER", "draw_ahead", "load_ahead", "start_ahead", "stop_ahead"]


def _load() -> None:
    """In the helper: import what drawing a PNG needs."""
    from camtool.preview.raster import preload

    preload()


def _draw(data: bytes) -> bytes:
    """In the helper: the PNG bytes of the pickled scene ``data``."""
    from camtool.preview.raster import scene_png

    return scene_png(pickle.loads(data))


DRAWER = HelperAhead(_load, _draw)
"""This process's drawing helper (started by :func:`start_ahead`, used by one picture)."""


def start_ahead() -> None:
    """Start the helper that will draw this process's next PNG (see :meth:`HelperAhead.start`)."""
    DRAWER.start()


def load_ahead() -> None:
    """Tell the helper to load matplotlib now: call it where this process leaves a core idle."""
    DRAWER.load()


def draw_ahead(scene: Scene) -> bytes | None:
    """The PNG bytes of ``scene`` drawn by the helper, which then leaves.

    ``None`` when there is no helper, or it sent nothing back: the caller draws it itself
    (:func:`camtool.preview.raster.scene_png`), the same bytes.
    """
    if DRAWER.helper is None:
        return None
    try:
        data = pickle.dumps(scene, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:  # not a scene that pickles: drawn here
        DRAWER.stop()
        return None
    return DRAWER.ask(data)


def stop_ahead() -> None:
    """End the helper if it was not used (idempotent; a command's ``finally``)."""
    DRAWER.stop()
