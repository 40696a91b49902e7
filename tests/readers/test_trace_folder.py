"""A folder of trace files is one input: its trace files in name order, other files skipped."""

from __future__ import annotations

import pytest

from scenegrep.errors import UserError
from scenegrep.readers import detect_format, read_traces
from scenegrep.writers import write_trace_json, write_trace_parquet
from tests.label.tracks import trace_of

import numpy as np


def one_car(name: str):
    t = np.arange(5) * 0.1
    trace = trace_of(("car", np.full(5, 1.75), 10.0 * t, None))
    return trace.__class__.build(name, trace.frame_index, trace.frame_time, trace.objects, trace.states)


def test_reads_the_trace_files_in_name_order_and_skips_the_rest(tmp_path):
    write_trace_parquet(one_car("b"), tmp_path / "b.parquet")
    write_trace_json(one_car("a"), tmp_path / "a.json")
    (tmp_path / "manifest.json").write_text('{"version": 1, "frames": []}')
    (tmp_path / "README.md").write_text("not a trace")
    (tmp_path / "sub").mkdir()
    write_trace_parquet(one_car("c"), tmp_path / "sub" / "c.parquet")
    assert detect_format(tmp_path) == "trace-folder"
    assert [t.name for t in read_traces(tmp_path)] == ["a", "b"]


def test_a_folder_without_traces_is_a_user_error(tmp_path):
    (tmp_path / "README.md").write_text("nothing here")
    with pytest.raises(UserError, match="neither an Argoverse 2 log or scenario nor holds trace files"):
        detect_format(tmp_path)
