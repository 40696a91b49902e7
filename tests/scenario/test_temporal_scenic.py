"""Temporal requirements as Scenic 3.1.1 itself decides them (issue 16 acceptance).

Small programs with ``require always`` / ``require eventually`` run in Scenic's Newtonian
simulator (as ``scenegrep synth`` runs them, through :mod:`scenegrep.synth`), but every
simulation is kept, accepted or rejected: the states are recorded whenever Scenic updates its
requirement monitors (``DynamicScenario._step``, steps 0 to the last, including the final state
and the state that violated an ``always``), so the recorded run is exactly what Scenic judged.
Behaviour labels are those the synth recorder observes (each object's one primitive). Every run
Scenic accepted matches the query with the window = the whole run; every run Scenic rejected for
the temporal requirement (its line named in the rejection) does not.
"""

from __future__ import annotations

import contextlib
import dataclasses
from pathlib import Path

import pytest

from scenegrep.model import BehaviourLabels, MapSource
from scenegrep.scenario import compile_scenario
from scenegrep.synth._scenic import compile_program, map_params, seed_scenic
from scenegrep.synth.running import observe_steps
from scenegrep.synth.simulate import _Recorder, _simulator, run_seed

pytestmark = pytest.mark.slow

RUNS = 16
STEPS = 40
SIM = "model scenic.simulators.newtonian.driving_model\n"
SETUP = """ego = new Car with behavior FollowLaneBehavior(target_speed=8)
lead = new Car following roadDirection from ego for Range(10, 40), with name "lead"
require lead in ego.lane
require (distance to intersection) > 80
"""
QUERY_SCENE = """ego = new Car with behavior FollowLaneBehavior(target_speed=8)
lead = new Car on visible ego.lane, with name "lead"
"""
REQUIREMENTS = {
    "always": "require always (distance to lead) > 12",
    "eventually": "require eventually (distance to lead) < 6",
    "both": "require (always (distance to lead) > 6) and (eventually ego.speed > 4)",
}


@contextlib.contextmanager
def monitored_states(recorder: _Recorder):
    """Record the simulation's state each time Scenic steps its top-level scenario (where it
    updates the requirement monitors)."""
    from scenic.core.dynamics.scenarios import DynamicScenario
    from scenic.syntax import veneer

    original = DynamicScenario._step

    def step(self):
        simulation = veneer.currentSimulation
        if simulation is not None and self is simulation.scene.dynamicScenario:
            recorder.observe(simulation)
        return original(self)

    DynamicScenario._step = step
    try:
        yield
    finally:
        DynamicScenario._step = original


def simulate_all(path: Path, town: Path, line: int) -> list[tuple[bool, object]]:
    """(accepted by Scenic, trace of the states its monitors saw) per run; runs rejected for
    anything but the requirement on ``line`` are left out."""
    from scenic.core.dynamics import RejectSimulationException

    scenario = compile_program(path, {**map_params(town), "render": False})
    simulator = _simulator(scenario, path)
    runs = []
    for run in range(RUNS):
        seed_scenic(run_seed(0, run))
        scene, _ = scenario.generate(maxIterations=5000, verbosity=0)
        states, actions = _Recorder(scene.egoObject), _Recorder(scene.egoObject)
        accepted = True
        with monitored_states(states), observe_steps(actions.observe):
            try:
                simulator.createSimulation(scene, maxSteps=STEPS, name=str(run), verbosity=0, timestep=None)
            except RejectSimulationException as rejection:
                if f"line {line}" not in str(rejection):
                    continue
                accepted = False
        trace = states.trace(f"run{run}", {}, MapSource(str(town), "opendrive"), path)
        runs.append((accepted, with_labels(trace, actions)))
    return runs


def with_labels(trace, actions: _Recorder):
    """The trace with each object's behaviour label as the synth recorder saw it when behaviours
    chose actions (each object runs one primitive throughout: checked); Scenic runs no behaviour
    at the final state, which keeps the same label."""
    labels = {}
    for (_, row, *_), stack in zip(actions.values, actions.stacks):
        labels.setdefault(row, set()).add(stack[-1] if stack else "Stationary")
    assert all(len(found) == 1 for found in labels.values()), labels
    names = [{next(iter(labels[int(row)])).removesuffix("Behavior")} for row in trace.states.object]

    return dataclasses.replace(trace, behaviours=BehaviourLabels.from_sets(names))


@pytest.mark.parametrize("kind", sorted(REQUIREMENTS))
def test_scenic_verdicts_are_the_query_answers_over_the_whole_run(kind, maps_dir, scenic_cache, tmp_path):
    town = maps_dir / "Town06.xodr"
    requirement = REQUIREMENTS[kind]
    program = tmp_path / f"{kind}.scenic"
    program.write_text(SIM + SETUP + requirement + "\n")
    line = (SIM + SETUP).count("\n") + 1
    query = compile_scenario(SIM + QUERY_SCENE + requirement + "\n", f"{kind}.scenic")
    runs = simulate_all(program, town, line)
    verdicts = [accepted for accepted, _ in runs]
    assert verdicts.count(True) >= 2 and verdicts.count(False) >= 2, verdicts
    answers = [query.match(trace, "all").matched for _, trace in runs]
    assert answers == verdicts
