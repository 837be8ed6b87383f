"""Job files: what load_job takes, and the clear error for each thing it refuses."""

from __future__ import annotations

from pathlib import Path

import pytest

from camtool.jobs.job import MAX_TOOLS, Job
from camtool.jobs.jobfile import load_job
from camtool.model.errors import InputError

ROOT = Path(__file__).resolve().parents[2]

GOOD = """
[job]
origin = "lower-left"
clearance_z = 8
[[tools]]
id = 1
type = "end-mill"
diameter = 3.0
feed = 500
[[tools]]
id = 2
type = "drill"
diameter = 2.5
[[operations]]
type = "profile"
tool = 1
layers = ["OUTLINE"]
side = "outside"
depth = 6.0
step_down = 2.0
tabs = 3
[[operations]]
name = "holes"
type = "drill"
tool = 2
layers = "HOLES"
depth = 6.5
step_down = 2
peck = "chip-break"
"""


def _job(tmp_path: Path, text: str) -> Job:
    path = tmp_path / "job.toml"
    path.write_text(text)
    return load_job(path)


def test_a_job_file_becomes_tools_operations_and_setup(tmp_path: Path) -> None:
    job = _job(tmp_path, GOOD)
    assert [t.id for t in job.tools] == [1, 2]
    assert job.tool(2).describe() == "drill 2.5 mm"
    profile, drill = job.operations
    assert (profile.kind, profile.plan.offset, profile.plan.tool_diameter) == (
        "profile outside",
        "outside",
        3.0,
    )
    assert (profile.plan.depth, profile.plan.step_down, profile.plan.tabs) == (6.0, 2.0, 3)
    assert profile.plan.feed_mm_min == 500  # the tool's feed
    assert profile.plan.placement == "lower-left" and profile.plan.clearance == 8
    assert drill.select.layers == ("HOLES",) and drill.select.points
    assert (drill.peck, drill.plan.step_down, drill.plan.offset) == ("chip-break", 2.0, "on")
    assert job.source == "job.toml" and not job.shorthand


@pytest.mark.parametrize(
    ("keys", "points"),
    [
        ("", True),  # a drill drills the points of its layers
        ("diameter = 2.5\n", False),  # only circles of a size: no point has one
        ("closed = true\n", False),
        ('linetypes = ["CONTINUOUS"]\n', False),
        ("diameter = 2.5\npoints = true\n", True),  # asked for: both
        ("points = false\n", False),
    ],
)
def test_a_drill_selects_points_unless_it_selects_by_shape(
    tmp_path: Path, keys: str, points: bool
) -> None:
    text = (
        '[[tools]]\nid = 2\ntype = "drill"\ndiameter = 2.5\n'
        f'[[operations]]\ntype = "drill"\ntool = 2\ndepth = 3\n{keys}'
    )
    (drill,) = _job(tmp_path, text).operations
    assert drill.select.points is points
    assert drill.select.contours  # every contour the other keys keep, as well


def test_points_only_selects_no_contour_and_takes_no_shape_key(tmp_path: Path) -> None:
    text = (
        '[[tools]]\nid = 2\ntype = "drill"\ndiameter = 2.5\n'
        '[[operations]]\ntype = "drill"\ntool = 2\ndepth = 3\npoints = "only"\n'
    )
    (drill,) = _job(tmp_path, text).operations
    assert drill.select.points and not drill.select.contours
    with pytest.raises(InputError, match='points = "only" selects no contour, so diameter'):
        _job(tmp_path, text + "diameter = 2.5\n")
    with pytest.raises(InputError, match='give true, false or "only"'):
        _job(tmp_path, text.replace('"only"', '"alone"'))


_PROFILE = (
    '[[tools]]\nid = 1\ntype = "end-mill"\ndiameter = 3\n'
    '[[operations]]\ntype = "profile"\ntool = 1\ndepth = 1\n'
)


@pytest.mark.parametrize(
    "value", ["1", '"red"', '"Red"', '"#F00"', '"#ff0000"', '"rgb(255, 0, 0)"', '"rgb(100%,0%,0%)"']
)
def test_a_colour_is_read_as_its_rgb(tmp_path: Path, value: str) -> None:
    # DXF colour 1 is red (ezdxf's ACI table); red is #ff0000 in CSS Color 3
    (op,) = _job(tmp_path, f"{_PROFILE}colours = [{value}]\n").operations
    assert op.select.colours == ("#ff0000",)


