"""Correspondence search (seed 000 Algorithm 1, without its brute force).

1. Candidates per program object: label objects of its class observed for at least
   m consecutive frames (the program's ego is the trace's ego when the trace names one).
2. Per-object filtering: each candidate runs the object's own HFSM with its guards
   decided where they read only the object itself, and *both* where they read an
   object not yet assigned (optimistic); a candidate with no window of m frames goes.
3. Feasibility: a Hopcroft–Karp matching must give every program object a distinct
   candidate, or nothing is enumerated.
4. Backtracking in dependency order (the ego, then the objects its guards read, ...):
   assigning an object completes the objects whose guards it was the last to bind;
   their exact window reach is computed for all candidates of the step at once and
   memoised per assignment of the objects they read. The initial scene's dependency
   groups that the assignment decides are checked at the surviving starts (the scene
   query with this partial correspondence). A partial correspondence with no window
   start left is abandoned with all its extensions (seed 003's pruning of
   correspondences extending a bad one); a complete one with starts left is a match.

Reach vectors give, per window start, how many frames the HFSMs survive (capped at
m); a start is alive while its reach is m. Temporal requirements (:mod:`.temporal`) are
components like the HFSMs, without a label object of their own: a requirement is completed,
and its monitor run on all candidates of the step at once, when the last object it reads is
assigned (one that reads no object, at the root); its reach is m only where it holds over
the window.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from .automaton import Automaton, LazyDfa, OverBudget, encode
from .hfsm import BOTH, Hfsm
from .matching import maximum_matching
from .observations import Observations
from .simulate import simulate_reach
from .temporal import Monitor
from .translate import Guard
from .windows import table_reach

Assignment = dict[str, int]
"""Program object -> label object index (row of the trace's object table)."""


@dataclass
class Node:
    """A partial correspondence, its reach per window start (min over its components), each
    component's reach (program objects and completed requirements), and the starts still alive
    (behaviours and requirements reach m frames and the decided scene groups hold)."""

    assignment: Assignment
    reach: np.ndarray
    per_object: dict[str, np.ndarray]
    alive: np.ndarray


@dataclass
class Outcome:
    """What the search found: complete correspondences with their matching window starts, the
    candidates, and what the explanation of a non-match needs."""

    matches: list[tuple[Assignment, np.ndarray]] = field(default_factory=list)
    candidates: dict[str, list[int]] = field(default_factory=dict)
    unary: dict[str, dict[int, np.ndarray]] = field(default_factory=dict)
    feasible: bool = True
    best: Node | None = None
    scene_failures: list[tuple[Assignment, np.ndarray]] = field(default_factory=list)


class Search:
    """One search over one trace; ``scene_starts(assignment, starts, newest)`` is the initial-scene
    check of the scene groups an assignment decides that involve its newest object; ``monitors``
    are the temporal requirements' monitors by name."""

    def __init__(
        self,
        hfsms: dict[str, Hfsm],
        kinds: dict[str, frozenset[str] | None],
        guards: list[Guard],
        automata: dict[str, Automaton],
        obs: Observations,
        window: int,
        scene_starts: Callable[[Assignment, np.ndarray, str], np.ndarray],
        find_all: bool,
        monitors: dict[str, Monitor],
    ):
        self.hfsms = hfsms
        self.monitors = monitors
        self.components: dict[str, LazyDfa] = {**automata, **monitors}
        self.kinds = kinds
        self.guards = guards
        self.automata = automata
        self.obs = obs
        self.m = window
        self.n_starts = obs.n_frames - window + 1
        self.scene_starts = scene_starts
        self.find_all = find_all
        self.reads = {o: set().union({o}, *(guards[g].objects for g in h.guards)) for o, h in hfsms.items()}
        self.reads.update({name: set(m.requirement.objects) for name, m in monitors.items()})
        self._memo: dict[tuple[str, tuple[tuple[str, int], ...]], np.ndarray] = {}
        self.outcome = Outcome()

    # ---------------------------------------------------------------- reach of one object
    def reach(self, obj: str, assignments: list[Assignment]) -> np.ndarray:
        """(len(assignments), starts) reach of component ``obj`` (a program object's HFSM or a
        requirement's monitor); guards reading unassigned objects are BOTH."""
        keys = [self._key(obj, a) for a in assignments]
        missing = list(dict.fromkeys(k for k in keys if k not in self._memo))
        if missing:
            for key, row in zip(missing, self._compute(obj, [dict(k[1]) for k in missing])):
                self._memo[key] = row
        if not keys:
            return np.zeros((0, self.n_starts), dtype=np.int64)
        return np.stack([self._memo[k] for k in keys])

    def _key(self, obj: str, assignment: Assignment) -> tuple[str, tuple[tuple[str, int], ...]]:
        return obj, tuple(sorted((o, assignment[o]) for o in self.reads[obj] if o in assignment))

    def symbols(self, obj: str, assignments: list[Assignment]) -> np.ndarray:
        """(len(assignments), frames) symbols of component ``obj``'s automaton (no label bits for a
        requirement)."""
        automaton = self.components[obj]
        if obj in self.monitors:
            masks = np.zeros((len(assignments), self.obs.n_frames), dtype=np.int64)
        else:
            label = np.array([a[obj] for a in assignments], dtype=np.int64)
            masks = self.obs.accept(automaton.outputs)[:, label].T
        codes = []
        for g in automaton.guards:
            guard = self.guards[g]
            value = np.full(masks.shape, BOTH, dtype=np.int64)
            bound = [j for j, a in enumerate(assignments) if all(o in a for o in guard.objects)]
            if bound:
                block = np.array([[assignments[j][o] for o in guard.objects] for j in bound], dtype=np.int64)
                value[bound] = self.obs.guard_codes(guard, block)
            codes.append(value)
        return encode(masks, codes, len(automaton.outputs))

    def _compute(self, obj: str, assignments: list[Assignment]) -> np.ndarray:
        """Reach per assignment and start: by the DFA's table, or by simulating configuration sets
        when the DFA is over its state budget or its step tables too large (:func:`.windows.table_reach`)."""
        symbols = self.symbols(obj, assignments)
        automaton = self.components[obj]
        if not automaton.over_budget:
            try:
                return table_reach(automaton, symbols, self.m)[:, : self.n_starts]
            except OverBudget:
                pass
        return simulate_reach(automaton, symbols, self.m)[:, : self.n_starts]

    # ---------------------------------------------------------------- the search
    def run(self) -> Outcome:
        out = self.outcome
        if self.n_starts <= 0:
            return out
        out.candidates = {o: self._candidates(o) for o in self.hfsms}
        for o, cands in out.candidates.items():
            rows = self.reach(o, [{o: c} for c in cands])
            out.unary[o] = {c: row for c, row in zip(cands, rows) if (row >= self.m).any()}
        edges = {o: list(out.unary[o]) for o in self.hfsms}
        if len(maximum_matching(edges)) < len(edges):
            out.feasible = False
            return out
        order = self._order(edges)
        root = Node({}, np.full(self.n_starts, self.m, dtype=np.int64), {}, np.ones(self.n_starts, dtype=bool))
        for name in self.monitors:
            if not self.reads[name]:
                root.per_object[name] = self.reach(name, [{}])[0]
                root.reach = np.minimum(root.reach, root.per_object[name])
        root.alive = root.reach >= self.m
        for _ in self._extend(order, root):
            if not self.find_all:
                break
        return out

    def _candidates(self, obj: str) -> list[int]:
        trace = self.obs.trace
        ok = self.obs.longest_presence >= self.m
        kinds = self.kinds[obj]
        if kinds is not None:
            ok &= np.isin(trace.objects.kinds(), list(kinds))
        if obj == "ego" and trace.ego is not None:
            only = np.zeros_like(ok)
            only[trace.object_index(trace.ego)] = True
            ok &= only
        return np.flatnonzero(ok).tolist()

    def _order(self, edges: dict[str, list[int]]) -> list[str]:
        """Dependency order: ego (else the most constrained object) first, then objects sharing guards."""
        linked = {o: set() for o in edges}
        for o in self.hfsms:
            for p in self.reads[o] - {o}:
                linked[o].add(p)
                linked[p].add(o)
        for name in self.monitors:
            for o in self.reads[name]:
                linked[o] |= self.reads[name] - {o}
        order: list[str] = []
        remaining = sorted(edges, key=lambda o: (o != "ego", len(edges[o]), o))
        while remaining:
            frontier = [remaining[0]]
            while frontier:
                o = frontier.pop(0)
                if o in order:
                    continue
                order.append(o)
                frontier.extend(sorted(linked[o] - set(order), key=lambda p: (len(edges[p]), p)))
            remaining = [o for o in remaining if o not in order]
        return order

    def _extend(self, order: list[str], node: Node) -> Iterator[None]:
        out = self.outcome
        self._note_best(node)
        if len(node.assignment) == len(order):
            out.matches.append((dict(node.assignment), np.flatnonzero(node.alive)))
            yield
            return
        q = order[len(node.assignment)]
        used = set(node.assignment.values())
        cands = [c for c in out.unary[q] if c not in used]
        trials = [{**node.assignment, q: c} for c in cands]
        completed = (
            [o for o in self.components if q in self.reads[o] and self.reads[o] <= set(trials[0])] if trials else []
        )
        exact = {o: self.reach(o, trials) for o in completed}
        for j, (c, assignment) in enumerate(zip(cands, trials)):
            per_object = dict(node.per_object)
            per_object[q] = out.unary[q][c]
            for o in completed:
                per_object[o] = np.minimum(per_object.get(o, exact[o][j]), exact[o][j])
            joint = np.minimum(node.reach, per_object[q])
            for o in completed:
                joint = np.minimum(joint, per_object[o])
            child = Node(assignment, joint, per_object, node.alive & (joint >= self.m))
            if child.alive.any():
                self._check_scene(child, q)
            if child.alive.any():
                for found in self._extend(order, child):
                    yield found
                    if not self.find_all:
                        return
            else:
                self._note_best(child)

    def _check_scene(self, node: Node, newest: str) -> None:
        """Keep the window starts where the initial-scene groups this assignment completes hold."""
        starts = np.flatnonzero(node.alive)
        good = self.scene_starts(node.assignment, starts, newest)
        if len(good) < len(starts):
            node.alive = np.zeros_like(node.alive)
            node.alive[good] = True
            if not len(good):
                self.outcome.scene_failures.append((dict(node.assignment), starts))

    def _note_best(self, node: Node) -> None:
        best = self.outcome.best
        if not node.assignment:
            return
        score = (len(node.assignment), int(node.reach.max()))
        if best is None or score > (len(best.assignment), int(best.reach.max())):
            self.outcome.best = node
