"""Queries over a dataset equal the same queries trace by trace; runs survive interruptions."""

from __future__ import annotations

import json
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from functools import cache
from pathlib import Path

import pyarrow.parquet as pq
import pytest

from scenegrep import readers
from scenegrep.dataset import QuerySpec, RunOptions, open_dataset
from scenegrep.dataset.catalog import Catalog
from scenegrep.dataset.results import Results
from scenegrep.dataset.run import run_query
from scenegrep.errors import UserError
from scenegrep.label import label_trace
from scenegrep.scenario import ScenarioOptions, load_scenario
from scenegrep.scene import SceneOptions, Tolerance, load_scene
from scenegrep.spre import TraceSearch, compile_query

from scenegrep.model.layers import UnknownLayers
from .conftest import REPO

pytestmark = pytest.mark.real_data

SCENARIO = REPO / "examples/queries/s1_lane_change_stationary_car.scenic"
SCENE = REPO / "examples/scenes/fig3_car_ahead.scenic"
SPRE = "[[:pedestrian:]][[:bicycle:]]"
TOLERANCE = {"tolerance_position": 0.5, "tolerance_heading": 0.1}
UNKNOWN = "strict"
"""Map layers a map does not publish (nuScenes' crosswalks, shoulders) taken as empty, as the
ingest of the ``real_dataset`` fixture labels them."""


def specs() -> dict[str, QuerySpec]:
    return {
        "scenario": QuerySpec.from_file("scenario", SCENARIO, window=75, unknown_layers=UNKNOWN),
        "scene": QuerySpec.from_file("scene", SCENE, **TOLERANCE, unknown_layers=UNKNOWN),
        "spre": QuerySpec.of("spre", SPRE),
    }


@cache
def one_by_one(kind: str, root: Path) -> dict[str, list[tuple]]:
    """Trace name -> its matches (first frame, last frame, correspondence), each source read and
    queried on its own with the query packages (no dataset engine); computed once per test process
    for each kind and dataset (the local pool and Ray are both checked against it)."""
    with Catalog(root, read_only=True) as catalog:
        sources = [s for (s,) in catalog.rows("SELECT path FROM sources ORDER BY path")]
    scenario, scene = load_scenario(SCENARIO), load_scene(SCENE)
    spre = compile_query(SPRE)
    found: dict[str, list[tuple]] = {}
    for source in sources:
        for trace in readers.read_traces(source):
            road_map = readers.read_map(trace.map_source) if trace.map_source else None
            if kind == "scenario":
                choice = UnknownLayers(UNKNOWN)
                trace = label_trace(trace, road_map, unknown_layers=choice).trace if trace.behaviours is None else trace
                result = scenario.match(trace, 75, road_map, ScenarioOptions(unknown_layers=choice))
                windows = [(m.correspondence, first, last) for m, first, last in result.windows()[:1]]
            elif kind == "scene":
                result = scene.match(
                    trace, road_map, SceneOptions(Tolerance(0.5, 0.1), unknown_layers=UnknownLayers(UNKNOWN))
                )
                windows = [(result.correspondence(f), f, f) for f in result.frames().tolist()]
            else:
                windows = [(m.bound or {}, m.start, m.end - 1) for m in TraceSearch(spre, trace).offline()]
            found[trace.name] = [
                (int(trace.frame_index[a]), int(trace.frame_index[b]), json.dumps(c, sort_keys=True))
                for c, a, b in windows
            ]
    return found


@pytest.fixture(scope="module")
def pooled(real_dataset: Path) -> Callable[[str], Results]:
    """The results of each kind's query over the real dataset on the local pool (two jobs), run
    once per module: several tests compare other runs with the same reference."""
    return cache(lambda kind: run_query(real_dataset, specs()[kind], RunOptions(jobs=2)))


def by_trace(results) -> dict[str, list[tuple]]:
    found: dict[str, list[tuple]] = {}
    for row in results.to_arrow().to_pylist():
        found.setdefault(row["name"], [])
        if row["status"] == "match":
            found[row["name"]].append((row["start_frame"], row["end_frame"], row["correspondence"]))
        else:
            assert row["status"] in ("no match", "pruned"), row
    return found


@pytest.mark.parametrize("kind", ["scenario", "scene", "spre"])
def test_local_pool_equals_trace_by_trace(real_dataset: Path, pooled, kind: str):
    results = pooled(kind)
    assert results.status == "finished"
    expected = one_by_one(kind, real_dataset)
    assert by_trace(results) == expected
    assert results.counts()["matched"] == sum(1 for m in expected.values() if m) > 0
    assert results.counts()["pruned"] > 0


