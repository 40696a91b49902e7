"""The results table's ``objects`` column: for every match, each program object's labeled id and
the frames (inclusive) and times in which it is involved, in every output, and tables written
before the column still read."""

from __future__ import annotations

import json

import pyarrow.parquet as pq
import pytest

from scenegrep.cli.main import main
from scenegrep.dataset import QuerySpec
from scenegrep.dataset.files import query_files
from scenegrep.dataset.results import Results
from tests.conftest import REPO

from .conftest import SAMPLE

SPECS = {
    "scene": lambda: QuerySpec.from_file(
        "scene", REPO / "examples/scenes/fig3_car_ahead.scenic", tolerance_position=0.5, tolerance_heading=0.1
    ),
    "scenario": lambda: QuerySpec.from_file(
        "scenario", REPO / "examples/queries/s1_lane_change_stationary_car.scenic", window=75, unknown_layers="strict"
    ),
    "spre": lambda: QuerySpec.of("spre", "E(c := [:car:]) ([@x(c) > 300][@x(c) > 300])"),
}


@pytest.mark.parametrize("kind", list(SPECS))
def test_every_match_names_each_objects_id_frames_and_times(kind):
    results = query_files([str(SAMPLE)], SPECS[kind]())
    matches = results.matches.to_pylist()
    assert matches, "the sample has matches of each query"
    for row in matches:
        correspondence = json.loads(row["correspondence"])
        objects = json.loads(row["objects"])
        assert set(objects) == set(correspondence) and objects
        for name, found in objects.items():
            # scenario windows hold every object in each frame, a scene match is one frame, a
            # top-level track binder holds its object over the whole match
            assert found == {
                "id": correspondence[name],
                "start_frame": row["start_frame"],
                "end_frame": row["end_frame"],
                "start_time": row["start_time"],
                "end_time": row["end_time"],
            }
        if kind == "scene":
            assert row["start_frame"] == row["end_frame"]
    for row in results.table.to_pylist():
        if row["status"] != "match":
            assert row["objects"] is None


def test_the_column_travels_through_json_csv_and_parquet(tmp_path, capsys):
    code = main(["spre", "E(c := [:car:]) ([@x(c) > 300][@x(c) > 300])", str(SAMPLE), "--json"])
    out = capsys.readouterr().out
    assert code == 0
    rows = [json.loads(line) for line in out.splitlines()]
    assert all(isinstance(r["objects"], dict) for r in rows if r["status"] == "match")
    (tmp_path / "r.json").write_text(out)
    from_json = Results.read(tmp_path / "r.json")
    assert main(["spre", "E(c := [:car:]) ([@x(c) > 300][@x(c) > 300])", str(SAMPLE), "--csv"]) == 0
    (tmp_path / "r.csv").write_text(capsys.readouterr().out)
    assert Results.read(tmp_path / "r.csv").table.equals(from_json.table)
    assert (
        main(
            [
                "spre",
                "E(c := [:car:]) ([@x(c) > 300][@x(c) > 300])",
                str(SAMPLE),
                "--output",
                str(tmp_path / "r.parquet"),
            ]
        )
        == 0
    )
    assert Results.read(tmp_path / "r.parquet").table.equals(from_json.table)


def test_a_table_written_before_the_column_reads_and_exports(tmp_path, capsys):
    results = query_files([str(SAMPLE)], SPECS["scene"]())
    results.write_parquet(tmp_path / "new.parquet")
    old = pq.read_table(tmp_path / "new.parquet").drop_columns(["objects"])
    pq.write_table(old, tmp_path / "old.parquet")
    again = Results.read(tmp_path / "old.parquet")
    assert again.table["objects"].null_count == again.table.num_rows
    assert main(["export", str(tmp_path / "old.parquet"), "--mcap", str(tmp_path / "m.mcap"), "-q"]) == 0
