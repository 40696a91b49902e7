"""Explanations of answers: values of the random variables for a match, soft requirements.

For a matched frame the witness is the reported correspondence together with a
value for every random variable of the program (and every random point, and the
option each ``Options`` chose) that reproduces the frame's labels: each group is
decided again for that one correspondence and a solver is asked for a satisfying
assignment. Soft requirements (``require[p]``) are not enforced; for each matched
frame they are reported as holding or not for its correspondence.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .decide import closed_form_witness, decide, decide_expanded
from .tolerance import Tolerance
from .dependencies import Group, random_leaves
from .evaluate import Evaluator, Labels, Rows
from .geometry import MapGeometry
from .match import TraceMatches
from .program import SceneProgram
from .randoms import unique_names
from .solvers import solve
from .solvers.problem import build


def witness_values(
    program: SceneProgram,
    matches: TraceMatches,
    labels: Labels,
    geometry: MapGeometry,
    tolerance: Tolerance,
    survivor: int,
) -> dict[str, Any]:
    """The random values of one matched frame (``survivor`` indexes ``matches.survivors``):
    name (unique: :func:`.randoms.unique_names`) -> number, [x, y] for a random point, or
    ``"option k of n"``; None where the
    solver proved feasibility without producing a value (a δ-sat box)."""
    rows = matches.survivors.take(np.array([survivor]))
    objects = {o.name: o for o in program.objects}
    names = unique_names(matches.groups)
    values: dict[str, Any] = {}
    for group in matches.groups:
        if group.unknowns:
            ev = Evaluator(rows, labels, objects, geometry, position_tolerance=tolerance.position)
            values.update(_group_witness(ev, group, tolerance, names))
    return values


def _group_witness(ev: Evaluator, group: Group, tolerance: Tolerance, names: dict[Any, str]) -> dict[str, Any]:
    """One group's values, named by ``names`` (:func:`.randoms.unique_names`)."""
    choices = sorted((u for u in group.unknowns if u.op == "choice"), key=repr)
    for leaf in choices:
        ev.expand_choice(leaf)
    ev.unknowns = frozenset(u for u in group.unknowns if u.op != "choice")
    feasible = np.flatnonzero(decide_expanded(ev, group, tolerance))
    if not len(feasible):
        return {}
    row = int(feasible[0])
    found: dict[str, Any] = {
        names[leaf.value]: f"option {int(ev.memo[leaf][row]) + 1} of {leaf.value.size}" for leaf in choices
    }
    if not ev.unknowns:
        return found
    assignment = closed_form_witness(ev, group, tolerance, row)
    if assignment is None:
        assignment = solve(build(ev, group, tolerance, row), ev.geometry, tolerance).witness or {}
    points: dict[str, list[float | None]] = {}
    for leaf in ev.unknowns:
        value = assignment.get(leaf)
        value = None if value is None else float(value)
        if leaf.op == "point":
            points.setdefault(names[leaf.value[0]], [None, None])[leaf.value[1]] = value
        else:
            found[names[leaf.value]] = value
    found.update(points)
    return found


def soft_requirements(
    program: SceneProgram, matches: TraceMatches, labels: Labels, geometry: MapGeometry, tolerance: Tolerance
) -> dict[str, np.ndarray]:
    """For each soft requirement, whether it holds for each matched frame's correspondence
    (arrays aligned with ``matches.survivors``)."""
    objects = {o.name: o for o in program.objects}
    found: dict[str, np.ndarray] = {}
    rows: Rows = matches.survivors
    for requirement in (r for r in program.requirements if r.soft):
        group = Group(requirements=[requirement], unknowns=frozenset(random_leaves(requirement.condition)))
        if not len(rows):
            found[requirement.description] = np.zeros(0, dtype=bool)
            continue
        ev = Evaluator(rows, labels, objects, geometry, position_tolerance=tolerance.position)
        found[requirement.description] = decide(ev, group, tolerance)
    return found
