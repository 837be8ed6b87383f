"""Toolpath planning: chain, offset, order, and turn contours into a Program."""
