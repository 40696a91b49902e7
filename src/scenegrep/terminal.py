"""Text for terminals: names that come from data (object ids, class names, trace names, paths)
may hold escape sequences that would move the cursor, clear the screen or retitle the window.
Every control character but newline and tab is shown as a ``\\xNN`` escape instead."""

from __future__ import annotations

from functools import cache
from typing import Any, TextIO

from .errors import UserError, at


@cache
def _escapes(keep: str) -> dict[int, str]:
    """C0 controls, DEL and C1 controls (U+0080..U+009F) but those in ``keep``, mapped to escapes."""
    return {c: f"\\x{c:02x}" for c in (*range(0x20), *range(0x7F, 0xA0)) if chr(c) not in keep}


def printable(text: str, keep: str = "\n\t") -> str:
    """``text`` with every control character not in ``keep`` escaped as ``\\xNN``."""
    return text.translate(_escapes(keep))


class EscapingStream:
    """A text stream that writes :func:`printable` text to another (keeping the controls of
    ``keep``: standard error keeps the carriage return of progress bars); everything else is
    the other stream's."""

    def __init__(self, stream: TextIO, keep: str = "\n\t"):
        self.stream = stream
        self.keep = keep

    def write(self, text: str) -> int:
        try:
            return self.stream.write(printable(text, self.keep))
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise OutputError(self.stream, exc) from None

    def flush(self) -> None:
        try:
            self.stream.flush()
        except BrokenPipeError:
            raise
        except OSError as exc:
            raise OutputError(self.stream, exc) from None

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)


class OutputError(UserError):
    """Writing a standard stream failed (disk full); a closed pipe stays a BrokenPipeError, which
    ends the command quietly."""

    def __init__(self, stream: TextIO, exc: OSError):
        name = {1: "<stdout>", 2: "<stderr>"}.get(_fileno(stream), "<output>")
        super().__init__(f"cannot write: {exc.strerror or exc}", at(name))


def _fileno(stream: TextIO) -> int | None:
    try:
        return stream.fileno()
    except (OSError, ValueError, AttributeError):
        return None
