"""Coverage of a program's parameter space by the matches of a query run.

Input: a results table whose match rows carry ``intervals`` (the recovered values of every
random variable, :mod:`scenegrep.scene.projection`) and the program's declared random values
(:func:`scenegrep.scene.randoms.declared`). Each variable becomes one or two *axes* binned over
its declared domain: a ``Range``/``TruncatedNormal`` with constant ends over [low, high] in
``bins`` equal bins; a variable without constant finite ends (``Normal``, ends that depend on
other values) over the extent of its recovered values; a random point as two axes (x and y, m)
over the extent of its recovered coordinates (one bin when that extent is at most twice the
widest recovered interval: the values cannot be told apart more finely); an ``Options``
choice one bin per alternative.

A match's recovered value is an interval (several values reproduce the frame: tolerances,
several correspondences); it *covers* a bin only when the whole interval lies in the bin
(bins are [lo, hi), the last [lo, hi]); an interval over several bins covers none and the match
counts as ambiguous for that variable; an ``Options`` value covers its alternative only when
one alternative alone reproduces the frame. Bins no match covers are *gaps*. Two axes' joint
coverage counts the matches that cover one bin of each. Each axis's bins are also broken down by
the results' ``source`` (the input file or the ingested source).

Data the run did not decide (failed traces, the traces an interrupted run did not reach) may
hold matches anywhere: a coverage with ``unknown`` set (the sentence saying which data) reports
no bin as a gap: an uncovered bin's ``gap`` is null ("not covered in the data decided").
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import pyarrow as pa

from ..errors import UserError
from ..scene.randoms import Declared, declared
from .queries import QuerySpec, compiled

MAX_BINS = 200
"""Most bins per axis a user may ask for."""

MAX_PAIR_AXES = 8
MAX_PAIR_BINS = 50
"""Joint coverage is computed for the pairs of the first MAX_PAIR_AXES axes with at most
MAX_PAIR_BINS bins each (a pair's table rows and heat map grow with the product)."""

AMBIGUOUS = -1
"""Bin of a match whose interval spans several bins (or several alternatives)."""

NO_VALUE = -2
"""Bin of a match without a value for the axis (its results row has no intervals)."""

TABLE_SCHEMA = pa.schema(
    [
        ("variable", pa.string()),
        ("variable2", pa.string()),
        ("source", pa.string()),
        ("bin", pa.int32()),
        ("bin2", pa.int32()),
        ("lo", pa.float64()),
        ("hi", pa.float64()),
        ("lo2", pa.float64()),
        ("hi2", pa.float64()),
        ("label", pa.string()),
        ("matches", pa.int64()),
        ("gap", pa.bool_()),
    ]
)
"""The coverage table: one row per bin of each axis (``variable2`` null) and per cell of each
pair of axes (:meth:`Coverage.pairs`), over all sources (``source`` null), and one per bin of
each axis that a source's matches cover (``source`` set); ``matches`` covering it, ``gap``
when none does (null when part of the data is unknown: :attr:`Coverage.unknown`)."""


def checked_bins(bins: int) -> int:
    """A user's bin count (UserError outside 1..MAX_BINS)."""
    if not 1 <= bins <= MAX_BINS:
        raise UserError(f"--bins must be between 1 and {MAX_BINS} (got {bins})")
    return bins


def check_output(path: str) -> str:
    """The format of a coverage table file, by its suffix: 'parquet' or 'json' (else UserError)."""
    suffix = path.lower().rsplit(".", 1)[-1]
    if suffix not in ("parquet", "json"):
        raise UserError(f"--output {path}: the coverage table is a .parquet or .json file")
    return suffix


@dataclass(frozen=True)
class Axis:
    """One binned quantity: ``name`` (the variable's, with ``.x``/``.y`` for a point's
    coordinates), its declared value (``declared``), ``edges`` (numeric bins) or ``size``
    alternatives, and ``basis``: 'declared' when the bins span the declared domain, 'recovered'
    when they span the recovered values' extent."""

    name: str
    declared: Declared
    edges: np.ndarray | None
    size: int
    basis: str

    @property
    def bins(self) -> int:
        return self.size if self.edges is None else len(self.edges) - 1

    def bounds(self, k: int) -> tuple[float, float]:
        """Bin ``k``'s [lo, hi) (an alternative's index twice for a choice)."""
        if self.edges is None:
            return float(k), float(k)
        return float(self.edges[k]), float(self.edges[k + 1])

    def label(self, k: int) -> str:
        if self.edges is None:
            return f"option {k + 1} of {self.size}"
        lo, hi = self.bounds(k)
        return f"[{lo:.6g}, {hi:.6g}{']' if k == self.bins - 1 else ')'}"

    def domain_text(self) -> str:
        d = self.declared
        if d.kind == "options":
            return f"{d.size} alternatives"
        if self.basis == "declared":
            return f"declared [{d.low:g}, {d.high:g}]"
        if d.kind == "point":
            return "a random point's coordinate (m); bins over the recovered extent"
        return f"declared [{_end(d.low)}, {_end(d.high)}]; bins over the recovered extent"


def _end(value: float | None) -> str:
    return "?" if value is None else f"{value:g}"


@dataclass
class Coverage:
    """The coverage of one run: its ``axes``, per match row (``rows``: trace_id, name, source,
    match, start_frame, end_frame, correspondences) and axis the recovered interval (``lo``,
    ``hi``; NaN: no value) and the bin covered (``assigned``; :data:`AMBIGUOUS`,
    :data:`NO_VALUE`); ``unknown`` says which data the run did not decide ("" when none), so
    that an uncovered bin is no gap but uncovered in the data decided."""

    axes: list[Axis]
    rows: list[dict[str, Any]]
    lo: np.ndarray
    hi: np.ndarray
    assigned: np.ndarray
    unknown: str = ""

    @property
    def sources(self) -> list[str]:
        return sorted({r["source"] for r in self.rows})

    def counts(self, a: int, source: str | None = None) -> np.ndarray:
        """Matches covering each bin of axis ``a`` (of one source, or all)."""
        bins = self.assigned[self._of(source), a]
        return np.bincount(bins[bins >= 0], minlength=self.axes[a].bins)

    def joint(self, a: int, b: int, source: str | None = None) -> np.ndarray:
        """Matches covering each (bin of axis a, bin of axis b) cell."""
        ka, kb = self.assigned[self._of(source), a], self.assigned[self._of(source), b]
        both = (ka >= 0) & (kb >= 0)
        cells = np.bincount(ka[both] * self.axes[b].bins + kb[both], minlength=self.axes[a].bins * self.axes[b].bins)
        return cells.reshape(self.axes[a].bins, self.axes[b].bins)

    def pairs(self) -> list[tuple[int, int]]:
        """The pairs of axes whose joint coverage is reported (of the first :data:`MAX_PAIR_AXES`)."""
        chosen = [a for a, axis in enumerate(self.axes) if axis.bins <= MAX_PAIR_BINS][:MAX_PAIR_AXES]
        return [(a, b) for i, a in enumerate(chosen) for b in chosen[i + 1 :]]

    def matches_in(self, a: int, k: int) -> list[int]:
        """The match rows (indices into ``rows``) covering bin ``k`` of axis ``a``."""
        return np.flatnonzero(self.assigned[:, a] == k).tolist()

    def ambiguous(self) -> int:
        """Matches ambiguous for some axis (an interval over several bins)."""
        return int(np.any(self.assigned == AMBIGUOUS, axis=1).sum()) if len(self.rows) else 0

    def several(self) -> int:
        """Matches that several correspondences reproduce."""
        return sum(1 for r in self.rows if r["correspondences"] > 1)

    def _of(self, source: str | None) -> np.ndarray:
        if source is None:
            return np.arange(len(self.rows))
        return np.flatnonzero(np.array([r["source"] == source for r in self.rows], dtype=bool))

    def table(self) -> pa.Table:
        """The coverage table (:data:`TABLE_SCHEMA`)."""
        out: list[dict[str, Any]] = []
        for source in [None, *self.sources]:
            for a, axis in enumerate(self.axes):
                for k, n in enumerate(self.counts(a, source).tolist()):
                    if n or source is None:
                        lo, hi = axis.bounds(k)
                        out.append(
                            _row(axis.name, None, source, k, None, lo, hi, None, None, axis.label(k), n, self._gap(n))
                        )
        for a, b in self.pairs():
            for (i, j), n in np.ndenumerate(self.joint(a, b)):
                (lo, hi), (lo2, hi2) = self.axes[a].bounds(i), self.axes[b].bounds(j)
                label = f"{self.axes[a].label(i)} × {self.axes[b].label(j)}"
                out.append(
                    _row(self.axes[a].name, self.axes[b].name, None, i, j, lo, hi, lo2, hi2, label, n, self._gap(n))
                )
        return pa.Table.from_pylist(out, schema=TABLE_SCHEMA)

    def _gap(self, matches: int) -> bool | None:
        """Whether a bin (cell) covered by ``matches`` is a gap: None when it is not covered but
        part of the data is unknown."""
        if matches:
            return False
        return None if self.unknown else True

    def write(self, path: str) -> None:
        """The coverage table as Parquet (``.parquet``) or a JSON array of rows (``.json``), atomically."""
        import pyarrow.parquet as pq

        from ..writers.atomic import atomic_path

        with atomic_path(path) as tmp:
            if check_output(path) == "parquet":
                pq.write_table(self.table(), tmp)
            else:
                tmp.write_text(json.dumps(self.table().to_pylist(), allow_nan=False), encoding="utf-8")


def _row(variable, variable2, source, k, k2, lo, hi, lo2, hi2, label, n, gap) -> dict[str, Any]:
    return {
        "variable": variable,
        "variable2": variable2,
        "source": source,
        "bin": int(k),
        "bin2": None if k2 is None else int(k2),
        "lo": lo,
        "hi": hi,
        "lo2": lo2,
        "hi2": hi2,
        "label": label,
        "matches": int(n),
        "gap": gap,
    }


def unknown_data(results: Any) -> str:
    """Which data a run (:class:`~.results.Results`) did not decide, as a sentence: its failed
    traces, and the traces it did not reach when interrupted; "" when it decided all."""
    parts = []
    failed = results.counts()["failed"]
    if failed:
        parts.append(f"{failed} trace{'s' * (failed != 1)} failed")
    if results.status == "interrupted":
        parts.append("the run was interrupted before every trace was queried")
    return "; ".join(parts)


def variables_of(spec: QuerySpec) -> list[Declared]:
    """The declared random values of a scene spec's program, or of a scenario spec's initial scene."""
    query = compiled(spec)
    scene = query if spec.kind == "scene" else query.scene
    return declared(scene.groups)


def coverage_of(match_rows: list[dict[str, Any]], variables: list[Declared], bins: int, unknown: str = "") -> Coverage:
    """The coverage of the match rows of a results table (see the module docstring); ``unknown``
    says which data the run did not decide ("" when it decided all)."""
    bins = checked_bins(bins)
    parsed = [json.loads(r.get("intervals") or "null") or {} for r in match_rows]
    rows = [
        {
            **{k: r[k] for k in ("trace_id", "name", "source", "match", "start_frame", "end_frame")},
            "correspondences": int(p.get("correspondences", 0)),
        }
        for r, p in zip(match_rows, parsed)
    ]
    values = [p.get("values", {}) for p in parsed]
    axes, columns = [], []
    for variable in variables:
        for suffix, lo, hi, chosen in _columns(variable, values):
            axis = _axis(variable, suffix, lo, hi, bins)
            if axis is not None:
                axes.append(axis)
                columns.append((lo, hi, chosen))
    n = len(rows)
    lo = np.column_stack([c[0] for c in columns]) if columns else np.zeros((n, 0))
    hi = np.column_stack([c[1] for c in columns]) if columns else np.zeros((n, 0))
    assigned = np.full((n, len(axes)), NO_VALUE, dtype=np.int64)
    for a, (axis, (low, high, chosen)) in enumerate(zip(axes, columns)):
        assigned[:, a] = _assign(axis, low, high, chosen)
    return Coverage(axes, rows, lo, hi, assigned, unknown)


def _columns(variable: Declared, values: list[dict[str, Any]]):
    """(axis suffix, lows, highs, chosen alternatives) per axis of a variable, over the matches."""
    entries = [v.get(variable.name) or {} for v in values]
    if variable.kind == "options":
        chosen = [e.get("chosen") if e.get("kind") == "options" else None for e in entries]
        nan = np.full(len(entries), np.nan)
        yield "", nan, nan, chosen
        return
    if variable.kind == "point":
        for axis, suffix in ((0, ".x"), (1, ".y")):
            ends = [e[("x", "y")[axis]] if e.get("kind") == "point" else [np.nan, np.nan] for e in entries]
            yield suffix, _floats([x[0] for x in ends]), _floats([x[1] for x in ends]), None
        return
    ranges = [e if e.get("kind") == "range" else {} for e in entries]
    yield "", _floats([e.get("lo", np.nan) for e in ranges]), _floats([e.get("hi", np.nan) for e in ranges]), None


def _floats(values: list[Any]) -> np.ndarray:
    return np.array([np.nan if v is None else float(v) for v in values], dtype=float)


def _axis(variable: Declared, suffix: str, lo: np.ndarray, hi: np.ndarray, bins: int) -> Axis | None:
    """The axis of a variable's values (None: a variable without a bounded domain or any finite value)."""
    name = variable.name + suffix
    if variable.kind == "options":
        return Axis(name, variable, None, variable.size, "declared")
    low, high = variable.low, variable.high
    if variable.kind == "range" and low is not None and high is not None and math.isfinite(low + high):
        if high > low:
            return Axis(name, variable, np.linspace(low, high, bins + 1), 0, "declared")
        return Axis(name, variable, np.array([low, high]), 0, "declared")
    ends = np.concatenate([lo, hi])
    ends = ends[np.isfinite(ends)]
    if not len(ends):
        return None
    first, last = float(ends.min()), float(ends.max())
    widths = (hi - lo)[np.isfinite(hi - lo)]
    if last - first <= 2 * (widths.max() if len(widths) else 0.0):
        return Axis(name, variable, np.array([first, last]), 0, "recovered")
    return Axis(name, variable, np.linspace(first, last, bins + 1), 0, "recovered")


def _assign(axis: Axis, lo: np.ndarray, hi: np.ndarray, chosen: list | None) -> np.ndarray:
    """Each match's covered bin of the axis, :data:`AMBIGUOUS` or :data:`NO_VALUE`."""
    if axis.edges is None:
        assert chosen is not None
        return np.array(
            [NO_VALUE if not c else (int(c[0]) if len(c) == 1 else AMBIGUOUS) for c in chosen], dtype=np.int64
        )
    edges = axis.edges
    k = np.clip(np.searchsorted(edges, lo, side="right") - 1, 0, axis.bins - 1)
    last = k == axis.bins - 1
    inside = (lo >= edges[0]) & (lo <= hi) & ((hi < edges[k + 1]) | (last & (hi <= edges[-1])))
    found = np.where(inside, k, AMBIGUOUS)
    return np.where(np.isnan(lo) | np.isnan(hi), NO_VALUE, found)
