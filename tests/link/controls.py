"""An operator stand-in shared by the link tests: pause after a given block, then answer."""

from __future__ import annotations

from camtool.link.sender import Progress
from camtool.link.spec import WireBlock


class PauseAt:
    """Asks for a pause once ``at`` blocks are done, then resumes (or stops)."""

    def __init__(self, at: int, answer: str) -> None:
        self.at, self.answer = at, answer
        self.pause_requested = False
        self.pauses: list[Progress] = []

    def progress(self, p: Progress) -> None:
        if p.done == self.at:
            self.pause_requested = True

    def paused(self, progress: Progress) -> str:
        self.pauses.append(progress)
        return self.answer

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        return False


class AnswersTurns:
    """An operator who answers every turn the link gives them with ``answer``."""

    def __init__(self, answer: bool) -> None:
        self.answer = answer
        self.pause_requested = False
        self.prompts: list[str] = []

    def paused(self, progress: Progress) -> str:
        return "stop"

    def between_blocks(self, prompt: str, done: WireBlock, following: WireBlock) -> bool:
        self.prompts.append(prompt)
        return self.answer
