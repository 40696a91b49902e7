"""Algorithm 1 of seed 003 over every frame of a trace at once.

Rows are partial object correspondences (a frame, and the label state matched
to each program object so far). Groups are checked in dependency order; a
group first extends each row with every candidate for the program objects it
brings in (same frame, compatible kind, not already used: the correspondence is
injective), then keeps the rows its features and requirements admit. A failed
row is never extended again, which is exactly the paper's pruning of
correspondences that extend a known-bad partial one (badOCs), done breadth
first and vectorised over frames. A frame matches when a row survives every
group (and, with ``exact``, uses every label object in view).

Before a group with random variables (whose rows go to the solvers, the dear part) the later
groups without any whose objects are all in the rows already are checked first (a frame turned
away from the road is refuted by its heading group before its position group inverts a walk):
a row that fails one is dropped either way, so the rows that survive every group are the same. Only
the first group a frame fails (``failed_group``, what ``--explain`` and the nearest misses name)
depends on the order: for a frame that lost rows to a group checked early and then died, it is
found again in the documented order, without checking early, when first asked for. With a choice
for unknown map layers (``--unknown-layers``) nothing is checked early: its report counts each
decision under the first layer that made it, in the documented order.

The program's ego corresponds to the trace's ego object when the trace names
one (the sensor platform); ``visible_distance`` keeps only label objects whose
centre is within that many metres of the ego, and restricts random points to
that disc around it (seed 003's crop of the map).
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field, replace

import numpy as np

from ..model import LabelTrace
from ..model.layers import UnknownLayers
from .decide import decide
from .tolerance import Tolerance
from .dependencies import Group
from .evaluate import Evaluator, Labels, Rows
from .geometry import MapGeometry
from .program import ProgramObject, SceneProgram


@dataclass(frozen=True)
class SceneOptions:
    """How to match: tolerances, ``exact`` (surjective correspondence), visible distance (m), a
    known (partial) correspondence, program object -> label object id, to check instead of search,
    and the frame positions to check (None: all; the others are reported as not matching);
    ``unknown_layers`` is the user's choice for map layers the map does not publish (None: none,
    a query that needs one is an error)."""

    tolerance: Tolerance = field(default_factory=Tolerance)
    exact: bool = False
    visible_distance: float | None = None
    correspondence: dict[str, str] | None = None
    frames: np.ndarray | None = None
    unknown_layers: UnknownLayers | None = None


@dataclass
class TraceMatches:
    """Per frame of one trace: matched or not, the first surviving correspondence (program object ->
    label object id) and, for frames that fail, the index (into ``groups``, the groups checked) of
    the first group no row survived (``failed_group``); ``survivors`` holds the first surviving row
    of each matched frame, in frame order; ``notes`` counts the row solvers' verdicts.
    ``unsure`` marks the frames whose ``found_failed`` may be too early (they lost rows to a group
    checked early) and ``recheck`` finds theirs in the documented order."""

    matched: np.ndarray
    correspondence: list[dict[str, str] | None]
    found_failed: np.ndarray
    groups: list[Group]
    survivors: Rows
    notes: Counter = field(default_factory=Counter)
    every: Rows | None = None
    unsure: np.ndarray | None = None
    recheck: Callable[[np.ndarray], np.ndarray] | None = None

    @property
    def failed_group(self) -> np.ndarray:
        """Per frame, the index of the first group (in the documented order) no row survived (-1:
        matched)."""
        if self.unsure is not None and self.unsure.any() and self.recheck is not None:
            frames = np.flatnonzero(self.unsure)
            self.found_failed[frames] = self.recheck(frames)[frames]
            self.unsure = None
        return self.found_failed


class Candidates:
    """Label states each program object may correspond to, per frame (CSR arrays)."""

    def __init__(self, trace: LabelTrace, options: SceneOptions):
        states = trace.states
        self.n_frames = trace.n_frames
        self.kinds = trace.objects.kinds()[states.object]
        self.frame = states.frame
        self.ego_row = trace.object_index(trace.ego) if trace.ego is not None else None
        visible = np.ones(len(states), dtype=bool)
        if options.visible_distance is not None and self.ego_row is not None:
            ego_state = self.ego_state_per_frame(states.object, states.frame)
            has_ego = ego_state >= 0
            ex = np.where(has_ego, states.x[np.maximum(ego_state, 0)], np.nan)
            ey = np.where(has_ego, states.y[np.maximum(ego_state, 0)], np.nan)
            dist = np.hypot(states.x - ex[states.frame], states.y - ey[states.frame])
            visible = dist <= options.visible_distance
        self.visible = visible
        self.object = states.object
        self.known = {}
        if options.correspondence:
            rows = trace.objects.row_of()
            self.known = {name: rows.get(label, -1) for name, label in options.correspondence.items()}

    def ego_state_per_frame(self, objects: np.ndarray, frames: np.ndarray) -> np.ndarray:
        """The state row of the trace's ego in each frame (-1 where absent)."""
        found = np.full(self.n_frames, -1, dtype=np.intp)
        rows = np.flatnonzero(objects == self.ego_row)
        found[frames[rows]] = rows
        return found

    def for_object(self, obj: ProgramObject) -> tuple[np.ndarray, np.ndarray]:
        """(CSR offsets per frame, state rows) of the candidates for a program object."""
        eligible = self.visible.copy()
        if obj.kinds is not None:
            eligible &= np.isin(self.kinds, list(obj.kinds))
        if obj.is_ego and self.ego_row is not None:
            eligible &= self.object == self.ego_row
        if obj.name in self.known:
            eligible &= self.object == self.known[obj.name]
        rows = np.flatnonzero(eligible)
        offsets = np.searchsorted(self.frame[rows], np.arange(self.n_frames + 1), side="left")
        return offsets, rows

    def in_view(self) -> np.ndarray:
        """Number of label objects in view per frame (for exact matching)."""
        return np.bincount(self.frame[self.visible], minlength=self.n_frames)


