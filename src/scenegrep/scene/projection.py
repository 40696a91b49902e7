"""The set of values of each random variable that reproduces a matched frame: its projection.

A witness (:mod:`.explain`) is one value per variable; coverage needs them all. For a matched
frame, every surviving correspondence (at most :data:`MAX_CORRESPONDENCES` of them) is decided
again group by group, and for each unknown of a feasible row the interval of its feasible
values is computed:

* exactly, in closed form and vectorised over rows, where the group has one scalar unknown in
  affine constraints (at most one heading constraint, modulo 2π):
  :func:`.decide.closed_form_intervals`;
* for a random point pinned by the position features: its tolerance box;
* otherwise with the row's decision procedure (:func:`.solvers.solve`): is the row still
  feasible with the unknown restricted to [start, v]? First with v just below the witness's value
  (:data:`NEAR`; one call settles the usual case of a tiny interval), else by bisection, at most
  :data:`STEPS` steps per end, within the box interval contraction gives. A verdict other than a
  proof of infeasibility counts as feasible, so the interval is an outer bound of the
  projection (the true one lies inside), within NEAR of the box width (or (box width) /
  2**STEPS) of it.

A frame's interval of a variable is the hull (not the union) of its intervals over the frame's
correspondences and the alternatives of its ``Options`` choices; for an ``Options`` choice it is
the set of alternatives some feasible row takes. ``correspondences`` says how many matched.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .decide import closed_form_intervals, decide_expanded
from .tolerance import Tolerance
from .dependencies import Group
from .evaluate import Evaluator, Labels
from .geometry import MapGeometry
from .match import TraceMatches
from .program import SceneProgram
from .randoms import unique_names
from .solvers import solve
from .solvers.branch_prune import BranchAndPrune
from .solvers.problem import Bound, Problem, build
from .terms import Term

MAX_CORRESPONDENCES = 16
"""Correspondences of one frame whose values are computed (all are counted)."""

STEPS = 14
"""Bisection steps per end of an interval that no closed form gives."""

NEAR = 1e-4
NEAREST = 1e-2
"""How far below (above) a witness value a bisection first looks for a feasible value: this part of
the search width, at most NEAREST (m, rad or the variable's unit)."""

LIMIT = 1e9
"""Ends beyond ±LIMIT are reported as unbounded."""


@dataclass
class FrameValues:
    """The recovered values of one matched frame: ``ranges`` (scalar variable name -> [lo, hi]),
    ``points`` (random point name -> ([x lo, x hi], [y lo, y hi])), ``options`` (choice name ->
    (sorted alternatives, 0-based, some feasible row takes; number of alternatives)) and the
    number of ``correspondences`` that match the frame."""

    correspondences: int
    ranges: dict[str, list[float]] = field(default_factory=dict)
    points: dict[str, list[list[float]]] = field(default_factory=dict)
    options: dict[str, tuple[list[int], int]] = field(default_factory=dict)

    def to_json(self) -> dict:
        """As a JSON object: ``{"correspondences": n, "values": {name: {"kind": "range", "lo",
        "hi"} | {"kind": "point", "x": [lo, hi], "y": [lo, hi]} | {"kind": "options", "chosen":
        [...], "size": n}}}`` (unbounded ends are ±Infinity)."""
        values: dict[str, dict] = {}
        for name, (lo, hi) in self.ranges.items():
            values[name] = {"kind": "range", "lo": lo, "hi": hi}
        for name, (x, y) in self.points.items():
            values[name] = {"kind": "point", "x": x, "y": y}
        for name, (chosen, size) in self.options.items():
            values[name] = {"kind": "options", "chosen": chosen, "size": size}
        return {"correspondences": self.correspondences, "values": values}


def frame_values(
    program: SceneProgram, matches: TraceMatches, labels: Labels, geometry: MapGeometry, tolerance: Tolerance
) -> list[FrameValues]:
    """The recovered values of every matched frame, in frame order (see the module docstring)."""
    every = matches.every if matches.every is not None else matches.survivors
    frames, first, counts = np.unique(every.frame, return_index=True, return_counts=True)
    rank = np.arange(len(every)) - np.repeat(first, counts)
    rows = every.take(np.flatnonzero(rank < MAX_CORRESPONDENCES))
    hulls = _Hulls(len(frames), unique_names(matches.groups))
    objects = {o.name: o for o in program.objects}
    for group in matches.groups:
        if group.unknowns and len(rows):
            ev = Evaluator(rows, labels, objects, geometry, position_tolerance=tolerance.position)
            _group_values(ev, group, tolerance, np.searchsorted(frames, rows.frame), hulls)
    return hulls.frames(counts)


class _Hulls:
    """Per matched frame, the hull of each unknown's intervals and the alternatives of each choice
    (arrays over frames, filled group by group)."""

    def __init__(self, n: int, names: dict[Any, str]):
        self.n = n
        self.names = names
        self.bounds: dict[Term, tuple[np.ndarray, np.ndarray]] = {}
        self.chosen: dict[Term, np.ndarray] = {}

    def widen(self, u: Term, frames: np.ndarray, low: np.ndarray, high: np.ndarray) -> None:
        lo, hi = self.bounds.setdefault(u, (np.full(self.n, np.inf), np.full(self.n, -np.inf)))
        np.minimum.at(lo, frames, low)
        np.maximum.at(hi, frames, high)

    def choose(self, leaf: Term, frames: np.ndarray, alternatives: np.ndarray) -> None:
        taken = self.chosen.setdefault(leaf, np.zeros((self.n, leaf.value.size), dtype=bool))
        taken[frames, alternatives.astype(np.intp)] = True

    def frames(self, counts: np.ndarray) -> list[FrameValues]:
        found = [FrameValues(int(n)) for n in counts]
        for u, (lo, hi) in self.bounds.items():
            for k in np.flatnonzero(lo <= hi).tolist():
                if u.op == "point":
                    point, axis = u.value
                    box = found[k].points.setdefault(self.names[point], [[], []])
                    box[axis] = [float(lo[k]), float(hi[k])]
                else:
                    found[k].ranges[self.names[u.value]] = [float(lo[k]), float(hi[k])]
        for leaf, taken in self.chosen.items():
            for k in np.flatnonzero(taken.any(axis=1)).tolist():
                found[k].options[self.names[leaf.value]] = (np.flatnonzero(taken[k]).tolist(), leaf.value.size)
        return found


def _group_values(ev: Evaluator, group: Group, tolerance: Tolerance, slot: np.ndarray, hulls: _Hulls) -> None:
    """Put one group's values of every row into its frame's hulls (``slot``: each row's frame)."""
    choices = sorted((u for u in group.unknowns if u.op == "choice"), key=repr)
    for leaf in choices:
        ev.expand_choice(leaf)
    ev.unknowns = frozenset(u for u in group.unknowns if u.op != "choice")
    feasible = np.flatnonzero(decide_expanded(ev, group, tolerance))
    where = slot[ev.origin[feasible]]
    for leaf in choices:
        hulls.choose(leaf, where, ev.memo[leaf][feasible])
    if not ev.unknowns:
        return
    for u, (low, high) in _intervals(ev, group, tolerance, feasible).items():
        hulls.widen(u, where, low[feasible], high[feasible])


def _intervals(
    ev: Evaluator, group: Group, tolerance: Tolerance, feasible: np.ndarray
) -> dict[Term, tuple[np.ndarray, np.ndarray]]:
    """Per unknown, its interval in the ``feasible`` rows (indices; arrays over all rows): closed
    form, else bisection row by row."""
    closed = closed_form_intervals(ev, group, tolerance)
    if closed is not None:
        return closed
    unknowns = sorted(ev.unknowns, key=repr)
    found = {u: (np.full(ev.size, np.nan), np.full(ev.size, np.nan)) for u in unknowns}
    for row in feasible.tolist():
        problem = build(ev, group, tolerance, row)
        for u, (lo, hi) in _bisected(problem, ev.geometry, tolerance).items():
            found[u][0][row], found[u][1][row] = lo, hi
    return found


def _bisected(problem: Problem, geometry: MapGeometry, tolerance: Tolerance) -> dict[Term, tuple[float, float]]:
    """Outer bounds of every unknown's feasible values in one row's system (module docstring)."""
    search = BranchAndPrune(problem, geometry, max(tolerance.position, tolerance.heading))
    box = search.initial_box()
    box = None if box is None else search.contract(box)
    witness = solve(problem, geometry, tolerance).witness or {}
    found = {}
    for u in problem.unknowns:
        start = -LIMIT if box is None else max(box[u].lo, -LIMIT)
        end = LIMIT if box is None else min(box[u].hi, LIMIT)

        def feasible(lo: float, hi: float, u: Term = u) -> bool:
            restricted = Problem(
                problem.factory,
                problem.scalars,
                problem.ranges,
                problem.points,
                [*problem.bounds, Bound(u, lo, hi)],
                problem.conditions,
            )
            return solve(restricted, geometry, tolerance).feasible

        value = witness.get(u)
        mirrored = None if value is None else -value
        found[u] = (
            _lowest(feasible, start, end, value),
            -_lowest(lambda a, b: feasible(-b, -a), -end, -start, mirrored),
        )
    return found


def _lowest(feasible, start: float, end: float, witness: float | None) -> float:
    """A lower bound of the lowest feasible value in [start, end]: ``witness - step`` when nothing
    below it is feasible (a witness is a feasible value; step = :data:`NEAR` of the width, at most
    :data:`NEAREST`), else within (end - start) / 2**STEPS of it by bisection."""
    step = min(NEAR * (end - start), NEAREST)
    if witness is not None and math.isfinite(witness):
        if witness - step <= start:
            return start
        if not feasible(start, witness - step):
            return witness - step
        end = witness - step
    low, high = start, end
    for _ in range(STEPS):
        middle = (low + high) / 2
        if feasible(start, middle):
            high = middle
        else:
            low = middle
    return -math.inf if low <= -LIMIT else low
