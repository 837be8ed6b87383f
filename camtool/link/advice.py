"""What a stopped job leaves: which lines surely ran, which may have, and where to resume.

The messages of :mod:`camtool.link.sender` when a job stops (an error, an alarm, the
operator, a lost port), from the stream's counts (:class:`~camtool.link.stream.Stream`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from camtool.link.plan import SendPlan
    from camtool.link.stream import Stream


def unsure(s: Stream, plan: SendPlan) -> str:
    """What surely ran, what may have run in part, and where to resume."""
    run = s.surely_run()
    if s.failed_at is not None:
        run = min(run, s.failed_at)
    sent = s.sent_count
    first = s.first_line_from(run)
    if first is None:
        return "every block had run"
    done = [s.block(k) for k in range(run) if s.block(k).index]
    known = f"lines up to {done[-1].last_line} surely ran; " if done else ""
    maybe = [s.block(k) for k in range(run, sent) if s.block(k).index]
    maybe = [b for b in maybe if s.failed_at is None or b.index != s.block(s.failed_at).index]
    partly = ""
    if maybe:
        span = (
            f"line {maybe[0].line}"
            if len(maybe) == 1
            else f"lines {maybe[0].line}–{maybe[-1].last_line}"
        )
        partly = f"{span} had been taken by the controller and may have run, whole or in part; "
    return f"{known}{partly}{_resume_advice(s, plan, first, bool(maybe))}"


def _resume_advice(s: Stream, plan: SendPlan, line: int, partly: bool) -> str:
    """Where to resume: the line, and for an arc begun, where to bring the tool first."""
    fix = "fix the cause, then " if s.failed_at is not None else ""
    if not partly:
        return f"{fix}resume with --from-line {line}"
    where, arc = plan.start_of(line)
    if not arc:
        return (
            f"{fix}resume with --from-line {line} (a straight move re-run from where the "
            "tool stands ends where it should)"
        )
    stand = f" (X{where[0]:g} Y{where[1]:g} Z{where[2]:g})" if where is not None else ""
    return (
        f"{fix}line {line} is an arc: if it began, bring the tool back to where it starts"
        f"{stand} first (an arc re-run from part way has the wrong centre), then resume "
        f"with --from-line {line}"
    )


def lost_hint(s: Stream, plan: SendPlan) -> str:
    """Where a job stood when the port went: what is known to have run, what may have."""
    spec = plan.spec
    sent = [s.block(k) for k in range(s.sent_count) if s.block(k).index]
    if not sent:
        return "no block of the program had been sent"
    last = sent[-1]
    if spec.flow == "char-count":
        return unsure(s, plan)
    if spec.flow == "timed" or s.in_flight or s.attempted is not None:
        confirmed = s.last_done if spec.flow != "timed" else None
        known = (
            f"blocks up to line {confirmed.line} were confirmed; "
            if confirmed is not None and confirmed.index
            else ""
        )
        paced = (
            "this link confirms nothing: camtool sent each block after the one before "
            f"had its estimated time plus {spec.pace_margin:.0%}, so the lines "
            f"before line {last.line} ran only if the machine kept that pace (a slower "
            "machine may not have run them yet); "
            if spec.flow == "timed"
            else ""
        )
        return (
            f"{known}the last block sent was line {last.line} and camtool cannot know "
            f"whether the blocks after the last confirmed one ran; {paced}look where the "
            f"tool stands, then resume with --from-line {last.line} if line {last.line} "
            "did not run, or with the line after it if it did (an earlier line if the "
            "tool stands before it)"
        )
    line = s.resume_line()
    return f"resume with --from-line {line}" if line else "every block had been sent"