def extend(rows: Rows, name: str, offsets: np.ndarray, candidates: np.ndarray) -> Rows:
    """Every row extended by every candidate of its frame not already used in the row."""
    counts = offsets[rows.frame + 1] - offsets[rows.frame]
    parent = np.repeat(np.arange(len(rows)), counts)
    first = np.repeat(offsets[rows.frame] - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    chosen = candidates[np.arange(len(parent)) + first] if len(parent) else np.zeros(0, np.intp)
    grown = rows.take(parent)
    keep = np.ones(len(parent), dtype=bool)
    for used in grown.state.values():
        keep &= used != chosen
    grown.state[name] = chosen
    return grown.take(np.flatnonzero(keep))


def labels_of(trace: LabelTrace) -> Labels:
    """The label columns the scene query reads: velocities as the trace holds them (recorded, or
    estimated from positions by a reader whose data records none: the trace attribute
    :data:`~scenegrep.model.kinematics.ESTIMATED_VELOCITY` says so), and no angular speeds (no
    data format scenegrep reads has them)."""
    states = trace.states
    return Labels(
        states.x,
        states.y,
        states.heading,
        states.length,
        states.width,
        dict(trace.attributes),
        vx=states.vx,
        vy=states.vy,
        speed=states.speed(),
        trace=trace,
    )


def match_trace(
    scene: SceneProgram,
    groups: list[Group],
    trace: LabelTrace,
    geometry: MapGeometry,
    options: SceneOptions,
    early: bool = True,
) -> TraceMatches:
    """Algorithm 1 for every frame of ``trace`` (see the module docstring; ``early``: check the
    groups without random variables early, unless a choice for unknown layers is made)."""
    labels = labels_of(trace)
    objects = {o.name: o for o in scene.objects}
    candidates = Candidates(trace, options)
    frames = np.arange(trace.n_frames) if options.frames is None else np.asarray(options.frames, dtype=np.intp)
    rows = Rows(frames, {})
    failed = np.full(trace.n_frames, -1, dtype=np.intp)
    unsure = np.zeros(trace.n_frames, dtype=bool)
    notes: Counter = Counter()
    present: set[str] = set()
    done: set[int] = set()

    def keep(rows: Rows, group: Group) -> Rows:
        ev = Evaluator(rows, labels, objects, geometry, position_tolerance=options.tolerance.position)
        kept = rows.take(np.flatnonzero(decide(ev, group, options.tolerance)))
        notes.update(ev.notes)
        return kept

    for g, group in enumerate(groups):
        for name in group.introduces:
            rows = extend(rows, name, *candidates.for_object(objects[name]))
        present.update(group.introduces)
        if early and group.unknowns and options.unknown_layers is None:
            for h in range(g + 1, len(groups)):
                if len(rows) and h not in done and not groups[h].unknowns and groups[h].objects <= present:
                    before = np.bincount(rows.frame, minlength=trace.n_frames)
                    rows = keep(rows, groups[h])
                    done.add(h)
                    unsure |= np.bincount(rows.frame, minlength=trace.n_frames) < before
        if len(rows) and g not in done:
            rows = keep(rows, group)
        _record_failures(failed, rows, g)
    if options.exact:
        used = len(scene.objects)
        rows = rows.take(np.flatnonzero(candidates.in_view()[rows.frame] == used))
        _record_failures(failed, rows, len(groups))
    matched = np.zeros(trace.n_frames, dtype=bool)
    matched[rows.frame] = True
    rows = rows.take(np.argsort(rows.frame, kind="stable"))
    survivors = rows.take(np.unique(rows.frame, return_index=True)[1])
    unsure &= failed >= 0

    def recheck(frames: np.ndarray) -> np.ndarray:
        found = match_trace(scene, groups, trace, geometry, replace(options, frames=frames), early=False)
        return found.failed_group

    correspondence = _correspondences(survivors, trace)
    return TraceMatches(matched, correspondence, failed, groups, survivors, notes, rows, unsure, recheck)


def _record_failures(failed: np.ndarray, rows: Rows, g: int) -> None:
    alive = np.zeros(len(failed), dtype=bool)
    alive[rows.frame] = True
    failed[(~alive) & (failed < 0)] = g


def _correspondences(survivors: Rows, trace: LabelTrace) -> list[dict[str, str] | None]:
    """Each matched frame's surviving row, as program object -> label object id."""
    found: list[dict[str, str] | None] = [None] * trace.n_frames
    ids = trace.objects.id
    objects = trace.states.object
    for row, frame in enumerate(survivors.frame.tolist()):
        found[frame] = {name: str(ids[objects[states[row]]]) for name, states in survivors.state.items()}
    return found
