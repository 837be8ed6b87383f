"""camtool's built-in targets, installed as ``camtool_postprocessors``.

One folder per machine: ``<stem>/<name>.toml`` (its dialect and its ``[machine]`` table
together) and an ``__init__.py`` that builds its :class:`~camtool.post.base.Target` from
that file and the Python it names (dialect, motion model, link). camtool finds them like any
plugin: pyproject registers :data:`TARGETS` under the entry-point group
``camtool.postprocessors`` (see :mod:`camtool.post.registry`).
"""

from camtool.post.registry import TargetPackage

TARGETS = TargetPackage(__name__)
"""The provider of every machine folder (and ``<name>.toml``) in this package."""
