"""A class, image channel or program object kind that no searched trace has is a warning (one
line, naming it and the names the data has), from the Python API and on stderr, the same over
files and over a dataset; never a silent "no match"."""

from pathlib import Path

import numpy as np
import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.dataset import QuerySpec
from scenegrep.dataset.files import query_files
from scenegrep.dataset.ingest import ingest
from scenegrep.dataset.run import RunOptions, run_query
from scenegrep.spre import TraceSearch, compile_query
from scenegrep.spre.vocabulary import class_names

REPO = Path(__file__).resolve().parents[1]
BG1 = str(REPO / "examples/sample/bg1_following_traffic-000.parquet")
PEDESTRIAN = "examples/queries/s3_pass_pedestrian.scenic"


@pytest.fixture(scope="module")
def stream(conformance_dir) -> str:
    return str(conformance_dir / "strem/data/seq_a.json")


@pytest.fixture(scope="module")
def names(stream):
    """The classes and channels the two inputs hold, read from their raw tables."""
    bg1, strem = readers.read_trace(BG1), readers.read_trace(stream)
    images = strem.images
    return {
        "bg1": sorted(set(bg1.objects.category.astype(str).tolist())),
        "strem": sorted({images.boxes.classes[c] for c in np.unique(images.boxes.category)}),
        "channels": sorted(images.samples.channels),
    }


@pytest.fixture(scope="module")
def dataset(tmp_path_factory, stream):
    root = tmp_path_factory.mktemp("warnings") / "ds"
    ingest([BG1, stream], root, jobs=1)
    return root


def spec(kind, text, **options):
    defaults = {"spre": {"compat": False, "space": None, "channels": None, "skip": 0}}.get(kind, {})
    if kind != "spre":
        text = (REPO / text).read_text()
    return QuerySpec.of(kind, text, "<query>", **(defaults | options))


def both(query_spec, paths, dataset):
    """The warnings over the files and over the dataset that ingested them (equal)."""
    over_files = query_files(paths, query_spec).warnings
    over_dataset = run_query(dataset, query_spec, RunOptions(jobs=1)).warnings
    assert over_files == over_dataset
    return over_files


def test_class_names_leave_out_any_and_ego():
    assert class_names(compile_query("[[:*:] & [:ego:]][[:cra:] | [:car:]]").tree) == {"cra", "car"}


def test_an_unknown_class_names_the_known_ones_in_both_modes(dataset, stream, names):
    classes = ", ".join(sorted({*names["bg1"], *names["strem"]}))
    expected = (f"no trace searched has class 'cra' (classes there: {classes})",)
    assert both(spec("spre", "[[:car:]] | [[:cra:]]"), [BG1, stream], dataset) == expected
    assert both(spec("spre", "[[:car:]]+"), [BG1, stream], dataset) == ()  # a kind ('Car' is a car)


def test_an_unknown_channel_names_the_known_ones_in_both_modes(dataset, stream, names):
    expected = (f"no trace searched has image channel 'front' (channels there: {', '.join(names['channels'])})",)
    assert both(spec("spre", "[[:car:]]", channels=("front",)), [BG1, stream], dataset) == expected
    assert both(spec("spre", "[[:car:]]", channels=tuple(names["channels"])), [BG1, stream], dataset) == ()


def test_a_program_object_no_trace_can_be(dataset, stream):
    (warning,) = both(spec("scene", PEDESTRIAN), [BG1, stream], dataset)
    assert warning == "no trace searched has a pedestrian object for Pedestrian 'pedestrian' (kinds there: car)"


def test_the_command_line_prints_one_line_and_keeps_exit_code_1(capsys, names, monkeypatch):
    monkeypatch.chdir(REPO)
    assert main(["spre", "[[:cra:]]", BG1]) == 1
    warnings = [line for line in capsys.readouterr().err.splitlines() if "warning" in line]
    assert warnings == [f"scenegrep: warning: no trace searched has class 'cra' (classes there: {names['bg1'][0]})"]
    assert main(["scene", PEDESTRIAN, BG1]) == 1
    assert "scenegrep: warning: no trace searched has a pedestrian object" in capsys.readouterr().err
    walker = str(REPO / "examples/sample/s3_pass_pedestrian-000.parquet")
    assert main(["spre", "[[:pedestrian:]]", BG1, walker]) == 0  # over files, said as over a dataset:
    err = capsys.readouterr().err
    assert "scenegrep: pruned 1: no object or box of class 'pedestrian'\n" in err and "warning" not in err
    assert main(["spre", "-q", "[[:cra:]]", BG1]) == 1
    assert capsys.readouterr().err == ""


def test_streams_and_the_search_api_warn_per_trace(capsys, stream, names):
    search = TraceSearch(compile_query("[[:cra:]]", compat=True), readers.read_trace(stream))
    assert search.warnings == [f"no trace searched has class 'cra' (classes there: {', '.join(names['strem'])})"]
    assert main(["spre", "--compat", "strem", "-c", "front", "[[:car:]]", stream]) == 1
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(f"scenegrep: warning: {stream}: no trace searched has image channel 'front'")