@pytest.mark.parametrize(
    "value",
    ['""', '" "', '"rde"', '"7"', '"transparent"', '"currentColor"', '"#ff000080"', '"#12"'],
)
def test_what_is_no_colour_is_refused(tmp_path: Path, value: str) -> None:
    """An empty string, a typo, a keyword that is no colour, a translucent one: refused.

    (svgelements' own parser reads any word it does not know as black, so it is not the
    judge of what a colour is.)"""
    with pytest.raises(InputError, match="is not a colour"):
        _job(tmp_path, f"{_PROFILE}colours = [{value}]\n")


def test_the_bundled_sample_job_loads() -> None:
    job = load_job(ROOT / "samples" / "part.toml")
    assert [op.kind for op in job.operations] == [
        "drill",
        "engrave",
        "pocket",
        "profile outside",
    ]


def test_auto_sequence_drills_first_and_cuts_the_outline_last(tmp_path: Path) -> None:
    text = GOOD.replace('origin = "lower-left"', 'origin = "lower-left"\nsequence = "auto"')
    text += '[[operations]]\ntype = "pocket"\ntool = 1\ndepth = 1\n'
    text += '[[operations]]\ntype = "profile"\nside = "inside"\ntool = 1\ndepth = 2\n'
    kinds = [op.kind for op in _job(tmp_path, text).sequenced()]
    assert kinds == ["drill", "pocket", "profile inside", "profile outside"]
    # in the file's order unless asked
    assert [op.kind for op in _job(tmp_path, GOOD).sequenced()] == ["profile outside", "drill"]


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("depth = 6.0", "dept = 6.0"), r"unknown key 'dept'; did you mean 'depth'\?"),
        (('side = "outside"', 'side = "outsid"'), r'side = "outsid" \(did you mean "outside"\?\)'),
        # quoted as the file writes it, not as Python's False or ['a', 'b']
        (('side = "outside"', "side = false"), r"side = false; choose one of outside"),
        (('side = "outside"', 'side = ["on"]'), r'side = \["on"\]; choose one of outside'),
        (("tabs = 3", "tabs = true"), r"tabs = true; give a whole number"),
        (("tool = 2", "tool = 7"), r"uses tool 7, which \[\[tools\]\] does not define"),
        (("diameter = 3.0", "diameter = -3.0"), r"tool 1 diameter = -3 mm"),
        (  # the key that was refused, not "diameter"
            ('side = "outside"', 'side = "outside"\nexcept_diameter = [4, 3]'),
            r"operation 1 except_diameter = \[4, 3\]: min above max",
        ),
        (  # read for nothing: the profile has no pocket to step over
            ('side = "outside"', 'side = "outside"\nstepover = 0.4'),
            r"operation 1: stepover applies to a pocket operation, not to this profile",
        ),
        # far below 1 µm, an offset's half-diameter is lost in the coordinates' precision
        (("diameter = 3.0", "diameter = 1e-300"), r"tool 1 diameter = 1e-300 mm; .*0\.001…1000"),
        (
            ("feed = 500", "feed = 1e308"),
            r"feed = 1e\+308 mm/min; give a value > 0 and at most 1e\+06",
        ),
        (  # not: "Tool.feed_mm_min must be > 0 and ≤ 1e+06", naming neither file nor tool
            ("feed = 500", "feed = 5e6"),
            r"tool 1 feed = 5e\+06 mm/min; give a value > 0 and at most 1e\+06",
        ),
        (("depth = 6.0", 'depth = "6"'), r'depth = "6"; give a number'),
        (("tabs = 3", "tabs = 3.5"), r"tabs = 3.5; give a whole number"),
        (("step_down = 2.0", "step_down = -2.0"), r"step_down must be > 0 mm"),
        (("[job]", "[jobs]"), r"unknown key 'jobs'; did you mean 'job'\?"),
        (("id = 2", "id = 1"), r"two tools with id 1"),
        (('peck = "chip-break"', 'peck = "chip"'), r'peck = "chip"'),
        (("depth = 6.5", "depth = 6.5\ntabs = 2"), r"tabs does not apply to drilling"),
        (("depth = 6.5", "depth = 6.5\ntab_height = 1"), r"tab_height does not apply to drill"),
        (
            ('side = "outside"', 'side = "inside"'),
            r"operation 1: tabs: tabs hold a part on an outside profile only, and this is a "
            r'profile with side = "inside"; remove it here',
        ),
        (
            (
                *('type = "profile"\ntool = 1', 'type = "pocket"\ntool = 1\ntab_width = 4'),
                *('side = "outside"', ""),
            ),
            r"tabs, tab_width: tabs hold a part on an outside profile only, and this is a "
            r"pocket operation; remove them here",
        ),
        (
            (
                *('type = "profile"\ntool = 1', 'type = "engrave"\ntool = 1\npeck = "retract"'),
                *('side = "outside"', ""),
                *("tabs = 3", ""),
            ),
            r"peck: only a drill operation takes this key; remove it here",
        ),
        (("clearance_z = 8", "clearance_z = 1"), r"clearance_z 1 mm is below safe_z 2 mm"),
        (
            ('side = "outside"', 'side = "on"\nlead_in = 1', "tabs = 3", ""),
            r'operation 1: lead_in needs a side to approach from: use side = "outside" or '
            r'"inside"$',  # post's --offset, as the job says it
        ),
    ],
)
def test_what_a_job_file_may_not_say_is_refused_naming_it(
    tmp_path: Path, change: tuple[str, ...], message: str
) -> None:
    text = GOOD
    for old, new in zip(change[::2], change[1::2], strict=True):
        assert old in text
        text = text.replace(old, new, 1)
    with pytest.raises(InputError, match=message) as caught:
        _job(tmp_path, text)
    assert str(caught.value).startswith(f"{tmp_path / 'job.toml'}: ")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"[[tools]]\nid = 1\n", r"diameter is missing"),
        (b"[job]\n", r"no \[\[tools\]\]"),
        (b"[[tools]]\nid=1\ndiameter=3\n", r"no \[\[operations\]\]"),
        (b"[[tools]\n", r"not valid TOML"),
        (b"\xff\xfe[job]", r"not UTF-8 text"),
        (b"a = " + b"[" * 5000 + b"]" * 5000 + b"\n", r"nests arrays or tables"),
    ],
)
def test_broken_job_files_are_refused(tmp_path: Path, data: bytes, message: str) -> None:
    path = tmp_path / "job.toml"
    path.write_bytes(data)
    with pytest.raises(InputError, match=message):
        load_job(path)


