"""Helpers shared by the readers: reading input files, turning failures into user errors."""

from __future__ import annotations

import contextlib
import stat
from pathlib import Path
from typing import Any
from collections.abc import Iterator, Mapping

from ..errors import UserError, at, first_line

STDIN = "-"
"""The path that means standard input."""


def display_name(path: str | Path) -> str:
    """How a path is named in messages (``<stdin>`` for ``-``)."""
    return "<stdin>" if str(path) == STDIN else str(path)


def regular_file(path: str | Path, what: str) -> Path:
    """``path`` when it names a regular file (symbolic links followed), else a one-line
    :class:`UserError` saying what it is instead and that ``what`` (e.g. "an OpenDRIVE .xodr
    file") was expected: missing, a directory, or a device, fifo or socket (which could block
    or never end)."""
    path = Path(path)
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise UserError(f"no such file (expected {what})", at(path)) from None
    except OSError as exc:
        raise UserError(f"cannot read ({exc.strerror}; expected {what})", at(path)) from None
    if stat.S_ISDIR(mode):
        raise UserError(f"is a directory, expected {what}", at(path))
    if not stat.S_ISREG(mode):
        raise UserError(f"not a regular file (a device, fifo or socket), expected {what}", at(path))
    return path


def read_bytes(path: str | Path) -> bytes:
    """The whole content of a file; a missing or unreadable file is a :class:`UserError`."""
    try:
        return Path(path).read_bytes()
    except FileNotFoundError:
        raise UserError("no such file", at(path)) from None
    except IsADirectoryError:
        raise UserError("is a directory, expected a file", at(path)) from None
    except OSError as exc:
        raise UserError(f"cannot read: {exc.strerror}", at(path)) from None


@contextlib.contextmanager
def reading(path: str | Path, what: str, *errors: type[BaseException]) -> Iterator[None]:
    """Turn the given library exceptions (and OSError) raised while reading ``path`` as
    ``what`` (e.g. "an Argoverse 2 annotations file") into a one-line :class:`UserError`."""
    try:
        yield
    except UserError:
        raise
    except FileNotFoundError as exc:
        raise UserError(f"no such file: {exc.filename or path}", at(path)) from None
    except (OSError, *errors) as exc:
        raise UserError(f"not a valid {what} (truncated or corrupt?): {first_line(exc)}", at(path)) from None


def field(mapping: Mapping[str, Any], key: str, path: str | Path, where: str) -> Any:
    """``mapping[key]``, or a :class:`UserError` naming the missing field and where it was expected."""
    if not isinstance(mapping, Mapping):
        raise UserError(f"expected an object at {where}, found {type(mapping).__name__}", at(path))
    try:
        return mapping[key]
    except KeyError:
        raise UserError(f"missing field {key!r} in {where}", at(path)) from None


@contextlib.contextmanager
def malformed(path: str | Path, format_name: str) -> Iterator[None]:
    """Turn any failure of a reader on ``path`` into a one-line :class:`UserError` naming it.

    Readers report the mistakes they foresee as user errors with their place; this catches the
    rest (a value of a wrong type deep in a file, an inconsistency the data model refuses:
    ``LabelTrace.validate`` raises ValueError naming frame and object), so that a malformed
    input is never a traceback. Out of memory and too deep a recursion are reported the same way.
    """
    try:
        yield
    except UserError:
        raise
    except OSError as exc:
        raise UserError(f"cannot read: {exc.strerror or first_line(exc)}", at(exc.filename or path)) from None
    except Exception as exc:
        kind = "" if type(exc) is ValueError else f"{type(exc).__name__}: "
        raise UserError(f"not a valid {format_name} input: {kind}{first_line(exc)}", at(path)) from None