def test_pruning_is_reported_with_reasons(real_dataset: Path):
    results = run_query(real_dataset, specs()["spre"], RunOptions(jobs=1))
    pruned = results.with_status("pruned").to_pylist()
    assert pruned and all(r["explanation"] == "no object or box of class 'bicycle'" for r in pruned)
    with Catalog(real_dataset, read_only=True) as catalog:
        for row in pruned:
            kinds = catalog.rows("SELECT DISTINCT kind FROM objects WHERE trace_id = ?", [row["trace_id"]])
            assert ("bicycle",) not in kinds


@pytest.mark.slow
def test_ray_equals_trace_by_trace(real_dataset: Path):
    ray = pytest.importorskip("ray")
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        for kind, spec in specs().items():
            results = run_query(real_dataset, spec, RunOptions(jobs=2, engine="ray"))
            assert by_trace(results) == one_by_one(kind, real_dataset), kind
    finally:
        ray.shutdown()


def cli(*args: str) -> list[str]:
    return [sys.executable, "-m", "scenegrep", *args]


def scenario_command(root: Path, *extra: str) -> list[str]:
    return cli(
        "scenario",
        str(SCENARIO),
        "--window",
        "75",
        "--dataset",
        str(root),
        "-j",
        "1",
        "--unknown-layers",
        UNKNOWN,
        *extra,
    )


def copy_of(real_dataset: Path, tmp_path: Path) -> Path:
    root = tmp_path / "ds"
    shutil.copytree(real_dataset, root, ignore=shutil.ignore_patterns("runs"))
    with Catalog(root) as catalog:
        catalog.rows("DELETE FROM runs")
        catalog.rows("DELETE FROM results")
    return root


def wait_for_part(root: Path, process: subprocess.Popen) -> None:
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and process.poll() is None:
        if any(root.glob("runs/*/parts/*.parquet")):
            return
        time.sleep(0.005)
    raise AssertionError("the run ended before it could be interrupted")


def final_results(root: Path):
    (path,) = root.glob("runs/*/results.parquet")
    return pq.read_table(path)


@pytest.mark.slow
@pytest.mark.parametrize("stop", [signal.SIGKILL, signal.SIGINT])
def test_an_interrupted_run_resumes_to_the_same_results(real_dataset: Path, pooled, tmp_path: Path, stop: int):
    root = copy_of(real_dataset, tmp_path)
    reference = pooled("scenario").to_arrow()
    process = subprocess.Popen(scenario_command(root, "-q"), stderr=subprocess.PIPE, text=True)
    wait_for_part(root, process)
    process.send_signal(stop)
    _, stderr = process.communicate()
    open_dataset(root).traces()
    with Catalog(root, read_only=True) as catalog:
        (status,) = catalog.rows("SELECT status FROM runs")[0]
    if stop == signal.SIGINT:
        assert process.returncode == 130 and "Traceback" not in stderr
        assert status == "interrupted"
        kept = final_results(root)
        assert 0 < kept.num_rows < reference.num_rows
    else:
        assert status == "running"
    assert subprocess.run(scenario_command(root, "-q", "--resume")).returncode == 0
    assert final_results(root).equals(reference)
    with Catalog(root, read_only=True) as catalog:
        assert catalog.rows("SELECT status, traces FROM runs") == [("finished", len(reference["trace_id"].unique()))]
        assert catalog.rows("SELECT count(*) FROM results")[0][0] == reference.num_rows


def test_a_trace_that_fails_is_recorded_and_the_run_goes_on(real_dataset: Path, tmp_path: Path):
    root = copy_of(real_dataset, tmp_path)
    victim = sorted((root / "traces").glob("fig1*.parquet"))[0]
    victim.write_bytes(b"not parquet")
    result = subprocess.run(scenario_command(root), capture_output=True, text=True)
    assert result.returncode == 3
    assert "Traceback" not in result.stderr
    (failed,) = [line for line in result.stderr.splitlines() if line.startswith("scenegrep: failed:")]
    assert str(victim) in failed
    table = final_results(root).to_pylist()
    assert [r["status"] for r in table if r["trace_id"] == victim.stem] == ["failed"]
    assert sum(r["status"] == "match" for r in table) == 11  # the 12 matches less the broken trace's


def in_process(argv: list[str], capsys) -> list[str]:
    """The standard output of ``cli(*args)`` run by the CLI's ``main`` in this process, which must
    return 0 (the tests of interruptions, failures and the terminal run the real process)."""
    from scenegrep.cli.main import main

    capsys.readouterr()
    assert main(argv[3:]) == 0
    return capsys.readouterr().out.splitlines()


