"""Errors in a query: one line with the place (``<query>:line:column``) and a caret display."""

from __future__ import annotations

from ..errors import UserError, at, caret


def line_column(text: str, offset: int) -> tuple[int, int]:
    """1-based line and column of an offset in the query text."""
    line_start = text.rfind("\n", 0, offset) + 1
    return text.count("\n", 0, offset) + 1, offset - line_start + 1


def _caret(text: str, start: int, end: int) -> str:
    """The query line holding ``start`` with carets under [start, end)."""
    line_start = text.rfind("\n", 0, start) + 1
    line_end = text.find("\n", start)
    line = text[line_start : len(text) if line_end < 0 else line_end]
    return caret(line, start - line_start + 1, end - start)


def query_error(message: str, text: str, start: int, end: int, source: str = "<query>") -> UserError:
    """A :class:`UserError` at [start, end) of the query text, with a caret display as detail."""
    return UserError(message, at(source, *line_column(text, start)), detail=_caret(text, start, end))
