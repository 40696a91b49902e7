"""Command-line conventions held by every command (README "Command-line conventions"): options
before or after positionals, unknown options in one line with the nearest options, bad choices
listing the valid ones, ``-o`` naming the output."""

from __future__ import annotations

import argparse
from pathlib import Path

import pytest

from scenegrep.cli import options
from scenegrep.cli.main import COMMANDS, build_parser, main
from scenegrep.cli.parsing import parse_command_line

REPO = Path(__file__).resolve().parents[2]

MIXED = {
    "coverage": (["coverage", "p.scenic", "d1", "--bins", "4", "d2"], {"data": ["d1", "d2"], "bins": 4}),
    "evaluate": (["evaluate", "pred.json", "--max-range", "30", "truth.json"], {"ground_truth": "truth.json"}),
    "export": (["export", "results.parquet", "--mcap", "o.mcap", "-q"], {"results": "results.parquet"}),
    "info": (["info", "a", "--json", "b"], {"paths": ["a", "b"], "json": True}),
    "ingest": (["ingest", "a", "--into", "ds", "b"], {"sources": ["a", "b"], "into": "ds"}),
    "label": (["label", "a", "-o", "out", "b"], {"data": ["a", "b"], "output": "out"}),
    "report": (["report", "results", "-o", "r.html"], {"results": "results", "output": "r.html"}),
    "scenario": (["scenario", "p.scenic", "--window", "3s", "d"], {"program": "p.scenic", "data": ["d"]}),
    "scene": (["scene", "p.scenic", "d1", "--tolerance-position", "0.5", "d2"], {"data": ["d1", "d2"]}),
    "serve": (["serve", "ds", "--port", "0"], {"dataset": "ds", "port": 0}),
    "show": (["show", "results", "-o", "x.png", "--trace", "t"], {"target": "results", "trace": "t"}),
    "spre": (["spre", "[[:car:]]", "f1", "--skip", "2", "f2"], {"pattern": "[[:car:]]", "files": ["f1", "f2"]}),
    "synth": (["synth", "p.scenic", "--map", "m.xodr", "--runs", "1", "--steps", "2", "-o", "out"], {"runs": 1}),
}
"""A command line of each command with an option after a positional, and some of what it gives."""

MISSPELT = {
    "coverage": ("--bnis", "--bins"),
    "evaluate": ("--max-rnage", "--max-range"),
    "export": ("--openscenaro", "--openscenario"),
    "info": ("--no-mpa", "--no-map"),
    "ingest": ("--no-labell", "--no-label"),
    "label": ("--min-confidance", "--min-confidence"),
    "report": ("--datset", "--dataset"),
    "scenario": ("--widow", "--window"),
    "scene": ("--visible-distanse", "--visible-distance"),
    "serve": ("--time-limt", "--time-limit"),
    "show": ("--trce", "--trace"),
    "spre": ("--onlne", "--online"),
    "synth": ("--sed", "--seed"),
}
"""An option of each command misspelt, and the option meant."""

OUTPUT = {"coverage": "output", "export": "output", "ingest": "into", "label": "output", "report": "output"}
OUTPUT |= {"scenario": "output"}
OUTPUT |= {"scene": "output", "show": "output", "spre": "output", "synth": "output"}
"""The commands that write a file or folder named by ``-o``, and the option ``-o`` stands for."""


@pytest.fixture(scope="module")
def parser():
    return build_parser()


def options_first(argv: list[str], parser) -> list[str]:
    """The same command line with every option (and its value) before the positionals."""
    command = parser._subparsers._group_actions[0].choices[argv[0]]
    takes_value = {name for a in command._actions if a.nargs != 0 for name in a.option_strings}
    options, positionals, rest = [], [], iter(argv[1:])
    for token in rest:
        if token.startswith("-"):
            options += [token, next(rest)] if token in takes_value else [token]
        else:
            positionals.append(token)
    return [argv[0], *options, *positionals]


def test_every_command_is_covered():
    assert set(MIXED) == set(MISSPELT) == set(COMMANDS)


@pytest.mark.parametrize("command", COMMANDS)
def test_options_after_positionals(command, parser):
    argv, expected = MIXED[command]
    mixed = vars(parse_command_line(parser, argv))
    first = options_first(argv, parser)
    assert first != argv  # the option really moved
    assert mixed == vars(parse_command_line(parser, first))
    assert {key: mixed[key] for key in expected} == expected
    assert mixed["command"] == command


@pytest.mark.parametrize("command", COMMANDS)
def test_unknown_option_one_line_with_suggestion(command, capsys):
    wrong, meant = MISSPELT[command]
    argv = MIXED[command][0]
    assert main([*argv, wrong, "1"]) == 2
    out, err = capsys.readouterr()
    assert out == ""
    assert err == f"scenegrep: error: {command}: unknown option {wrong} (did you mean {meant}?)\n"


@pytest.mark.parametrize("command", COMMANDS)
def test_unknown_option_without_a_near_one(command, capsys):
    assert main([MIXED[command][0][0], "--zzzzzz=1"]) == 2  # reported before missing arguments
    assert capsys.readouterr().err == f"scenegrep: error: {command}: unknown option --zzzzzz\n"


