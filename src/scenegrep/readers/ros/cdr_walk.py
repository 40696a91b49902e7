"""CDR messages of any layout decoded by a walk in C, one message after the other.

:func:`program` compiles a type and the wanted fields (once per schema and field set) into rows
that :mod:`._cdr_walk` follows for every message: a primitive (aligned, read or skipped), a
plain struct skipped at once, a string, a sequence skipped at once, or a sequence whose
elements are items of a level (their parent item and rank noted, their rows walked). Every read
is bounded as the generic walk (:mod:`.cdr`) bounds it: nothing past a message's end, a count
leaving room for its elements (``least`` bytes each, at least one). So the walk accepts the
messages the generic walk accepts (but for a fixed-size array of more elements than bytes left,
which it refuses, so a hostile schema cannot size its output); :func:`decode_walked` gives None at
the first message it cannot walk (the caller then runs the generic walk, which names the fault or
decodes it), else the levels
the generic walk gives (items in message order; a level exists once its sequence is reached,
its fields once it has an item).

The Python work is per batch and per field; the C loop per message and field.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from . import _cdr_walk
from .buffers import Group, groups
from .cdr import _DTYPES, Level, Payloads, _Walker
from .msgdef import PRIMITIVE_SIZES, STRINGS, Field

PRIM, SKIP, STRING, SEQ_SKIP, SEQ = 1, 2, 3, 4, 5
MAX_DEPTH = 32
"""The deepest nesting of structs compiled (a deeper or recursive type: the generic walk)."""


class Unsupported(ValueError):
    """A type the program cannot express (nesting deeper than :data:`MAX_DEPTH`)."""


@dataclass(frozen=True)
class Program:
    """A compiled walk: ``rows`` (n, 6) int64; ``levels`` the level names (``""`` first) and each
    one's parent level; ``columns`` (level, path, dtype, values per item; dtype None: a string)."""

    rows: np.ndarray
    levels: tuple[tuple[str, str], ...]
    columns: tuple[tuple[str, str, str | None, int], ...]


def program(types: dict[str, tuple[Field, ...]], type_name: str, wanted: frozenset[str]) -> Program:
    """The program of ``type_name`` keeping the ``wanted`` paths (see the module docstring)."""
    plainer = _Walker(types, wanted, Payloads(np.zeros(0, np.uint8), np.zeros(0, np.int64), np.zeros(0, np.int64)))
    prefixes = plainer._prefixes
    rows: list[list[int]] = []
    levels: list[tuple[str, str]] = [("", "")]
    columns: list[tuple[str, str, str | None, int]] = []

    def column(level: str, path: str, dtype: str | None, k: int) -> int:
        columns.append((level, path, dtype, k))
        return len(columns) - 1

    def struct(name: str, level: str, prefix: str, depth: int) -> None:
        if depth > MAX_DEPTH:
            raise Unsupported(f"{name}: nested deeper than {MAX_DEPTH}")
        for f in types[name]:
            path = prefix + f.name
            full = f"{level}.{path}" if level else path
            want = full in prefixes
            if f.type in PRIMITIVE_SIZES and f.count != -1:
                size, k = PRIMITIVE_SIZES[f.type], 1 if f.count is None else f.count
                if k:
                    rows.append([PRIM, size, k, column(level, path, _DTYPES[f.type], k) if want else -1, 0, 0])
            elif f.count is None and f.type in STRINGS:
                rows.append([STRING, column(level, path, None, 1) if want else -1, 0, 0, 0, 0])
            elif f.count is None:
                plain = plainer.plain(f.type)
                if plain is not None and not want:
                    rows.append([SKIP, plain[0], plain[1], 0, 0, 0])
                else:
                    struct(f.type, level, path + ".", depth + 1)
            else:
                element = plainer.element(f.type)
                fixed = -1 if f.count == -1 else f.count
                if element is not None and not want:
                    rows.append([SEQ_SKIP, element[0], element[1], fixed, 0, 0])
                    continue
                levels.append((full, level))
                at = len(rows)
                rows.append([SEQ, len(levels) - 1, 0, element[0] if element else 1, fixed, 0])
                if f.type in STRINGS:
                    rows.append([STRING, column(full, "", None, 1), 0, 0, 0, 0])
                elif f.type in PRIMITIVE_SIZES:
                    rows.append([PRIM, PRIMITIVE_SIZES[f.type], 1, column(full, "", _DTYPES[f.type], 1), 0, 0])
                else:
                    struct(f.type, full, "", depth + 1)
                rows[at][2] = len(rows) - at - 1

    struct(type_name, "", "", 0)
    return Program(np.array(rows, dtype=np.int64).reshape(len(rows), 6), tuple(levels), tuple(columns))


