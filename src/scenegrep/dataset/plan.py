"""The planner: which traces a query can possibly match, decided with SQL on the catalog.

A query's :class:`Needs` are necessary conditions read off the compiled query:

- Scenic scene and scenario queries need, in each frame of some run of ``frames`` consecutive
  frames, enough labeled objects of the kinds the program's objects may correspond to: for
  every set K of kinds a program object may match (or "any kind"), at least as many objects
  of kinds in K as the program has objects whose kinds all lie in K. A scene needs one
  frame; a scenario needs its window of m frames, since a corresponded object must be
  present in every frame of the window.
- A SpRE needs an object or box of every class its matches require
  (:func:`scenegrep.spre.requirements.required_classes`) somewhere in the trace.

The conditions are necessary, never sufficient: pruning skips only traces that cannot
match, and the exact query decides the rest. They read object and class counts only, never the
catalog's behaviour label statistics (``labels``): those are of the labels ingest made under its
choice for unknown map layers, and a scenario query under another choice labels the trace again
(:mod:`.labelling`), so they say nothing of the labels the query reads.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from ..errors import UserError
from ..wording import counted
from .catalog import Catalog
from .queries import QuerySpec


@dataclass(frozen=True)
class KindGroup:
    """At least ``count`` objects of the ``kinds`` (None: any kind) present in a frame."""

    kinds: frozenset[str] | None
    count: int

    def describe(self) -> str:
        what = "object" if self.kinds is None else "/".join(sorted(self.kinds)) + " object"
        return counted(self.count, what)


@dataclass(frozen=True)
class Needs:
    """What a trace must have for a query to match: kind groups present together for
    ``frames`` consecutive frames (an int, ``"Ns"`` seconds or ``"all"``), and ``classes``
    present anywhere."""

    groups: tuple[KindGroup, ...] = ()
    frames: int | str = 1
    classes: frozenset[str] = frozenset()


@dataclass(frozen=True)
class Plan:
    """The traces to query (catalog rows) and the pruned ones with the reason for each."""

    kept: list[dict[str, Any]]
    pruned: list[tuple[dict[str, Any], str]]


def needs_of(spec: QuerySpec, query: Any) -> Needs:
    """The needs of a compiled query."""
    if spec.kind == "spre":
        from ..spre.requirements import required_classes

        return Needs(classes=required_classes(query.tree))
    if spec.kind == "scene":
        return Needs(kind_groups(query.program.objects))
    objects = [o for o in query.scene.program.objects if o.name in query.hfsms]
    return Needs(kind_groups(objects), _frames(spec.option("window")))


def _frames(window: Any) -> int | str:
    text = str(window).strip()
    try:
        if text == "all":
            return text
        length = float(text[:-1]) if text.endswith("s") else int(text)
    except ValueError:
        raise UserError(f"bad window {window!r}: give frames (50), seconds (5s) or 'all'") from None
    if not length > 0:
        raise UserError(f"the window must be at least one frame (got {window!r})")
    return text if text.endswith("s") else int(length)


def kind_groups(objects: list[Any]) -> tuple[KindGroup, ...]:
    """One group per distinct kind set of the objects (and one for any kind): the objects
    whose kinds lie in it."""
    sets = {o.kinds for o in objects} | {None}
    groups = []
    for kinds in sorted(sets, key=lambda k: (k is None, sorted(k or ()))):
        count = sum(1 for o in objects if kinds is None or (o.kinds is not None and o.kinds <= kinds))
        if count:
            groups.append(KindGroup(kinds, count))
    return tuple(g for g in groups if not any(_implies(h, g) for h in groups if h is not g))


def _implies(a: KindGroup, b: KindGroup) -> bool:
    """Whether meeting group ``a`` meets ``b``: ``a`` asks as many objects of fewer kinds."""
    narrower = b.kinds is None or (a.kinds is not None and a.kinds <= b.kinds)
    return narrower and a.count >= b.count


def plan(catalog: Catalog, needs: Needs) -> Plan:
    """Split the catalog's traces into those to query and those that cannot match."""
    traces = catalog.sql("SELECT * FROM traces ORDER BY trace_id").to_pylist()
    reasons: dict[str, str] = {}
    if needs.groups:
        reasons |= _prune_by_groups(catalog, needs)
    if needs.classes:
        for trace_id, reason in _prune_by_classes(catalog, needs.classes).items():
            reasons.setdefault(trace_id, reason)
    kept = [t for t in traces if t["trace_id"] not in reasons]
    pruned = [(t, reasons[t["trace_id"]]) for t in traces if t["trace_id"] in reasons]
    return Plan(kept, pruned)


