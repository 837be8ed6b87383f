"""A test plugin package of targets, like camtool's built-ins (``camtool_postprocessors``).

One machine folder, ``xy_then/``: ``xy-then.toml`` (its word-address dialect and its machine
together), ``motion.py`` (its ``MOTION``: a line interpolator that steps X, then Y, and a
timing model of one second per block) and ``__init__.py``, which builds its ``TARGET``.
A distribution would register :data:`TARGETS` under the entry-point group
``camtool.postprocessors``, e.g. ``xythen = "xythen_plugin:TARGETS"``;
tests/plugins/test_plugin_motion.py adds that entry point to the discovery instead of
installing one. Nothing in ``camtool/`` names it.
"""

from camtool.post.registry import TargetPackage

TARGETS = TargetPackage(__name__)
"""The provider of every ``<name>.toml`` in this package (here: ``xy-then``)."""
