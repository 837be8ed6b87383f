"""The model: shapes, programs, machine profiles, units and errors (imports nothing of camtool)."""
