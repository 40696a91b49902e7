"""``scenegrep export -o OUT``: ``-o`` names the output as in every command; the kind is
``--format``'s or the suffix's, and ``-o`` with a kind writes what the kind's own option
(``--mcap OUT``, ``--scenic DIR``, ...) writes."""

from __future__ import annotations

from pathlib import Path

import pytest

from scenegrep.cli.main import main

REPO = Path(__file__).resolve().parents[2]
TRACE = str(REPO / "examples/sample/s3_pass_pedestrian-000.parquet")


@pytest.fixture(scope="module")
def results(tmp_path_factory) -> Path:
    """A results table with times (a sample trace, top-down)."""
    path = tmp_path_factory.mktemp("export") / "r.parquet"
    assert main(["spre", "--space", "topdown", "-q", "[[:pedestrian:]]{5}", TRACE, "-o", str(path)]) == 0
    return path


def export(*argv) -> int:
    return main(["export", *map(str, argv)])


def test_dash_o_writes_what_the_suffix_says(results, tmp_path, capsys):
    assert export(results, "-o", tmp_path / "a.MCAP", "-q") == 0
    assert export(results, "--mcap", tmp_path / "b.mcap", "-q") == 0
    assert (tmp_path / "a.MCAP").read_bytes() == (tmp_path / "b.mcap").read_bytes()
    assert export(results, "--output", tmp_path / "c.mcap", "--format", "mcap") == 0
    assert capsys.readouterr().err.endswith(f"written as Foxglove events to {tmp_path / 'c.mcap'}\n")


def test_a_folder_takes_its_kind_from_format(results, tmp_path, capsys):
    assert export(results, "-o", tmp_path / "a", "--format", "scenic", "-q") == 0
    assert export(results, "--scenic", tmp_path / "b", "-q") == 0
    written = sorted(p.name for p in (tmp_path / "a").iterdir())
    assert written and written == sorted(p.name for p in (tmp_path / "b").iterdir())
    assert all((tmp_path / "a" / name).read_text() == (tmp_path / "b" / name).read_text() for name in written)


@pytest.mark.parametrize(
    "argv, message",
    [
        (["-o", "{tmp}/out"], "-o {tmp}/out: say what to write with --format mcap|refav|openscenario|scenic"),
        (["--scenic", "{tmp}/out", "--format", "scenic"], "--format goes with -o/--output (or write --scenic OUT)"),
        (["-o", "{tmp}/s.pkl"], "-o {tmp}/s.pkl: a RefAV submission needs --prompt TEXT"),
        (["-o", "{tmp}/a.mcap", "--mcap", "{tmp}/b.mcap"], "argument --mcap: not allowed with argument -o/--output"),
        (["-o", "{tmp}/a.mcap", "--format", "xosc"], "invalid choice: 'xosc' (choose from 'mcap', 'refav'"),
        ([], "one of the arguments -o/--output --mcap --refav --openscenario --scenic is required"),
        (["-o", "{results}", "--format", "scenic"], "-o {results}: not a directory"),
        (["-o", "", "--format", "mcap"], "-o: give the file to write to"),
        (["--mcap", " "], "--mcap: give the file to write to"),
        (["--refav", "", "--prompt", "p"], "--refav: give the file to write to"),
    ],
)
def test_one_line_errors(results, tmp_path, capsys, argv, message):
    fill = {"tmp": tmp_path, "results": results}
    assert export(results, *(a.format(**fill) for a in argv)) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message.format(**fill) in err


def test_results_without_times_are_no_foxglove_events(tmp_path, capsys):
    """A STREM stream's frames carry no times: one line, not a traceback."""
    results = tmp_path / "r.parquet"
    assert main(["spre", "-q", "[[:car:]]", str(REPO / "examples/stream.json"), "-o", str(results)]) == 0
    assert export(results, "-o", tmp_path / "m.mcap") == 2
    err = capsys.readouterr().err
    assert err.startswith("scenegrep: error: match 0 of stream: the trace gives no time") and err.count("\n") == 1
    assert not (tmp_path / "m.mcap").exists()


@pytest.mark.parametrize("argv", [["-o", "adir", "--format", "mcap"], ["--mcap", "adir"]])
def test_an_existing_folder_is_no_mcap_file(results, tmp_path, monkeypatch, capsys, argv):
    """A relative OUT that is a folder: one line naming it, not the temporary file beside it."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "adir").mkdir()
    assert export(results, *argv) == 2
    assert capsys.readouterr().err == "scenegrep: error: adir: cannot write: Is a directory\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["adir"] and not any((tmp_path / "adir").iterdir())
