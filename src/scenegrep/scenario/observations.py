"""What a scenario query reads from one label trace, arranged for vectorised access.

``state_at[f, k]`` is the state row of label object k in frame f (-1 when absent);
``accept`` gives, per HFSM output alphabet, a bit mask per frame and object of the
outputs the observed behaviour label set admits (through the vocabulary; a primitive that
admits any label set, such as ``AnyBehavior``, is admitted wherever the object is observed);
:meth:`Observations.guard_codes` evaluates a guard for many assignments of label
objects at once, with the scene query's decision procedure: a guard *can be true*
when some value of its random variables satisfies it, *can be false* when some
value falsifies it (``CAN_TRUE | CAN_FALSE``), per frame.
"""

from __future__ import annotations

from functools import cached_property

import numpy as np

from ..model import LabelTrace
from ..scene.decide import decide
from ..scene.tolerance import Tolerance
from ..scene.dependencies import Group, random_leaves
from ..scene.evaluate import Evaluator, Labels, Rows
from ..scene.geometry import MapGeometry
from ..scene.match import labels_of
from ..scene.program import ProgramObject, Requirement
from ..scene.terms import Term
from .hfsm import BOTH, CAN_FALSE, CAN_TRUE
from .translate import Guard
from .vocabulary import Vocabulary


class Observations:
    """One trace's inputs and outputs for scenario queries (see the module docstring)."""

    def __init__(
        self,
        trace: LabelTrace,
        geometry: MapGeometry,
        vocabulary: Vocabulary,
        objects: dict[str, ProgramObject],
        tolerance: Tolerance,
    ):
        self.trace = trace
        self.geometry = geometry
        self.vocabulary = vocabulary
        self.objects = objects
        self.tolerance = tolerance
        self.n_frames = trace.n_frames
        states = trace.states
        self.state_at = np.full((trace.n_frames, trace.n_objects), -1, dtype=np.int64)
        self.state_at[states.frame, states.object] = np.arange(len(states))
        self.labels: Labels = labels_of(trace)
        self._accept: dict[tuple[str, ...], np.ndarray] = {}
        self._guards: dict[tuple[int, tuple[int, ...]], np.ndarray] = {}

    @cached_property
    def period(self) -> float:
        return self.trace.frame_period

    @cached_property
    def longest_presence(self) -> np.ndarray:
        """Per label object, the longest run of consecutive frames it is observed in."""
        present = np.pad(self.state_at.T >= 0, ((0, 0), (1, 1)))
        change = np.diff(present.astype(np.int8), axis=1)
        obj, start = np.nonzero(change == 1)
        _, end = np.nonzero(change == -1)
        best = np.zeros(self.trace.n_objects, dtype=np.int64)
        np.maximum.at(best, obj, end - start)
        return best

    def accept(self, outputs: tuple[str, ...]) -> np.ndarray:
        """(frames, objects) bit masks: bit p set where the label set admits ``outputs[p]``."""
        found = self._accept.get(outputs)
        if found is None:
            behaviours = self.trace.behaviours
            assert behaviours is not None
            column = {name: k for k, name in enumerate(behaviours.vocabulary)}
            per_row = np.zeros(len(self.trace.states), dtype=np.int64)
            for p, name in enumerate(outputs):
                primitive = self.vocabulary.primitive(name)
                if primitive.admits_any:
                    per_row |= np.int64(1) << p
                    continue
                cols = [column[label] for label in primitive.labels if label in column]
                if cols:
                    per_row |= behaviours.member[:, cols].any(axis=1).astype(np.int64) << p
            found = np.where(self.state_at >= 0, per_row[np.maximum(self.state_at, 0)], 0)
            self._accept[outputs] = found
        return found

    def guard_codes(self, guard: Guard, assignments: np.ndarray) -> np.ndarray:
        """(len(assignments), frames) guard values; row j binds ``guard.objects`` to the label
        objects ``assignments[j]``. Frames where one of them is absent are BOTH (the window
        cannot use them anyway: every corresponded object must be observed)."""
        keys = [(guard.index, tuple(int(v) for v in row)) for row in assignments]
        missing = sorted({key for key in keys if key not in self._guards})
        if missing:
            block = np.array([key[1] for key in missing], dtype=np.int64).reshape(len(missing), -1)
            for key, codes in zip(missing, self._evaluate(guard, block)):
                self._guards[key] = codes
        if not keys:
            return np.zeros((0, self.n_frames), dtype=np.int64)
        return np.stack([self._guards[key] for key in keys])

    def _evaluate(self, guard: Guard, block: np.ndarray) -> np.ndarray:
        codes = np.full((len(block), self.n_frames), BOTH, dtype=np.int64)
        if not guard.objects:
            frames = np.arange(self.n_frames)
            rows = Rows(frames, {})
            combo = np.zeros(self.n_frames, dtype=np.int64)
        else:
            states = self.state_at[:, block]  # (frames, assignments, objects)
            frame, combo = np.nonzero((states >= 0).all(axis=2))
            rows = Rows(frame, {name: states[frame, combo, i] for i, name in enumerate(guard.objects)})
        if len(rows) == 0:
            return codes
        can_true = self._satisfiable(guard.condition, guard, rows)
        can_false = ~can_true if not guard.is_random else self._satisfiable(guard.negation, guard, rows)
        value = can_true * CAN_TRUE + can_false * CAN_FALSE
        value[value == 0] = BOTH  # undecided by the solvers: kept optimistic
        if not guard.objects:
            codes[:] = value
        else:
            codes[combo, rows.frame] = value
        return codes

    def _satisfiable(self, term: Term, guard: Guard, rows: Rows) -> np.ndarray:
        evaluator = Evaluator(
            rows, self.labels, self.objects, self.geometry, position_tolerance=self.tolerance.position
        )
        requirement = Requirement(term, guard.text, guard.span)
        group = Group(requirements=[requirement], unknowns=frozenset(random_leaves(term)))
        return decide(evaluator, group, self.tolerance)
