"""A batch of CDR messages that all have one layout, decoded with strided views.

A message's *layout* is where every field is. :func:`layout` walks one message (scalar Python,
once) and notes the byte offset of every wanted primitive and string and of every count (a
sequence's length, a string's length). Two messages of one type whose sizes are equal and whose
counts are equal at those offsets have the same layout: each offset depends only on the counts
before it, and every bound the generic walk checks (a read past the end, a count too large for
the bytes left) depends only on the counts and the size. :func:`decode_same_layout` checks
exactly that for a whole batch with one gather, then reads every wanted field of every message
as one strided view of the batch's rows (an item's field is at a constant step from the one
before: one view, one copy), so the Python work is per field, not per message or object.

A batch that is not of one layout, or holds a bad header, or a type this module does not walk
(a wanted sequence of strings or primitives) gives None: the caller decodes it with
:func:`.cdr.decode`, which also names a bad message. The levels returned are those
:func:`.cdr.decode` gives, items in message order.
"""

from __future__ import annotations

import struct
from operator import attrgetter
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .cdr import _DTYPES, HEADER, Level, Payloads, _Walker
from .msgdef import PRIMITIVE_SIZES, STRINGS, Field


class Unsupported(ValueError):
    """A message this module does not lay out: a wanted sequence of strings or primitives, or
    one that is malformed (the generic walk names the fault)."""


@dataclass(frozen=True)
class _Spots:
    """Where one field is in every item of a level: ``k`` values of ``dtype`` at each CDR offset
    ``at``. Items of one size are evenly spaced, items of other sizes (a longer string) break
    that into runs: ``runs`` are (first item, items, step) of evenly spaced offsets, None when
    there are more than :data:`MAX_RUNS` (then ``columns``, the byte offsets of all the values,
    are gathered)."""

    dtype: str
    k: int
    at: np.ndarray
    runs: tuple[tuple[int, int, int], ...] | None
    columns: np.ndarray

    @classmethod
    def of(cls, dtype: str, k: int, at: list[int]) -> _Spots:
        spots = np.array(at, dtype=np.int64)
        columns = (spots[:, None] + np.arange(np.dtype(dtype).itemsize * k)).ravel()
        runs: list[tuple[int, int, int]] = []
        start = 0
        while start < len(spots):
            step = int(spots[start + 1] - spots[start]) if start + 1 < len(spots) else 0
            end = start + 1
            while end < len(spots) and spots[end] - spots[end - 1] == step:
                end += 1
            runs.append((start, end - start, step))
            start = end
        return cls(dtype, k, spots, tuple(runs) if len(runs) <= MAX_RUNS else None, columns)


MAX_RUNS = 8
"""The most runs of evenly spaced places read as strided views (more are gathered)."""


@dataclass
class _LevelPlan:
    """One level of a layout: per item its parent item and rank; per wanted primitive field its
    dtype, values per item and each item's offset; per wanted string each item's offset and
    length."""

    parent_level: str
    parent: list[int] = field(default_factory=list)
    rank: list[int] = field(default_factory=list)
    fields: dict[str, tuple[str, int, list[int]]] = field(default_factory=dict)
    strings: dict[str, tuple[list[int], list[int]]] = field(default_factory=dict)
    blocks: list[tuple[tuple[str, ...], _Spots]] = field(default_factory=list)


@dataclass
class Layout:
    """Where things are in a message of this layout: ``size`` its CDR bytes (after the
    encapsulation header), ``count_at`` the offsets of its counts and ``count_value`` their
    values, ``levels`` the items and fields (offsets from the CDR origin)."""

    size: int
    count_at: _Spots
    count_value: np.ndarray
    levels: dict[str, _LevelPlan]


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
                element = PRIMITIVE_SIZES.get(f.type) or (None if f.type in STRINGS else plainer.plain(f.type))
                element = (element, element) if isinstance(element, int) else element
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
    at = _Spots.of("<u4", 1, [c[0] for c in counts])
    return Layout(len(raw), at, np.array([c[1] for c in counts], dtype=np.uint32), levels)


def _blocks(fields: dict[str, tuple[str, int, list[int]]]) -> list[tuple[tuple[str, ...], _Spots]]:
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
        blocks.append((tuple(paths), _Spots.of(dtype, len(paths) if k == 1 else k, at)))
        i += len(paths)
    return blocks


@dataclass(frozen=True)
class _Group:
    """Messages of a batch that lie in one buffer (one decompressed chunk): ``base`` its bytes,
    ``origins`` each message's CDR origin in it (after its header), ``stride`` the constant step
    between them (0 for one message), None when they are not evenly spaced."""

    base: np.ndarray
    origins: np.ndarray
    stride: int | None


def _group(base: np.ndarray, origins: np.ndarray) -> _Group:
    steps = np.diff(origins)
    stride = 0 if not len(steps) else int(steps[0]) if (steps == steps[0]).all() and steps[0] > 0 else None
    return _Group(base, origins, stride)


def _address(buffer) -> int:
    """The memory address of a buffer's first byte."""
    return np.frombuffer(buffer, np.uint8).__array_interface__["data"][0]


