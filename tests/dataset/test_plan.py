"""The planner prunes only traces that cannot match: kind groups against a brute-force search
for a correspondence, SpRE class requirements against the SpRE engine's matches."""

from __future__ import annotations

import itertools
from types import SimpleNamespace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.dataset.catalog import Catalog
from scenegrep.dataset.plan import KindGroup, Needs, TracePlanner, kind_groups, plan
from scenegrep.dataset.statistics import TraceStatistics
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from scenegrep.model.taxonomy import kind_of
from scenegrep.spre import TraceSearch, compile_query
from scenegrep.spre.requirements import required_classes

CATEGORIES = ("car", "vehicle.truck", "pedestrian", "bus")
KIND_SETS = (None, frozenset({"car"}), frozenset({"car", "truck"}), frozenset({"pedestrian"}))


@st.composite
def traces(draw) -> LabelTrace:
    n_frames, n_objects = draw(st.integers(1, 7)), draw(st.integers(0, 4))
    present = draw(st.lists(st.booleans(), min_size=n_frames * n_objects, max_size=n_frames * n_objects))
    cells = [(f, o) for f in range(n_frames) for o in range(n_objects) if present[f * n_objects + o]]
    categories = [draw(st.sampled_from(CATEGORIES)) for _ in range(n_objects)]
    zeros = np.zeros(len(cells))
    states = StateTable.build([c[0] for c in cells], [c[1] for c in cells], zeros, zeros, zeros)
    frames = np.arange(n_frames)
    return LabelTrace.build(
        "t", frames, frames * 0.1, ObjectTable.build([f"o{i}" for i in range(n_objects)], categories), states
    )


def could_match(trace: LabelTrace, objects: list, m: int) -> bool:
    """Brute force: some window of m frames and injective assignment of objects present throughout."""
    present = trace.present()
    kinds = [kind_of(str(c)) for c in trace.objects.category]
    for start in range(trace.n_frames - m + 1):
        throughout = present[start : start + m].all(axis=0)
        for chosen in itertools.permutations(range(trace.n_objects), len(objects)):
            if all(throughout[r] and (o.kinds is None or kinds[r] in o.kinds) for r, o in zip(chosen, objects)):
                return True
    return False


@pytest.fixture(scope="module")
def catalog(tmp_path_factory):
    """One catalog for the module's examples (creating one takes 0.1 s): :func:`holding` puts each
    example's trace in it in place of the previous one."""
    with Catalog(tmp_path_factory.mktemp("plan"), create=True) as catalog:
        yield catalog


def holding(catalog: Catalog, trace: LabelTrace) -> Catalog:
    """``catalog`` with ``trace`` as its only trace (of the source ``s``, whose earlier traces it forgets)."""
    stats = TraceStatistics.of(trace)
    row = {"trace_id": "t", **stats.trace, "source_path": "s", "file": "f", "map_id": None}
    catalog.replace_sources([({"path": "s", "format": "x", "checksum": "c"}, [(row, stats)])])
    assert catalog.rows("SELECT count(*) FROM traces") == [(1,)]
    return catalog


@settings(max_examples=120)
@given(traces(), st.lists(st.sampled_from(KIND_SETS), min_size=1, max_size=3), st.integers(1, 4), st.data())
def test_kind_pruning_keeps_every_trace_that_could_match(catalog, trace, kind_sets, m, data):
    objects = [SimpleNamespace(kinds=k) for k in kind_sets]
    result = plan(holding(catalog, trace), Needs(kind_groups(objects), m))
    if could_match(trace, objects, m):
        assert result.kept and not result.pruned
    if not result.pruned:
        return
    assert "consecutive frame" in result.pruned[0][1]


@settings(max_examples=25, deadline=None)
@given(
    st.lists(traces(), min_size=1, max_size=3),
    st.lists(st.sampled_from(KIND_SETS), min_size=1, max_size=3),
    st.integers(1, 4),
    st.sampled_from([frozenset(), frozenset({"pedestrian"})]),
)
def test_the_trace_planner_gives_the_catalog_planners_reasons(catalog, sequence, kind_sets, m, classes):
    """A query over files plans trace after trace with one TracePlanner: each reason is the one
    plan() gives on a dataset's catalog holding that trace."""
    needs = Needs(kind_groups([SimpleNamespace(kinds=k) for k in kind_sets]), m, classes)
    with TracePlanner(needs) as planner:
        for trace in sequence:
            expected = plan(holding(catalog, trace), needs).pruned
            stats = TraceStatistics.of(trace)
            row = {"trace_id": "t", **stats.trace, "source_path": "s", "file": "f", "map_id": None}
            assert planner.prune_reason(row, stats) == (expected[0][1] if expected else None)


def test_kind_groups_drop_implied_groups():
    car, truck = SimpleNamespace(kinds=frozenset({"car"})), SimpleNamespace(kinds=frozenset({"car", "truck"}))
    ped = SimpleNamespace(kinds=frozenset({"pedestrian"}))
    assert kind_groups([car, car]) == (KindGroup(frozenset({"car"}), 2),)
    assert kind_groups([car, truck, ped]) == (
        KindGroup(frozenset({"car"}), 1),
        KindGroup(frozenset({"car", "truck"}), 2),
        KindGroup(frozenset({"pedestrian"}), 1),
        KindGroup(None, 3),
    )


@pytest.mark.parametrize(
    ("query", "required"),
    [
        ("[[:car:]]", {"car"}),
        ("[[:car:]]*", {"car"}),  # reported matches are never empty
        ("[[:car:]]*[[:bus:]]", {"bus"}),
        ("[[:car:]]+|[[:car:] & [:bus:]]", {"car"}),
        ("[NE([:car:] & [:pedestrian:])]+", {"car", "pedestrian"}),
        ("[[:car:]]?[[:bus:]]?", set()),
        ("([[:car:]][[:bus:]])?[[:truck:]]", {"truck"}),
        ("[![:car:]]", set()),
        ("[[:*:]][[:ego:]]", set()),
        (".[[:pedestrian:]]{2,3}", {"pedestrian"}),
    ],
)
def test_required_classes(query: str, required: set[str]):
    assert required_classes(compile_query(query).tree) == required


def _queries() -> st.SearchStrategy[str]:
    letters = st.sampled_from(
        ["[[:car:]]", "[[:pedestrian:]]", "[[:truck:]]", "[NE([:car:] & [:pedestrian:])]", "[![:car:]]", "."]
    )

    def extend(inner: st.SearchStrategy[str]) -> st.SearchStrategy[str]:
        return st.one_of(
            st.tuples(inner, inner).map(lambda p: p[0] + p[1]),
            st.tuples(inner, inner).map(lambda p: f"({p[0]}|{p[1]})"),
            st.tuples(inner, st.sampled_from(["*", "+", "?", "{2}", "{0,2}"])).map(lambda p: f"({p[0]}){p[1]}"),
        )

    return st.recursive(letters, extend, max_leaves=5)


@settings(max_examples=200)
@given(_queries(), traces())
def test_required_classes_hold_in_every_match(query: str, trace: LabelTrace):
    compiled = compile_query(query)
    required = required_classes(compiled.tree)
    categories = trace.objects.category.astype(str)
    for match in TraceSearch(compiled, trace).offline():
        window = trace.states.frame >= match.start
        window &= trace.states.frame < match.end
        seen = set()
        for row in set(trace.states.object[window].tolist()):
            seen |= {categories[row], kind_of(categories[row])}
        assert required <= seen, (query, match)
