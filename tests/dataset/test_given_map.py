"""``--map``: the road map of traces without one, in ingest, the query commands and label; a trace
with its own map and a ``--map`` is an error for that trace, never a silent choice."""

import shutil
from dataclasses import replace

import pytest

from scenegrep.cli.main import main
from scenegrep.dataset import open_dataset
from scenegrep.readers import read_trace
from scenegrep.writers.trace_json import write_trace_json
from tests.conftest import REPO

SAMPLE = REPO / "examples" / "sample"
FIG3 = str(REPO / "examples" / "scenes" / "fig3_car_ahead.scenic")
TOLERANCES = ["--tolerance-position", "0.5", "--tolerance-heading", "0.1"]


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """Frames 25-34 of a sample trace twice: ``own.json`` naming its map beside it, ``bare.json``
    naming none; and the map."""
    root = tmp_path_factory.mktemp("given")
    shutil.copy(SAMPLE / "Town06.xodr", root)
    trace = read_trace(SAMPLE / "fig1_lane_change-000.parquet").slice_frames(25, 35)
    write_trace_json(
        replace(trace, name="own", map_source=replace(trace.map_source, path=str(root / "Town06.xodr"))),
        root / "own.json",
    )
    write_trace_json(replace(trace, name="bare", map_source=None), root / "bare.json")
    return root


def lines(capsys):
    captured = capsys.readouterr()
    return captured.out.splitlines(), captured.err.splitlines()


def test_a_trace_without_a_map_takes_the_given_one_and_matches_as_with_its_own(folder, capsys):
    assert main(["scene", FIG3, str(folder / "own.json"), *TOLERANCES, "--no-values"]) == 0
    own, _ = lines(capsys)
    assert (
        main(
            ["scene", FIG3, str(folder / "bare.json"), "--map", str(folder / "Town06.xodr"), *TOLERANCES, "--no-values"]
        )
        == 0
    )
    bare, _ = lines(capsys)
    assert own and [line.replace("bare.json#bare", "own.json#own", 1) for line in bare] == own
    assert main(["scene", FIG3, str(folder / "bare.json"), *TOLERANCES]) == 2  # no map at all


def test_a_trace_with_its_own_map_and_a_given_one_is_an_error_for_that_trace(folder, capsys):
    town = str(folder / "Town06.xodr")
    assert main(["scene", FIG3, str(folder / "own.json"), "--map", town, *TOLERANCES]) == 2
    _, err = lines(capsys)
    assert err == [
        "scenegrep: error: trace 'own' has its own road map (Town06.xodr) and --map gives another; "
        "--map is for traces without a map: leave it out for this trace"
    ]
    code = main(["scene", FIG3, str(folder / "own.json"), str(folder / "bare.json"), "--map", town, *TOLERANCES])
    out, err = lines(capsys)
    assert code == 3 and out and all(line.startswith(f"{folder / 'bare.json'}#bare:") for line in out)
    assert err[0].startswith("scenegrep: failed: own: ") and "has its own road map" in err[0]
    assert main(["label", str(folder / "own.json"), "--map", town, "-o", str(folder / "labelled"), "-q"]) == 2


def test_a_given_map_must_be_a_map_file(folder, capsys):
    for bad in (folder / "bare.json", folder, folder / "missing.xodr"):
        assert main(["scene", FIG3, str(folder / "bare.json"), "--map", str(bad)]) == 2
        _, err = lines(capsys)
        assert len(err) == 1 and err[0].startswith("scenegrep: error: ")


def test_ingest_gives_traces_without_a_map_the_given_one_and_queries_over_the_dataset_read_it(folder, tmp_path, capsys):
    data = tmp_path / "data"
    data.mkdir()
    shutil.copy(folder / "bare.json", data)
    fleet = str(tmp_path / "fleet")
    assert main(["ingest", str(data), "--into", fleet, "-j", "1", "--map", str(folder / "Town06.xodr")]) == 0
    maps = open_dataset(fleet).sql("SELECT source_path FROM maps").column(0).to_pylist()
    assert maps == [str((folder / "Town06.xodr").resolve())]
    lines(capsys)
    assert main(["scene", FIG3, "--dataset", fleet, *TOLERANCES, "--no-values"]) == 0
    assert lines(capsys)[0]
    assert main(["scene", FIG3, "--dataset", fleet, "--map", str(folder / "Town06.xodr"), *TOLERANCES]) == 3
    assert "has its own road map" in "".join(lines(capsys)[1])
    # another --map makes the unchanged source new: its traces take the other map
    other = tmp_path / "Town06-copy.xodr"
    shutil.copy(folder / "Town06.xodr", other)
    other.write_bytes(other.read_bytes() + b"\n")
    assert main(["ingest", str(data), "--into", fleet, "-j", "1", "--map", str(other)]) == 0
    assert "1 source ingested (1 trace), 0 unchanged" in lines(capsys)[1][-1]
