"""Find where in a JSON text an error is, to report it as line:column.

Only error paths use this module: it trades speed for simplicity.
"""

from __future__ import annotations

import json
import re
from collections.abc import Sequence
from typing import TYPE_CHECKING

from ..errors import UserError, at

if TYPE_CHECKING:
    import msgspec

_DECODER = json.JSONDecoder()
_WS = re.compile(r"[ \t\r\n]*")
_BYTE_AT = re.compile(r"\(byte (\d+)\)")
_PATH_PART = re.compile(r"\.([A-Za-z_@][\w@/-]*)|\[(\d+)\]")


def line_column(data: bytes | str, offset: int) -> tuple[int, int]:
    """1-based line and column of a character offset."""
    newline = b"\n" if isinstance(data, bytes) else "\n"
    line = data.count(newline, 0, offset) + 1  # type: ignore[arg-type]
    column = offset - (data.rfind(newline, 0, offset) + 1) + 1  # type: ignore[arg-type]
    return line, column


def parse_path(path: str) -> list[str | int]:
    """Components of a JSON path such as ``$.frames[3].samples[0]``."""
    return [key if key else int(index) for key, index in _PATH_PART.findall(path)]


def locate(text: str, path: Sequence[str | int], start: int = 0) -> int:
    """Offset of the value at ``path`` in the JSON value starting at ``start``; where the
    path leaves the document (a missing key), the offset of the deepest container reached."""
    pos = _WS.match(text, start).end()
    for part in path:
        found = _child(text, pos, part)
        if found is None:
            return pos
        pos = found
    return pos


def _child(text: str, pos: int, part: str | int) -> int | None:
    opener = text[pos : pos + 1]
    if opener not in ("{", "["):
        return None
    i = _WS.match(text, pos + 1).end()
    index = 0
    while i < len(text) and text[i] not in "}]":
        if opener == "{":
            key, i = json.decoder.scanstring(text, i + 1)  # type: ignore[attr-defined]
            i = _WS.match(text, _WS.match(text, i).end() + 1).end()
            if key == part:
                return i
        elif index == part:
            return i
        _, i = _DECODER.raw_decode(text, i)
        i = _WS.match(text, i).end()
        if text[i : i + 1] == ",":
            i = _WS.match(text, i + 1).end()
        index += 1
    return None


def path_text(parts: Sequence[str | int]) -> str:
    """``frames[3].samples[0]`` from path components."""
    return "".join(f"[{p}]" if isinstance(p, int) else f".{p}" for p in parts).lstrip(".")


def byte_offset(document: bytes, path: Sequence[str | int]) -> int:
    """Byte offset, within ``document``, of the value at ``path`` (see :func:`locate`)."""
    text = document.decode("utf-8", errors="replace")
    return len(text[: locate(text, path)].encode("utf-8"))


def msgspec_error(exc: msgspec.MsgspecError, data: bytes, start: int, source: str) -> UserError:
    """A one-line user error at the place that a msgspec decode error of the JSON document
    starting at byte ``start`` of ``data`` names (a JSON path, or a byte offset)."""
    import msgspec

    text = str(exc)
    if isinstance(exc, msgspec.ValidationError):
        message, _, path = text.partition(" - at `")
        parts = parse_path(path.rstrip("`"))
        offset = start + byte_offset(data[start:], parts)
        return UserError(message, at(source, *line_column(data, offset), path=path_text(parts)))
    if "truncated" in text:
        return UserError("unexpected end of input (truncated JSON?)", at(source, *line_column(data, len(data))))
    found = _BYTE_AT.search(text)
    offset = start + max(int(found.group(1)) - 1, 0) if found else start  # msgspec names the byte after
    return UserError(_BYTE_AT.sub("", text).strip(), at(source, *line_column(data, offset)))
