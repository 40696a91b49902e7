"""Every query command prints a match as ``SOURCE#NAME:START-END`` (scenegrep.dataset.places),
with the source path as the user gave it (the catalog's over ``--dataset``), and ``show --trace``
takes each printed place back to that very match (view.trace_names.chosen_match)."""

from __future__ import annotations

import contextlib
import io
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from scenegrep.cli.main import main
from scenegrep.dataset.places import as_given, place
from scenegrep.view.sources import ResultsSource
from scenegrep.view.trace_names import chosen_match
from tests.conftest import REPO

SAMPLE = "examples/sample"
FILES = [f"{SAMPLE}/fig1_lane_change-000.parquet", f"{SAMPLE}/fig1_lane_change-003.parquet"]
SCENE = ["scene", "examples/scenes/fig3_car_ahead.scenic", "--tolerance-position", "0.5", "--tolerance-heading", "0.1"]
SCENARIO = ["scenario", "examples/queries/fig1_lane_change.scenic", "--window", "3s"]
SPRE = ["spre", "[[:car:]]{3}"]
COMMANDS = {"scene": SCENE, "scenario": SCENARIO, "spre": SPRE}
PLACE = re.compile(r"(?P<source>.+)#(?P<name>[^#:]+):(?P<start>\d+)-(?P<end>\d+)")


def _run(argv: list[str]) -> list[str]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        assert main(argv) == 0
    return out.getvalue().splitlines()


@pytest.fixture(scope="module")
def printed(tmp_path_factory) -> dict[str, tuple[Path, Path | None, list[str]]]:
    """Per command and input (files given relative to the repository, or a dataset of them): the
    results file, the dataset (None over files) and the text lines printed."""
    folder = tmp_path_factory.mktemp("places")
    runs: dict[str, tuple[Path, Path | None, list[str]]] = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(REPO)
        for kind, argv in COMMANDS.items():
            results = folder / f"{kind}.parquet"
            runs[kind] = (results, None, _run([*argv, SAMPLE, "-o", str(results)]))
        dataset = folder / "dataset"
        _run(["ingest", *FILES, "--into", str(dataset), "-q"])
        for kind in ("scene", "spre"):
            results = folder / f"{kind}-dataset.parquet"
            runs[f"{kind} --dataset"] = (
                results,
                dataset,
                _run([*COMMANDS[kind], "--dataset", str(dataset), "-o", str(results)]),
            )
    return runs


@pytest.mark.slow
def test_every_match_line_starts_with_its_source_name_and_window(printed):
    for kind, (_, dataset, lines) in printed.items():
        assert lines, kind
        for line in lines:
            found = PLACE.fullmatch(line.split("  ")[0])
            assert found is not None, (kind, line)
            source = found["source"]
            if dataset is None:
                assert source.startswith(f"{SAMPLE}/") and Path(REPO / source).is_file(), line
            else:
                assert Path(source).is_absolute() and Path(source).resolve() in {(REPO / f).resolve() for f in FILES}
            assert Path(source).stem == found["name"], line


@pytest.mark.slow
def test_show_takes_every_printed_place_to_that_match(printed, monkeypatch):
    monkeypatch.chdir(REPO)
    for kind, (results, dataset, lines) in printed.items():
        source = ResultsSource.open(results, dataset)
        rows = source.results.table.to_pylist()
        for given in _each_trace_first_and_last([line.split("  ")[0] for line in lines]):
            found = PLACE.fullmatch(given)
            trace_id, number = chosen_match(source, given, None)
            (row,) = [r for r in rows if r["trace_id"] == trace_id and r["match"] == number]
            assert (row["name"], row["start_frame"], row["end_frame"]) == (
                found["name"],
                int(found["start"]),
                int(found["end"]),
            ), (kind, given)


def _each_trace_first_and_last(places: list[str]) -> list[str]:
    """The first and the last printed place of each trace (every line form, fewer lookups)."""
    by_trace: dict[str, list[str]] = {}
    for given in places:
        by_trace.setdefault(given.rsplit(":", 1)[0], []).append(given)
    return [given for found in by_trace.values() for given in dict.fromkeys([found[0], found[-1]])]


@pytest.mark.slow
def test_spre_over_a_stream_prints_the_same_places(printed):
    """spre's stream mode (here: a file given with standard input) prints a file's matches as the
    engine's mode does, and standard input's as ``-#NAME``."""
    stream = (REPO / "examples" / "stream.json").read_bytes()
    done = subprocess.run(
        [sys.executable, "-m", "scenegrep", *SPRE, FILES[0], "-"],
        cwd=REPO,
        input=stream,
        capture_output=True,
        check=True,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
    )
    lines = done.stdout.decode().splitlines()
    engine = [line for line in printed["spre"][2] if line.startswith(f"{FILES[0]}#")]
    assert engine and lines[: len(engine)] == engine
    assert lines[len(engine) :] and all(re.fullmatch(r"-#stdin:\d+-\d+", line) for line in lines[len(engine) :])


def test_place_and_the_path_as_given(tmp_path, monkeypatch):
    (tmp_path / "d" / "e").mkdir(parents=True)
    monkeypatch.chdir(tmp_path)
    shown = as_given(["-", "./d/", "d/e/../e"])
    assert shown(str(tmp_path / "d" / "e" / "t.parquet")) == "./d/e/t.parquet"
    assert shown(str(tmp_path / "d")) == "./d/"
    assert as_given(["d/e/../e"])(str(tmp_path / "d" / "e" / "t.parquet")) == "d/e/../e/t.parquet"
    assert shown("/elsewhere/t.parquet") == "/elsewhere/t.parquet"
    assert place("a b/t#1.json", "t#1", 0, 4) == "a b/t#1.json#t#1:0-4"
    assert place("-", "stdin") == "-#stdin"
