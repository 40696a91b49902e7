"""One execution path: a query over files runs the dataset engine's per-trace path and gives the
results table a dataset run gives; one bad file or trace fails alone (exit 3); one frame-range
convention in every output; the table a query over files writes opens in show, report, export."""

from __future__ import annotations

import csv
import io
import json
import shutil
import time
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from scenegrep.cli.main import main
from scenegrep.dataset.results import Results
from scenegrep.readers.trace_json import read_trace as read_json_trace
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet
from tests.conftest import REPO
from tests.scenario.worked_example import worked_map, worked_trace

from .conftest import SAMPLE

QUERIES = {
    "scene": [
        "scene",
        "examples/scenes/fig3_car_ahead.scenic",
        "--tolerance-position",
        "0.5",
        "--tolerance-heading",
        "0.1",
        "--unknown-layers",
        "strict",
    ],
    "scenario": [
        "scenario",
        "examples/queries/s1_lane_change_stationary_car.scenic",
        "--window",
        "75",
        "--unknown-layers",
        "strict",
    ],
    "spre": ["spre", "[[:pedestrian:]][[:bicycle:]]"],
}
FIG1 = "examples/queries/fig1_lane_change.scenic"


def run(argv: list, capsys) -> tuple[int, list[str], list[str]]:
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out.splitlines(), err.splitlines()


