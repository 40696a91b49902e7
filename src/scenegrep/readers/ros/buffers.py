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
    """The payloads (each message's bytes or a memoryview into its chunk) in groups, in order."""
    n = len(payloads)
    address, size, owner = np.empty((3, n), np.int64)
    _cdr_copy.addresses(payloads, address, size, owner)
    if not all(type(p) is memoryview for p in payloads):
        base = np.frombuffer(b"".join(payloads), dtype=np.uint8)
        return [Group(base, np.cumsum(size) - size + HEADER, size - HEADER, 0)]
    cuts = [0, *(np.flatnonzero(owner[1:] != owner[:-1]) + 1).tolist(), n]
    out = []
    for start, end in zip(cuts, cuts[1:]):
        base = np.frombuffer(payloads[start].obj, dtype=np.uint8)
        origin = address[start:end] - base.__array_interface__["data"][0] + HEADER
        out.append(Group(base, origin, size[start:end] - HEADER, start))
    return out
