"""docs/ci.md's script runs as written: a drawings repository posted, verified and drawn.

The sample is samples/logo.dxf for pic-mmh; its predicted error is the X over-compensation of
UNAM-GMM §5.2 (204 µm compensated, 190 µm true backlash in region H1, Tabla 13): 14 µm, at most
combined with 2 µm of Y under-compensation (180/178 µm in V2), so a 50 µm limit passes. A
2 × 1 mm rectangle, whose reversals leave tens of µm (the same compensation), fails a 1 µm
limit with exit code 4 (a small part keeps the test fast).
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.shapes import rectangle_dxf

ROOT = Path(__file__).parents[1]
SCRIPT = re.compile(r"```sh\n(#!/bin/sh\n.*?)```", re.S)


@pytest.fixture
def repository(tmp_path: Path) -> Path:
    """A drawings repository: the CI script in ci/ and an empty drawings/logos/."""
    match = SCRIPT.search((ROOT / "docs" / "ci.md").read_text(encoding="utf-8"))
    assert match, "docs/ci.md has no ```sh block starting with #!/bin/sh"
    (tmp_path / "ci").mkdir()
    (tmp_path / "ci" / "camtool-ci.sh").write_text(match.group(1))
    (tmp_path / "drawings" / "logos").mkdir(parents=True)
    return tmp_path


def run_script(repository: Path, **env: str) -> subprocess.CompletedProcess[str]:
    bin_dir = str(Path(sys.executable).parent)  # the venv's camtool is on PATH
    environ = {**os.environ, "PATH": f"{bin_dir}{os.pathsep}{os.environ.get('PATH', '')}", **env}
    environ.pop("CAMTOOL_PIP_SPEC", None)
    return subprocess.run(
        ["sh", "ci/camtool-ci.sh"],
        cwd=repository,
        env=environ,
        capture_output=True,
        text=True,
        check=False,
    )


def test_the_script_keeps_programs_reports_and_previews(repository: Path) -> None:
    shutil.copy(ROOT / "samples" / "logo.dxf", repository / "drawings" / "logos" / "logo.dxf")
    proc = run_script(repository, CAMTOOL_MAX_ERROR_UM="50")
    assert proc.returncode == 0, proc.stderr
    out = repository / "camtool-out"
    assert (out / "logos" / "logo.pic").read_text().startswith("G54;")
    preview = (out / "logos" / "logo.svg").read_text()
    assert preview.startswith("<svg") and 'id="trace"' in preview  # verified: the simulated cut
    verify = json.loads((out / "logos" / "logo.json").read_text())
    assert 204 - 190 - 0.2 <= verify["deviation_um"]["max"] <= math.hypot(14, 2) + 0.2
    batch = json.loads((out / "batch.json").read_text())
    assert batch["exit_code"] == 0 and batch["totals"]["ok"] == 1
    assert "every drawing posts for pic-mmh within 50 µm" in proc.stdout


def test_a_limit_below_the_predicted_error_fails_and_keeps_the_artefacts(
    repository: Path,
) -> None:
    rectangle_dxf(repository / "drawings" / "logos" / "rect.dxf", 2, 1)
    proc = run_script(repository, CAMTOOL_MAX_ERROR_UM="1")
    assert proc.returncode == 4, proc.stderr
    out = repository / "camtool-out"
    assert (out / "logos" / "rect.svg").is_file() and (out / "logos" / "rect.pic").is_file()
    batch = json.loads((out / "batch.json").read_text())
    assert batch["files"][0]["status"] == "over-limit"
    assert "predicted error over 1 µm" in proc.stderr
