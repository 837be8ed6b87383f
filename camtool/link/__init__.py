"""The send framework: a posted program to the machine over the target's own link.

- :mod:`camtool.link.spec` — a target's ``[link]`` table (:class:`~camtool.link.spec.LinkSpec`),
  its ``LINK`` hooks (:class:`~camtool.link.spec.LinkHooks`) and wire blocks;
- :mod:`camtool.link.plan` — before anything is sent: read back, checked, framed, timed;
- :mod:`camtool.link.sender` — the sans-IO stream and its driver over a pyserial port;
- :mod:`camtool.link.device` — controller simulators, on a pseudo-terminal or in-process.

This package names no machine: each target declares its protocol in its TOML and
brings Python (``postprocessors/<stem>_link.py``) only where it needs it.
"""
