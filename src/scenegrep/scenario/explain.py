"""Explanations of scenario answers.

For a match: per step of the window, each program object's label object, observed
label set, the values of the guards its HFSM reads, the HFSM's possible outputs
(before pruning, as in seed 000 Table 3) and the states kept after pruning.
For a non-match: the first reason in pipeline order (trace too short, no candidate
of a class, no candidate whose own behaviour fits, no injective assignment) or,
after the search, the correspondence that got furthest, the frame where its run
died and the object whose observed label its HFSM could not produce there; or,
when the behaviours fit somewhere, that the initial scene fails at every start, and at the
start nearest to holding (:func:`scenegrep.scene.misses.nearest_miss`) the program object, its
label object, the features that fail and the tolerances that would admit them.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..scene.misses import nearest_miss, spread
from ..scene.program import SceneProgram
from ..scene.query import SceneResult

from .hfsm import CAN_FALSE, CAN_TRUE, Config, Hfsm
from .search import Assignment, Outcome, Search
from .translate import Guard
from .vocabulary import STATIONARY
from ..wording import counted

_GUARD_TEXT = {CAN_TRUE: "true", CAN_FALSE: "false", CAN_TRUE | CAN_FALSE: "true or false"}


class Explainer:
    """Builds the explanations of one search (lazily: nothing is computed unless asked)."""

    def __init__(
        self,
        hfsms: dict[str, Hfsm],
        guards: list[Guard],
        program: SceneProgram,
        search: Search,
        outcome: Outcome,
        scene_at: Callable[[dict[str, str], np.ndarray], SceneResult],
    ):
        """The query's HFSMs (by program object), guards and scene program; the search and its
        outcome. ``scene_at(correspondence, starts)`` matches the initial scene at some window
        starts with a (partial) correspondence, program object -> label object id."""
        self.hfsms = hfsms
        self.guards = guards
        self.program = program
        self.scene_at = scene_at
        self.search = search
        self.outcome = outcome
        self.trace = search.obs.trace

    def frame(self, position: int) -> str:
        index = int(self.trace.frame_index[position])
        return f"frame {index} (t = {float(self.trace.frame_time[position]):.2f} s)"

    def labels_at(self, row: int, position: int) -> str:
        state = int(self.search.obs.state_at[position, row])
        if state < 0:
            return "not observed"
        behaviours = self.trace.behaviours
        assert behaviours is not None
        names = [behaviours.vocabulary[k] for k in np.flatnonzero(behaviours.member[state])]
        return "{" + ", ".join(names) + "}"

    def _assignment(self, correspondence: dict[str, str]) -> Assignment:
        rows = self.trace.objects.row_of()
        return {name: rows[label] for name, label in correspondence.items()}

    def run(self, obj: str, assignment: Assignment, start: int, steps: int) -> list[tuple[int, set, frozenset]]:
        """Per step from ``start``: (symbol, possible outputs, configurations kept after pruning)."""
        automaton = self.search.automata[obj]
        symbols = self.search.symbols(obj, [assignment])[0]
        configs: frozenset[Config] = frozenset({None})
        found = []
        for t in range(start, min(start + steps, len(symbols))):
            outputs = automaton.outputs_from(configs, int(symbols[t]))
            configs = automaton.step_set(configs, int(symbols[t]))
            found.append((int(symbols[t]), outputs, configs))
            if not configs:
                break
        return found

    def witness(self, correspondence: dict[str, str], start: int) -> list[str]:
        assignment = self._assignment(correspondence)
        m = self.search.m
        lines = [
            f"window {self.frame(start)} to {self.frame(start + m - 1)} ({counted(m, 'frame')}); "
            + ", ".join(f"{name} = {label}" for name, label in correspondence.items())
        ]
        runs = {obj: self.run(obj, assignment, start, m) for obj in self.hfsms}
        for step in range(m):
            position = start + step
            lines.append(f"step {step}, {self.frame(position)}:")
            for obj, hfsm in self.hfsms.items():
                symbol, outputs, configs = runs[obj][step]
                guards = self._guard_values(obj, symbol)
                kept = sorted({hfsm.path(c) for c in configs})
                lines.append(
                    f"  {obj} ({correspondence[obj]}): label {self.labels_at(assignment[obj], position)}"
                    f"{guards}; HFSM outputs {{{', '.join(sorted(outputs))}}}; states: {' | '.join(kept)}"
                )
        return lines

    def _guard_values(self, obj: str, symbol: int) -> str:
        automaton = self.search.automata[obj]
        inputs = automaton.inputs(symbol)
        parts = [f"{self.guards[g].text} is {_GUARD_TEXT[inputs.guards[g]]}" for g in self.hfsms[obj].guards]
        return "; " + "; ".join(parts) if parts else ""

    # ---------------------------------------------------------------- non-matches
    def why_not(self) -> str:
        out = self.outcome
        m = self.search.m
        if self.search.n_starts <= 0:
            return f"the trace has {counted(self.trace.n_frames, 'frame')}, fewer than the window of {m}"
        for obj, cands in out.candidates.items():
            if not cands:
                program_object = self.program.object(obj)
                return (
                    f"no label object that can be {obj} ({program_object.class_name}) is observed for "
                    f"{m} consecutive frames"
                )
        for obj, kept in out.unary.items():
            if not kept:
                return f"no candidate for {obj} behaves as its HFSM for {counted(m, 'frame')}: " + self._furthest_unary(
                    obj
                )
        if not out.feasible:
            names = ", ".join(f"{o} ({len(k)})" for o, k in out.unary.items())
            return f"the program objects cannot take distinct label objects (candidates: {names})"
        if out.scene_failures:
            assignment, starts = out.scene_failures[0]
            return (
                f"the behaviours match from {counted(len(starts), 'window start')} with {self._names(assignment)}, "
                f"but the initial scene holds at none of them; {self._scene_failure(assignment, starts)}"
            )
        best = out.best
        if best is None:
            return "no correspondence was found"
        return self._died(best.assignment, best.per_object, best.reach)

    def _scene_failure(self, assignment: Assignment, starts: np.ndarray) -> str:
        """Where the initial scene comes nearest to holding (else at the first start): the frame,
        the program and label objects of the group that fails there, its features, and the
        tolerances that would admit it."""
        ids = self.trace.objects.id
        result = self.scene_at({name: str(ids[row]) for name, row in assignment.items()}, starts)
        miss = nearest_miss(result, spread(starts))
        start = int(starts[0]) if miss is None else miss.position
        matches = result.matches
        group = matches.groups[int(matches.failed_group[start])]
        correspondence = {**(miss.correspondence if miss else {}), **result.options.correspondence}
        names = ", ".join(f"{name} = {correspondence.get(name, 'no label object')}" for name in sorted(group.objects))
        text = f"at {self.frame(start)}, with {names}, it fails {group.describe()}"
        return text if miss is None else f"{text}: {miss.shortfalls()}"

    def _furthest_unary(self, obj: str) -> str:
        cands = self.outcome.candidates[obj]
        rows = self.search.reach(obj, [{obj: c} for c in cands])
        outputs = self.search.automata[obj].outputs
        moving = sum(1 << p for p, label in enumerate(outputs) if label != STATIONARY)
        admitted = (self.search.obs.accept(outputs)[:, cands] & moving).astype(bool).sum(axis=0)
        j = max(range(len(cands)), key=lambda k: (int(rows[k].max()), int(admitted[k])))
        return self._died({obj: cands[j]}, {obj: rows[j]}, rows[j])

    def _names(self, assignment: Assignment) -> str:
        ids = self.trace.objects.id
        return ", ".join(f"{name} = {ids[row]}" for name, row in assignment.items())

    def _died(self, assignment: Assignment, per_object: dict[str, np.ndarray], joint: np.ndarray) -> str:
        start = int(np.argmax(joint))
        obj = min(per_object, key=lambda o: int(per_object[o][start]))
        survived = int(per_object[obj][start])
        if obj in self.search.monitors:
            return (
                f"furthest reach with {self._names(assignment)}: over the window from {self.frame(start)}, "
                f"the behaviours fit but {obj} does not hold"
            )
        position = start + survived
        outputs = self.run(obj, assignment, start, survived + 1)[-1][1]
        ids = self.trace.objects.id
        return (
            f"furthest reach with {self._names(assignment)}: the window from {self.frame(start)} "
            f"fails at {self.frame(position)}, where {obj} ({ids[assignment[obj]]}) is labelled "
            f"{self.labels_at(assignment[obj], position)} but its HFSM could output "
            f"{{{', '.join(sorted(outputs))}}}"
        )