def test_near_options_are_listed_best_first(capsys):
    assert main(["scene", "--tolerance-postion", "1", "p.scenic"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "scenegrep: error: scene: unknown option --tolerance-postion (did you mean --tolerance-position"
    )
    assert err.count("\n") == 1


@pytest.mark.parametrize(
    "argv, message",
    [
        (["scen", "x"], "unknown command 'scen' (did you mean scene or scenario?); commands: coverage, evaluate"),
        (["--bogus"], "unknown option --bogus"),
        (
            ["spre", "--compat", "strm", "[[:car:]]"],
            "spre: argument --compat: invalid choice: 'strm' (choose from 'strem')",
        ),
        (["scene", "--unknown-layers", "lax", "p"], "(choose from 'permissive', 'strict')"),
        (["evaluate", "a", "b", "c"], "evaluate: unexpected argument: c"),
        (["serve", "-p", "80", "ds"], "serve: unknown option -p (did you mean --port?)"),
        (["scenario", "p.scenic", "d"], "scenario: the following arguments are required: --window"),
    ],
)
def test_usage_errors_are_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("scenegrep: error: ") and err.count("\n") == 1
    assert message in err
    assert "scenegrep scenegrep" not in err and "error: scenegrep" not in err


@pytest.mark.parametrize("command", COMMANDS)
def test_dash_o_is_the_output(command, parser):
    actions = parser._subparsers._group_actions[0].choices[command]._option_string_actions
    assert ("-o" in actions) == (command in OUTPUT)
    if command in OUTPUT:
        assert actions["-o"].dest == OUTPUT[command]
        assert actions["--output"] is actions["-o"]  # -o/--output everywhere (ingest also --into)


def test_spre_online_has_no_short_form(parser, capsys):
    assert main(["spre", "-o", "x.parquet", "--online", "[[:car:]]"]) == 2
    assert "--output and --csv give the results table" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv, expected",
    [
        (["info", "--json", "--", "--no-map", "-"], {"paths": ["--no-map", "-"], "json": True, "no_map": False}),
        (["scene", "p.scenic", "--json", "--", "-d"], {"program": "p.scenic", "data": ["-d"], "json": True}),
        (["spre", "--", "-x", "f"], {"pattern": "-x", "files": ["f"], "export": False}),
    ],
)
def test_double_dash_ends_options(argv, expected, parser):
    args = vars(parse_command_line(parser, argv))
    assert {key: args[key] for key in expected} == expected


def test_scenario_window_after_the_program_runs(tmp_path, capsys):
    """The issue's example end to end: the same results whichever side of DATA the options are."""
    import pyarrow.parquet as pq

    program = str(REPO / "examples/queries/fig1_lane_change.scenic")
    data = str(REPO / "examples/sample/fig1_lane_change-000.parquet")
    after, before = tmp_path / "after.parquet", tmp_path / "before.parquet"
    assert main(["scenario", program, "--window", "3s", data, "-o", str(after), "-q"]) == 0
    assert main(["scenario", "-q", "-o", str(before), "--window", "3s", program, data]) == 0
    rows = pq.read_table(after).to_pylist()
    assert rows == pq.read_table(before).to_pylist()
    assert [row["status"] for row in rows] == ["match"]


SHARED = {
    options.add_map_argument: ("coverage", "ingest", "label", "scenario", "scene"),
    options.add_tolerance_arguments: ("coverage", "scenario", "scene"),
    options.add_unknown_layers_argument: ("coverage", "ingest", "label", "scenario", "scene"),
    options.add_results_arguments: ("scenario", "scene", "spre"),
    options.add_dataset_arguments: ("coverage", "scenario", "scene", "spre"),
    options.add_bag_arguments: ("info", "label", "scenario", "scene", "spre"),
    options.add_live_arguments: ("scenario", "spre"),
}
"""Each shared option group (:mod:`scenegrep.cli.options`) and the commands that have it."""


def _signature(action) -> tuple:
    return (action.dest, action.help, action.type, action.choices, action.default, action.nargs, action.required)


@pytest.mark.parametrize("add", list(SHARED), ids=lambda add: add.__name__)
def test_shared_options_come_from_one_place(add, parser):
    """Every command of a group has its options exactly as the group adds them; no other command
    has the whole group (it would belong in the table)."""
    alone = argparse.ArgumentParser()
    add(alone)
    group = {name: _signature(a) for a in alone._actions[1:] for name in a.option_strings}
    for command, sub in parser._subparsers._group_actions[0].choices.items():
        has = {
            name: _signature(sub._option_string_actions[name]) for name in group if name in sub._option_string_actions
        }
        if command in SHARED[add]:
            assert has == group, command
        else:
            assert has != group, command


@pytest.mark.parametrize(
    "argv, message",
    [
        (["show", "results.parquet", "-o", "x.svg"], "-o x.svg: write a .png, .gif or .html file"),
        (["show", "results.parquet", "-o", "folder.PNG"], "-o folder.PNG: a directory; name the file to write"),
        (["report", "results.parquet", "-o", "r.txt"], "-o r.txt: write an .html file"),
        (["report", "results.parquet", "-o", "folder.html"], "-o folder.html: a directory; name the file to write"),
        (["coverage", "p.scenic", "d", "-o", "t.csv"], "--output t.csv: write a .parquet or .json file"),
        (["coverage", "p.scenic", "d", "--png", ""], "--png : write a .png file"),
    ],
)
def test_output_files_are_checked_before_any_work(argv, message, tmp_path, monkeypatch, capsys):
    """Neither the results nor the program exist: the output is refused first."""
    monkeypatch.chdir(tmp_path)
    for folder in ("folder.PNG", "folder.html"):
        (tmp_path / folder).mkdir()
    assert main(argv) == 2
    assert capsys.readouterr().err == f"scenegrep: error: {message}\n"
