"""`camtool preview` as a user runs it: exit codes, default output, stdout, determinism."""

from __future__ import annotations

import io
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from camtool.cli.main import main
from tests.preview.test_preview import INJECTED_CODE, NS

ROOT = Path(__file__).parents[2]
LOGO = ROOT / "samples" / "logo.dxf"
NGC = ROOT / "tests" / "data" / "gcodetools-circle.ngc"
# 100 µm of X backlash the controller does not compensate (see tests/preview/test_preview.py).
LASH_TOML = """[machine.backlash]
true_um = [100.0, 0.0, 0.0]
compensation_um = [0.0, 0.0, 0.0]
regions = []
"""


def run(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def ids(svg: str | bytes) -> set[str]:
    return {e.get("id", "") for e in ET.fromstring(svg).iter() if e.get("id")}


@pytest.fixture
def work(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> Path:
    """tmp_path with logo.dxf, its pic-mmh program logo.pic and the injected-error files."""
    shutil.copy(LOGO, tmp_path / "logo.dxf")
    posted = run(["post", str(LOGO), "-t", "pic-mmh", "-o", str(tmp_path / "logo.pic")], capsys)
    assert posted[0] == 0
    (tmp_path / "injected.pic").write_text(INJECTED_CODE, encoding="ascii")
    (tmp_path / "lash.toml").write_text(LASH_TOML, encoding="utf-8")
    (tmp_path / "bad.pic").write_text("G54;\nG01X12;\n", encoding="ascii")
    (tmp_path / "path.csv").write_text("x_mm,y_mm\n2,0\n4,0\n3.9,2\n", encoding="ascii")
    return tmp_path


@pytest.mark.parametrize(
    ("args", "code"),
    [
        (["logo.dxf", "-o", "a.svg"], 0),
        (["logo.dxf", "-o", "a.png", "-t", "pic-mmh"], 0),
        (["logo.pic", "-t", "pic-mmh", "-o", "a.svg"], 0),
        (["logo.dxf", "--program", "logo.pic", "-t", "pic-mmh", "-o", "a.svg"], 0),
        (["injected.pic", "-t", "pic-mmh", "--verify", "--machine", "lash.toml", "-o", "a.svg"], 0),
        ([str(NGC), "-o", "a.svg"], 0),  # G-code needs no target
        (["missing.dxf", "-o", "a.svg"], 3),
        (["missing.pic", "-t", "pic-mmh", "-o", "a.svg"], 3),
        (["logo.dxf", "--program", "missing.pic", "-t", "pic-mmh", "-o", "a.svg"], 3),
        (["bad.pic", "-t", "pic-mmh", "-o", "a.svg"], 3),  # unparseable code
        (["logo.dxf", "-o", "a.jpg"], 2),  # bad ending
        (["logo.pic", "-o", "a.svg"], 2),  # a program without --target
        (["logo.pic", "-t", "no-such-target", "-o", "a.svg"], 2),
        (["logo.dxf", "--verify", "-t", "pic-mmh", "-o", "a.svg"], 2),  # nothing to verify
        (["logo.pic", "--verify", "-t", "pic-mmh", "--program", "logo.pic"], 2),
        (["logo.dxf", "--machine", "lash.toml", "-o", "a.svg"], 2),  # --machine needs --target
        (["logo.dxf", "--tool-diameter", "-1"], 2),  # click's own range check
        (["logo.dxf", "--no-such-option"], 2),
    ],
)
def test_exit_codes(
    work: Path,
    args: list[str],
    code: int,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.chdir(work)
    got, out, err = run(["preview", *args], capsys)
    assert got == code, err
    assert out == ""
    assert "Traceback" not in err
    if code == 0:
        assert (work / args[args.index("-o") + 1]).stat().st_size > 0
    else:
        assert "error" in err.lower() and not (work / "a.svg").exists()


def test_default_output_is_beside_the_input_and_never_the_input(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    drawing = work / "logo.svg"  # an SVG drawing: its preview must not overwrite it
    drawing.write_bytes(
        b'<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0L10 0L10 5Z"/></svg>'
    )
    before = drawing.read_bytes()
    code, _, err = run(["preview", str(drawing)], capsys)
    assert code == 0, err
    assert drawing.read_bytes() == before
    assert (work / "logo.preview.svg").is_file() and "logo.preview.svg" in err
    code, _, err = run(["preview", str(drawing), "-o", str(drawing)], capsys)
    assert code == 2 and "overwrite" in err and drawing.read_bytes() == before


def test_dash_writes_svg_to_stdout_only(work: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(["preview", str(work / "logo.dxf"), "-o", "-"], capsys)
    assert code == 0 and out.startswith("<svg") and "wrote" not in err
    assert "drawing" in ids(out)


def test_program_from_stdin_with_a_target(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    code_text = (work / "logo.pic").read_text(encoding="ascii")
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(code_text.encode("ascii"))))
    code, out, _ = run(["preview", "-", "-t", "pic-mmh"], capsys)
    assert code == 0
    assert {"cuts", "rapids", "starts", "order", "work-area"} <= ids(out)


def test_verify_with_a_machine_file_marks_the_injected_error(
    work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = work / "v.svg"
    args = ["preview", str(work / "injected.pic"), "-t", "pic-mmh", "--verify"]
    code, _, err = run([*args, "--machine", str(work / "lash.toml"), "-o", str(out)], capsys)
    assert code == 0, err
    root = ET.fromstring(out.read_bytes())
    worst = next(g for g in root.iter(f"{NS}g") if g.get("id") == "worst")
    ring = next(worst.iter(f"{NS}circle"))
    # the carriage stays at X = 4 while Y reaches 2 (tests/preview/test_preview.py works it out)
    assert (float(ring.get("cx", "")), -float(ring.get("cy", ""))) == pytest.approx(
        (4.0, 2.0), abs=1e-3
    )
    assert "line 5" in "".join(t.text or "" for t in worst.iter(f"{NS}text"))


def test_verify_preview_shows_the_tool_width_and_the_drawing(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(work)
    out = work / "p.svg"
    args = ["verify", str(work / "injected.pic"), "-t", "pic-mmh", "--against", "path.csv"]
    args += ["--machine", "lash.toml", "--tool-diameter", "0.2", "--preview", str(out)]
    code, _, err = run(args, capsys)
    assert code == 0, err
    assert {"tool-width", "drawing", "trace", "worst", "inset"} <= ids(out.read_bytes())


def test_same_bytes_in_another_process(
    work: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(work)
    args = ["preview", "injected.pic", "-t", "pic-mmh", "--machine", "lash.toml", "--verify"]
    assert run([*args, "-o", "here.svg"], capsys)[0] == 0
    proc = subprocess.run(
        [sys.executable, "-m", "camtool", *args, "-o", "there.svg"],
        cwd=work,
        capture_output=True,
        text=True,
        check=False,
    )
    assert proc.returncode == 0, proc.stderr
    assert (work / "here.svg").read_bytes() == (work / "there.svg").read_bytes()


@pytest.mark.parametrize("command", ["post", "verify"])
def test_a_bad_preview_ending_is_refused_before_anything_is_written(
    command: str, work: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--preview x.jpg`` fails first: no program, report or picture is written."""
    out, report = work / "new.gcode", work / "new.json"
    if command == "post":
        args = ["post", str(work / "logo.dxf"), "-t", "grbl", "-o", str(out)]
    else:
        args = ["verify", str(work / "logo.pic"), "-t", "pic-mmh"]
    code, _, err = run([*args, "--report", str(report), "--preview", str(work / "x.jpg")], capsys)
    assert code == 2
    assert "a preview is .png or .svg, not '.jpg'" in err
    assert not out.exists() and not report.exists() and not (work / "x.jpg").exists()


def test_the_picture_says_what_it_rests_on_once(
    work: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """The drawing's and the program's warnings (units assumed) come with the picture, as
    with post; with --verify, not a second time."""
    monkeypatch.chdir(work)
    (work / "plain.ngc").write_text("G90\nG0 X0 Y0\nG1 X2 Y1 F100\nM2\n", encoding="ascii")
    said = "no G20/G21 before the first move: coordinates read as mm"
    code, _, err = run(["preview", "plain.ngc", "-t", "grbl", "--verify", "-o", "a.svg"], capsys)
    assert code == 0 and err.count(said) == 1
    svg_path = work / "ai.svg"
    svg_path.write_text(
        "<!-- Generator: Adobe Illustrator 27.0.0, SVG Export Plug-In -->\n"
        '<svg xmlns="http://www.w3.org/2000/svg" width="72px" height="72px" viewBox="0 0 72 72">'
        '<rect x="10" y="10" width="40" height="40" fill="none" stroke="#000"/></svg>',
        encoding="utf-8",
    )
    code, _, err = run(["preview", "ai.svg", "-o", "b.svg"], capsys)
    assert code == 0 and err.count("made by Adobe Illustrator 27.0.0") == 1
