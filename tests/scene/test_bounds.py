"""Everything a Scenic program can make huge is bounded before work starts (README "Limits"): loop
counts, random choices, the program's size in tokens and its nesting are each a one-line error at
line:column with exit code 2, fast, never a RecursionError; programs within the limits answer.

The programs go through the command line in process (``main([...])``); Scenic's own parser takes
about a millisecond per token, so "fast" here is seconds.
"""

from __future__ import annotations

import time

import pytest

from scenegrep.cli.main import main
from scenegrep.scene.expressions import MAX_CHOICES
from scenegrep.scene.resolve import MAX_LOOP_STATEMENTS
from scenegrep.scenic.parser import MAX_NESTING, MAX_TOKENS

TRACE = "examples/sample/fig1_lane_change-000.parquet"
HEAD = "model scenic.simulators.newtonian.driving_model\nego = new Car\n"
WIDE = 50_000
LOOPS = f"at most {MAX_LOOP_STATEMENTS} statements"
TOKENS = f"more than {MAX_TOKENS} tokens"
NESTS = f"nests more than {MAX_NESTING} levels deep"

HUGE = {
    "range(10**9)": ("for i in range(10**9):\n    new Car\n", 3, LOOPS),
    "range(Range(0, 1e9))": ("for i in range(Range(0, 1e9)):\n    new Car\n", 3, "constant whole number"),
    "range(10**10**10)": ("for i in range(10**10**10):\n    new Car\n", 3, "constant whole number"),
    "nested loops": ("for i in range(1000):\n    for j in range(1000):\n        x = i\n", 4, LOOPS),
    "DiscreteRange(0, 10**9)": ("x = DiscreteRange(0, 10**9)\n", 3, f"at most {MAX_CHOICES} values"),
    "Options of 100 values": (
        "x = Options([" + ", ".join(str(k) for k in range(100)) + "])\n",
        3,
        f"at most {MAX_CHOICES} values",
    ),
    "a 50,000-term sum": ("require " + " + ".join(["(distance to ego)"] * WIDE) + " >= 0\n", 3, TOKENS),
    "a 50,000-term conjunction": ("require " + " and ".join(["(distance to ego) >= 0"] * WIDE) + "\n", 3, TOKENS),
    "a 50,000-value list": ("x = Options([" + ", ".join(["1"] * WIDE) + "])\n", 3, TOKENS),
    "50,000 nested brackets": ("require " + "(" * WIDE + "1" + ")" * WIDE + " > 0\n", 3, "brackets nest"),
    "50,000 minus signs": ("require " + "-" * WIDE + "1 > 0\n", 3, TOKENS),
    "150 minus signs": ("require " + "-" * 150 + "1 > 0\n", 3, NESTS),
    "a 150-term sum": ("require " + " + ".join(["(distance to ego)"] * 150) + " >= 0\n", 3, NESTS),
}


def _run(program: str, tmp_path, command: tuple[str, ...] = ("scene",)) -> tuple[int, list[str], float, str]:
    path = tmp_path / "huge.scenic"
    path.write_text(HEAD + program)
    began = time.perf_counter()
    code = main([*command, str(path), TRACE, "-q"])
    return code, [], time.perf_counter() - began, str(path)


@pytest.mark.parametrize("name", HUGE)
def test_a_huge_program_is_a_one_line_error(name, tmp_path, capsys):
    program, line, message = HUGE[name]
    code, _, elapsed, path = _run(program, tmp_path)
    lines = capsys.readouterr().err.splitlines()
    assert code == 2
    assert lines[0].startswith(f"scenegrep: error: {path}:{line}:") and message in lines[0], lines[0][:300]
    assert len(lines) <= 3 and all(len(text) < 120 for text in lines[1:]), "only a short caret display follows"
    assert "Traceback" not in "\n".join(lines) and "recursion" not in "\n".join(lines)
    assert elapsed < 10, f"{elapsed:.1f} s"


def test_the_scenario_command_shares_the_bounds(tmp_path, capsys):
    code, _, _, path = _run("for i in range(10**9):\n    new Car\n", tmp_path, ("scenario", "--window", "5"))
    assert code == 2 and LOOPS in capsys.readouterr().err.splitlines()[0]


WITHIN = {
    "95 nested brackets": "require " + "(" * 95 + "(distance to ego)" + ")" * 95 + " >= 0\n",
    "90 minus signs": "require " + "-" * 90 + "(distance to ego) <= 0\n",
    "a 90-term sum": "require " + " + ".join(["(distance to ego)"] * 90) + " >= 0\n",
    "a 200-term conjunction": "require " + " and ".join(["(distance to ego) >= 0"] * 200) + "\n",
    "a 200-term disjunction": "require " + " or ".join(["(distance to ego) >= 0"] * 200) + "\n",
    "Options of the most values": "x = Options(["
    + ", ".join(str(k) for k in range(MAX_CHOICES))
    + "])\nrequire x >= 0\n",
    "a loop": "for i in range(3):\n    y = i\n",
}


@pytest.mark.parametrize("name", WITHIN)
def test_a_program_within_the_limits_answers(name, tmp_path, capsys):
    code, _, elapsed, _ = _run(WITHIN[name], tmp_path)
    assert code in (0, 1), capsys.readouterr().err[:300]
    assert elapsed < 30
