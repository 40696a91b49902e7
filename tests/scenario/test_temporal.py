"""Temporal requirements in scenario queries (issue 16): ``require always/eventually/next/until/implies``.

* Property: on random traces and random formulas over a few atomic comparisons, the windows a
  query finds (every correspondence, every start) are those of a brute-force evaluator written
  here: the initial scene by the scene query at the start, then the formula evaluated literally
  over the window (finite-trace LTL, strong next and until), per window; with the monitors' DFA
  and with the configuration-set fallback (state budget 2).
* The brute-force evaluator agrees with Scenic's own monitor library (rv_ltl, as Scenic 3.1.1
  runs it: a run is rejected when a verdict is definitely false at some step or falsy at the end).
* Per operator, hand-worked windows; errors are one line at the construct.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import rv_ltl
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.errors import UserError
from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.scenario import ScenarioOptions, compile_scenario
from scenegrep.scene import compile_scene
from scenegrep.scene.match import SceneOptions

from .worked_example import worked_map

MAP = worked_map()
HEADER = "model scenic.domains.driving.model\nego = new Car\nc = new Car\n"
ATOMS = {
    "ego.position.y > 0.5": lambda ego, c: ego[1] > 0.5,
    "c.position.y < -10.5": lambda ego, c: c[1] < -10.5,
    "(distance from ego to c) < 12.5": lambda ego, c: math.dist(ego, c) < 12.5,
    "c.position.x > -0.25": lambda ego, c: c[0] > -0.25,
}
UNARY = ("not", "always", "eventually", "next")


# ---------------------------------------------------------------------------- formulas
def formulas() -> st.SearchStrategy:
    """Formula trees: ("atom", text) | (unary op, f) | (binary op, f, g). Scenic's grammar takes
    only a non-temporal hypothesis for ``implies`` (else it reads ``always (...)`` as a call)."""
    atoms = st.sampled_from(sorted(ATOMS)).map(lambda text: ("atom", text))
    plain = st.recursive(
        atoms,
        lambda inner: st.one_of(
            st.tuples(st.just("not"), inner), st.tuples(st.sampled_from(("and", "or")), inner, inner)
        ),
        max_leaves=2,
    )
    return st.recursive(
        atoms,
        lambda inner: st.one_of(
            st.tuples(st.sampled_from(UNARY), inner),
            st.tuples(st.sampled_from(("and", "or", "until")), inner, inner),
            st.tuples(st.just("implies"), plain, inner),
        ),
        max_leaves=5,
    )


def render(f: tuple) -> str:
    """Scenic source of a formula, every operand parenthesised."""
    op = f[0]
    if op == "atom":
        return f"({f[1]})"
    if op in UNARY:
        return f"{op} ({render(f[1])})"
    return f"({render(f[1])}) {op} ({render(f[2])})"


def holds(f: tuple, values: dict[str, list[bool]], i: int, end: int) -> bool:
    """Whether ``f`` holds at frame i of the run of frames up to ``end`` (exclusive): finite-trace
    LTL, strong ``next`` (false at the last frame) and strong ``until``."""
    op = f[0]
    if op == "atom":
        return values[f[1]][i]
    if op == "not":
        return not holds(f[1], values, i, end)
    if op == "and":
        return holds(f[1], values, i, end) and holds(f[2], values, i, end)
    if op == "or":
        return holds(f[1], values, i, end) or holds(f[2], values, i, end)
    if op == "implies":
        return not holds(f[1], values, i, end) or holds(f[2], values, i, end)
    if op == "always":
        return all(holds(f[1], values, j, end) for j in range(i, end))
    if op == "eventually":
        return any(holds(f[1], values, j, end) for j in range(i, end))
    if op == "next":
        return i + 1 < end and holds(f[1], values, i + 1, end)
    return any(
        holds(f[2], values, k, end) and all(holds(f[1], values, j, end) for j in range(i, k)) for k in range(i, end)
    )


# ---------------------------------------------------------------------------- traces
def trace_of(positions: list[list[tuple[float, float]]], ids=("ego", "car1", "car2")) -> LabelTrace:
    """A trace of cars labelled Stationary; ``positions[frame][object]`` = (x, y)."""
    rows = [(f, k, x, y) for f, frame in enumerate(positions) for k, (x, y) in enumerate(frame)]
    frame, obj, x, y = (np.array(column, dtype=float) for column in zip(*rows))
    states = StateTable.build(
        frame=frame.astype(int), object=obj.astype(int), x=x, y=y, heading=np.zeros(len(rows)),
        length=np.full(len(rows), 4.5), width=np.full(len(rows), 2.0),
    )  # fmt: skip
    n = len(positions)
    return LabelTrace.build(
        "temporal", np.arange(n), np.arange(n) * 0.1, ObjectTable.build(list(ids), ["car"] * len(ids)), states,
        behaviours=BehaviourLabels.from_sets([{"Stationary"}] * len(rows)), ego="ego",
    )  # fmt: skip


@st.composite
def traces(draw) -> LabelTrace:
    n_frames = draw(st.integers(1, 8))
    ys = st.sampled_from([-30.0, -20.0, -12.0, -5.0, 0.0, 6.0, 14.0])
    xs = st.sampled_from([0.0, 0.0, -0.5])
    return trace_of([[(draw(xs), draw(ys) + k * 0.01) for k in range(3)] for _ in range(n_frames)])


def brute_force(query, f: tuple, trace: LabelTrace, m: int) -> set[tuple[str, int]]:
    """{(label object of c, start)} of every window where the initial scene holds and ``f`` holds
    over the window, by evaluating ``f`` at each start."""
    found = set()
    positions = {k: [] for k in range(trace.n_objects)}
    for obj, x, y in zip(trace.states.object, trace.states.x, trace.states.y):
        positions[int(obj)].append((float(x), float(y)))
    for row in (1, 2):
        label = str(trace.objects.id[row])
        values = {text: [test(e, c) for e, c in zip(positions[0], positions[row])] for text, test in ATOMS.items()}
        scene = query.scene.match(trace, MAP, SceneOptions(correspondence={"ego": "ego", "c": label})).matched
        found |= {(label, s) for s in range(trace.n_frames - m + 1) if scene[s] and holds(f, values, s, s + m)}
    return found


def answers(query, trace: LabelTrace, m: int) -> set[tuple[str, int]]:
    result = query.match(trace, m, MAP, ScenarioOptions(find_all=True))
    return {(match.correspondence["c"], first) for match, first, _ in result.windows()}


@settings(max_examples=120, deadline=None)
@given(formulas(), traces(), st.integers(1, 5))
def test_windows_equal_the_brute_force_evaluator(f, trace, m):
    program = f"{HEADER}require {render(f)}\n"
    query = compile_scenario(program, "random.scenic")
    expected = brute_force(query, f, trace, m)
    assert answers(query, trace, m) == expected
    fallback = compile_scenario(program, "random.scenic")
    fallback.state_budget = 2  # every monitor over budget: the configuration-set simulation
    assert answers(fallback, trace, m) == expected


def scenic_accepts(f: tuple, values: dict[str, list[bool]]) -> bool:
    """Scenic 3.1.1's verdict on a run: its monitor (rv_ltl) updated at every step, the run rejected
    as soon as the value is FALSE or when it ends on a falsy value (scenic/core/dynamics/scenarios.py)."""

    def build(g: tuple):
        op = g[0]
        if op == "atom":
            return atoms[g[1]]
        parts = [build(a) for a in g[1:]]
        return {
            "not": rv_ltl.Not, "always": rv_ltl.Always, "eventually": rv_ltl.Eventually, "next": rv_ltl.Next,
            "until": rv_ltl.Until, "implies": rv_ltl.Implies,
        }.get(op, lambda *p: (rv_ltl.And if op == "and" else rv_ltl.Or)(*p))(*parts)  # fmt: skip

    atoms = {text: rv_ltl.Atomic(identifier=text) for text in ATOMS}
    monitor = build(f).create_monitor()
    value = None
    for t in range(len(next(iter(values.values())))):
        monitor.update({text: values[text][t] for text in ATOMS})
        value = monitor.evaluate()
        if value == rv_ltl.B4.FALSE:
            return False
    return value.is_truthy


@settings(max_examples=400, deadline=None)
@given(formulas(), st.integers(1, 7), st.data())
def test_the_brute_force_evaluator_is_scenics_verdict(f, n, data):
    values = {text: data.draw(st.lists(st.booleans(), min_size=n, max_size=n), label=text) for text in ATOMS}
    assert holds(f, values, 0, n) == scenic_accepts(f, values)


# ---------------------------------------------------------------------------- per operator
EGO_Y = [-30, -20, 6, 14, -5, 0]  # ego.position.y > 0.5 at frames 2 and 3
UP, DOWN = "(ego.position.y > 0.5)", "(ego.position.y < 0.5)"
FAR = "(c.position.y < -10.5)"  # c at y -12 throughout: always true


@pytest.mark.parametrize(
    ("requirement", "m", "starts"),
    [
        (f"always {UP}", 1, [2, 3]),
        (f"always {UP}", 2, [2]),
        (f"always {UP}", 3, []),
        (f"eventually {UP}", 1, [2, 3]),
        (f"eventually {UP}", 3, [0, 1, 2, 3]),
        (f"{DOWN} until {UP}", 2, [1, 2, 3]),
        (f"{DOWN} until {UP}", 3, [0, 1, 2, 3]),
        (f"{UP} until {DOWN}", 3, [0, 1, 2, 3]),
        (f"next {UP}", 1, []),  # strong next: false at the last frame
        (f"next {UP}", 3, [1, 2]),
        (f"next (next {UP})", 3, [0, 1]),
        (f"not (next {UP})", 2, [0, 3, 4]),
        (f"{UP} implies (next {DOWN})", 2, [0, 1, 3, 4]),
        (f"(always {FAR}) and (eventually {UP})", 2, [1, 2, 3]),
        (f"(always {UP}) or (eventually (ego.position.y < -25))", 2, [0, 2]),
        (f"always ({UP} implies eventually {DOWN})", 6, [0]),
        (f"always ({UP} implies eventually {DOWN})", 3, [2, 3]),
    ],
)
def test_each_operator_on_a_worked_trace(requirement, m, starts):
    trace = trace_of([[(0.0, float(y)), (0.0, -12.0)] for y in EGO_Y], ids=("ego", "car1"))
    query = compile_scenario(f"{HEADER}require {requirement}\n", "worked.scenic")
    assert sorted(s for _, s in answers(query, trace, m)) == starts


def test_a_window_of_the_whole_run_is_the_run():
    trace = trace_of([[(0.0, float(y)), (0.0, -12.0)] for y in EGO_Y], ids=("ego", "car1"))
    query = compile_scenario(f"{HEADER}require eventually {UP}\nrequire always {FAR}\n", "run.scenic")
    assert query.match(trace, "all", MAP).matched
    assert (
        not compile_scenario(f"{HEADER}require eventually (ego.position.y > 20)\n", "r.scenic")
        .match(trace, "all", MAP)
        .matched
    )


def test_an_explanation_names_the_requirement_that_fails():
    trace = trace_of([[(0.0, float(y)), (0.0, -12.0)] for y in EGO_Y], ids=("ego", "car1"))
    result = compile_scenario(f"{HEADER}require always {UP}\n", "why.scenic").match(trace, 3, MAP)
    assert not result.matched
    assert f"require always {UP} (line 4) does not hold" in result.why_not()


@pytest.mark.parametrize(
    ("requirement", "message"),
    [
        ("require[0.5] always ego.position.y > 0", "4:1: a soft requirement (require[p]) cannot use temporal"),
        ("require always (distance to c) < Range(1, 5)", "4:16: a condition of a temporal requirement cannot read a"),
        (
            "require " + " and ".join(f"(always (c.position.y > {k}))" for k in range(25)),
            "4:1: a temporal requirement may have at most 24 conditions",
        ),
        # Scenic's grammar has temporal operators only in a requirement's propositions: elsewhere a call
        ("require (eventually (ego.position.y > 0)) + 1 > 0", "4:10: unknown or unsupported function 'eventually'"),
    ],
)
def test_unsupported_temporal_uses_are_one_line_errors(requirement, message):
    with pytest.raises(UserError) as caught:
        compile_scenario(f"{HEADER}{requirement}\n", "bad.scenic")
    line = caught.value.one_line()
    assert line.startswith(f"bad.scenic:{message}"), line


def test_scene_queries_refuse_temporal_requirements():
    with pytest.raises(UserError) as caught:
        compile_scene(f"{HEADER}require eventually ego.position.y > 0\n", "scene.scenic")
    assert caught.value.one_line().startswith("scene.scenic:4:9: temporal requirements need a scenario query")