def _texts(heap: bytes, places: np.ndarray) -> np.ndarray:
    """The strings at (offset, length) rows of ``heap``, decoded once per distinct value (NULs
    at the end dropped, as the generic walk decodes each)."""
    out = np.empty(len(places), dtype=object)
    decoded: dict[bytes, str] = {}
    for i, (start, length) in enumerate(places.tolist()):
        raw = heap[start : start + length]
        text = decoded.get(raw)
        if text is None:
            text = decoded[raw] = raw.rstrip(b"\0").decode("utf-8", "replace")
        out[i] = text
    return out


class Walk:
    """Batches of messages walked by ``plan`` into one set of levels, one :meth:`add` after the
    other (each while its buffer is at hand; nothing refers to it afterwards)."""

    def __init__(self, plan: Program):
        self.plan = plan
        count = len(plan.levels)
        self.columns = [bytearray() for _ in plan.columns]
        self.parents, self.ranks = [bytearray() for _ in range(count)], [bytearray() for _ in range(count)]
        self.counts, self.reached = np.zeros(count, np.int64), np.zeros(count, np.int64)
        self.heap = bytearray()
        self.n = 0

    def add(self, found: list[Group]) -> bool:
        """Walk the messages of ``found`` (a batch's groups, :func:`.buffers.groups`); False, with
        nothing added, when the walk refuses one of them (see the module docstring)."""
        buffers = (*self.columns, *self.parents, *self.ranks, self.heap)
        before = ([len(b) for b in buffers], self.counts.copy(), self.reached.copy())
        n = self.n
        for g in found:
            walked = (g.sizes >= 0).all() and _cdr_walk.walk(
                g.base, g.origins, g.sizes, self.plan.rows, self.columns, self.heap, self.parents, self.ranks,
                self.counts, self.reached, n,
            ) < 0  # fmt: skip
            if not walked:
                for buffer, length in zip(buffers, before[0]):
                    del buffer[length:]
                self.counts[:], self.reached[:] = before[1], before[2]
                return False
            n += len(g.origins)
        self.n = n
        self.counts[0] = self.reached[0] = n
        return True

    def levels(self) -> dict[str, Level]:
        """The levels of the messages added (items in message order)."""
        n = self.n
        out: dict[str, Level] = {"": Level(np.arange(n, dtype=np.int64), np.zeros(n, dtype=np.int64), {})}
        for k, (name, _) in enumerate(self.plan.levels[1:], start=1):
            if self.reached[k]:
                out[name] = Level(np.frombuffer(self.parents[k], np.int64), np.frombuffer(self.ranks[k], np.int64), {})
        text = bytes(self.heap)
        for (level, path, dtype, k), raw in zip(self.plan.columns, self.columns):
            if level not in out or not len(out[level].parent):
                continue
            if dtype is None:
                out[level].fields[path] = _texts(text, np.frombuffer(raw, np.int64).reshape(-1, 2))
            else:
                values = np.frombuffer(raw, dtype)
                out[level].fields[path] = values if k == 1 else values.reshape(-1, k)
        return out


def decode_walked(plan: Program, payloads: Sequence) -> dict[str, Level] | None:
    """The levels of a batch (each payload its bytes or a memoryview into its chunk), or None at
    the first message the walk refuses (see the module docstring)."""
    walk = Walk(plan)
    return walk.levels() if walk.add(groups(payloads)) else None
