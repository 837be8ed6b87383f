"""The word-address writer's closing warnings: one per kind of thing dropped or converted.

:class:`~camtool.post.wordaddress_write.BlockWriter` counts what its dialect cannot write as
it was asked (a feed without an F word, a spindle speed without S, a move split into a Z and
an XY block, an arc written as chords...) and words each kind once, after the last block.
"""

from __future__ import annotations

import itertools
from collections import Counter
from collections.abc import Iterable, Sequence

from camtool.model.program import Program
from camtool.post.numfmt import NumberFormat
from camtool.post.wordaddress_spec import WordAddressSpec


def closing_warnings(
    spec: WordAddressSpec, counts: Counter[str], grid_error_mm: float, chord_tolerance_mm: float
) -> list[str]:
    """One warning per kind of thing dropped or converted, in a fixed order.

    Args:
        spec: the dialect (its name, codes, quantum and step grids).
        counts: what the writer counted, by kind (``"feed"``, ``"Spindle"``, ``"speed"``,
            ``"Coolant"``, ``"Dwell"``, ``"ToolChange"``, ``"Home"``, ``"PathControl"``,
            ``"z-split"``, ``"arc-chords"``, ``"far-centre"``, ``"plane-chords"``,
            ``"tiny-arc"``); kinds
            not counted give no warning.
        grid_error_mm: the largest change of a coordinate rounded to a step grid, mm.
        chord_tolerance_mm: the chord deviation allowed to an arc written as chords, mm
            (at least twice the dialect's quantum).
    """
    name, d = spec.name, counts
    i_word = spec.words.get("I")  # a dialect without arcs has none
    i_digits = i_word.number.int_digits if i_word is not None else None
    codes = [c for c in (spec.spindle_cw, spec.spindle_ccw) if c]
    spindle = f"{'/'.join(codes)} take" if len(codes) > 1 else f"{''.join(codes)} takes"
    texts = {
        "feed": f"{name} has no F word: the feed of {d['feed']} cutting block(s) is not "
        "written; the machine moves at its own speed",
        "Spindle": f"{name} has no spindle command: {d['Spindle']} spindle command(s) "
        "dropped; switch the spindle (or tool) on and off by hand",
        "speed": f"{name}'s {spindle} no S word: {d['speed']} spindle speed(s) not "
        "written; set the speed on the machine",
        "Coolant": f"{name} has no code for {d['Coolant']} coolant command(s) (M7 mist, M8 "
        "flood or a laser's air assist, M9 off): dropped; switch it by hand",
        "Dwell": f"{name} has no dwell: {d['Dwell']} pause(s) dropped",
        "ToolChange": f"{name} has no tool change: {d['ToolChange']} tool change(s) "
        "dropped; change tools by hand",
        "Home": f"{name}: {d['Home']} G28/G30/G53 return(s) to a machine position "
        "dropped (camtool does not write them for it); move there by hand if the job needs it",
        "PathControl": f"{name} has no path control code: {d['PathControl']} G61/G61.1/G64 "
        "mode(s) dropped; the machine's own mode applies",
        "z-split": f"{d['z-split']} move(s) changing XY and Z together written as a Z block "
        f"and an XY block (Z first when rising, last when plunging): {name} puts Z moves in "
        "blocks of their own",
        "arc-chords": f"arcs that no printable centre lets {name}'s arc check accept at "
        f"{spec.quantum_mm():g} mm written as {d['arc-chords']} straight chord(s) "
        f"within {max(2.0 * spec.quantum_mm(), chord_tolerance_mm):g} mm of them",
        "far-centre": f"{d['far-centre']} arc(s) with a centre farther away than {name}'s "
        f"I and J write ({i_digits} integer digits): almost "
        f"straight, written as chords within {max(2.0 * spec.quantum_mm(), chord_tolerance_mm):g}"
        " mm of them",
        "plane-chords": f"{d['plane-chords']} arc(s) in the ZX or YZ plane whose printed "
        f"numbers {name}'s arc check refuses, or too small to print, written as their "
        "chords (a G-code file's within 0.001 mm, as read)",
        "tiny-arc": f"{d['tiny-arc']} arc(s) too small for the "
        f"{spec.quantum_mm():g} mm the dialect writes were written as straight lines "
        "(or left out when both ends print the same)",
    }
    out = [texts[kind] for kind in texts if d[kind]]
    if grid_error_mm > 0:
        grids = {w.number.grid_mm for w in spec.words.values() if w.number.grid_mm}
        grid = ", ".join(f"{g:g}" for g in sorted(grids))
        out.append(
            f"coordinates rounded to the {grid} mm step grid of {name}: largest change "
            f"{grid_error_mm:.4f} mm"
        )
    return out


