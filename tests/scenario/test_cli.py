"""``scenegrep scenario``: outputs, options, exit codes, one-line errors, online mode."""

from __future__ import annotations

import io
import json
import sys

import pytest

from scenegrep.cli.main import main
from scenegrep.writers.trace_json import trace_document, write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet

from .worked_example import worked_map, worked_trace

FIG1 = "examples/queries/fig1_lane_change.scenic"


@pytest.fixture
def files(tmp_path):
    write_trace_json(worked_trace(), tmp_path / "table2.json")
    write_trace_json(
        worked_trace(["TurnLeft", "FollowLane", "LaneChange", "TurnLeft", "FollowLane"]), tmp_path / "tl.json"
    )
    write_map_parquet(worked_map(), tmp_path / "map.parquet")
    return tmp_path


def run(args, capsys):
    code = main(["scenario", *map(str, args)])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err.splitlines()


def test_match_line_names_window_and_correspondence(files, capsys):
    code, lines, err = run([FIG1, files / "table2.json", "--window", "5", "--map", files / "map.parquet"], capsys)
    assert code == 0
    assert lines == [f"{files / 'table2.json'}#table2:0-4  ego=car2  otherCar=car1"]
    assert err == ["scenegrep: 1 of 1 trace matches, 0 pruned, 0 failed"]


def test_no_match_exits_1_and_explains(files, capsys):
    args = [FIG1, files / "tl.json", "--window", "5", "--map", files / "map.parquet", "--explain"]
    code, lines, _ = run(args, capsys)
    assert code == 1
    assert lines[0].startswith(f"{files / 'tl.json'}#table2  no match: ") and "TurnLeft" in lines[0]


def test_json_and_explain_give_the_witness(files, capsys):
    args = [FIG1, files / "table2.json", "--window", "all", "--map", files / "map.parquet", "--json", "--explain"]
    code, lines, _ = run(args, capsys)
    record = json.loads(lines[0])
    assert code == 0 and record["start_frame"] == 0 and record["end_frame"] == 4
    assert record["correspondence"] == {"ego": "car2", "otherCar": "car1"}
    assert len([line for line in record["explanation"].splitlines() if line.startswith("step ")]) == 5


def test_window_in_seconds(files, capsys):
    code, lines, _ = run([FIG1, files / "table2.json", "--window", "2.5s", "--map", files / "map.parquet"], capsys)
    assert code == 0 and lines[0].endswith(":0-4  ego=car2  otherCar=car1")  # 0.5 s frames: 5 frames


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--window", "x"], "bad window 'x'"),
        (["--window", "0"], "at least one frame"),
        (["--window", "99"], None),
    ],
)
def test_window_errors(files, capsys, args, message):
    code, lines, err = run([FIG1, files / "table2.json", "--map", files / "map.parquet", *args], capsys)
    if message is None:
        assert code == 1 and lines == []
    else:
        assert code == 2 and len(err) == 1 and message in err[0]


def test_unsupported_construct_is_one_line_with_place(files, tmp_path, capsys):
    program = tmp_path / "bad.scenic"
    program.write_text("behavior B():\n    do Turn() until self.height > 3\n\nego = new Car with behavior B()\n")
    code, _, err = run([program, files / "table2.json", "--window", "5"], capsys)
    assert code == 2 and "Traceback" not in "\n".join(err)
    assert err[0].startswith(f"scenegrep: error: {program}:2:21: ") and "height" in err[0]


def test_online_reports_the_windows_of_the_offline_query(files, capsys, monkeypatch):
    """Frames pushed one at a time give the windows an offline --all run gives, in order."""
    trace = worked_trace()
    _, offline, _ = run([FIG1, files / "table2.json", "--window", "3", "--map", files / "map.parquet", "--all"], capsys)
    lines = [json.dumps(trace_document(trace.slice_frames(k, k + 1))) for k in range(trace.n_frames)]
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO("\n".join(lines).encode())))
    code, online, _ = run([FIG1, "--online", "--window", "3", "--map", files / "map.parquet", "--all"], capsys)
    assert code == 0 and len(online) == 3
    assert [line.split(":", 1)[1] for line in online] == [line.rsplit(":", 1)[1] for line in offline]


@pytest.mark.real_data
def test_online_counts_the_unknown_layer_decisions_of_the_offline_labeller(real_data, capsys, monkeypatch):
    """nuScenes scene-0061 (its map publishes no crosswalks), 40 unlabelled frames in chunks of 10:
    the decisions the permissive choice affected, on stderr, are the offline labeller's (each
    observation once, though the online labeller relabels its kept history at every chunk)."""
    from dataclasses import replace

    from scenegrep import readers
    from scenegrep.label import label_trace
    from scenegrep.model.layers import UnknownLayers

    trace = readers.read_trace(real_data / "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl")
    trace = replace(trace.slice_frames(0, 40), behaviours=None)
    offline = UnknownLayers("permissive")
    label_trace(trace, readers.read_map(trace.map_source), unknown_layers=offline)
    assert offline.decisions["crossing"] > 0
    lines = [json.dumps(trace_document(trace.slice_frames(k, k + 10))) for k in range(0, 40, 10)]
    monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(io.BytesIO("\n".join(lines).encode())))
    query = "examples/queries/real/stationary_vehicle.scenic"
    args = [query, "--online", "--window", "10", "--map", trace.map_source.path, "--unknown-layers", "permissive"]
    _, _, err = run(args, capsys)
    assert f"scenegrep: {offline.report()}" in err
