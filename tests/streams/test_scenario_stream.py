"""A scenario query over a live input (:mod:`scenegrep.streams.scenario`): its rows are the results
table's with the stream's identity, and the program objects no frame of the stream can be are
warned about once it has ended, with the words of a query over files (also on stderr, ``scenario
--online``)."""

from __future__ import annotations

import io
import json
import sys
from pathlib import Path

import pytest

from scenegrep.cli.main import main
from scenegrep.dataset import QuerySpec
from scenegrep.dataset.files import query_files
from scenegrep.dataset.queries import scenario_rows
from scenegrep.scenario import ScenarioOptions, load_scenario
from scenegrep.streams.scenario import ScenarioStream
from scenegrep.writers.trace_json import trace_document, write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet

from ..scenario.worked_example import worked_map, worked_trace

REPO = Path(__file__).resolve().parents[2]
FIG1 = str(REPO / "examples/queries/fig1_lane_change.scenic")
LORRY = "model scenic.simulators.newtonian.driving_model\nego = new Car with behavior AnyBehavior()\n" + (
    "lorry = new Truck with behavior AnyBehavior()\n"
)
"""A program with a truck: the worked example's trace has cars only."""


@pytest.fixture(scope="module")
def lorry(tmp_path_factory) -> str:
    path = tmp_path_factory.mktemp("lorry") / "lorry.scenic"
    path.write_text(LORRY)
    return str(path)


@pytest.fixture(scope="module")
def trace():
    return worked_trace()


def frames(trace):
    return [trace.slice_frames(k, k + 1) for k in range(trace.n_frames)]


def rows_of(stream: ScenarioStream, chunks) -> list[dict]:
    results = [result for per_chunk in stream.results(chunks) for result in per_chunk] + stream.final()
    return [row for result in results for row in stream.rows(result)]


def test_rows_are_the_offline_rows_with_the_streams_identity(trace):
    query, road_map, options = load_scenario(FIG1), worked_map(), ScenarioOptions(find_all=True)
    stream = ScenarioStream(query, 3, road_map, options, "-", find_all=True)
    online = rows_of(stream, frames(trace))
    offline = scenario_rows(query.match(trace, 3, road_map, options), True, False)
    assert len(online) == len(offline) == 3
    assert {(row["trace_id"], row["name"], row["source"]) for row in online} == {(trace.name, trace.name, "-")}
    keys = ("start_frame", "end_frame", "correspondence", "status")
    assert [[row[k] for k in keys] for row in online] == [[row[k] for k in keys] for row in offline]
    assert stream.warnings == []  # every program object has a kind the stream has


def test_a_program_object_no_frame_can_be_is_warned_about_as_over_files(trace, lorry, tmp_path):
    write_trace_json(trace, tmp_path / "t.json")
    write_map_parquet(worked_map(), tmp_path / "map.parquet")
    spec = QuerySpec.of("scenario", LORRY, lorry, window=3)
    over_files = query_files([str(tmp_path / "t.json")], spec, str(tmp_path / "map.parquet")).warnings
    assert len(over_files) == 1 and "'lorry'" in over_files[0]
    stream = ScenarioStream(load_scenario(lorry), 3, worked_map(), ScenarioOptions(), "-")
    assert stream.warnings == []  # nothing read yet: nothing is known
    assert rows_of(stream, frames(trace)) == []
    assert tuple(stream.warnings) == over_files


def test_scenario_online_warns_at_the_end(trace, lorry, tmp_path, capsys, monkeypatch):
    write_map_parquet(worked_map(), tmp_path / "map.parquet")
    documents = "".join(json.dumps(trace_document(chunk)) + "\n" for chunk in frames(trace))
    args = ["scenario", lorry, "--online", "--window", "3", "--map", str(tmp_path / "map.parquet")]
    for quiet in ([], ["-q"]):
        monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO(documents.encode())))
        assert main([*args, *quiet]) == 1
        out, err = capsys.readouterr()
        lorry_line = "scenegrep: warning: no trace searched has a truck object for Truck 'lorry' (kinds there: car)"
        assert out == "" and err.splitlines() == ([] if quiet else [lorry_line])