def _needed_frames(frames: int | str) -> str:
    """SQL for the run length a trace needs (seconds round down: never more than the query's m)."""
    if isinstance(frames, int):
        return str(frames)
    if frames == "all":
        return "t.frames"
    seconds = float(frames[:-1])
    return f"greatest(1, floor({seconds!r} / t.period_s))"


def _prune_by_groups(catalog: Catalog, needs: Needs) -> dict[str, str]:
    sums, checks = [], []
    for number, group in enumerate(needs.groups):
        if group.kinds is None:
            sums.append(f"sum(count) AS g{number}")
        else:
            kinds = ", ".join(f"'{k}'" for k in sorted(group.kinds))
            sums.append(f"coalesce(sum(count) FILTER (WHERE kind IN ({kinds})), 0) AS g{number}")
        checks.append(f"g{number} >= {group.count}")
    query = f"""
        WITH per_frame AS (
            SELECT trace_id, frame, {", ".join(sums)} FROM frame_counts WHERE layer = 'objects'
            GROUP BY trace_id, frame),
        ok AS (SELECT trace_id, frame - row_number() OVER (PARTITION BY trace_id ORDER BY frame) AS island
               FROM per_frame WHERE {" AND ".join(checks)}),
        runs AS (SELECT trace_id, count(*) AS length FROM ok GROUP BY trace_id, island),
        longest AS (SELECT trace_id, max(length) AS longest FROM runs GROUP BY trace_id)
        SELECT t.trace_id, coalesce(l.longest, 0) AS longest, {_needed_frames(needs.frames)} AS needed
        FROM traces t LEFT JOIN longest l USING (trace_id)
        WHERE coalesce(l.longest, 0) < {_needed_frames(needs.frames)}
    """
    together = " and ".join(g.describe() for g in needs.groups)
    return {
        trace_id: f"never {together} present together for {counted(int(needed), 'consecutive frame')} "
        f"(at most {longest})"
        for trace_id, longest, needed in catalog.rows(query)
    }


def _prune_by_classes(catalog: Catalog, classes: frozenset[str]) -> dict[str, str]:
    reasons: dict[str, str] = {}
    for name in sorted(classes):
        query = """
            SELECT trace_id FROM traces WHERE trace_id NOT IN (
                SELECT DISTINCT trace_id FROM frame_counts WHERE category = ? OR kind = ?)
        """
        for (trace_id,) in catalog.rows(query, [name, name]):
            reasons.setdefault(trace_id, f"no object or box of class {name!r}")
    return reasons


class TracePlanner:
    """:func:`plan` for one trace at a time (a query over files): the same SQL, on a catalog in
    memory that holds only the trace being planned. Use as a context manager."""

    def __init__(self, needs: Needs):
        self.needs = needs
        self.catalog = Catalog(None) if needs.groups or needs.classes else None

    def __enter__(self) -> TracePlanner:
        return self

    def __exit__(self, *exc: object) -> None:
        if self.catalog is not None:
            self.catalog.close()

    def prune_reason(self, row: dict[str, Any], statistics: Any) -> str | None:
        """Why :func:`plan` would prune the trace of this ``traces`` row and
        :class:`~scenegrep.dataset.statistics.TraceStatistics`, or None."""
        if self.catalog is None:
            return None
        self.catalog.show_trace(row, statistics)
        pruned = plan(self.catalog, self.needs).pruned
        return pruned[0][1] if pruned else None
