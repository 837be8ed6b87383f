"""How a DXF entity is drawn: its colour and linetype, resolved through layer and block.

Design notes: docs/internals.md, ``camtool/importers/dxf_style.py``.
"""

from __future__ import annotations

from typing import Any

from camtool.model.construction import LAYER_FLAGS, dashed_name

Style = tuple[str, str]
"""``(colour, linetype)``: ``"#rrggbb"`` (``""``: unknown) and the upper-case linetype
name when it is not continuous (``""``: continuous), or a layer's flag that says its
entities are not the part (:data:`~camtool.model.construction.LAYER_FLAGS`)."""

CONTINUOUS: Style = ("", "")
"""No colour known, continuous."""


class StyleResolver:
    """Resolves entities' styles in one document; layers and linetypes looked up once."""

    def __init__(self, doc: Any) -> None:
        self.doc = doc
        self._layers: dict[str, Style] = {}
        self._dashed: dict[str, bool] = {}
        self._by_decoded: dict[str, Any] | None = None

    def style(self, entity: Any, layer: str, block: Style = CONTINUOUS) -> Style:
        """The colour and linetype ``entity`` on effective ``layer`` is drawn with.

        Args:
            entity: an ezdxf graphic entity.
            layer: its effective layer (a block entity on layer ``0`` takes the INSERT's).
            block: the style of the INSERT that places it (for BYBLOCK).
        """
        dxf = entity.dxf
        if not dxf.is_supported("color"):
            return self.layer_style(layer)
        by_layer = self.layer_style(layer)
        colour = self._colour(dxf, by_layer[0], block[0])
        if by_layer[1] in LAYER_FLAGS:  # the layer's, whatever line the entity is drawn in
            return colour, by_layer[1]
        linetype = str(dxf.get("linetype", "BYLAYER") or "BYLAYER").upper()
        if linetype == "BYLAYER":
            dashed = by_layer[1]
        elif linetype == "BYBLOCK":
            dashed = block[1]
        else:
            dashed = linetype if self._is_dashed(linetype) else ""
        return colour, dashed

    def layer_style(self, layer: str) -> Style:
        """The colour and linetype of ``layer`` (white and continuous when it is missing).

        The linetype is ``"CONSTRUCTION"`` for a LibreCAD construction layer and
        ``"NO-PLOT"`` for a layer whose plot flag is off (:func:`layer_flag`).
        """
        found = self._layers.get(layer)
        if found is None:
            found = self._layers[layer] = self._read_layer(layer)
        return found

    def _read_layer(self, name: str) -> Style:
        from ezdxf.colors import aci2rgb

        table = self.doc.layers
        record = table.get(name) if table.has_entry(name) else self._decoded().get(name.casefold())
        if record is None:
            return "#ffffff", ""
        dxf = record.dxf
        true = dxf.get("true_color")
        aci = abs(int(dxf.get("color", 7) or 7))
        colour = _hex_int(true) if true is not None else _hex(aci2rgb(aci if aci < 256 else 7))
        flag = layer_flag(record)
        if flag:
            return colour, flag
        linetype = str(dxf.get("linetype", "CONTINUOUS") or "CONTINUOUS").upper()
        return colour, (linetype if self._is_dashed(linetype) else "")

    def _decoded(self) -> dict[str, Any]:
        """The layer table's records by decoded, case-folded name, made on first need.

        The names entities give (:func:`~camtool.importers.dxf_entities.layer_name`).
        """
        if self._by_decoded is None:
            from camtool.importers.dxf_entities import layer_name

            self._by_decoded = {}
            for record in self.doc.layers:
                self._by_decoded.setdefault(layer_name(str(record.dxf.name)).casefold(), record)
        return self._by_decoded

    def _colour(self, dxf: Any, layer_colour: str, block_colour: str) -> str:
        from ezdxf.colors import aci2rgb

        true = dxf.get("true_color")
        if true is not None:
            return _hex_int(true)
        aci = int(dxf.get("color", 256))
        if aci == 256:
            return layer_colour
        if aci == 0:
            return block_colour or "#ffffff"
        return _hex(aci2rgb(aci)) if 0 < aci < 256 else layer_colour

    def _is_dashed(self, name: str) -> bool:
        found = self._dashed.get(name)
        if found is None:
            found = self._dashed[name] = self._judge(name)
        return found

    def _judge(self, name: str) -> bool:
        """Whether linetype ``name`` is not continuous.

        By its pattern where the file gives one: a gap in it (a negative element, group 49;
        a complex linetype's text and shapes sit in such gaps, so ``---GAS---`` is not
        continuous); else by its name: an LTYPE entry without pattern groups (as dxflib
        writes them) or one not in the table, which CAD programs draw by name.
        """
        if name in ("CONTINUOUS", "BYLAYER", "BYBLOCK", ""):
            return False
        table = self.doc.linetypes
        if table.has_entry(name):
            try:
                tags = table.get(name).pattern_tags.tags
                if len(tags):
                    return any(tag.code == 49 and float(tag.value) < 0 for tag in tags)
            except (ValueError, TypeError, AttributeError):
                pass  # a damaged pattern: judged by its name
        return dashed_name(name)


def layer_flag(record: Any) -> str:
    """What the LAYER table entry ``record`` says of its entities: not the part, or ``""``.

    ``"CONSTRUCTION"``: LibreCAD's construction layer, written as the layer's extended data
    of the application ``LibreCad`` with a 1070 value of 1 (LibreCAD's DXF filter reads it
    so); ``"NO-PLOT"``: the plot flag (group 290) is 0, the layer is not printed (AutoCAD's
    and LibreCAD's layer property). A damaged entry is read as a plain layer.
    """
    try:
        if record.has_xdata("LibreCad") and any(
            tag.code == 1070 and int(tag.value) == 1 for tag in record.get_xdata("LibreCad")
        ):
            return "CONSTRUCTION"
        if int(record.dxf.get("plot", 1)) == 0:
            return "NO-PLOT"
    except (AttributeError, TypeError, ValueError):
        pass
    return ""


def _hex(rgb: Any) -> str:
    r, g, b = (max(0, min(255, int(v))) for v in rgb)
    return f"#{r:02x}{g:02x}{b:02x}"


def _hex_int(value: Any) -> str:
    """A DXF true colour (group 420: 0x00RRGGBB) as ``#rrggbb``."""
    v = int(value) & 0xFFFFFF
    return f"#{v:06x}"
