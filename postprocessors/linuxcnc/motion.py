"""Motion model of a LinuxCNC stepgen machine (``linuxcnc``) for the verifier.

Its stepgen follows the commanded position to the nearest step (the generic
``bresenham`` line) and its arcs are modelled as fine ``sagitta`` chords; the
``linuxcnc`` timing model is the generic rest-to-rest trapezoid
(:class:`camtool.verify.timing.TrapezoidTiming`): exact in exact-stop mode
(G61.1), an upper bound of the time LinuxCNC's planner blends in G64. The INI
file sets acceleration and maximum rate (the profile's ``[machine.timing]``).
"""

from __future__ import annotations

from camtool.verify.motion import MotionHooks, timing_class
from camtool.verify.timing import TrapezoidTiming

MOTION = MotionHooks(timing={"linuxcnc": timing_class(TrapezoidTiming)})
"""What ``linuxcnc`` adds to the verifier: its timing model's name."""