def _groups(payloads: Sequence) -> list[_Group] | None:
    """The batch as runs of messages sharing one buffer (memoryviews of one chunk; bytes are
    copied into one buffer), or None when the payloads' sizes differ or one lacks the
    little-endian CDR encapsulation header."""
    size = len(payloads[0])
    if size < HEADER or set(map(len, payloads)) != {size}:
        return None
    if set(map(type, payloads)) != {memoryview}:
        base = np.frombuffer(b"".join(payloads), dtype=np.uint8)
        groups = [_group(base, np.arange(len(payloads), dtype=np.int64) * size + HEADER)]
    else:
        owners = list(map(attrgetter("obj"), payloads))
        same = np.fromiter(map(id, owners), np.int64, len(owners))  # (all alive: ids are distinct)
        cuts = [0, *(np.flatnonzero(same[1:] != same[:-1]) + 1).tolist(), len(owners)]
        address = np.fromiter(map(_address, payloads), np.int64, len(payloads))
        groups = []
        for start, end in zip(cuts, cuts[1:]):
            base = np.frombuffer(owners[start], dtype=np.uint8)
            groups.append(_group(base, address[start:end] - _address(base) + HEADER))
    for g in groups:
        if (g.base[g.origins - HEADER] != 0).any() or (g.base[g.origins - HEADER + 1] != 1).any():
            return None
    return groups


def _values(group: _Group, spots: _Spots, out: np.ndarray) -> np.ndarray:
    """Per message of ``group``, the field at ``spots``, written into ``out`` (shape (messages,
    spots, k)) and returned: one strided view of the group's buffer per run of evenly spaced
    places (:class:`_Spots`) when the group's messages are evenly spaced, else one gather."""
    n, m = len(group.origins), len(spots.at)
    if group.stride is not None and spots.runs is not None:
        size, first = np.dtype(spots.dtype).itemsize, int(group.origins[0])
        for start, count, step in spots.runs:
            at = first + int(spots.at[start])
            view = np.ndarray((n, count, spots.k), spots.dtype, group.base, at, (group.stride, step, size))
            out[:, start : start + count] = view
        return out
    out[...] = group.base[group.origins[:, None] + spots.columns].view(spots.dtype).reshape(n, m, spots.k)
    return out


def matches(plan: Layout, groups: list[_Group]) -> bool:
    """Whether every message of ``groups`` (all of the plan's size) has the layout ``plan``."""
    if not len(plan.count_at.at):
        return True
    counts = plan.count_at
    return all(
        (_values(g, counts, np.empty((len(g.origins), len(counts.at), 1), "<u4"))[:, :, 0] == plan.count_value).all()
        for g in groups
    )


def _strings(groups: list[_Group], at: list[int], lengths: list[int]) -> np.ndarray:
    """Per message, the string at each offset (of its length): item order (message, then
    offset); decoded once per distinct value, as the generic walk decodes each."""
    n, m = sum(len(g.origins) for g in groups), len(at)
    texts = np.empty(n * m, dtype=object)
    for j, (pos, length) in enumerate(zip(at, lengths)):
        if not length:
            texts[j::m] = ""
            continue
        spots = _Spots.of(f"V{length}", 1, [pos])
        raw = np.concatenate([_values(g, spots, np.empty((len(g.origins), 1, 1), spots.dtype)).ravel() for g in groups])
        unique, inverse = np.unique(raw, return_inverse=True)
        decoded = np.array([bytes(u).rstrip(b"\0").decode("utf-8", "replace") for u in unique], dtype=object)
        texts[j::m] = decoded[inverse.ravel()]
    return texts


def decode_groups(plan: Layout, groups: list[_Group]) -> dict[str, Level]:
    """The levels of the messages of ``groups`` (every one of layout ``plan``: check
    :func:`matches` first), in message order. Every block of fields of a group is copied out
    before the next group is read (its chunk is then still in cache)."""
    n = sum(len(g.origins) for g in groups)
    wanted = [(name, paths, spots) for name, p in plan.levels.items() for paths, spots in p.blocks]
    columns = {(name, paths): np.empty((n, len(s.at), s.k), s.dtype) for name, paths, s in wanted}
    start = 0
    for g in groups:
        end = start + len(g.origins)
        for name, paths, spots in wanted:
            _values(g, spots, columns[name, paths][start:end])
        start = end
    sizes = {name: len(p.parent) for name, p in plan.levels.items()}
    out: dict[str, Level] = {}
    for name, p in plan.levels.items():
        m = len(p.parent)
        message = np.repeat(np.arange(n, dtype=np.int64), m)
        parent = message
        if name:
            parent = message * sizes[p.parent_level] + np.tile(np.array(p.parent, dtype=np.int64), n)
        fields: dict[str, np.ndarray] = {}
        for paths, spots in p.blocks:
            values = columns[name, paths]
            if len(paths) == 1:
                fields[paths[0]] = values.reshape(n * m) if spots.k == 1 else values.reshape(n * m, spots.k)
            else:
                fields.update((path, values[:, :, j].reshape(n * m)) for j, path in enumerate(paths))
        for path, (at, lengths) in p.strings.items():
            fields[path] = _strings(groups, at, lengths)
        out[name] = Level(parent, np.tile(np.array(p.rank, dtype=np.int64), n), fields)
    return out


def decode_same_layout(
    types: dict[str, tuple[Field, ...]],
    type_name: str,
    wanted: frozenset[str],
    payloads: Sequence,
    cache: dict[object, Layout],
    key: object,
) -> dict[str, Level] | None:
    """The levels of a batch of one layout (that of ``cache[key]``, else of its first message,
    then kept there), or None when the batch is not of one layout (see the module docstring).
    ``payloads``: each message's bytes or a memoryview into its chunk (read in place)."""
    groups = _groups(payloads)
    if groups is None:
        return None
    plan = cache.get(key)
    if plan is None or plan.size != len(payloads[0]) - HEADER or not matches(plan, groups):
        try:
            plan = layout(types, type_name, wanted, bytes(payloads[0][HEADER:]))
        except Unsupported:
            return None
        cache[key] = plan
        if not matches(plan, groups):
            return None
    return decode_groups(plan, groups)
