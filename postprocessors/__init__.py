"""camtool's built-in targets: one ``<name>.toml`` per machine (dialect and machine together),
plus ``<name>.py`` where the machine needs Python (installed as ``camtool_postprocessors``)."""
