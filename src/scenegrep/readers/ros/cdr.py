"""Vectorised CDR decoding: many ROS 2 messages of one type decoded at once into columns.

ROS 2 serialises messages as little-endian CDR (XCDR1, encapsulation ``00 01``): each primitive
is aligned to its size (8 at most) from the start of the payload after the 4-byte
encapsulation header; a string or a sequence is a ``uint32`` count followed by its elements.

:func:`decode` walks a type over a :class:`Payloads` batch *field by field for all messages at
once*: every primitive field is one numpy gather over the batch (a struct of k values of one
type, a point or a quaternion, one (n, k) gather; a fixed-size struct not wanted one skip). A
sequence of structs is first walked *speculatively* all at once, every element placed as if the
elements of its sequence were as long as its first (the usual case: every object of a message
has as many classifications and footprint points); the walk proves itself when each element
ends where the next was placed. Otherwise it is walked position by position (element j of
every message whose sequence is longer than j). So the Python work is per field (and, at
worst, per sequence position), never per message or element. The result
is a set of :class:`Level` tables: the messages (level ``""``) and one per sequence of structs
or strings (``objects``, ``objects.classification``), each item naming its parent item.

Everything is bounded by the input before it is used: every read is checked against its
message's size, and a sequence's count against the bytes left (each element takes at least
one byte), so a hostile count never sizes an allocation. A violation is a :class:`CdrError`
naming the message (its position in the batch).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .messages import DecodeError
from .msgdef import PRIMITIVE_SIZES, STRINGS, Field

_DTYPES = {
    "bool": "u1",
    "byte": "u1",
    "char": "u1",
    "int8": "i1",
    "uint8": "u1",
    "int16": "<i2",
    "uint16": "<u2",
    "int32": "<i4",
    "uint32": "<u4",
    "float32": "<f4",
    "int64": "<i8",
    "uint64": "<u8",
    "float64": "<f8",
}

HEADER = 4
"""Bytes of the encapsulation header before a CDR payload."""

ALIGN = 8
"""The largest CDR alignment: payload origins in a batch's buffer are multiples of it."""


class CdrError(DecodeError):
    """A CDR message that cannot be decoded: ``message`` is its position in the batch."""


@dataclass
class Payloads:
    """The payloads of a batch of messages, concatenated: ``start[i]`` is where message i's
    CDR origin is in ``buffer`` (after its encapsulation header), ``size[i]`` its bytes after it."""

    buffer: np.ndarray
    start: np.ndarray
    size: np.ndarray

    @classmethod
    def of(cls, payloads: Sequence[bytes]) -> Payloads:
        """The batch of ``payloads`` (raw CDR messages); CdrError for one without a little-endian
        CDR encapsulation header."""
        lengths = np.fromiter((len(p) for p in payloads), dtype=np.int64, count=len(payloads))
        for i, payload in enumerate(payloads):
            if len(payload) < HEADER or payload[0] != 0 or payload[1] != 1:
                kind = "big-endian CDR (not supported)" if payload[:2] in (b"\0\0", b"\0\2") else "not CDR"
                raise CdrError(i, f"{kind}: encapsulation header {bytes(payload[:HEADER]).hex() or 'missing'}")
        # each payload placed so that its CDR origin is 8-aligned: an aligned field is then
        # aligned in the buffer too, and a column is one gather from a typed view of it
        slots = (lengths + (ALIGN - 1 + ALIGN - HEADER)) // ALIGN * ALIGN
        ends = np.cumsum(slots)
        buffer = np.zeros(int(ends[-1]) if len(ends) else 0, dtype=np.uint8)
        first = ends - slots + (ALIGN - HEADER)
        for offset, payload in zip(first.tolist(), payloads):
            buffer[offset : offset + len(payload)] = np.frombuffer(payload, dtype=np.uint8)
        return cls(buffer, first + HEADER, lengths - HEADER)


