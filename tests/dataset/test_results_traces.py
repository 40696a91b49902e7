"""dataset.results_traces.ResultsTraces: a results table with the traces it was computed on (what
``export`` reads; the views' ResultsSource adds drawing to it)."""

from __future__ import annotations

from pathlib import Path

import pytest

from scenegrep import readers
from scenegrep.dataset import QuerySpec
from scenegrep.dataset.files import query_files
from scenegrep.dataset.results_traces import ResultsTraces
from scenegrep.errors import UserError
from scenegrep.view.sources import ResultsSource

REPO = Path(__file__).resolve().parents[2]
TRACES = [str(REPO / f"examples/sample/s3_pass_pedestrian-00{k}.parquet") for k in (0, 1)]
QUERY = "[[:pedestrian:]]{5}"


@pytest.fixture(scope="module")
def results_file(tmp_path_factory) -> Path:
    spec = QuerySpec.of("spre", QUERY, "<query>", compat=False, space="topdown", channels=None, skip=0)
    path = tmp_path_factory.mktemp("results") / "r.parquet"
    query_files(TRACES, spec).write_parquet(path)
    return path


def test_results_over_files_read_each_trace_from_its_source(results_file):
    opened = ResultsTraces.open(results_file)
    assert opened.root is None and (opened.query.kind, opened.query.text) == ("spre", QUERY)
    assert len(opened.trace_ids()) == len(TRACES)
    for trace_id, path in zip(opened.trace_ids(), TRACES):
        read, expected = opened.trace(trace_id), readers.read_trace(path)
        assert (read.name, read.n_frames) == (expected.name, expected.n_frames)
        assert read.frame_time.tolist() == expected.frame_time.tolist()
        assert {row["trace_id"] for row in opened.rows_of(trace_id)} == {trace_id}
    with pytest.raises(UserError, match="the results have no trace 'nowhere'"):
        opened.trace("nowhere")
    matches = opened.results.matches.num_rows
    with pytest.raises(UserError, match=f"--match {matches}: the results have {matches} matches"):
        opened.match_row(matches)


def test_the_views_source_is_the_same_data(results_file):
    opened, viewed = ResultsTraces.open(results_file), ResultsSource.open(results_file)
    assert isinstance(viewed, ResultsSource) and viewed.query == opened.query
    assert viewed.matched_trace_ids() == opened.matched_trace_ids()
