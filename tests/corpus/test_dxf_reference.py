"""The corpus DXFs as camtool reads them lie on the curves ezdxf itself draws.

An independent reading of every sampled corpus drawing (LibreCAD's parts and symbols, as
CAD programs wrote them): ezdxf's own evaluators (``ARC``/``CIRCLE``/``ELLIPSE``/``SPLINE``
``.flattening``, the ``LINE``\\ s and bulge arcs of a polyline's ``virtual_entities``, blocks
exploded by ``ezdxf.disassemble.recursive_decompose``), sampled densely, against camtool's
contours (lines and exact arcs, curves fitted within ``--tolerance``). Every point of
camtool's must lie within the tolerance plus the sampling step of ezdxf's curves: a wrong
bulge direction, a mirrored OCS arc, a lost block transform or a fit out of tolerance moves
points by far more. The other way (ezdxf's points near camtool's) is checked only for the
entities camtool reads without a warning; a 2D POLYLINE of spline-fit vertices is left out
of the reference (ezdxf's ``virtual_entities`` draws its frame too, AutoCAD only the curve).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pytest

from camtool.importers.dxf import import_dxf
from camtool.importers.options import ImportOptions
from camtool.model.errors import InputError
from camtool.model.shapes import Arc
from tests.corpus.conftest import (
    CORPUS,
    EMPTY,
    case_id,
    corpus_files,
    load_manifest,
    skip_reason,
)
from tests.corpus.dxf_exact import densified

MANIFEST = load_manifest()
DXF = [f for f in corpus_files(MANIFEST) if f.lower().endswith(".dxf")]
KINDS = ("LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE")


def _reference(path: str, mm: float, step: float) -> np.ndarray:
    import ezdxf
    from ezdxf import disassemble, recover

    try:
        doc = ezdxf.readfile(path)
    except ezdxf.DXFStructureError:
        doc, _ = recover.readfile(path)
    pts = []
    for e in disassemble.recursive_decompose(doc.modelspace()):
        kind = e.dxftype()
        if kind not in KINDS or (kind == "POLYLINE" and e.dxf.flags & 4):
            continue
        try:
            parts = list(e.virtual_entities()) if kind.endswith("POLYLINE") else [e]
        except Exception:  # an entity ezdxf cannot draw: camtool skips it with a warning
            continue
        for q in parts:
            if q.dxftype() == "LINE":
                v = np.array([tuple(q.dxf.start)[:2], tuple(q.dxf.end)[:2]])
            elif q.dxftype() in ("ARC", "CIRCLE", "ELLIPSE", "SPLINE"):
                try:
                    v = np.array([(w.x, w.y) for w in q.flattening(0.0002 / mm)])
                except Exception:
                    continue
            else:
                continue
            if len(v):
                pts.append(densified(v * mm, step))
    return np.concatenate(pts) if pts else np.zeros((0, 2))


def _camtool(contours: Any, step: float) -> np.ndarray:
    pts = []
    for c in contours:
        for s in c.segments:
            if isinstance(s, Arc):
                n = max(2, int(abs(s.sweep) * s.radius / step) + 1)
                a0 = math.atan2(s.start[1] - s.centre[1], s.start[0] - s.centre[0])
                a = a0 + s.sweep * np.linspace(0.0, 1.0, n)
                pts.append(
                    np.c_[s.centre[0] + s.radius * np.cos(a), s.centre[1] + s.radius * np.sin(a)]
                )
            else:
                pts.append(densified(np.array([s.start, s.end]), step))
    return np.concatenate(pts) if pts else np.zeros((0, 2))


@pytest.mark.skipif(MANIFEST is None, reason=skip_reason())
@pytest.mark.parametrize("rel", DXF or ["<none>"], ids=case_id)
def test_camtool_s_contours_lie_on_ezdxf_s_curves(rel: str) -> None:
    from scipy.spatial import cKDTree

    path = str(CORPUS / rel)
    options = ImportOptions()
    try:
        read = import_dxf(path, options)
    except InputError as exc:
        assert any(text in str(exc) for text in EMPTY), str(exc)  # nothing to compare
        return
    box = read.drawing.bbox()
    size = max(box[2] - box[0], box[3] - box[1], 1.0)
    step = max(0.002, size / 20_000)
    ours = _camtool(read.drawing.contours, step)
    theirs = _reference(path, read.mm_per_unit, step)
    assert len(theirs), f"{rel}: ezdxf draws nothing camtool reads"
    off, _ = cKDTree(theirs).query(ours)
    limit = options.tolerance + step + 1e-9 * size
    worst = int(np.argmax(off))
    assert off[worst] <= limit, (
        f"{rel}: camtool's point {ours[worst]} is {off[worst] * 1000:.1f} µm from ezdxf's "
        f"curves (limit {limit * 1000:.1f} µm)"
    )