def test_cli_outputs_and_the_catalog_agree(real_dataset: Path, tmp_path: Path, capsys):
    root = copy_of(real_dataset, tmp_path)
    lines = in_process(scenario_command(root), capsys)
    source = (REPO / "examples/sample/fig1_lane_change-000.parquet").resolve()  # as the catalog records it
    assert len(lines) == 12 and lines[0].startswith(f"{source}#fig1_lane_change-000:0-74  ego=ego")
    records = [json.loads(r) for r in in_process(scenario_command(root, "--json"), capsys)]
    assert len(records) == 62 and sum(r["status"] == "match" for r in records) == 12
    output = tmp_path / "out.parquet"
    csv = in_process(scenario_command(root, "--csv", "--output", str(output)), capsys)
    assert csv[0].startswith("trace_id,name,source,status")
    assert len(csv) == 63
    assert pq.read_table(output).equals(final_results(root))
    dataset = open_dataset(root)
    run_id = dataset.sql("SELECT run_id FROM runs").to_pylist()[0]["run_id"]
    assert dataset.sql(
        "SELECT count(*) AS n FROM results WHERE run_id = ? AND status = 'match'", [run_id]
    ).to_pylist() == [{"n": 12}]


def test_export_writes_each_match_as_a_foxglove_event(real_dataset: Path, tmp_path: Path):
    from mcap.reader import make_reader

    root = copy_of(real_dataset, tmp_path)
    subprocess.run(cli("spre", SPRE, "--dataset", str(root), "-q"), check=True)
    (run,) = (root / "runs").iterdir()
    out = tmp_path / "matches.mcap"
    assert subprocess.run(cli("export", str(run), "--mcap", str(out))).returncode == 0
    matches = final_results(root).to_pylist()
    matches = [r for r in matches if r["status"] == "match"]
    with open(out, "rb") as handle:
        reader = make_reader(handle)
        messages = list(reader.iter_messages())
    assert len(messages) == len(matches) > 0
    schema, channel, message = messages[0]
    assert (schema.name, channel.topic, channel.message_encoding) == ("foxglove.Event", "/scenegrep/matches", "json")

    def ns(time: dict) -> int:
        return time["sec"] * 10**9 + time["nsec"]

    events = [json.loads(m.data) for _, _, m in messages]
    assert all(m.log_time == ns(e["start_time"]) for (_, _, m), e in zip(messages, events))
    got = sorted((ns(e["start_time"]), ns(e["end_time"])) for e in events)
    expected = sorted(
        (r["time_origin_ns"] + round(r["start_time"] * 1e9), r["time_origin_ns"] + round(r["end_time"] * 1e9))
        for r in matches
    )
    assert got == expected
    first = {p["key"]: p["value"] for p in events[0]["metadata"]}
    assert {"trace", "trace_id", "frames", "run_id"} <= set(first)


def test_python_api_results_convert_to_pandas_polars_and_arrow(real_dataset: Path, tmp_path: Path):
    dataset = open_dataset(copy_of(real_dataset, tmp_path))
    results = dataset.spre(SPRE, run=RunOptions(jobs=1))
    frame = results.to_pandas()
    assert list(frame.columns) == results.to_arrow().column_names and len(frame) == len(results)
    assert results.to_polars().shape == (len(results), results.to_arrow().num_columns)
    assert {"match", "pruned"} <= set(frame["status"]) <= {"match", "no match", "pruned"}
    assert len(dataset.traces()) == 62


def test_user_errors_are_one_line(tmp_path: Path):
    result = subprocess.run(
        cli("spre", "[[:car:]]", "--dataset", str(tmp_path / "none")), capture_output=True, text=True
    )
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "not a scenegrep dataset" in result.stderr
    result = subprocess.run(cli("spre", "[[:car:]]", "x.json", "--resume"), capture_output=True, text=True)
    assert result.returncode == 2 and "--resume needs --dataset" in result.stderr
    with pytest.raises(UserError, match="tolerances must not be negative"):
        QuerySpec.from_file("scene", SCENE, tolerance_position=-0.1)


def test_window_in_seconds_prunes_and_matches_as_frames(real_dataset: Path, pooled):
    frames = pooled("scenario").to_arrow()
    seconds = run_query(
        real_dataset,
        QuerySpec.from_file("scenario", SCENARIO, window="7.5s", unknown_layers=UNKNOWN),
        RunOptions(jobs=2),
    )
    assert seconds.to_arrow().drop_columns(["explanation"]).equals(frames.drop_columns(["explanation"]))
    assert seconds.counts()["pruned"] == 15


@pytest.mark.slow
def test_progress_bar_on_a_terminal_only(real_dataset: Path, tmp_path: Path):
    import fcntl
    import os
    import pty
    import struct
    import termios

    root = copy_of(real_dataset, tmp_path)
    leader, follower = pty.openpty()
    fcntl.ioctl(follower, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 120, 0, 0))  # a terminal's size
    process = subprocess.Popen(scenario_command(root), stdout=subprocess.DEVNULL, stderr=follower)
    os.close(follower)
    shown = b""
    while True:
        try:
            chunk = os.read(leader, 4096)
        except OSError:
            break
        if not chunk:
            break
        shown += chunk
    process.wait()
    text = shown.decode(errors="replace")
    assert "trace/s" in text and "matched" in text and "/47" in text
    piped = subprocess.run(scenario_command(root), capture_output=True, text=True)
    assert "trace/s" not in piped.stderr
