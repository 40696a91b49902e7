"""Every STREM v0.2.0 conformance case (../shared/conformance/strem/cases.jsonl), run through
the real command line in ``--compat strem`` mode.

Rules (the cases' README): matches must equal ``expected`` (for ``quirk`` cases,
``true_longest_expected``: clean leftmost-longest semantics); exit codes 0 match / 1 none;
cases STREM rejected (``expected_error``) need a clear one-line error and a non-zero exit.
"""

import json
from pathlib import Path

import pytest

from scenegrep.cli.main import main

CASES_FILE = Path(__file__).resolve().parents[2].parent / "shared" / "conformance" / "strem" / "cases.jsonl"
CASES = [json.loads(line) for line in CASES_FILE.read_text().splitlines()] if CASES_FILE.is_file() else []


def _ranges(out: str) -> list[list[int]]:
    ranges = []
    for line in out.splitlines():
        span = line.rsplit(":", 1)[-1]
        start, end = span.split("..")
        ranges.append([int(start), int(end)])
    return ranges


@pytest.mark.parametrize("case", CASES, ids=[c["name"] for c in CASES])
def test_case(case, conformance_dir, capsys):
    path = conformance_dir / "strem" / case["frames_file"]
    argv = [
        "spre",
        "--compat",
        "strem",
        *case.get("args", []),
        *(["--online"] if case["mode"] == "online" else []),
        case["query"],
        str(path),
    ]
    code = main(argv)
    out, err = capsys.readouterr()
    if case.get("expected_error"):
        assert code == 2
        lines = [line for line in err.splitlines() if line.startswith("scenegrep: error:")]
        assert len(lines) == 1, err
        return
    expected = case.get("true_longest_expected", case["expected"])
    assert _ranges(out) == expected, (out, err)
    expected_code = case["exit_code"] if "true_longest_expected" not in case else (0 if expected else 1)
    assert code == expected_code
    assert "Traceback" not in err
    for warning in case.get("stderr_warnings", []):
        char = warning.split("`")[1]
        assert f"ignoring unrecognized character `{char}`" in err


def test_cases_are_present(conformance_dir):
    assert len(CASES) == 197
