"""Post-processors: write a Program in a target's dialect and read it back."""
