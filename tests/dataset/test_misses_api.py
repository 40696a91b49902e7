"""Nearest misses through the Python API (:func:`scenegrep.dataset.misses.misses_of_results`):
over files and over a dataset the same trace gives the same miss, and a trace that no longer
loads is counted as not examined."""

from __future__ import annotations

import pytest

from scenegrep.dataset import Dataset, QuerySpec
from scenegrep.dataset.files import query_files
from scenegrep.dataset.misses import misses_of_results
from scenegrep.writers.trace_parquet import write_trace_parquet
from tests.scene.frames import HEADER, trace_of

PROGRAM = HEADER + "ego = new Car at (2, 30), facing 0.3, with regionContainedIn None\n"
DX = 0.25
"""The ego stands this far (m, along x) from where the program puts it: the nearest miss's position."""


@pytest.fixture(scope="module")
def trace_file(tmp_path_factory):
    return str(
        write_trace_parquet(trace_of({"ego": ("Car", 2 + DX, 30, 0.3)}), tmp_path_factory.mktemp("t") / "t.parquet")
    )


def test_the_same_miss_over_files_and_over_a_dataset(trace_file, tmp_path):
    spec = QuerySpec.of("scene", PROGRAM)
    over_files = query_files([trace_file], spec)
    assert over_files.counts()["matched"] == 0
    from_files = misses_of_results(spec, over_files)
    (miss,) = from_files.found
    (position,) = [s for s in miss.needed if s.name == "position"]
    assert position.value == pytest.approx(DX, rel=1e-3)
    dataset = Dataset(tmp_path / "ds")
    dataset.ingest([trace_file], jobs=1, label=False)
    over_dataset = dataset.query("scene", PROGRAM)
    (again,) = misses_of_results(spec, over_dataset, dataset.path).found
    assert again.text().split(":", 1)[1] == miss.text().split(":", 1)[1]  # all but the trace's name


def test_a_trace_gone_from_the_dataset_is_not_examined(trace_file, tmp_path):
    spec = QuerySpec.of("scene", PROGRAM)
    results = query_files([trace_file], spec)
    empty = Dataset(tmp_path / "empty")
    empty.ingest([], jobs=1)
    misses = misses_of_results(spec, results, empty.path)
    assert not misses.found and misses.skipped == 1
