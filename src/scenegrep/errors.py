"""User-facing errors.

A :class:`UserError` is a mistake in what the user gave scenegrep (a file, a
query, an option), as opposed to a bug in scenegrep. The command line prints
it as one line, ``scenegrep: error: PLACE: MESSAGE``, and exits with code 2;
it never shows a traceback for it.
"""

from __future__ import annotations

import difflib
from dataclasses import dataclass
from collections.abc import Sequence
from os import PathLike


@dataclass(frozen=True)
class SourceLocation:
    """A place in a user's input: a file (or ``<stdin>``, ``<query>``), optionally a
    1-based line and column, optionally a path inside a structured document
    (``frames[3].samples[0].image``)."""

    source: str
    line: int | None = None
    column: int | None = None
    path: str | None = None

    def __str__(self) -> str:
        text = self.source
        if self.line is not None:
            text += f":{self.line}"
            if self.column is not None:
                text += f":{self.column}"
        if self.path:
            text += f": {self.path}"
        return text


class UserError(Exception):
    """An error in the user's input, reported as one line with its location."""

    def __init__(self, message: str, location: SourceLocation | None = None, detail: str | None = None):
        self.message = message
        self.location = location
        self.detail = detail
        super().__init__(self.one_line())

    def one_line(self) -> str:
        """The message as the CLI prints it (without the ``scenegrep: error:`` prefix)."""
        text = self.message if self.location is None else f"{self.location}: {self.message}"
        return " ".join(text.split())


def at(
    source: str | PathLike[str], line: int | None = None, column: int | None = None, path: str | None = None
) -> SourceLocation:
    """Shorthand for a :class:`SourceLocation`."""
    return SourceLocation(str(source), line, column, path)


CARET_WIDTH = 100
"""The most characters of a source line an error's caret display shows."""


def caret(line: str, column: int, width: int = 1) -> str:
    """A two-line display: the source ``line`` and carets under 1-based columns [column, column + width);
    a line longer than :data:`CARET_WIDTH` shows only that many characters around the column."""
    width = max(1, min(width, len(line) - column + 1))
    if len(line) > CARET_WIDTH:
        start = max(0, min(column - 1 - CARET_WIDTH // 4, len(line) - CARET_WIDTH))
        shown = line[start : start + CARET_WIDTH]
        line = ("..." if start else "") + shown + ("..." if start + CARET_WIDTH < len(line) else "")
        column = column - start + (3 if start else 0)
        width = max(1, min(width, CARET_WIDTH - (column - 1)))
    return f"  {line}\n  {' ' * (column - 1)}{'^' * width}"


def first_line(exc: BaseException) -> str:
    """The first line of an exception's message (its type name when it has none), for the
    one-line report of a library's error."""
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def failure_text(exc: Exception, where: str | PathLike[str]) -> str:
    """One line for an error that ends one source or trace while the others go on: a
    :class:`UserError`'s own line, else ``WHERE: TYPE: MESSAGE`` (a bug, reported, not raised)."""
    if isinstance(exc, UserError):
        return exc.one_line()
    return " ".join(f"{where}: {type(exc).__name__}: {exc}".split())


def nearest(word: str, choices: Sequence[str]) -> list[str]:
    """The choices closest to ``word``, for a "did you mean" (at most three, best first; none if
    nothing is close), compared without leading dashes (which every option shares); for one
    letter (``-p``), the choices starting with it."""
    bare = {choice.lstrip("-"): choice for choice in choices}
    if len(word.lstrip("-")) == 1:
        return [choice for name, choice in bare.items() if name.startswith(word.lstrip("-"))][:3]
    return [bare[found] for found in difflib.get_close_matches(word.lstrip("-"), list(bare), n=3, cutoff=0.6)]
