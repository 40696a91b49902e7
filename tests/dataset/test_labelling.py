"""Which labels a scenario query over a dataset reads: ingest records the choice for unknown map
layers it labelled each trace under; a query under another choice labels the trace again (as a
query over files labels it), never a trace's own labels; the planner keeps a trace whose ingest
labels lack a behaviour the query's labels have."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import scenegrep.label
from scenegrep.dataset import QuerySpec, RunOptions
from scenegrep.dataset.catalog import Catalog
from scenegrep.dataset.files import query_files, read_queried_trace
from scenegrep.dataset.ingest import ingest
from scenegrep.dataset.labelling import COLUMN, NO_CHOICE, UNKNOWN, catalog_value, recorded_choice, relabels
from scenegrep.dataset.plan import needs_of, plan
from scenegrep.dataset.queries import compiled
from scenegrep.dataset.run import run_query
from scenegrep.label import VOCABULARY
from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.view.sources import ResultsSource

from .conftest import REPO, SAMPLE

S1 = REPO / "examples/queries/s1_lane_change_stationary_car.scenic"
CROSSING = """model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior CrossBehavior(), with regionContainedIn everywhere
"""
"""A pedestrian labelled Cross (on nuScenes, whose maps publish no crosswalks, as the choice says)."""


def labelled_trace(vocabulary: tuple[str, ...] | None) -> LabelTrace:
    """One object in two frames, labelled with the first name of ``vocabulary`` (None: no labels)."""
    states = StateTable.build([0, 1], [0, 0], np.zeros(2), np.zeros(2), np.zeros(2))
    labels = None if vocabulary is None else BehaviourLabels.from_sets([[vocabulary[0]]] * 2, vocabulary)
    return LabelTrace.build(
        "t", np.arange(2), np.arange(2) * 0.1, ObjectTable.build(["o"], ["car"]), states, behaviours=labels
    )


OWN = ("FollowLane",)


@pytest.mark.parametrize(
    ("recorded", "mode", "vocabulary", "again"),
    [
        (None, "permissive", OWN, False),  # its own labels
        (None, "permissive", VOCABULARY, False),  # its own labels, made by scenegrep label
        (None, "strict", None, True),  # no labels: a query labels it
        ("strict", "strict", VOCABULARY, False),
        ("strict", "permissive", VOCABULARY, True),
        ("permissive", None, VOCABULARY, True),
        (NO_CHOICE, None, VOCABULARY, False),
        (NO_CHOICE, "strict", VOCABULARY, True),
        (UNKNOWN, "strict", VOCABULARY, True),  # a catalog written before the column: the labeller's labels
        (UNKNOWN, "strict", OWN, False),  # ... or the trace's own
    ],
)
def test_which_traces_a_query_labels_again(recorded, mode, vocabulary, again):
    assert relabels(recorded, mode, labelled_trace(vocabulary)) is again


def test_no_choice_is_recorded_apart_from_no_labelling():
    assert recorded_choice(None) == NO_CHOICE and recorded_choice("strict") == "strict"


def test_a_catalog_written_before_the_column_reads_unknown(tmp_path: Path):
    """Opening an older catalog for writing adds the column; its rows read 'unknown'; a row read
    from a catalog that has no column at all (opened read-only) reads the same."""
    trace = labelled_trace(VOCABULARY)
    from scenegrep.dataset.ingest import catalog_row

    with Catalog(tmp_path, create=True) as catalog:
        catalog.replace_sources(
            [({"path": "s", "format": "x", "checksum": "c"}, [catalog_row(trace, "t", "s", "f", None)])]
        )
        catalog.db.execute(f"ALTER TABLE traces DROP COLUMN {COLUMN}")
    with Catalog(tmp_path, read_only=True) as catalog:
        (row,) = catalog.sql("SELECT * FROM traces").to_pylist()
    assert COLUMN not in row and catalog_value(row) == UNKNOWN
    with Catalog(tmp_path) as catalog:
        assert catalog.rows(f"SELECT {COLUMN} FROM traces") == [(UNKNOWN,)]


@pytest.mark.real_data
def test_ingest_records_the_choice_it_labelled_each_trace_under(real_dataset: Path):
    """The real dataset's recordings were labelled under 'strict'; the sample's traces came with
    their own labels (NULL)."""
    with Catalog(real_dataset, read_only=True) as catalog:
        found = dict(catalog.rows(f"SELECT source_path, {COLUMN} FROM traces"))
    sample = {path: choice for path, choice in found.items() if path.startswith(str(SAMPLE))}
    recordings = {path: choice for path, choice in found.items() if path not in sample}
    assert len(sample) == 42 and set(sample.values()) == {None}
    assert recordings and set(recordings.values()) == {"strict"}


@pytest.mark.real_data
def test_a_traces_own_labels_are_never_labelled_again(tmp_path: Path, monkeypatch):
    """Sample traces ingested under 'strict', queried under 'permissive': no trace is labelled, in
    either mode, and the tables are equal, with a match."""
    paths = [
        str(SAMPLE / "s1_lane_change_stationary_car-000.parquet"),
        str(SAMPLE / "bg1_following_traffic-000.parquet"),
    ]
    assert not ingest(paths, tmp_path, jobs=1, unknown_layers="strict").failed
    calls: list[str] = []
    monkeypatch.setattr(scenegrep.label, "label_trace", lambda trace, *a, **k: calls.append(trace.name))
    spec = QuerySpec.from_file("scenario", S1, window=75, unknown_layers="permissive")
    over_dataset = run_query(tmp_path, spec, RunOptions(jobs=1))
    over_files = query_files(paths, spec)
    assert calls == []
    assert over_dataset.table.to_pylist() == over_files.table.to_pylist()
    assert over_dataset.counts()["matched"] == 1 and over_dataset.counts()["failed"] == 0


@pytest.mark.slow
@pytest.mark.real_data
def test_the_planner_keeps_a_trace_whose_ingest_labels_lack_what_the_query_reads(real_data: Path, tmp_path: Path):
    """nuScenes scene-0757 labelled under 'strict' has no Cross label (no crosswalk published), under
    'permissive' it has some: a permissive query for a crossing pedestrian is not pruned on the
    ingest's label statistics, and matches; the views of its results show the labels it read."""
    source = real_data / "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0757.pkl"
    assert not ingest([str(source)], tmp_path, jobs=1, unknown_layers="strict").failed
    with Catalog(tmp_path, read_only=True) as catalog:
        assert catalog.rows("SELECT observations FROM labels WHERE label = 'Cross'") == [(0,)]
    query = tmp_path / "crossing.scenic"
    query.write_text(CROSSING)
    spec = QuerySpec.from_file("scenario", query, window="1s", tolerance_heading=0.2, unknown_layers="permissive")
    with Catalog(tmp_path) as catalog:
        planned = plan(catalog, needs_of(spec, compiled(spec)))
    assert [row["name"] for row in planned.kept] == ["scene-0757"] and planned.pruned == []
    results = run_query(tmp_path, spec, RunOptions(jobs=1))
    assert results.counts()["matched"] == 1
    trace_id = results.matches["trace_id"][0].as_py()
    shown = ResultsSource.of_run(tmp_path, results).load(trace_id)[0].behaviours
    queried = read_queried_trace(str(source.resolve()), trace_id, unknown_layers="permissive")[0].behaviours
    assert shown.vocabulary == queried.vocabulary and np.array_equal(shown.member, queried.member)
    assert shown.member[:, shown.vocabulary.index("Cross")].any()