def test_a_job_file_that_is_not_a_regular_file_is_refused_without_blocking(
    tmp_path: Path,
) -> None:
    import os

    fifo = tmp_path / "job.toml"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="not a regular file"):
        load_job(fifo)
    with pytest.raises(InputError, match="cannot read the job file"):
        load_job(tmp_path / "missing.toml")


def test_a_bom_is_read_as_utf8_text(tmp_path: Path) -> None:
    path = tmp_path / "job.toml"
    path.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    assert len(load_job(path).operations) == 2


def test_command_line_shared_options_replace_the_files(tmp_path: Path) -> None:
    path = tmp_path / "job.toml"
    path.write_text(GOOD)
    job = load_job(path, overrides={"placement": "center", "translate": (1.0, 2.0)})
    assert job.setup.plan.placement == "center" and job.setup.plan.translate == (1.0, 2.0)
    assert all(op.plan.placement == "center" for op in job.operations)
    # the drawing's size is one choice: the command line's scale replaces the file's fit
    path.write_text(GOOD.replace("[job]\n", "[job]\nfit = [40, 40]\n", 1))
    assert load_job(path).setup.plan.fit == (40.0, 40.0)
    plan = load_job(path, overrides={"scale": 2.0}).setup.plan
    assert (plan.scale, plan.fit) == (2.0, None)
    plan = load_job(path, overrides={"fit": (10.0, 20.0)}).setup.plan
    assert (plan.scale, plan.fit) == (1.0, (10.0, 20.0))


def _tools_job(count: int) -> str:
    """A job of ``count`` end mills and one operation using the first."""
    tools = "".join(f"[[tools]]\nid = {n}\ndiameter = 3\n" for n in range(1, count + 1))
    return tools + '[[operations]]\ntype = "engrave"\ntool = 1\ndepth = 0.5\n'


def test_a_tool_table_of_more_tools_than_a_job_may_hold_is_refused(tmp_path: Path) -> None:
    # Each program of a job lists its tools and operations, and a machine without a tool
    # changer gets one program per tool: 5 000 tools wrote 5 000 programs of 10 000 header
    # lines each (3 GB) from a 0.7 MB file. MAX_TOOLS holds more than a tool changer.
    assert len(_job(tmp_path, _tools_job(MAX_TOOLS)).tools) == MAX_TOOLS
    with pytest.raises(InputError, match=rf"{MAX_TOOLS + 1} \[\[tools\]\], more than the "):
        _job(tmp_path, _tools_job(MAX_TOOLS + 1))
