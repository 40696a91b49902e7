"""Label traces simulated from a Scenic program in Scenic's Newtonian driving simulator.

:func:`simulate_runs` compiles a Scenic program once (2-D mode; the road map is the global
parameter ``map``, handed over as :mod:`._scenic` describes, overriding any the program sets;
``render`` is False) and yields one :class:`~scenegrep.model.LabelTrace` per run. The program
must use the Newtonian driving model (``model scenic.simulators.newtonian.driving_model``).

A run: Scenic samples a scene and simulates it for ``steps`` time steps (fewer when the
program terminates earlier); a simulation Scenic rejects (a ``require`` violated while it
runs, ...) is retried on a new scene, up to ``max_iterations`` simulations in all. Frame k is
the state at the start of step k: index k, time k * timestep seconds (Scenic's timestep, 0.1 s).

Objects: the ego is ``"ego"``; the others are named by their Scenic ``name`` when the program
gives one (``with name "otherCar"``), else ``obj1``, ``obj2``, ... by creation order among the
non-ego objects (as :mod:`.scenic_scenes` names them); the category is the Scenic class name
(``Car``, ``Pedestrian``). States per step: ``x``, ``y`` (m, map frame), ``heading`` (rad,
Scenic's convention, in (-pi, pi]), ``vx``, ``vy`` (m/s), ``length``, ``width``, ``height`` (m),
``lane`` (the Scenic uid of the lane the object's position is in, e.g. ``road40_lane1``; none
off lanes); ``z`` is unknown (2-D mode).

Behaviour labels: one per object per step, the primitive behaviour running then (see
:mod:`.running`): the innermost running behaviour's name without the ``Behavior`` suffix
(``FollowLane``, ``LaneChange``, ``Turn``, ...), ``Stationary`` for an object running none.
The full stacks are kept in the attribute ``behaviour_stacks``: per object, the steps at which
its stack changed and the stack from then on (outermost first).

Reproducibility: run r is seeded (``random`` and ``numpy.random``) with :func:`run_seed`
(``seed``, r) before its scene is sampled, so the same arguments give identical traces, and
run r does not depend on how many runs come before it. Attributes record ``program`` (file
name), ``seed``, ``run``, ``run_seed``, ``steps``, ``timestep``, ``scenic_version``,
``rejected_scenes`` (scene samples Scenic rejected), ``rejected_simulations``, ``termination``
and, with noise (:mod:`.noise`, stream = run number), ``noise``.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError, at
from ..model import BehaviourLabels, LabelTrace, MapSource, ObjectTable, StateTable
from ._scenic import (
    checked_inputs,
    compile_program,
    map_params,
    scenic_errors,
    scenic_headings,
    scenic_version,
    seed_scenic,
)
from .noise import LabelNoise, add_noise
from .running import behaviour_stack, observe_steps, primitive_label

MAX_SCENE_ITERATIONS = 5000
"""Bound on Scenic's rejection sampling of one scene."""

NEWTONIAN_MODEL = "scenic.simulators.newtonian.driving_model"


def run_seed(seed: int, run: int) -> int:
    """The seed of run ``run`` of a set seeded with ``seed`` (both non-negative): a 32-bit
    value drawn from ``numpy.random.SeedSequence([seed, run])``."""
    return int(np.random.SeedSequence([seed, run]).generate_state(1)[0])


def simulate_runs(
    program: str | Path,
    *,
    map_path: str | Path,
    runs: int,
    steps: int,
    seed: int = 0,
    max_iterations: int = 50,
    noise: LabelNoise | None = None,
    params: Mapping[str, Any] | None = None,
) -> Iterator[LabelTrace]:
    """One trace per run of a Scenic program (see the module docstring).

    The inputs are checked and the program compiled before this returns; the runs are simulated
    as the iterator is consumed. ``params`` are further global parameters of the program.
    ``runs``, ``steps`` and ``max_iterations`` must be at least 1 and ``seed`` non-negative
    (ValueError). A missing file, a program Scenic cannot compile or that fails while running
    (located at its line and column when Scenic says), one without the Newtonian simulator, and
    a run whose ``max_iterations`` simulations are all rejected are :class:`UserError`\\ s.
    """
    if min(runs, steps, max_iterations) < 1 or seed < 0:
        raise ValueError("runs, steps and max_iterations must be at least 1 and seed non-negative")
    program, map_path = checked_inputs(program, map_path)
    scenario = compile_program(program, {**map_params(map_path), "render": False, **(params or {})})
    runner = _Runner(
        scenario,
        _simulator(scenario, program),
        program,
        MapSource(str(map_path.absolute()), "opendrive"),
        steps,
        seed,
        max_iterations,
    )
    return (runner.run(k) if noise is None else add_noise(runner.run(k), noise, k) for k in range(runs))


def _simulator(scenario: Any, program: Path) -> Any:
    """The scenario's simulator, which must be Scenic's Newtonian one."""
    from scenic.simulators.newtonian import NewtonianSimulator

    simulator = None if scenario.simulator is None else scenario.getSimulator()
    if not isinstance(simulator, NewtonianSimulator):
        raise UserError(f"the program must use the Newtonian driving model: model {NEWTONIAN_MODEL}", at(program))
    return simulator


