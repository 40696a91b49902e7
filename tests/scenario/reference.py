"""A brute-force scenario query: seed 000 Algorithms 1 and 2 as written, for checking the fast one.

Every injective correspondence by class is tried (the trace's ego for the program's ego when
the trace names one), every window start in order, the initial scene with the scene query
at that frame, then ValidStep literally: the set of each HFSM's configurations stepped frame
by frame with :meth:`Hfsm.step`, kept when the observed label admits the output. Guard values
come from the shared decision procedure (:meth:`Observations.guard_codes`).
"""

import itertools

import numpy as np

from scenegrep.scenario.hfsm import StepInputs
from scenegrep.scenario.observations import Observations
from scenegrep.scene.geometry import geometry_of
from scenegrep.scene.match import SceneOptions


def reference_matches(query, trace, m, road_map=None, first_only=False):
    """{(sorted correspondence items, start)} of the matching windows (the first one only if asked)."""
    road_map = query.scene.map_for(trace, road_map, query.uses_map())
    objects = {o.name: o for o in query.scene.program.objects}
    obs = Observations(trace, geometry_of(road_map), query.vocabulary, objects, SceneOptions().tolerance)
    names = list(query.hfsms)
    kinds = trace.objects.kinds()
    sets = trace.behaviours.sets()
    found = set()
    for rows in itertools.permutations(range(trace.n_objects), len(names)):
        assignment = dict(zip(names, rows))
        if not _classes_fit(assignment, objects, kinds, trace):
            continue
        correspondence = {name: str(trace.objects.id[row]) for name, row in assignment.items()}
        scene = None
        for start in range(trace.n_frames - m + 1):
            if _runs(query, obs, sets, assignment, start, m):
                if scene is None:
                    scene = query.scene.match(trace, road_map, SceneOptions(correspondence=correspondence)).matched
                if scene[start]:
                    found.add((tuple(sorted(correspondence.items())), start))
                    if first_only:
                        return found
    return found


def _classes_fit(assignment, objects, kinds, trace):
    for name, row in assignment.items():
        allowed = objects[name].kinds
        if allowed is not None and kinds[row] not in allowed:
            return False
        if name == "ego" and trace.ego is not None and trace.objects.id[row] != trace.ego:
            return False
    return True


def _runs(query, obs, sets, assignment, start, m):
    codes = {}
    for guard in query.guards:
        if all(o in assignment for o in guard.objects):
            block = np.array([[assignment[o] for o in guard.objects]], dtype=np.int64).reshape(1, -1)
            codes[guard.index] = obs.guard_codes(guard, block)[0]
    current = {name: {None} for name in assignment}
    for t in range(start, start + m):
        inputs = StepInputs(tuple(int(codes[g][t]) for g in range(len(query.guards))), obs.period)
        for name, row in assignment.items():
            state = obs.state_at[t, row]
            observed = sets[state] if state >= 0 else frozenset()
            hfsm = query.hfsms[name]
            current[name] = {
                o.config
                for c in current[name]
                for o in hfsm.step(c, inputs)
                if state >= 0 and admits(query.vocabulary.primitive(o.label), observed)
            }
            if not current[name]:
                return False
    return True


def admits(primitive, observed: frozenset[str]) -> bool:
    """Whether an observed label set admits a primitive (an "any" primitive admits every set)."""
    return primitive.admits_any or bool(primitive.labels & observed)
