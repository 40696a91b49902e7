"""Columns that grow in place: the bag reader's trace rows, written as its frames are built.

A :class:`Column` is a 1-D array that grows. Past :data:`SMALL` bytes it lives in anonymous
private memory (``mmap``) and grows by remapping it (``mremap`` on Linux): growing copies
nothing and fills nothing, and a page is touched only when a row on it is written. So a long
column costs the memory of its rows once, where an array made again at each doubling (or a
list of parts concatenated at the end) writes every row two or three times into fresh memory;
the trace of a 100k-message bag is about 430 MB, and first touching memory is slow on some
machines. Where a map cannot be resized (systems without ``mremap``), a bigger map is made and
the rows copied into it. A short column (a live chunk's) stays an ordinary array, so chunks
hold no maps (a process may have only so many).
"""

from __future__ import annotations

import contextlib
import mmap
import sys

import numpy as np

SMALL = 1 << 20
"""Bytes up to which a column is an ordinary array."""

_FLAGS = getattr(mmap, "MAP_PRIVATE", 0) | getattr(mmap, "MAP_ANONYMOUS", 0)

_POPULATE = getattr(mmap, "MADV_POPULATE_WRITE", 23 if sys.platform == "linux" else None)
"""madvise's MADV_POPULATE_WRITE (Linux 5.14 on): the pages of rows about to be written are
made in one call, not one fault each (a quarter less time per page on this VM)."""


def _anonymous(size: int) -> mmap.mmap:
    """Zeroed private memory of ``size`` bytes, with the system's default pages (advising huge
    pages, as numpy does for large arrays, made first touches slower where the kernel compacts
    memory to find them: 100k-message bag, framing 6.0-6.2 us per message with 4 kB pages
    against 8.3-15.3 with huge pages)."""
    return mmap.mmap(-1, size, flags=_FLAGS) if _FLAGS else mmap.mmap(-1, size)


class Column:
    """A growing 1-D array of ``dtype``: :meth:`rows` gives rows to write (growing it first when
    they lie beyond its capacity), :meth:`array` the finished column. Views from :meth:`rows`
    must be dropped before the next call (a map that is viewed cannot be resized)."""

    def __init__(self, dtype: type | np.dtype, capacity: int = 1024):
        self.dtype = np.dtype(dtype)
        self.capacity = max(int(capacity), 1)
        self._small: np.ndarray | None = np.empty(self.capacity, self.dtype)
        self._memory: mmap.mmap | None = None

    def rows(self, start: int, stop: int) -> np.ndarray:
        """A writable view of rows ``[start, stop)``."""
        if stop > self.capacity:
            self._grow(max(stop, 2 * self.capacity))
        if self._small is not None:
            return self._small[start:stop]
        if _POPULATE is not None and stop > start:
            first = start * self.dtype.itemsize // mmap.PAGESIZE * mmap.PAGESIZE
            with contextlib.suppress(OSError, ValueError):  # (an older kernel: the pages come by faults)
                self._memory.madvise(_POPULATE, first, stop * self.dtype.itemsize - first)  # type: ignore[union-attr]
        return np.frombuffer(self._memory, self.dtype, stop - start, start * self.dtype.itemsize)  # type: ignore[arg-type]

    def array(self, n: int) -> np.ndarray:
        """The first ``n`` rows as an array (a map gives back the memory past them); the column
        is not written again."""
        if self._small is not None or not n:
            return self._small[:n] if self._small is not None else np.empty(0, self.dtype)
        with contextlib.suppress(OSError, SystemError):  # (no mremap: the map keeps its capacity)
            self._memory.resize(n * self.dtype.itemsize)  # type: ignore[union-attr]
        return np.frombuffer(self._memory, self.dtype, n)  # type: ignore[arg-type]

    def _grow(self, capacity: int) -> None:
        size = capacity * self.dtype.itemsize
        if size <= SMALL:
            grown = np.empty(capacity, self.dtype)
            grown[: self.capacity] = self._small
            self._small = grown
        elif self._memory is None:
            self._memory = _anonymous(size)
            self._memory[: self._small.nbytes] = self._small.tobytes()  # type: ignore[union-attr]
            self._small = None
        else:
            try:
                self._memory.resize(size)
            except (OSError, SystemError):  # (no mremap)
                bigger = _anonymous(size)
                bigger[: len(self._memory)] = self._memory
                self._memory.close()
                self._memory = bigger
        self.capacity = capacity
