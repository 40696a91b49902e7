"""Split a byte stream holding JSON documents one after another into whole documents.

STREM's online feed is several top-level JSON objects written back to back
(``{...}{...}`` or one per line). :class:`DocumentSplitter` takes bytes as they
arrive and hands back every document as soon as its closing brace is seen. It
tracks nesting depth outside strings with numpy over each chunk, so its cost is
linear in the input whatever the chunk sizes.
"""

from __future__ import annotations

import numpy as np

_QUOTE, _BACKSLASH = 0x22, 0x5C
_OPEN = np.zeros(256, dtype=np.int8)
_OPEN[[0x7B, 0x5B]] = 1
_OPEN[[0x7D, 0x5D]] = -1


class DocumentSplitter:
    """Incremental splitter; see the module docstring."""

    def __init__(self) -> None:
        self._pending = bytearray()
        self._depth = 0
        self._in_string = False
        self._carry = 0

    def feed(self, chunk: bytes) -> list[bytes]:
        """Add bytes; return the documents completed by them (possibly none)."""
        scan_from = len(self._pending)
        self._pending += chunk
        a = np.frombuffer(bytes(chunk), dtype=np.uint8)
        quotes = self._unescaped_quotes(a)
        brackets = np.flatnonzero(_OPEN[a])
        inside = (np.searchsorted(quotes, brackets) + int(self._in_string)) % 2 == 1
        brackets = brackets[~inside]
        depth = self._depth + np.cumsum(_OPEN[a[brackets]], dtype=np.int64)
        self._in_string = bool((len(quotes) + int(self._in_string)) % 2)
        if len(depth):
            self._depth = int(depth[-1])
        ends = brackets[(depth == 0) & (_OPEN[a[brackets]] < 0)] + scan_from + 1
        documents, start = [], 0
        for end in ends.tolist():
            documents.append(bytes(self._pending[start:end]).strip())
            start = end
        del self._pending[:start]
        return documents

    def _unescaped_quotes(self, a: np.ndarray) -> np.ndarray:
        """Positions of quote bytes not preceded by an odd run of backslashes; a run may
        continue from the end of the previous chunk."""
        quotes = np.flatnonzero(a == _QUOTE)
        slashes = np.flatnonzero(a == _BACKSLASH)
        carry_in, self._carry = self._carry, 0
        if len(slashes) == 0:
            return quotes[1:] if carry_in and len(quotes) and quotes[0] == 0 else quotes
        breaks = np.flatnonzero(np.diff(slashes) != 1) + 1
        starts = slashes[np.r_[0, breaks]]
        ends = slashes[np.r_[breaks - 1, len(slashes) - 1]] + 1
        lengths = ends - starts + np.where(starts == 0, carry_in, 0)
        escaped = ends[lengths % 2 == 1]
        if carry_in and starts[0] != 0:
            escaped = np.r_[0, escaped]
        if ends[-1] == len(a):
            self._carry = int(lengths[-1] % 2)
        return quotes[~np.isin(quotes, escaped)]

    def remainder(self) -> bytes:
        """Bytes after the last complete document (whitespace stripped); non-empty means truncated input."""
        return bytes(self._pending).strip()
