"""Every corpus drawing posts on every target, first try or after following the message.

A third-party drawing (LibreCAD parts, Tango icons, Inkscape examples: see fetch_corpus.py)
is posted as a new user first would (``camtool post FILE -t TARGET -o OUT``). It must post
(exit 0, and the target's own reader reads the program back), or fail with a message (exit
1/2/3, "camtool: error: ...", no output file, no stray file) whose suggested remedy — the
options it names, with the values it gives — then posts when followed as written. Small
machines (pic-mmh is 10 × 7 mm) will need ``--fit``: the message must say so with the sizes.
A drawing with nothing camtool can cut (text, images or filters only) may be refused with
exit 3 and "nothing to cut; camtool reads ...", and an SVG whose clip, mask or viewport
hides part of a shape with exit 3 and a message naming both: counted apart as "refused".

Counts (first try / after remedy / failed) are printed at the end of the run and kept in
``results.json`` in the run's own temporary folder (the summary prints where; the corpus
itself is only read); reproducers of failures go to the lead's findings file.
"""

from __future__ import annotations

import pytest

from tests.corpus.conftest import (
    TARGETS,
    case_id,
    corpus_files,
    load_manifest,
    outcome_for,
    skip_reason,
    suggested_flags,
)

MANIFEST = load_manifest()
FILES = corpus_files(MANIFEST)


@pytest.mark.skipif(MANIFEST is None, reason=skip_reason())
@pytest.mark.parametrize("target", TARGETS)
@pytest.mark.parametrize("rel", FILES or ["<none>"], ids=case_id)
def test_posts_first_try_or_after_the_suggested_remedy(rel: str, target: str) -> None:
    outcome = outcome_for(rel, target)
    problems = "\n".join(outcome.problems)
    assert outcome.status in ("first-try", "after-remedy", "refused"), problems
    assert not outcome.problems, problems


@pytest.mark.parametrize(
    ("message", "expected"),
    [
        (
            "camtool: error: contour 1: outside the 10 × 7 mm work area; use --fit 10 7",
            [["--fit", "10", "7"]],
        ),
        (
            "camtool: error: tool 3 mm; use --offset outside or `--fit 9.5 7`.",
            [["--offset", "outside"], ["--fit", "9.5", "7"]],
        ),
        ("camtool: error: x; use --hatch-boundaries to cut it", [["--hatch-boundaries"]]),
        (
            "camtool: error: too large; scale it with --fit 199.99 199.99 --origin lower-left "
            "--translate 0 0 or use a larger machine (--machine FILE.toml)",
            [["--fit", "199.99", "199.99", "--origin", "lower-left", "--translate", "0", "0"]],
        ),
        ("camtool: error: gap 0.3 mm; try --tolerance 0.5.", [["--tolerance", "0.5"]]),
    ],
)
def test_suggested_flags_are_read_as_a_user_reads_them(
    message: str, expected: list[list[str]]
) -> None:
    assert suggested_flags(message) == expected


@pytest.mark.parametrize(
    "message",
    [
        "camtool: error: outside the 10 × 7 mm work area; move the drawing or use --fit",
        "camtool: error: use --offset somewhere",
        "camtool: error: nothing to cut",
    ],
)
def test_a_remedy_without_usable_values_is_not_followable(message: str) -> None:
    assert isinstance(suggested_flags(message), str)
