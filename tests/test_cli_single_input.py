"""Exit codes over one input and over several, the same for every command that reads traces:
a lone input that fails is a user error (one line, exit code 2); over a folder or several paths a
failed input is named and the others go on (exit code 3)."""

from __future__ import annotations

import pytest

from scenegrep.cli.main import main
from tests.conftest import REPO
from tests.label.test_cli import folder_with_a_bad_file

COMMANDS = {
    "info": (["info"], ["--no-map"]),
    "label": (["label"], ["-q", "-o", "OUT"]),
    "scene": (["scene", str(REPO / "examples/scenes/fig3_car_ahead.scenic")], []),
    "scenario": (["scenario", str(REPO / "examples/queries/s1_lane_change_stationary_car.scenic")], ["--window", "75"]),
    "spre": (["spre", "[[:car:]]"], []),
}
"""Each command's words before its DATA paths and after them (``OUT``: an output folder)."""


def _run(command: str, paths: list, tmp_path, capsys) -> tuple[int, list[str]]:
    before, after = COMMANDS[command]
    code = main([*before, *(str(p) for p in paths), *(str(tmp_path / "out") if a == "OUT" else a for a in after)])
    return code, capsys.readouterr().err.strip().splitlines()


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_lone_bad_file_is_one_error_line_exit_2(command, tmp_path, capsys):
    bad = folder_with_a_bad_file(tmp_path / "in") / "bad.parquet"
    code, err = _run(command, [bad], tmp_path, capsys)
    assert code == 2 and len(err) == 1, err
    assert err[0].startswith(f"scenegrep: error: {bad}: not a valid Parquet file"), err


@pytest.mark.parametrize("command", list(COMMANDS))
def test_a_bad_file_among_several_is_named_exit_3(command, tmp_path, capsys):
    folder = folder_with_a_bad_file(tmp_path / "in")
    for paths in ([folder], [folder / "a.parquet", folder / "bad.parquet"]):
        code, err = _run(command, paths, tmp_path, capsys)
        failed = [line for line in err if line.startswith("scenegrep: failed: ")]
        assert code == 3 and len(failed) == 1 and failed[0].startswith("scenegrep: failed: bad.parquet: "), err