@dataclass
class Level:
    """Items of one level of a decoded batch: for each, the item it belongs to in the level
    above (``parent``; the message for level ``""``), its position in that sequence (``rank``)
    and the fields wanted, by path relative to the level (``pose.position.x``). Items are in
    the order they were decoded (by rank, then parent); sort by (parent, rank) for message order."""

    parent: np.ndarray
    rank: np.ndarray
    fields: dict[str, np.ndarray]


@dataclass
class _Collect:
    parent: list[np.ndarray] = field(default_factory=list)
    rank: list[np.ndarray] = field(default_factory=list)
    fields: dict[str, list] = field(default_factory=dict)
    count: int = 0

    def level(self) -> Level:
        def join(parts: list) -> np.ndarray:
            if parts and isinstance(parts[0], list):
                out = np.empty(sum(len(p) for p in parts), dtype=object)
                out[:] = [s for p in parts for s in p]
                return out
            return np.concatenate(parts) if parts else np.empty(0)

        empty = np.empty(0, np.int64)
        return Level(
            np.concatenate(self.parent) if self.parent else empty,
            np.concatenate(self.rank) if self.rank else empty,
            {k: join(v) for k, v in self.fields.items()},
        )


def _align(pos: np.ndarray, size: int) -> np.ndarray:
    return (pos + (size - 1)) & -size