@dataclass(frozen=True)
class _Runner:
    """A compiled program with its simulator and the settings shared by all runs."""

    scenario: Any
    simulator: Any
    program: Path
    map_source: MapSource
    steps: int
    seed: int
    max_iterations: int

    def run(self, run: int) -> LabelTrace:
        """Run number ``run``: scenes sampled and simulated until a simulation is not rejected."""
        this_seed = run_seed(self.seed, run)
        rejected_scenes = 0
        with scenic_errors(self.program):
            seed_scenic(this_seed)
            for attempt in range(self.max_iterations):
                scene, iterations = self.scenario.generate(maxIterations=MAX_SCENE_ITERATIONS, verbosity=0)
                rejected_scenes += iterations - 1
                recorder = _Recorder(scene.egoObject)
                with observe_steps(recorder.observe):
                    simulation = self.simulator.simulate(scene, maxSteps=self.steps, maxIterations=1, verbosity=0)
                if simulation is not None:
                    attributes = {
                        "program": self.program.name,
                        "seed": self.seed,
                        "run": run,
                        "run_seed": this_seed,
                        "steps": self.steps,
                        "timestep": simulation.timestep,
                        "scenic_version": scenic_version(),
                        "rejected_scenes": rejected_scenes,
                        "rejected_simulations": attempt,
                        "termination": str(simulation.result.terminationReason),
                    }
                    return recorder.trace(f"{self.program.stem}-{run:03d}", attributes, self.map_source, self.program)
        raise UserError(f"Scenic rejected all {self.max_iterations} simulations of run {run}", at(self.program))


@dataclass
class _Recorder:
    """What one simulation showed at every step: object states, lanes and behaviour stacks."""

    ego: Any
    timestep: float = 0.0
    objects: list[Any] = field(default_factory=list)
    rows: dict[int, int] = field(default_factory=dict)
    values: list[tuple[float, ...]] = field(default_factory=list)
    lanes: list[str | None] = field(default_factory=list)
    stacks: list[tuple[str, ...]] = field(default_factory=list)

    def observe(self, simulation: Any) -> None:
        """Record the state of every object of ``simulation`` at its current step."""
        self.timestep = simulation.timestep
        for obj in simulation.objects:
            row = self.rows.setdefault(id(obj), len(self.objects))
            if row == len(self.objects):
                self.objects.append(obj)
            p, v = obj.position, obj.velocity
            self.values.append(
                (simulation.currentTime, row, p.x, p.y, obj.heading, v.x, v.y, obj.length, obj.width, obj.height)
            )
            lane = getattr(obj, "_lane", None)
            self.lanes.append(None if lane is None else lane.uid)
            self.stacks.append(behaviour_stack(obj))

    def trace(self, name: str, attributes: dict[str, Any], source: MapSource, program: Path) -> LabelTrace:
        """The recorded simulation as a trace."""
        if not self.values:
            raise UserError("the simulation ended before its first step", at(program))
        ids = self._ids(program)
        step, obj, x, y, heading, vx, vy, length, width, height = np.array(self.values, dtype=np.float64).T
        lane_ids = tuple(dict.fromkeys(uid for uid in self.lanes if uid is not None))
        lane_code = {uid: k for k, uid in enumerate(lane_ids)}
        states = StateTable.build(
            step,
            obj,
            x,
            y,
            scenic_headings(heading),
            length=length,
            width=width,
            height=height,
            vx=vx,
            vy=vy,
            lane=[lane_code.get(uid, -1) for uid in self.lanes],
        )
        frames = np.arange(int(step.max()) + 1)
        attributes["behaviour_stacks"] = self._stack_changes(ids, states)
        return LabelTrace.build(
            name,
            frames,
            frames * self.timestep,
            ObjectTable.build(ids, [type(o).__name__ for o in self.objects]),
            states,
            lane_ids=lane_ids,
            behaviours=BehaviourLabels.from_sets([{primitive_label(s)} for s in self.stacks]),
            ego="ego" if self.ego is not None else None,
            attributes=attributes,
            map_source=source,
        )

    def _ids(self, program: Path) -> list[str]:
        """Object ids: ``ego``, the Scenic name, or ``objK`` (see the module docstring)."""
        ids, others = [], 0
        for obj in self.objects:
            if obj is self.ego:
                ids.append("ego")
                continue
            others += 1
            name = getattr(obj, "name", None)
            ids.append(f"obj{others}" if name is None else str(name))
        duplicates = sorted({i for i in ids if ids.count(i) > 1})
        if duplicates:
            raise UserError(f"several objects are named {duplicates[0]!r}; object names must be unique", at(program))
        return ids

    def _stack_changes(self, ids: list[str], states: StateTable) -> dict[str, list[list[Any]]]:
        """Per object id, ``[step, [behaviour, ...]]`` at its first step and wherever its stack changes."""
        changes: dict[str, list[list[Any]]] = {i: [] for i in ids}
        for step, row, stack in zip(states.frame.tolist(), states.object.tolist(), self.stacks):
            history = changes[ids[row]]
            if not history or history[-1][1] != list(stack):
                history.append([step, list(stack)])
        return changes
