"""Geometry algorithms shared by importers and planner: curve and arc fitting, chords."""
