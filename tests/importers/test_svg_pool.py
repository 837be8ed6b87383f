"""SVG import with the curve fits made ahead in worker processes (issue 17).

The reference is the same import without workers: the pool must change the speed only, so
the drawing must be the same, float for float (compared by ``repr``: ``-0.0`` too), and an
error the same message.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from camtool.geometry import fitpool
from camtool.importers import svg as svg_module
from camtool.importers.svg import read_svg
from camtool.model.errors import InputError
from tests.geometry.test_fitpool import spy_pool

# what this file checks is done by the accelerated versions only (docs/architecture.md)
pytestmark = pytest.mark.usefixtures("accel_on")

SVG = """<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
{paths}
</svg>"""


def _svg(tmp_path: Path, n: int) -> Path:
    rng = np.random.default_rng(17)
    paths = []
    for k in range(n):
        x, y = rng.uniform(5, 95, 2)
        c = rng.uniform(-4, 4, 6)
        d = (
            f"M {x:.3f} {y:.3f} c {c[0]:.3f} {c[1]:.3f} {c[2]:.3f} {c[3]:.3f} {c[4]:.3f} {c[5]:.3f}"
            f" q 2 3 4 -1 a 3 1.5 {k * 7 % 90} 0 1 -2 -3 s 1 2 3 0 t 2 2 z"
        )
        if k % 9 == 0:
            d += " M 10 10 c 0 0 0 0 0 0 l 1 1"  # a curve of zero length: dropped by the fit
        paths.append(f'<path d="{d}" fill="none" stroke="black"/>')
    path = tmp_path / "many.svg"
    path.write_text(SVG.format(paths="\n".join(paths)), encoding="utf-8")
    return path


def test_read_svg_with_workers_equals_without(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The same drawing, segment for segment, with the fits made ahead in workers or not."""
    path = _svg(tmp_path, 60)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 10**9)
    serial = read_svg(path)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "_CHUNK", 5)
    pooled = spy_pool(monkeypatch)
    assert repr(read_svg(path)) == repr(serial)
    assert pooled == [True]  # the fits came from the workers, not the serial fallback


def test_read_svg_with_workers_raises_the_serial_error(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A curve too big for the tolerance: the same error, naming the same element."""
    path = _svg(tmp_path, 12)
    text = path.read_text(encoding="utf-8").replace(
        "</svg>", '<path id="huge" d="M 0 0 C 1e12 0 0 1e12 5 5"/></svg>'
    )
    path.write_text(text, encoding="utf-8")
    monkeypatch.setattr(svg_module, "MIN_CURVES", 10**9)
    with pytest.raises(InputError) as serial:
        read_svg(path)
    monkeypatch.setattr(svg_module, "MIN_CURVES", 1)
    monkeypatch.setattr(fitpool, "MIN_CURVES", 1)
    with pytest.raises(InputError) as pooled:
        read_svg(path)
    assert str(pooled.value) == str(serial.value)


def test_a_shape_svgelements_fails_on_fails_in_its_turn(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Segments read ahead: a shape whose segments fail is asked again in its turn."""
    path = _svg(tmp_path, 3)
    calls: list[int] = []
    original = svg_module._segments

    def failing_once(shape: object) -> None:
        calls.append(1)
        return None  # as if svgelements had raised: read again, lazily, in its turn

    serial = read_svg(path)
    monkeypatch.setattr(svg_module, "_segments", failing_once)
    assert repr(read_svg(path)) == repr(serial)
    assert calls
    monkeypatch.setattr(svg_module, "_segments", original)