def same_tables(argv: list, paths: list, dataset: Path, folder: Path) -> Results:
    """The results of a query (``argv``: command, query, options) over the files ``paths`` and over
    ``dataset``, which ingested them, asserted equal (rows, columns, trace ids, statuses, pruning
    reasons, windows, correspondences, run id, query); outputs go to ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    files, dataset_results = folder / "files.parquet", folder / "dataset.parquet"
    command, query, *options = argv
    started = time.perf_counter()
    over_files = main([str(a) for a in [command, query, *paths, *options, "--output", files, "-q"]])
    middle = time.perf_counter()
    over_dataset = main([str(a) for a in [*argv, "--dataset", dataset, "--output", dataset_results, "-q"]])
    ended = time.perf_counter()
    a, b = Results.read(files), Results.read(dataset_results)
    assert over_files == over_dataset == 0
    assert a.table.column_names == b.table.column_names
    assert a.table.to_pylist() == b.table.to_pylist()
    assert a.run_id == b.run_id and a.query == b.query
    print(f"{a.table.num_rows} rows, {a.counts()}; files {middle - started:.1f} s, dataset {ended - middle:.1f} s")
    return a


@pytest.mark.slow
@pytest.mark.real_data
@pytest.mark.parametrize("kind", list(QUERIES))
def test_files_and_dataset_give_the_same_results_table(kind, real_data, real_dataset, tmp_path, capsys, monkeypatch):
    """Over all of ../shared/real_data and examples/sample: equal tables, with matches, in both modes."""
    monkeypatch.chdir(REPO)
    counts = same_tables(QUERIES[kind], [real_data, SAMPLE], real_dataset, tmp_path).counts()
    assert counts["traces"] == 62 and counts["matched"] > 0 and counts["failed"] == 0


CROSSING = """model scenic.simulators.newtonian.driving_model
ego = new Car with behavior AnyBehavior(), with roadDeviation Range(-180, 180) deg, with regionContainedIn everywhere
walker = new Pedestrian in everywhere, with behavior CrossBehavior(), with regionContainedIn everywhere
"""
"""A pedestrian the labeller labels Cross: nuScenes maps publish no crosswalks, so which of its
pedestrians are crossing depends on the choice for unknown map layers the labels were made under."""

CROSSING_RECORDINGS = (
    "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl",
    "av2/sensor/adcf7d18-0510-35b0-a2fa-b4cea13a6d76",
)


@pytest.mark.slow
@pytest.mark.real_data
@pytest.mark.parametrize(("ingested", "queried"), [("strict", "permissive"), ("permissive", "strict")])
def test_a_dataset_labelled_under_another_choice_gives_the_table_of_files(ingested, queried, real_data, tmp_path):
    """A scenario query whose choice for unknown map layers is not the ingest's labels the dataset's
    traces again under its own, as a query over files labels them: equal tables, under the query's
    choice and under the ingest's, and the two differ (nuScenes' Cross labels changed)."""
    from scenegrep.dataset.ingest import ingest

    paths = [real_data / name for name in CROSSING_RECORDINGS]
    dataset = tmp_path / "fleet"
    assert not ingest([str(p) for p in paths], dataset, jobs=1, unknown_layers=ingested).failed
    query = tmp_path / "crossing.scenic"
    query.write_text(CROSSING)
    argv = ["scenario", query, "--window", "1s", "--tolerance-heading", "0.2", "--tolerance-position", "0.5", "--all"]
    other = same_tables([*argv, "--unknown-layers", queried], paths, dataset, tmp_path / queried)
    same = same_tables([*argv, "--unknown-layers", ingested], paths, dataset, tmp_path / ingested)
    assert other.counts()["matched"] == same.counts()["matched"] == 2
    assert other.matches.num_rows != same.matches.num_rows


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """Three sample traces with their map beside them (as in examples/), a truncated trace file and
    a file of garbage among them."""
    traces = tmp_path / "traces"
    traces.mkdir()
    shutil.copy(SAMPLE / "Town06.xodr", traces)
    for number in (0, 1, 3):
        shutil.copy(SAMPLE / f"fig1_lane_change-00{number}.parquet", traces)
    (traces / "fig1_lane_change-002.parquet").write_bytes((SAMPLE / "fig1_lane_change-002.parquet").read_bytes()[:3000])
    (traces / "zz.parquet").write_bytes(b"garbage")
    return traces


def test_a_bad_file_in_a_folder_fails_alone(folder, capsys):
    code, lines, err = run(
        ["scenario", "examples/queries/s1_lane_change_stationary_car.scenic", folder, "--window", "75"], capsys
    )
    assert code == 3
    names = [f"fig1_lane_change-00{n}" for n in (0, 1, 3)]
    assert [line.rsplit(":", 1)[0] for line in lines] == [f"{folder}/{name}.parquet#{name}" for name in names]
    failed = [line for line in err if line.startswith("scenegrep: failed: ")]
    assert len(failed) == 2 and "fig1_lane_change-002.parquet" in failed[0] and "zz.parquet" in failed[1]
    assert "truncated or corrupt" in failed[0] and not any("Traceback" in line for line in err)
    assert err[-1] == "scenegrep: 3 of 5 traces match, 0 pruned, 2 failed"


def test_a_trace_whose_query_raises_fails_alone(folder, capsys, monkeypatch):
    """A bug while querying one trace (here: an exception planted in the scene matcher for one
    trace) fails that trace, with its type and message, and the later traces still run."""
    from scenegrep.scene.query import SceneQuery

    original = SceneQuery.match

    def match(self, trace, *args, **kwargs):
        if trace.name == "fig1_lane_change-001":
            raise RecursionError("planted")
        return original(self, trace, *args, **kwargs)

    monkeypatch.setattr(SceneQuery, "match", match)
    (folder / "fig1_lane_change-002.parquet").unlink()
    (folder / "zz.parquet").unlink()
    code, lines, err = run(["scene", "examples/scenes/fig3_car_ahead.scenic", folder, "--json"], capsys)
    rows = [json.loads(line) for line in lines]
    statuses = {r["name"]: r["status"] for r in rows}
    assert code == 3 and set(statuses) == {f"fig1_lane_change-00{n}" for n in (0, 1, 3)}
    assert statuses["fig1_lane_change-001"] == "failed"
    (failed,) = [r for r in rows if r["status"] == "failed"]
    assert failed["error"].endswith("fig1_lane_change-001.parquet: RecursionError: planted")
    assert any(line == f"scenegrep: failed: fig1_lane_change-001: {failed['error']}" for line in err)


def _spans(rows) -> list[tuple[int, int, float, float]]:
    """The frame-range columns of result rows (as text from CSV, or typed)."""
    return [(int(r["start_frame"]), int(r["end_frame"]), float(r["start_time"]), float(r["end_time"])) for r in rows]


@pytest.fixture
def shifted(tmp_path: Path) -> Path:
    """Seed 000's Table 2 trace without its first frame (frame indices 1..4 at 0.5..2 s, at
    positions 0..3), and its map."""
    trace = worked_trace()
    write_trace_json(trace.slice_frames(1, trace.n_frames), tmp_path / "shifted.json")
    write_map_parquet(worked_map(), tmp_path / "map.parquet")
    assert read_json_trace(tmp_path / "shifted.json").frame_index.tolist() == [1, 2, 3, 4]
    return tmp_path


def test_one_frame_convention_in_every_output(shifted, capsys):
    """``start_frame``/``end_frame`` are the dataset's frame indices of the first and last frame,
    ``start_time``/``end_time`` their times, in text, JSON, CSV and Parquet alike; a STREM stream's
    frames 10 and 20 are 10-20 (STREM's own 10..21 only with --compat strem)."""
    base = [FIG1, shifted / "shifted.json", "--window", "3", "--map", shifted / "map.parquet", "--all"]
    out = shifted / "out.parquet"
    code, text, _ = run(["scenario", *base, "--output", out], capsys)
    assert code == 0 and [line.split("  ")[0] for line in text] == [
        f"{shifted}/shifted.json#table2:{w}" for w in ("1-3", "2-4")
    ]
    expected = [(1, 3, 0.5, 1.5), (2, 4, 1.0, 2.0)]
    assert _spans(pq.read_table(out).to_pylist()) == expected
    assert _spans(map(json.loads, run(["scenario", *base, "--json"], capsys)[1])) == expected
    assert _spans(csv.DictReader(io.StringIO("\n".join(run(["scenario", *base, "--csv"], capsys)[1])))) == expected
    stream = REPO.parent / "shared" / "conformance" / "strem" / "data" / "noncontig.json"
    if stream.is_file():
        assert run(["spre", "[[:car:]]{2}", stream], capsys)[1] == [f"{stream}#noncontig:10-20"]
        (row,) = map(json.loads, run(["spre", "--json", "[[:car:]]{2}", stream], capsys)[1])
        assert (row["start_frame"], row["end_frame"]) == (10, 20)
        assert run(["spre", "--compat", "strem", "[[:car:]]{2}", stream], capsys)[1] == [f"{stream}:10..21"]


def test_results_of_a_query_over_files_open_in_show_report_and_export(folder, tmp_path, capsys, monkeypatch):
    """--output, --json and --csv of a query over files (no dataset) are read by show, report
    and export; the traces are read again from their files, the query from the Parquet file."""
    monkeypatch.chdir(REPO)
    for name in ("fig1_lane_change-002.parquet", "zz.parquet"):
        (folder / name).unlink()
    base = ["scenario", "examples/queries/s1_lane_change_stationary_car.scenic", str(folder), "--window", "75"]
    results = tmp_path / "results.parquet"
    assert main([*map(str, base), "--output", str(results), "-q"]) == 0
    for option, suffix in (("--json", ".json"), ("--csv", ".csv")):
        code, lines, _ = run([*base, option], capsys)
        assert code == 0
        (tmp_path / f"results{suffix}").write_text("".join(line + "\n" for line in lines))
        again = Results.read(tmp_path / f"results{suffix}")
        assert again.table.to_pylist() == Results.read(results).table.to_pylist()
        assert (
            main(["show", str(tmp_path / f"results{suffix}"), "--match", "1", "-o", str(tmp_path / "m.png"), "-q"]) == 0
        )
    assert main(["show", str(results), "--match", "2", "-o", str(tmp_path / "m.html"), "-q"]) == 0
    page = (tmp_path / "m.html").read_text()
    assert "fig1_lane_change-003" in page and "parkedCar" in page
    assert main(["report", str(results), "-o", str(tmp_path / "report.html")]) == 0
    report = (tmp_path / "report.html").read_text()
    assert 'data-count="matches"><b>3</b>' in report and "parkedCar" in report
    assert main(["export", str(results), "--mcap", str(tmp_path / "m.mcap"), "-q"]) == 0
    assert (tmp_path / "m.mcap").stat().st_size > 0


CROSSING_QUERY = (
    "model scenic.domains.driving.model\n"
    "ego = new Car on road, facing Range(-180, 180) deg, with regionContainedIn None\n"
    "ped = new Pedestrian in crossing, with regionContainedIn None\n"
)


def _unknown_layers_line(err: list[str]) -> list[str]:
    return [line for line in err if line.startswith("scenegrep: --unknown-layers")]


@pytest.fixture(scope="module")
def nuscenes_fleet(real_data, tmp_path_factory) -> Path:
    """The nuScenes recordings ingested unlabelled with two workers, once for the module (the
    queries below write only their own runs into it)."""
    from scenegrep.dataset.ingest import ingest

    fleet = tmp_path_factory.mktemp("nuscenes") / "fleet"
    assert not ingest([str(real_data / "nuscenes_mini_scenarionet")], fleet, jobs=2, label=False).failed
    return fleet


@pytest.mark.real_data
@pytest.mark.parametrize("mode", ["permissive", "strict"])
def test_dataset_workers_report_the_unknown_layer_decisions_of_files(mode, real_data, nuscenes_fleet, tmp_path, capsys):
    """The nuScenes recordings publish no crosswalks: a query that needs them reports on stderr how
    many decisions the choice affected; a dataset run whose workers (two processes) made them
    reports the same count as the query over the same files."""
    recordings = real_data / "nuscenes_mini_scenarionet"
    program = tmp_path / "crossing.scenic"
    program.write_text(CROSSING_QUERY)
    options = ["--unknown-layers", mode, "--no-values", "-q"]
    _, _, over_files = run(["scene", program, recordings, *options], capsys)
    _, _, over_dataset = run(["scene", program, *options, "--dataset", nuscenes_fleet, "-j", "2"], capsys)
    (line,) = _unknown_layers_line(over_files)
    assert line.endswith(f"; decisions affected: crossing {_pedestrian_states(recordings)}"), line
    assert _unknown_layers_line(over_dataset) == [line]


def _pedestrian_states(folder: Path) -> int:
    """The pedestrian states of the traces in ``folder``: each is one decision on the crossing layer."""
    return sum(_pedestrian_states_of(path) for path in sorted(folder.iterdir()))


def _pedestrian_states_of(path: Path) -> int:
    """The pedestrian states of the trace in the file ``path``."""
    from scenegrep import readers

    trace = readers.read_trace(path)
    return int((trace.objects.kinds()[trace.states.object] == "pedestrian").sum())


@pytest.mark.real_data
def test_a_resumed_run_counts_the_decisions_of_the_parts_it_keeps(real_data, tmp_path):
    """Each part keeps its chunk's count: a run resumed after losing one part counts what the
    whole run counted, not only the traces it queried again."""
    from scenegrep.dataset import QuerySpec
    from scenegrep.dataset.ingest import ingest
    from scenegrep.dataset.run import RunOptions, run_query

    recordings = sorted((real_data / "nuscenes_mini_scenarionet").iterdir())[:3]
    root = tmp_path / "fleet"
    assert not ingest([str(p) for p in recordings], root, jobs=1, label=False).failed
    spec = QuerySpec.of("scene", CROSSING_QUERY, unknown_layers="strict", values=False)
    whole = run_query(root, spec, RunOptions(jobs=3))
    parts = sorted((root / "runs" / whole.run_id / "parts").glob("*.parquet"))
    assert len(parts) == 3
    parts[0].unlink()
    resumed = run_query(root, spec, RunOptions(jobs=1, resume=True))
    assert whole.assumed == resumed.assumed == {"crossing": sum(_pedestrian_states_of(p) for p in recordings)}
