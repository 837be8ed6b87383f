"""The error sources a simulation can switch off, one at a time, for the error budget.

Design notes: docs/internals.md, ``camtool/verify/sources.py``.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

SOURCES: dict[str, str] = {
    "interpolation": "interpolation and step quantisation",
    "chords": "chords/segmentation",
    "scale": "steps/mm scale",
    "backlash": "backlash residual",
    "dynamics": "dynamics",
    "rounding": "rounding of the emitted numbers",
}
"""Every source switch, by name, with the words reports use for it (in budget order)."""

SIMULATED = ("interpolation", "chords", "scale", "backlash")
"""The sources the step simulator honours itself (the rest come from a machine's pieces)."""


@dataclass(frozen=True, kw_only=True)
class Sources:
    """Which error sources a simulation models (all on: the full model).

    Attributes:
        interpolation: the interpolator's staircase and the rounding of positions
            to whole steps; off: the motors follow the commanded geometry
            continuously (positions in fractional steps, lines straight, native
            arcs exact).
        chords: a controller's cutting of arcs into chords (``arc = "chords"``);
            off: chords far below a step (the arc itself, to within 1/10 step).
        scale: the true steps/mm differing from the nominal ones; off: the
            mechanics make exactly the steps/mm the controller assumes.
        backlash: the true backlash and the controller's compensation (what is
            left is the residual); off: no play and no compensation.
        dynamics: what a machine's own pieces model of time-dependent motion (a
            timer's overshoot, a servo's lag); off: the ideal version of the piece.
        rounding: the code's numbers as written; off: the unrounded plan (only
            known when the plan is at hand, not from the code alone).
        sampled_lines: not a source: with ``interpolation`` off, every sample of a
            line a row, as the drawing comparison needs (it thins a trace to every
            k-th row, k read from its first rows, so its rows must be of one length);
            ``False``: a line's straight rest in longer rows
            (:meth:`~camtool.verify.simulate.IdealController._line_shape`).
    """

    interpolation: bool = True
    chords: bool = True
    scale: bool = True
    backlash: bool = True
    dynamics: bool = True
    rounding: bool = True
    sampled_lines: bool = False

    def without(self, name: str) -> Sources:
        """These switches with ``name`` off.

        Raises:
            ValueError: ``name`` is not a source (one of :data:`SOURCES`).
        """
        if name not in SOURCES:
            raise ValueError(f"unknown error source {name!r}; valid: {', '.join(SOURCES)}")
        return dataclasses.replace(self, **{name: False})

    @property
    def off(self) -> tuple[str, ...]:
        """The names switched off, in :data:`SOURCES` order."""
        return tuple(name for name in SOURCES if not getattr(self, name))


ALL = Sources()
"""Every source on: the full model, what a verification reports."""
