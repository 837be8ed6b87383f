"""The send framework: a posted program to the machine over the target's own link.

Design notes: docs/internals.md, ``camtool/link/__init__.py``.
"""
