"""The sample dataset shipped in examples/sample: it loads, its maps resolve inside the
repository, and each program's traces show the behaviours its header promises."""

import json
import shutil
from pathlib import Path

import pytest

from scenegrep.readers import read_trace
from tests.conftest import REPO

SAMPLE = REPO / "examples" / "sample"
MAPS = SAMPLE
EGO_BEHAVIOURS = {
    "fig1_lane_change": ["FollowLane", "LaneChange", "FollowLane"],
    "s1_lane_change_stationary_car": ["FollowLane", "LaneChange", "FollowLane"],
    "s2_unprotected_left_turn": ["Stationary", "FollowTrajectory", "Turn", "FollowTrajectory"],
    "s3_pass_pedestrian": ["FollowLane"],
    "s4_yield_right_turn": ["FollowLane", "Stationary", "FollowTrajectory", "Turn", "FollowTrajectory"],
    "bg1_following_traffic": ["FollowLane"],
    "bg2_standing_pedestrian": ["FollowLane"],
}
FILES = sorted(SAMPLE.glob("*.parquet"))


def test_every_program_has_six_traces_and_the_manifest_lists_them():
    assert len(FILES) == 6 * len(EGO_BEHAVIOURS)
    assert {f.name.rsplit("-", 1)[0] for f in FILES} == set(EGO_BEHAVIOURS)
    manifest = json.loads((SAMPLE / "manifest.json").read_text())
    assert [e["file"] for e in manifest["traces"]] == [f.name for f in FILES]
    for entry in manifest["traces"]:
        assert (SAMPLE / entry["program"]).is_file() and (SAMPLE / entry["map"]).parent.resolve() == MAPS.resolve()
    assert sum(f.stat().st_size for f in FILES) < 3_000_000


@pytest.mark.parametrize("path", FILES, ids=[f.stem for f in FILES])
def test_trace_loads_with_labels_and_a_map_in_the_repository(path):
    trace = read_trace(path)
    assert trace.ego == "ego" and trace.n_frames == 150 and trace.present().all()
    assert trace.behaviours is not None and trace.behaviours.member.sum(axis=1).min() == 1
    map_path = Path(trace.map_source.path)
    assert trace.map_source.format == "opendrive" and map_path.is_file() and map_path.parent.resolve() == MAPS.resolve()
    header = (REPO / "examples" / "scenarios" / trace.attributes["program"]).read_text()
    assert f"# Map: {map_path.stem} " in header
    labels = [sorted(trace.behaviours.sets()[i])[0] for i in (trace.states.object == 0).nonzero()[0]]
    ego_runs = [v for k, v in enumerate(labels) if k == 0 or v != labels[k - 1]]
    assert ego_runs == EGO_BEHAVIOURS[path.stem.rsplit("-", 1)[0]]


def test_the_sample_folder_copied_anywhere_ingests_all_42_traces_with_its_maps(tmp_path, capsys):
    """Relocatable: each trace names a map beside it, so a copy of the folder is self-contained."""
    from scenegrep.cli.main import main
    from scenegrep.dataset import open_dataset

    copy = tmp_path / "elsewhere" / "sample"
    shutil.copytree(SAMPLE, copy)
    assert main(["ingest", str(copy), "--into", str(tmp_path / "fleet"), "-j", "1"]) == 0
    assert "42 sources ingested (42 traces), 0 unchanged, 0 failed" in capsys.readouterr().err
    maps = open_dataset(tmp_path / "fleet").sql("SELECT source_path FROM maps").column(0).to_pylist()
    assert sorted(Path(m).name for m in maps) == ["Town01.xodr", "Town06.xodr"]
    assert all(Path(m).parent == copy.resolve() for m in maps)
