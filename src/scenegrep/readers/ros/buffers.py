"""The payloads of a batch of CDR messages as groups that share one buffer, for the C loops that
read them in place (:mod:`._cdr_copy`, :mod:`._cdr_walk`).

Memoryviews of one decompressed chunk are one group, read where they lie; payloads that are not
all memoryviews (bytes, as the live reader gives them) are joined into one new buffer first.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import _cdr_copy
from .cdr import HEADER


@dataclass(frozen=True)
class Group:
    """Messages of a batch that lie in one buffer: ``base`` its bytes (uint8), per message its
    CDR ``origins`` in it (after the 4-byte encapsulation header) and ``sizes`` (bytes from the
    origin to the message's end; negative for a payload shorter than the header); ``start``
    the position of its first message in the batch."""

    base: np.ndarray
    origins: np.ndarray
    sizes: np.ndarray
    start: int


def groups(payloads: Sequence) -> list[Group]:
    """The payloads (each message's bytes or a memoryview into its chunk) in groups, in order:
    one per run of payloads of one owner, unless runs are short (payloads of their own, as bytes
    are): then one buffer of them all, joined."""
    n = len(payloads)
    offset, size = np.empty((2, n), np.int64)
    runs = _cdr_copy.locate(payloads, offset, size)
    if len(runs) > 1 and 4 * len(runs) > n:
        base = np.frombuffer(b"".join(payloads), dtype=np.uint8)
        return [Group(base, np.cumsum(size) - size + HEADER, size - HEADER, 0)]
    ends = [start for start, _ in runs[1:]] + [n]
    return [
        Group(np.frombuffer(owner, dtype=np.uint8), offset[start:end] + HEADER, size[start:end] - HEADER, start)
        for (start, owner), end in zip(runs, ends)
    ]
