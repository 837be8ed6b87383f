"""camtool's built-in targets, installed as ``camtool_postprocessors``.

One ``<name>.toml`` per machine (its dialect and its ``[machine]`` table
together), plus ``<stem>.py`` only where the machine needs Python. camtool finds
them like any plugin: pyproject registers :data:`TARGETS` under the entry-point
group ``camtool.postprocessors`` (see :mod:`camtool.post.registry`).
"""

from camtool.post.registry import TomlTargets

TARGETS = TomlTargets(__name__)
"""The provider of every ``<name>.toml`` in this package."""
