"""Which layers of a DXF drawing are read: ``--layers``, a job's layers, and what it hides.

What the CAD program does not show is not cut: entities on a layer that is off or frozen,
and everything a block reference on a frozen layer places (AutoCAD's rule: freezing the
reference's layer hides the whole block, switching it off hides only the block's entities
on that layer and on layer 0). A layer named by ``--layers`` or a job is read all the same.

Design notes: docs/internals.md, ``camtool/importers/dxf_layers.py``.
"""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

from camtool.importers.dxf_entities import layer_name, layer_of
from camtool.importers.options import layer_list
from camtool.model.errors import InputError


class LayerFilter:
    """Which effective layers are read.

    Those ``--layers`` names (all without it), less the layers the drawing hides (off or
    frozen) unless ``--layers`` or a job names them. Called with a layer name; counts the
    entities it leaves out for being hidden.
    """

    def __init__(
        self,
        wanted: set[str] | None,
        hidden: tuple[dict[str, str], set[str]],
        named: set[str],
    ) -> None:
        self.wanted = wanted
        self.hidden = {k: v for k, v in hidden[0].items() if k not in named}
        self.frozen = {k for k in hidden[1] if k not in named}
        self.dropped: Counter[str] = Counter()
        self.frozen_blocks: Counter[str] = Counter()  # block references hidden whole

    def freezes(self, layer: str) -> bool:
        """Whether a block reference on ``layer`` is hidden with all it holds, and counts it.

        AutoCAD hides everything a block reference places when the reference's layer is
        frozen, whatever the layers of the block's entities; a layer that is only off
        hides the entities on that layer (layer 0 ones included), not the others.
        """
        if layer.casefold() not in self.frozen:
            return False
        self.frozen_blocks[self.hidden.get(layer.casefold(), layer)] += 1
        return True

    def reads(self, layer: str) -> bool:
        """Whether entities on ``layer`` are read (nothing counted: a look ahead)."""
        key = layer.casefold()
        return (self.wanted is None or key in self.wanted) and key not in self.hidden

    def __call__(self, layer: str) -> bool:
        """:meth:`reads`, for an entity being read: one left out for a hidden layer counts."""
        if self.reads(layer):
            return True
        key = layer.casefold()
        if key in self.hidden and (self.wanted is None or key in self.wanted):
            self.dropped[self.hidden[key]] += 1
        return False


def hidden_layers(doc: Any) -> tuple[dict[str, str], set[str]]:
    """The drawing's layers that are off or frozen, by case-folded name; the frozen ones."""
    hidden, frozen = {}, set()
    for layer in doc.layers:
        try:
            cold = bool(layer.is_frozen())
            off = cold or layer.is_off()
        except (AttributeError, TypeError, ValueError):  # a damaged LAYER entry: shown
            cold = off = False
        name = layer_name(str(layer.dxf.name))
        key = name.casefold()
        if off:
            hidden[key] = name
        if cold:
            frozen.add(key)
    return hidden, frozen


def layer_filter(
    path: Path, doc: Any, layers: tuple[str, ...] | None, shown: tuple[str, ...] = ()
) -> LayerFilter:
    """The layer predicate (:class:`LayerFilter`).

    Raises:
        InputError: a name in ``layers`` is no layer of the drawing (the message lists them).
    """
    named = {name.casefold() for name in (*(layers or ()), *shown)}
    if layers is None:
        return LayerFilter(None, hidden_layers(doc), named)
    present = {layer_name(str(layer.dxf.name)) for layer in doc.layers}
    present |= {layer_of(e) for e in doc.modelspace()}
    by_key = {name.casefold(): name for name in present}
    unknown = [name for name in layers if name.casefold() not in by_key]
    if unknown:
        listed = ", ".join(repr(n) for n in unknown)
        raise InputError(
            f"{path}: no layer {listed} in the drawing; its layers are "
            + layer_list(sorted(present, key=str.casefold))
        )
    return LayerFilter({name.casefold() for name in layers}, hidden_layers(doc), named)


def hidden_warnings(path: Path, keep: LayerFilter, invisible: int) -> list[str]:
    """What was left out for being hidden in the drawing, with what cuts it."""
    out = []
    if keep.frozen_blocks:
        count = sum(keep.frozen_blocks.values())
        names = ", ".join(repr(n) for n in sorted(keep.frozen_blocks, key=str.casefold))
        out.append(
            f"{path}: skipped {count} block reference(s) (INSERT) on frozen layer(s) {names} "
            "with everything they place, whatever its layer (hidden, so not cut); name the "
            "layer in --layers or in a job operation to cut them"
        )
    if keep.dropped:
        count = sum(keep.dropped.values())
        names = ", ".join(repr(n) for n in sorted(keep.dropped, key=str.casefold))
        out.append(
            f"{path}: skipped {count} {'entity' if count == 1 else 'entities'} on layer(s) "
            f"{names}, off or frozen in the drawing (hidden, so not cut); name the layer in "
            "--layers or in a job operation to cut it"
        )
    if invisible:
        noun = "entity" if invisible == 1 else "entities"
        out.append(
            f"{path}: skipped {invisible} invisible {noun} (the entity's invisible flag is "
            "set: not shown, so not cut)"
        )
    return out
