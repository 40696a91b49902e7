"""The faces: scenegrep show, report and serve (its HTTP API), and their user errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from PIL import Image

from scenegrep.cli.main import main
from scenegrep.dataset.results import Results
from scenegrep.view.plot import GIF_MARGIN
from scenegrep.view.report import view_file
from tests.conftest import REPO
from tests.view.conftest import fetch

pytestmark = pytest.mark.real_data


def run_file(root: Path, run) -> Path:
    return root / "runs" / run.run_id / "results.parquet"


def test_show_writes_a_png_a_gif_and_an_html_page(real_dataset, scenario_run, tmp_path, capsys):
    source = run_file(real_dataset, scenario_run)
    row = scenario_run.matches.to_pylist()[2]
    assert main(["show", str(source), "--match", "2", "-o", str(tmp_path / "m.png")]) == 0
    assert f"match {row['match']} of {row['name']}" in capsys.readouterr().err
    with Image.open(tmp_path / "m.png") as png:
        assert png.format == "PNG" and png.size == (1000, 750)
    assert main(["show", str(source), "--match", "2", "-o", str(tmp_path / "m.gif"), "-q"]) == 0
    with Image.open(tmp_path / "m.gif") as gif:
        # sample traces: frames 0-149 with index = position; the margin is cut at the trace's ends
        first, last = max(row["start_frame"] - GIF_MARGIN, 0), min(row["end_frame"] + GIF_MARGIN, 149)
        assert gif.format == "GIF" and gif.n_frames == last - first + 1
    assert main(["show", str(source), "--match", "2", "-o", str(tmp_path / "m.html"), "-q"]) == 0
    page = (tmp_path / "m.html").read_text()
    assert f'data-initial-match="{row["match"]}"' in page and row["name"] in page


def test_show_reads_results_as_json_lines_and_csv_too(real_dataset, scenario_run, tmp_path):
    for suffix, write in ((".json", scenario_run.write_json), (".csv", scenario_run.write_csv)):
        path = tmp_path / f"results{suffix}"
        with open(path, "w") as stream:
            write(stream)
        again = Results.read(path)
        assert again.table.equals(scenario_run.table)
        out = tmp_path / f"view{suffix}.html"
        assert main(["show", str(path), "--dataset", str(real_dataset), "-o", str(out), "-q"]) == 0


def test_the_run_id_and_status_travel_in_the_parquet_file(real_dataset, scenario_run):
    again = Results.read(run_file(real_dataset, scenario_run))
    assert (again.run_id, again.status) == (scenario_run.run_id, "finished")


def test_show_draws_a_trace_file_on_its_map(tmp_path):
    trace = REPO / "examples" / "sample" / "s1_lane_change_stationary_car-000.parquet"
    assert main(["show", str(trace), "-o", str(tmp_path / "t.png"), "-q"]) == 0
    assert main(["show", str(trace), "-o", str(tmp_path / "t.html"), "-q"]) == 0
    assert '"lanes":[[' in (tmp_path / "t.html").read_text()


@pytest.mark.parametrize(
    ("arguments", "message"),
    [
        (["--match", "99"], "--match 99: the results have 12 matches"),
        (["-o", "x.svg"], "write a .png, .gif or .html file"),
        (["--trace", "nope"], "--trace nope: the results have no such trace"),
        (["--frame", "9999", "-o", "x.png"], "--frame 9999: the trace has no frame with that index"),
    ],
)
def test_show_user_errors_are_one_line_and_exit_2(real_dataset, scenario_run, tmp_path, capsys, arguments, message):
    source = run_file(real_dataset, scenario_run)
    argv = ["show", str(source), "-o", str(tmp_path / "x.html"), *arguments]
    if "-o" in arguments:
        argv = ["show", str(source), *[str(tmp_path / a) if a.startswith("x.") else a for a in arguments]]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_results_outside_a_dataset_read_their_traces_from_their_sources(scenario_run, tmp_path, capsys):
    """Outside a dataset (and without --dataset), each trace is read again from its source as the
    query over files reads it; a source that is gone is a one-line error."""
    import pyarrow as pa

    copy = tmp_path / "results.parquet"
    scenario_run.write_parquet(copy)
    assert main(["show", str(copy), "-o", str(tmp_path / "x.html"), "-q"]) == 0
    gone = scenario_run.table.set_column(2, "source", pa.array([str(tmp_path / "gone.parquet")] * len(scenario_run)))
    Results(gone, scenario_run.run_id).write_parquet(copy)
    assert main(["show", str(copy), "-o", str(tmp_path / "x.html")]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("scenegrep: error: ") and "gone.parquet" in line


def test_report_links_every_match_to_a_written_view(real_dataset, spre_run, tmp_path, capsys):
    out = tmp_path / "r" / "report.html"
    assert main(["report", str(run_file(real_dataset, spre_run).parent), "-o", str(out)]) == 0
    page = out.read_text()
    matches = spre_run.matches.to_pylist()
    assert page.count('class="match-link"') == len(matches)
    for row in matches:
        assert (out.parent / "report_views" / view_file(row["trace_id"])).is_file()
        assert f"report_views/{view_file(row['trace_id'])}#match={row['match']}" in page
    assert f'data-count="matched"><b>{spre_run.counts()["matched"]}</b>' in page
    for chart in ("chart-matches", "chart-windows", "chart-kinds"):
        assert f'id="{chart}"' in page
    assert f"{len(matches)} matches" in capsys.readouterr().err


def test_serve_binds_to_the_loopback_and_answers_the_catalog(server, real_dataset):
    assert server.server_address[0] == "127.0.0.1"
    status, body = fetch(server, "api/traces")
    assert status == 200 and len(json.loads(body)) == 62
    status, body = fetch(server, "")
    assert status == 200 and b'id="query-form"' in body


def test_serve_runs_queries_like_the_dataset_engine(server, spre_run):
    status, body = fetch(server, "api/query", {"kind": "spre", "text": "[[:pedestrian:]]+", "options": {}})
    answer = json.loads(body)
    assert status == 200 and answer["run_id"] == spre_run.run_id
    assert answer["counts"] == spre_run.counts()
    assert [m["trace_id"] for m in answer["matches"]] == spre_run.matches["trace_id"].to_pylist()
    status, page = fetch(server, answer["matches"][0]["href"].split("#")[0].lstrip("/"))
    assert status == 200 and b"scenegrep-data" in page
    status, page = fetch(server, answer["report"].lstrip("/"))
    assert status == 200 and page.count(b'class="match-link"') == len(answer["matches"])


@pytest.mark.parametrize(
    ("request_body", "message"),
    [
        ({"kind": "spre", "text": "[[:car:]", "options": {}}, "<query>:1:9"),
        ({"kind": "sql", "text": "x"}, "unknown query kind 'sql'"),
        ({"kind": "scenario", "text": "ego = new Car", "options": {}}, "scenario queries need a window"),
        ({"text": "x"}, "bad query request"),
    ],
)
def test_serve_answers_bad_queries_with_one_line(server, request_body, message):
    status, body = fetch(server, "api/query", request_body)
    assert status == 400 and message in json.loads(body)["error"]


def test_serve_answers_unknown_pages_and_runs(server):
    assert fetch(server, "view/nope")[0] == 400
    assert json.loads(fetch(server, "report/abc")[1])["error"] == "the dataset has no run 'abc'"
    assert fetch(server, "nothing/here")[0] == 404


def test_serve_runs_a_typed_scenic_scene_like_the_api(server, real_dataset):
    from scenegrep.dataset import open_dataset

    program = REPO / "examples" / "scenes" / "fig3_car_ahead.scenic"
    options = {"tolerance_position": 1.0, "tolerance_heading": 0.2618}
    request = {"kind": "scene", "text": program.read_text(), "options": {**options, "explain": False}}
    status, body = fetch(server, "api/query", request)
    assert status == 200
    expected = open_dataset(real_dataset).scene(program, **options)
    answer = json.loads(body)
    assert answer["counts"] == expected.counts() and answer["counts"]["matched"] > 0
    assert [(m["trace_id"], m["start_frame"]) for m in answer["matches"]] == [
        (r["trace_id"], r["start_frame"]) for r in expected.matches.to_pylist()
    ]
