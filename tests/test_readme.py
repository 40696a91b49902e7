"""The README stays true: its test command is what CI runs; its quick-start main job works."""

import re

import pytest
from pathlib import Path

from scenegrep.cli.main import main

REPO = Path(__file__).resolve().parents[1]
README = (REPO / "README.md").read_text()


def quick_start() -> list[str]:
    section = README.split("## Quick start", 1)[1].split("\n## ", 1)[0]
    return re.findall(r"```console\n\$ (.+?)\n```", section)


def test_two_quick_start_commands():
    assert len(quick_start()) == 2


def test_ci_runs_the_readme_test_command():
    ci = (REPO / ".ci" / "run").read_text()
    assert quick_start()[1] in ci.splitlines()


def test_quick_start_main_job_runs(monkeypatch):
    monkeypatch.chdir(REPO)
    command = quick_start()[0].split(".venv/bin/scenegrep ", 1)[1]
    assert main(command.split()) == 0


@pytest.mark.slow
@pytest.mark.real_data
def test_dataset_python_example_runs(real_data, tmp_path, monkeypatch):
    section = README.split("### Queries over a dataset", 1)[1]
    code = re.findall(r"```python\n(.+?)\n```", section, re.S)[0]
    monkeypatch.chdir(REPO)
    fleet = str(tmp_path / "fleet")
    names: dict = {}
    exec(code.replace('"fleet"', repr(fleet)).replace('"../shared/real_data"', repr(str(real_data))), names)
    assert (tmp_path / "fleet" / "catalog.duckdb").is_file()
    assert names["report"].failed == []
