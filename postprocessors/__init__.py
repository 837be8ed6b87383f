"""camtool's built-in targets (installed as ``camtool_postprocessors``).

One ``<name>.toml`` per machine (dialect and machine together), plus ``<name>.py`` where the
machine needs Python.
"""
