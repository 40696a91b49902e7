"""Errors in a Scenic program: one line ``file:line:column: message`` and a caret display."""

from __future__ import annotations

from ..errors import UserError, at, caret
from .ir import NOWHERE, Node, Program, Span


def program_error(message: str, where: Node | Span, program: Program) -> UserError:
    """A :class:`UserError` at a node (or span) of ``program``, with the source line and carets."""
    span = where if isinstance(where, Span) else where.span
    if span == NOWHERE:
        return UserError(message, at(program.filename))
    lines = program.text.splitlines()
    detail = None
    if 0 < span.line <= len(lines):
        width = span.end_column - span.column if span.end_line == span.line else len(lines[span.line - 1])
        detail = caret(lines[span.line - 1], span.column, width)
    return UserError(message, at(program.filename, span.line, span.column), detail=detail)