def rounding_warnings(
    spec: WordAddressSpec, program: Program, steps_per_mm: Sequence[float], tolerance_mm: float
) -> list[str]:
    """Warnings when the X and Y, or the Z, words move the program's positions too far.

    A dialect whose words write fewer decimals than the tolerance needs (a target file's
    ``decimals = 0``: whole millimetres) moves each position up to half its step, and a
    depth too (``--depth 1.5`` written as ``Z-2``). Where the largest change, measured on
    the program's moves (``|v − round(v / s)·s|``, ``s`` the word's
    :meth:`~camtool.post.numfmt.NumberFormat.resolution_mm`), is more than
    ``tolerance_mm`` and more than half a motor step of the axis (the machine cannot stand
    nearer), the user is told the step and how far. Words on a step grid are warned of by
    their grid error (:func:`closing_warnings`). Nothing is measured where the step is fine
    enough (half of it within both limits), so the usual dialects pay nothing.

    Args:
        spec: the dialect.
        program: the program written, mm.
        steps_per_mm: the machine's motor steps per mm, ``(x, y, z)``.
        tolerance_mm: how far a position may move, mm (``--tolerance``).
    """
    out = []
    allowed = max(tolerance_mm, 0.5 / min(steps_per_mm[:2]))
    plane = _coarse(spec, "XY", allowed)
    if plane is not None:
        xy = itertools.chain.from_iterable((m.x, m.y) for m in program.moves)
        change, _, _ = _largest_change(xy, plane)
        if change > allowed:
            out.append(
                f"{spec.name} writes X and Y to {plane.resolution_mm():g} mm: positions written "
                f"up to {change:.4f} mm from the toolpath, more than the {tolerance_mm:g} mm "
                "tolerance (--tolerance); give its X and Y words more decimals (target file: "
                "decimals), or check the part with --verify"
            )
    allowed = max(tolerance_mm, 0.5 / steps_per_mm[2])
    height = _coarse(spec, "Z", allowed)
    if height is not None:
        z = (m.z for m in program.moves if m.z is not None)
        change, planned, written = _largest_change(z, height)
        if change > allowed:
            step = height.resolution_mm()
            out.append(
                f"{spec.name} writes Z to {step:g} mm: heights written up to {change:.4f} mm "
                f"from those planned (Z{planned:g} as Z{written:g}), more than the "
                f"{tolerance_mm:g} mm tolerance; give depths and heights in steps of "
                f"{step:g} mm (--depth, --step-down, --safe-z), or its Z word more decimals"
            )
    return out


def _coarse(spec: WordAddressSpec, letters: str, allowed: float) -> NumberFormat | None:
    """The coarsest format of the words ``letters`` when half its step is over ``allowed`` mm.

    ``None`` where it is not, or where a word is missing or on a step grid.
    """
    words = [spec.words[c].number for c in letters if c in spec.words]
    if not words or any(w.grid_mm is not None for w in words):
        return None
    number = max(words, key=lambda w: w.resolution_mm())
    return number if number.resolution_mm() / 2.0 > allowed else None


def _largest_change(numbers: Iterable[float], number: NumberFormat) -> tuple[float, float, float]:
    """``(change, value, written)`` of the finite number that ``number`` moves most, mm.

    Found on the step (``|v − round(v / s)·s|``: a tie moves half a step either way), then
    written and read back by ``number`` itself (half away from zero: ``-2.5`` as ``-3``).
    ``(0, 0, 0)`` without finite numbers. (numpy is loaded here, for a coarse dialect only.)
    """
    import numpy as np

    values = np.fromiter(numbers, np.float64)
    values = values[np.isfinite(values)]
    if not len(values):
        return 0.0, 0.0, 0.0
    step = number.resolution_mm()
    value = float(values[int(np.argmax(np.abs(np.rint(values / step) * step - values)))])
    written = number.parse(number.format(value)) + 0.0  # -0.0 reads as 0
    return abs(written - value), value, written
