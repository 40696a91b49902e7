"""The Arrow/Parquet layout of traces and maps: lossless round trips."""

import os
from dataclasses import replace

import pyarrow.parquet as pq
from hypothesis import HealthCheck, given, settings

from scenegrep.model.trace_arrow import KINDS, trace_from_table, trace_to_table
from scenegrep.readers.trace_parquet import read_trace
from scenegrep.writers.trace_parquet import write_trace_parquet
from tests.strategies import label_traces


@given(label_traces())
def test_table_round_trip(trace):
    assert trace_from_table(trace_to_table(trace)).equals(trace)


@settings(max_examples=25, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(label_traces())
def test_parquet_round_trip(tmp_path, trace):
    """Lossless, except that a relative map path comes back as the same file seen from here
    (it is stored relative to the trace's folder)."""
    path = write_trace_parquet(trace, tmp_path / "t.parquet")
    back = read_trace(path)
    if trace.map_source is not None:
        assert back.map_source.path == os.path.abspath(trace.map_source.path)
        back = replace(back, map_source=trace.map_source)
    assert back.equals(trace)


@given(label_traces())
def test_every_frame_has_a_row_and_kinds_are_known(trace):
    table = trace_to_table(trace)
    assert set(table.column("position").to_pylist()) == set(range(trace.n_frames))
    assert set(table.column("kind").to_pylist()) <= set(KINDS)
    positions = table.column("position").to_pylist()
    assert positions == sorted(positions)


def test_file_is_plain_sql_friendly_parquet(tmp_path):
    from tests.model.test_trace import small_trace

    path = write_trace_parquet(small_trace(), tmp_path / "t.parquet")
    table = pq.read_table(path, columns=["kind", "frame", "object", "x"])
    assert table.column("frame").to_pylist() == [10, 10, 11, 12]
    assert table.column("object").to_pylist() == ["a", "b", "a", "a"]