class _Walker:
    def __init__(self, types: dict[str, tuple[Field, ...]], wanted: frozenset[str], data: Payloads):
        self.types = types
        self.wanted = wanted
        self._prefixes = {w.rsplit(".", k)[0] for w in wanted for k in range(w.count(".") + 1)}
        self.data = data
        self.levels: dict[str, _Collect] = {}
        self._plain: dict[str, tuple[int, int] | None] = {}
        self._views: dict[str, np.ndarray] = {}

    # ------------------------------------------------------------------ helpers
    def _want(self, path: str) -> bool:
        return path in self._prefixes

    def _check(self, owner: np.ndarray, end: np.ndarray, what: str) -> None:
        bad = end > self.data.size[owner]
        if bad.any():
            row = int(np.argmax(bad))
            raise CdrError(
                int(owner[row]), f"truncated: {what} ends at byte {int(end[row])} of {int(self.data.size[owner[row]])}"
            )

    def _read(self, dtype: str, count: int, owner: np.ndarray, pos: np.ndarray, what: str) -> np.ndarray:
        """``count`` values of ``dtype`` at ``pos`` (aligned already) of each item: shape (n,) or (n, count)."""
        size = np.dtype(dtype).itemsize
        self._check(owner, pos + size * count, what)
        view = self._views.get(dtype)
        if view is None:
            view = self._views[dtype] = self.data.buffer[: len(self.data.buffer) // size * size].view(dtype)
        at = (self.data.start[owner] + pos) // size
        return view[at] if count == 1 else view[at[:, None] + np.arange(count)]

    def _count(self, owner: np.ndarray, pos: np.ndarray, what: str, least: int) -> tuple[np.ndarray, np.ndarray]:
        """The uint32 count at ``pos`` (aligned here) and the position after it; a count whose
        elements (``least`` bytes each at least) cannot fit in the bytes left is a CdrError."""
        pos = _align(pos, 4)
        n = self._read("<u4", 1, owner, pos, what).astype(np.int64)
        pos = pos + 4
        self._check(owner, pos + n * max(least, 1), f"{what} ({'count' if least else 'length'} too large)")
        return n, pos

    def plain(self, type_name: str) -> tuple[int, int] | None:
        """(size, alignment) of a struct made only of fixed-size primitives and such structs whose
        size is a multiple of its alignment (its elements need no padding), else None."""
        if type_name in self._plain:
            return self._plain[type_name]
        size, align = 0, 1
        result: tuple[int, int] | None = None
        for f in self.types[type_name]:
            if f.type in STRINGS or f.count == -1:
                break
            inner = (PRIMITIVE_SIZES[f.type],) * 2 if f.type in PRIMITIVE_SIZES else self.plain(f.type)
            if inner is None:
                break
            size = -(-size // inner[1]) * inner[1] + inner[0] * (f.count or 1)
            align = max(align, inner[1])
        else:
            result = (size, align) if size % align == 0 and size else None
        self._plain[type_name] = result
        return result

    def element(self, type_name: str) -> tuple[int, int] | None:
        """(size, alignment) of an array element of ``type_name``: a primitive's size twice, a
        plain struct's (:meth:`plain`); None for a string or another struct."""
        if type_name in PRIMITIVE_SIZES:
            return (PRIMITIVE_SIZES[type_name],) * 2
        return None if type_name in STRINGS else self.plain(type_name)

    def _strings(self, owner: np.ndarray, pos: np.ndarray, want: bool, what: str) -> tuple[np.ndarray, list]:
        n, pos = self._count(owner, pos, what, 0)
        texts: list[str] = []
        if want:
            starts = self.data.start[owner] + pos
            raw = self.data.buffer
            texts = [bytes(raw[s : s + k]).rstrip(b"\0").decode("utf-8", "replace") for s, k in zip(starts, n)]
        return pos + n, texts

    # ------------------------------------------------------------------ walking
    def struct(self, type_name: str, level: str, prefix: str, owner, items, pos) -> np.ndarray:
        for f in self.types[type_name]:
            pos = self.field(f, level, prefix + f.name, owner, items, pos)
        return pos

    def _store(self, level: str, path: str, values) -> None:
        self.levels[level].fields.setdefault(path, []).append(values)

    def field(self, f: Field, level: str, path: str, owner, items, pos) -> np.ndarray:
        full = f"{level}.{path}" if level else path
        want = self._want(full)
        if f.type in PRIMITIVE_SIZES and f.count != -1:
            size = PRIMITIVE_SIZES[f.type]
            count = 1 if f.count is None else f.count
            if count == 0:
                return pos
            pos = _align(pos, size)
            if want:
                self._store(level, path, self._read(_DTYPES[f.type], count, owner, pos, full))
            else:
                self._check(owner, pos + size * count, full)
            return pos + size * count
        if f.count is None:
            if f.type in STRINGS:
                pos, texts = self._strings(owner, pos, want, full)
                if want:
                    self._store(level, path, texts)
                return pos
            return self._struct_field(f, level, path, full, want, owner, items, pos)
        return self.sequence(f, full, want, owner, items, pos)

    def _struct_field(self, f: Field, level: str, path: str, full: str, want: bool, owner, items, pos) -> np.ndarray:
        """A struct field: skipped at once when plain and not wanted; read as one (n, k) gather
        when its k fields are single values of one primitive type (a point, a quaternion)."""
        plain = self.plain(f.type)
        if plain is not None and not want:
            pos = _align(pos, plain[1])
            self._check(owner, pos + plain[0], full)
            return pos + plain[0]
        fields = self.types[f.type]
        kinds = {(g.type, g.count) for g in fields}
        if len(kinds) == 1 and next(iter(kinds))[1] is None and fields[0].type in PRIMITIVE_SIZES and len(fields) > 1:
            size = PRIMITIVE_SIZES[fields[0].type]
            pos = _align(pos, size)
            values = self._read(_DTYPES[fields[0].type], len(fields), owner, pos, full)
            for k, g in enumerate(fields):
                if self._want(f"{full}.{g.name}"):
                    self._store(level, f"{path}.{g.name}", values[:, k])
            return pos + size * len(fields)
        return self.struct(f.type, level, path + ".", owner, items, pos)

    def sequence(self, f: Field, full: str, want: bool, owner, items, pos) -> np.ndarray:
        """A fixed array of strings or structs, or a sequence: primitives and plain structs not
        wanted are skipped at once; other elements are walked as the items of level ``full``."""
        element = self.element(f.type)
        if f.count == -1:
            n, pos = self._count(owner, pos, full, element[0] if element else 1)
        else:
            n = np.full(len(pos), f.count, dtype=np.int64)
        if element is not None and not want:
            pos = np.where(n > 0, _align(pos, element[1]), pos) + n * element[0]
            self._check(owner, pos, full)
            return pos
        collect = self.levels.setdefault(full, _Collect())
        if f.type not in STRINGS and f.type not in PRIMITIVE_SIZES and int(n.max(initial=0)) > 1:
            end = self._uniform(f, full, owner, items, pos, n, collect)
            if end is not None:
                return end
        pos = pos.copy()
        for j in range(int(n.max(initial=0))):
            active = np.flatnonzero(n > j)
            ids = collect.count + np.arange(len(active))
            collect.count += len(active)
            collect.parent.append(items[active])
            collect.rank.append(np.full(len(active), j, dtype=np.int64))
            if f.type in STRINGS:
                pos[active], texts = self._strings(owner[active], pos[active], True, full)
                collect.fields.setdefault("", []).append(texts)
            elif f.type in PRIMITIVE_SIZES:
                size = PRIMITIVE_SIZES[f.type]
                at = _align(pos[active], size)
                collect.fields.setdefault("", []).append(self._read(_DTYPES[f.type], 1, owner[active], at, full))
                pos[active] = at + size
            else:
                pos[active] = self.struct(f.type, full, "", owner[active], ids, pos[active])
        return pos

    def _uniform(self, f: Field, full: str, owner, items, pos, n, collect: _Collect) -> np.ndarray | None:
        """Walk every element of a sequence of structs at once, each at the place it would have
        if all the elements of its sequence were as long as its first; the end of the sequence
        when the walk confirms it (each element ends where the next was taken to start, so every
        place was right), else None with nothing kept (the caller walks element by element)."""
        some = np.flatnonzero(n > 0)
        scratch = _Walker(self.types, frozenset(), self.data)
        try:
            first_end = scratch.struct(f.type, full, "", owner[some], items[some], pos[some])
        except CdrError:
            return None
        counts = n[some]
        stride = first_end - pos[some]
        parent = np.repeat(some, counts)
        rank = np.arange(len(parent)) - np.repeat(np.cumsum(counts) - counts, counts)
        starts = np.repeat(pos[some], counts) + rank * np.repeat(stride, counts)
        saved = {
            name: (len(c.parent), c.count, {k: len(v) for k, v in c.fields.items()}) for name, c in self.levels.items()
        }
        ids = collect.count + np.arange(len(parent))
        collect.count += len(parent)
        collect.parent.append(items[parent])
        collect.rank.append(rank)
        try:
            ends = self.struct(f.type, full, "", owner[parent], ids, starts)
        except CdrError:
            ends = None
        last = np.r_[parent[1:] != parent[:-1], True]
        if ends is None or not np.array_equal(ends[~last], starts[1:][~last[:-1]]):
            self._rollback(saved)
            return None
        end = pos.copy()
        end[parent[last]] = ends[last]
        return end

    def _rollback(self, saved: dict) -> None:
        """Forget what was collected since ``saved`` (levels' lengths) was taken."""
        for name in list(self.levels):
            if name not in saved:
                del self.levels[name]
                continue
            parents, count, fields = saved[name]
            c = self.levels[name]
            del c.parent[parents:], c.rank[parents:]
            c.count = count
            for key in list(c.fields):
                if key in fields:
                    del c.fields[key][fields[key] :]
                else:
                    del c.fields[key]


def decode(
    types: dict[str, tuple[Field, ...]], type_name: str, data: Payloads, wanted: frozenset[str]
) -> dict[str, Level]:
    """Decode every message of ``data`` as ``type_name``; the ``wanted`` field paths (full paths
    from the message: ``header.frame_id``, ``objects.shape.dimensions.x``) are kept, by level.
    CdrError names the first message that cannot be decoded."""
    walker = _Walker(types, wanted, data)
    n = len(data.start)
    top = walker.levels.setdefault("", _Collect())
    items = np.arange(n, dtype=np.int64)
    top.parent.append(items)
    top.rank.append(np.zeros(n, dtype=np.int64))
    top.count = n
    walker.struct(type_name, "", "", items, items, np.zeros(n, dtype=np.int64))
    return {name: collect.level() for name, collect in walker.levels.items()}
