"""A batch of CDR messages that all have one layout, decoded with strided views.

A message's *layout* is where every field is. :func:`layout` walks one message (scalar Python,
once) and notes the byte offset of every wanted primitive and string and of every count (a
sequence's length, a string's length). Two messages of one type whose sizes are equal and whose
counts are equal at those offsets have the same layout: each offset depends only on the counts
before it, and every bound the generic walk checks (a read past the end, a count too large for
the bytes left) depends only on the counts and the size. :func:`copy` checks exactly that for
every message, and copies every wanted field of every message into its column (:func:`columns`),
in one pass of C per chunk (:mod:`._cdr_copy`) over a plan made once per layout (what to
compare, what to copy where): no Python runs per message, object or field.

:func:`copy` stops at a message of another layout (or a bad header), and :func:`layout` refuses
a type this module does not walk (a wanted sequence of strings or primitives) or a malformed
message (:class:`Unsupported`): the caller (:mod:`.cdr_batch`) decodes those otherwise. The
levels of the rows copied (:func:`levels_of`) are those :func:`.cdr.decode` gives, items in
message order.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass, field

import numpy as np

from . import _cdr_copy
from .buffers import Group
from .cdr import _DTYPES, Level, Payloads, _Walker
from .msgdef import PRIMITIVE_SIZES, STRINGS, Field


class Unsupported(ValueError):
    """A message this module does not lay out: a wanted sequence of strings or primitives, or
    one that is malformed (the generic walk names the fault)."""


@dataclass
class _LevelPlan:
    """One level of a layout: per item its parent item and rank; per wanted primitive field its
    dtype, values per item and each item's offset; per wanted string each item's offset and
    length (its NUL included); ``blocks``: the fields read together (:func:`_blocks`)."""

    parent_level: str
    parent: list[int] = field(default_factory=list)
    rank: list[int] = field(default_factory=list)
    fields: dict[str, tuple[str, int, list[int]]] = field(default_factory=dict)
    strings: dict[str, tuple[list[int], list[int]]] = field(default_factory=dict)
    blocks: list[tuple[tuple[str, ...], str, int, list[int]]] = field(default_factory=list)


@dataclass(frozen=True)
class _Output:
    """One column the plan copies into: per message ``items`` x ``k`` values of ``dtype`` (a
    string column: ``V<longest>``, zero-padded) of field(s) ``paths`` of level ``level``."""

    level: str
    paths: tuple[str, ...]
    dtype: str
    items: int
    k: int
    string: bool

    @property
    def row_bytes(self) -> int:
        return self.items * self.k * np.dtype(self.dtype).itemsize


@dataclass
class Layout:
    """Where things are in a message of this layout: ``size`` its CDR bytes (after the
    encapsulation header), ``count_at`` the offsets of its counts and ``count_value`` their
    values, ``levels`` the items and fields (offsets from the CDR origin); the plan run per
    message: ``outputs`` (the columns) and ``copies`` (rows of source offset, output, offset in
    the output's row, bytes; sorted by source offset)."""

    size: int
    count_at: np.ndarray
    count_value: np.ndarray
    levels: dict[str, _LevelPlan]
    outputs: tuple[_Output, ...]
    copies: np.ndarray
    row_bytes: np.ndarray = field(init=False)
    """The bytes of one message's row of each output."""
    items: dict[str, tuple[int, np.ndarray, np.ndarray]] = field(init=False, default_factory=dict)
    """Per level, the parents and ranks of its items in the last number of messages decoded."""

    def __post_init__(self) -> None:
        self.row_bytes = np.array([o.row_bytes for o in self.outputs], dtype=np.int64)


def layout(types: dict[str, tuple[Field, ...]], type_name: str, wanted: frozenset[str], raw: bytes) -> Layout:
    """The layout of one message (``raw``: its bytes after the encapsulation header); Unsupported
    when it cannot be laid out (see :class:`Unsupported`)."""
    plainer = _Walker(types, wanted, Payloads(np.zeros(0, np.uint8), np.zeros(0, np.int64), np.zeros(0, np.int64)))
    prefixes = plainer._prefixes
    counts: list[tuple[int, int]] = []
    levels: dict[str, _LevelPlan] = {"": _LevelPlan("", [0], [0])}

    def count(pos: int, least: int) -> tuple[int, int]:
        pos = (pos + 3) & -4
        if pos + 4 > len(raw):
            raise Unsupported("truncated")
        (n,) = struct.unpack_from("<I", raw, pos)
        counts.append((pos, n))
        if pos + 4 + n * max(least, 1) > len(raw):  # as the generic walk bounds a count
            raise Unsupported("count too large")
        return n, pos + 4

    def walk(type_name: str, level: str, prefix: str, item: int, pos: int) -> int:
        plan = levels[level]
        for f in types[type_name]:
            path = prefix + f.name
            full = f"{level}.{path}" if level else path
            want = full in prefixes
            if f.type in PRIMITIVE_SIZES and f.count != -1:
                size, k = PRIMITIVE_SIZES[f.type], 1 if f.count is None else f.count
                if k == 0:
                    continue
                pos = (pos + size - 1) & -size
                if want:
                    plan.fields.setdefault(path, (_DTYPES[f.type], k, []))[2].append(pos)
                pos += size * k
            elif f.count is None and f.type in STRINGS:
                n, pos = count(pos, 0)
                if want:
                    spots = plan.strings.setdefault(path, ([], []))
                    spots[0].append(pos)
                    spots[1].append(n)
                pos += n
            elif f.count is None:
                plain = plainer.plain(f.type)
                if plain is not None and not want:
                    pos = ((pos + plain[1] - 1) & -plain[1]) + plain[0]
                else:
                    pos = walk(f.type, level, path + ".", item, pos)
            else:
                element = plainer.element(f.type)
                n, pos = count(pos, element[0] if element else 1) if f.count == -1 else (f.count, pos)
                if element is not None and not want:
                    pos = (((pos + element[1] - 1) & -element[1]) if n else pos) + n * element[0]
                elif f.type in STRINGS or f.type in PRIMITIVE_SIZES:
                    raise Unsupported(full)
                else:
                    sub = levels.setdefault(full, _LevelPlan(level))
                    for j in range(n):
                        sub.parent.append(item)
                        sub.rank.append(j)
                        pos = walk(f.type, full, "", len(sub.parent) - 1, pos)
            if pos > len(raw):
                raise Unsupported("truncated")
        return pos

    walk(type_name, "", "", 0, 0)
    for plan in levels.values():
        plan.blocks = _blocks(plan.fields)
    outputs, copies = _program(levels)
    at = np.array([c[0] for c in counts], dtype=np.int64)
    return Layout(len(raw), at, np.array([c[1] for c in counts], dtype=np.uint32), levels, outputs, copies)


def _program(levels: dict[str, _LevelPlan]) -> tuple[tuple[_Output, ...], np.ndarray]:
    """The columns of a layout and the copies that fill them from one message: every item's
    block of fields is one copy, every string's bytes one (after its count, NUL included)."""
    outputs: list[_Output] = []
    copies: list[tuple[int, int, int, int]] = []
    for name, plan in levels.items():
        for paths, dtype, k, at in plan.blocks:
            size = np.dtype(dtype).itemsize * k
            copies.extend((a, len(outputs), j * size, size) for j, a in enumerate(at))
            outputs.append(_Output(name, paths, dtype, len(at), k, False))
        for path, (at, lengths) in plan.strings.items():
            longest = max(max(lengths, default=0), 1)
            copies.extend((a, len(outputs), j * longest, n) for j, (a, n) in enumerate(zip(at, lengths)) if n)
            outputs.append(_Output(name, (path,), f"V{longest}", len(at), 1, True))
    program = np.array(sorted(copies), dtype=np.int64).reshape(len(copies), 4)
    return tuple(outputs), program


def _blocks(fields: dict[str, tuple[str, int, list[int]]]) -> list[tuple[tuple[str, ...], str, int, list[int]]]:
    """The wanted fields of a level as blocks read at once: single values of one type that
    follow each other without a gap in every item (a point's x, y, z) are one block of k values;
    any other field is a block of its own."""
    order = sorted(fields.items(), key=lambda item: item[1][2][0])
    blocks = []
    i = 0
    while i < len(order):
        path, (dtype, k, at) = order[i]
        paths, size = [path], np.dtype(dtype).itemsize
        while k == 1 and i + len(paths) < len(order):
            _, (other, count, places) = order[i + len(paths)]
            if other != dtype or count != 1 or any(b != a + size * len(paths) for a, b in zip(at, places)):
                break
            paths.append(order[i + len(paths)][0])
        blocks.append((tuple(paths), dtype, len(paths) if k == 1 else k, at))
        i += len(paths)
    return blocks


def _texts(raw: np.ndarray) -> np.ndarray:
    """Strings of zero-padded bytes (``V<n>``), decoded once per distinct value (trailing NULs
    dropped, as the generic walk decodes each)."""
    unique, inverse = np.unique(raw, return_inverse=True)
    decoded = np.array([bytes(u).rstrip(b"\0").decode("utf-8", "replace") for u in unique], dtype=object)
    return decoded[inverse.ravel()]


def columns(plan: Layout, capacity: int) -> tuple[np.ndarray, ...]:
    """Empty columns of ``plan`` for ``capacity`` messages (string columns zeroed: their bytes
    past a string's end are read as padding)."""
    return tuple((np.zeros if o.string else np.empty)((capacity, o.items, o.k), o.dtype) for o in plan.outputs)


def copy(plan: Layout, group: Group, out: tuple[np.ndarray, ...], row: int) -> int:
    """Copy the messages of ``group`` (all of the plan's size) into rows ``row``... of the
    columns ``out``, in order, while they are of layout ``plan``: how many were."""
    return _cdr_copy.run(
        group.base, group.origins, plan.size, plan.count_at, plan.count_value, plan.copies, out, plan.row_bytes, row
    )


def levels_of(plan: Layout, out: tuple[np.ndarray, ...], n: int) -> dict[str, Level]:
    """The levels of the first ``n`` rows of columns ``out`` of ``plan`` (in message order)."""
    result = {name: Level(*_items(plan, name, n), {}) for name in plan.levels}
    for o, column in zip(plan.outputs, out):
        values = column[:n]
        fields = result[o.level].fields
        if o.string:
            fields[o.paths[0]] = _texts(values.reshape(n * o.items))
        elif len(o.paths) == 1:
            fields[o.paths[0]] = values.reshape(n * o.items) if o.k == 1 else values.reshape(n * o.items, o.k)
        else:
            block = values.reshape(n * o.items, o.k)
            fields.update((path, block[:, j]) for j, path in enumerate(o.paths))  # strided views, no copy
    return result


def _items(plan: Layout, name: str, n: int) -> tuple[np.ndarray, np.ndarray]:
    """The parent and rank of every item of level ``name`` of ``n`` messages of ``plan`` (read-only;
    the last ``n``'s kept in the plan: batches are mostly of one size)."""
    found = plan.items.get(name)
    if found is None or found[0] != n:
        p = plan.levels[name]
        message = np.repeat(np.arange(n, dtype=np.int64), len(p.parent))
        parent = message
        if name:
            parent = message * len(plan.levels[p.parent_level].parent) + np.tile(np.array(p.parent, dtype=np.int64), n)
        rank = np.tile(np.array(p.rank, dtype=np.int64), n)
        parent.flags.writeable = rank.flags.writeable = False
        found = plan.items[name] = (n, parent, rank)
    return found[1], found[2]
