"""A batch of CDR messages of one type decoded as it arrives, a run of messages (a chunk's) at a
time, so every chunk is read while it is still in memory and nothing refers to it afterwards.

:class:`CdrBatch` runs each :meth:`CdrBatch.add` at once in C: while the batch's messages share
one layout, they are copied into columns made for it (:mod:`.cdr_layout`; the layout is the
cached one of the type, else the first message's); from the first message of another layout on,
they are walked (:mod:`.cdr_walk`); from the first run the walk refuses on (or for a type the walk
cannot express), they are kept and decoded by the generic walk (:func:`.cdr.decode`) at the end,
which names a bad message (a :class:`~.cdr.CdrError` at its position in the batch).
:meth:`CdrBatch.levels` joins the parts: the levels :func:`.cdr.decode` gives for the whole batch
(the same items, parents and values; items in message order but for the generic part's).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from .buffers import Group, groups
from .cdr import HEADER, CdrError, Level, Payloads, decode
from .cdr_layout import Layout, Unsupported, columns, copy, layout, levels_of
from .cdr_walk import Program, Walk
from .msgdef import Field


class CdrBatch:
    """The messages of one type added so far (see the module docstring). ``layouts`` keeps the
    last layout of each ``key`` (type and fields) across batches, ``programs`` the walk's program
    (None: a type the walk cannot express); ``capacity``: the messages expected (the columns of
    a layout grow past it)."""

    def __init__(
        self,
        types: dict[str, tuple[Field, ...]],
        type_name: str,
        wanted: frozenset[str],
        key: object,
        capacity: int,
        layouts: dict[object, Layout],
        program: Program | None,
    ):
        self.types, self.type_name, self.wanted, self.key = types, type_name, wanted, key
        self.capacity = max(capacity, 1)
        self.layouts, self.program = layouts, program
        self.parts: list[tuple[dict[str, Level], int]] = []
        self.plan: Layout | None = None
        self.out: tuple[np.ndarray, ...] = ()
        self.rows = 0
        self.walk: Walk | None = None
        self.kept: list = []
        self.mode = "layout"
        self.n = 0
        """Messages added."""

    def add(self, payloads: Sequence) -> None:
        """Decode the next messages (each one's bytes, or a memoryview into its chunk)."""
        done = 0
        if self.mode != "kept":
            found = groups(payloads)
            if self.mode == "layout":
                done = self._copy(payloads, found)
                if done < len(payloads):
                    self._close_layout()
                    self.mode = "walk" if self.program is not None else "kept"
                    found = groups(payloads[done:]) if done else found
            if self.mode == "walk":
                self.walk = self.walk or Walk(self.program)  # type: ignore[arg-type]
                if self.walk.add(found):
                    done = len(payloads)
                else:
                    self.mode = "kept"
        self.kept.extend(payloads[done:])
        self.n += len(payloads)

    def _copy(self, payloads: Sequence, found: list[Group]) -> int:
        """Copy messages of the batch's layout from the front of ``payloads``: how many were."""
        size = int(found[0].sizes[0])
        if size < 0 or any((g.sizes != size).any() for g in found):
            return 0
        if self.plan is None:
            plan = self.layouts.get(self.key)
            if plan is None or plan.size != size or not self._fits(plan, found[0]):
                try:
                    plan = self.layouts[self.key] = layout(
                        self.types, self.type_name, self.wanted, bytes(payloads[0][HEADER:])
                    )
                except Unsupported:
                    return 0
            self.plan, self.out = plan, columns(plan, max(self.capacity, len(payloads)))
        elif self.plan.size != size:
            return 0
        if self.rows + len(payloads) > len(self.out[0]):
            grown = columns(self.plan, max(2 * len(self.out[0]), self.rows + len(payloads)))
            for old, new in zip(self.out, grown):
                new[: self.rows] = old[: self.rows]
            self.out = grown
        done = 0
        for g in found:
            copied = copy(self.plan, g, self.out, self.rows)
            self.rows += copied
            done += copied
            if copied < len(g.origins):
                break
        return done

    @staticmethod
    def _fits(plan: Layout, group: Group) -> bool:
        """Whether the first message of ``group`` is of layout ``plan`` (nothing is copied)."""
        one = Group(group.base, group.origins[:1], group.sizes[:1], 0)
        return copy(plan, one, columns(plan, 1), 0) == 1

    def _close_layout(self) -> None:
        if self.rows:
            self.parts.append((levels_of(self.plan, self.out, self.rows), self.rows))  # type: ignore[arg-type]
        self.out = ()

    def levels(self) -> dict[str, Level]:
        """The levels of every message added (see the module docstring); CdrError names the
        position of a message the generic walk cannot decode."""
        if self.mode == "layout":
            self._close_layout()
        if self.walk is not None and self.walk.n:
            self.parts.append((self.walk.levels(), self.walk.n))
        if self.kept:
            before = self.n - len(self.kept)
            try:
                generic = decode(self.types, self.type_name, Payloads.of(self.kept), self.wanted)
            except CdrError as exc:
                raise CdrError(before + exc.message, exc.reason) from None
            self.parts.append((generic, len(self.kept)))
        return concatenate(self.parts)


def concatenate(parts: list[tuple[dict[str, Level], int]]) -> dict[str, Level]:
    """The levels of consecutive parts of a batch (each its levels and its messages) as one: each
    item's parent is moved past the earlier parts' items of its parent level (a level's parent is
    the longest other level whose name and a dot begin its name; the messages for a top level);
    a field is kept where every part with items of its level has it."""
    if len(parts) == 1:
        return parts[0][0]
    names = list(dict.fromkeys(name for levels, _ in parts for name in levels))
    parent_of = {n: max((p for p in names if n.startswith(p + ".") or (p == "" and n)), key=len) for n in names if n}
    seen = dict.fromkeys(names, 0)
    pieces: dict[str, list[Level]] = {n: [] for n in names}
    for levels, n in parts:
        offsets = dict(seen)
        for name, level in levels.items():
            shift = offsets[parent_of[name]] if name else offsets[""]
            pieces[name].append(Level(level.parent + shift, level.rank, level.fields))
            seen[name] += len(level.parent)
        seen[""] = offsets[""] + n
    out = {}
    for name, found in pieces.items():
        filled = [level for level in found if len(level.parent)]
        paths = set.intersection(*(set(level.fields) for level in filled)) if filled else set()
        out[name] = Level(
            np.concatenate([level.parent for level in found]),
            np.concatenate([level.rank for level in found]),
            {p: np.concatenate([level.fields[p] for level in filled]) for p in filled[0].fields if p in paths}
            if filled
            else {},
        )
    return out
