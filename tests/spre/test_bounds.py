"""Everything a SpRE can make huge is bounded before work starts (README "Limits"): nesting, the
number of terms, the text's length, repetition counts and the automaton's size are each a one-line
error at line:column with exit code 2 (a failed row, exit 3, when the limit depends on the trace:
the automaton built per trace, nested quantifiers' object combinations per frame), fast; queries
within the limits answer, whatever their shape, without recursion errors.

* explicit huge queries through the command line (``main([...])`` in process): exit 2, the error
  line names the place and the limit, only the caret display follows (clipped to a short line), no
  traceback, under a few seconds;
* queries just inside the nesting limit, in every construct that nests, and ``{0,500}`` answer;
* ``X{0,k}`` compiles to exactly the automaton of its nested spelling ``(X(X(...)?)?)?`` (the
  construction is now iterative; this is the recursive one it replaced), for nullable X too.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.errors import UserError
from scenegrep.spre import compile_query, search
from scenegrep.spre.evaluate import MAX_ROWS_PER_FRAME
from scenegrep.spre.automaton import MAX_EDGES, compile_automaton
from scenegrep.spre.parser import parse
from tests.spre.test_semantics import frames_matching, image_trace
from scenegrep.spre.tokens import MAX_CHARACTERS, MAX_NESTING, MAX_NODES, MAX_POSITIONS

TRACE = "examples/sample/fig1_lane_change-000.parquet"
DEEP = 10_000
WIDE = 50_000
NESTS = f"nests more than {MAX_NESTING} levels deep"

HUGE = {
    "groups": ("(" * DEEP + "[[:car:]]" + ")" * DEEP, NESTS),
    "formula groups": ("[" + "(" * DEEP + "[:car:]" + ")" * DEEP + "]", NESTS),
    "negations": ("[" + "!" * DEEP + "[:car:]]", NESTS),
    "complements": ("[NE " + "~" * DEEP + "[:car:]]", NESTS),
    "quantifiers": ("[" + "E(x := [:car:]) " * 5_000 + "x]", NESTS),
    "track binders": ("E(x := [:car:])" * 5_000 + "[x]", NESTS),
    "minus signs": ("[@area([:car:]) > " + "-" * DEEP + "1]", NESTS),
    "metric groups": ("[@area([:car:]) > " + "(" * DEEP + "1" + ")" * DEEP + "]", NESTS),
    "a sum chain": ("[" + "+".join(["1"] * 5_000) + " > 0]", NESTS),
    "nested repeats": ("(" * DEEP + "[[:car:]]" + "){2}" * DEEP, NESTS),
    "alternatives": ("|".join(["[[:car:]]"] * 5_000), f"more than {MAX_NODES} terms"),
    "disjuncts": ("[" + " | ".join(["[:car:]"] * 5_000) + "]", f"more than {MAX_NODES} terms"),
    "a concatenation": ("[[:car:]]" * 5_000 + "[[:bus:]]" * 5_000, f"more than {MAX_NODES} terms"),
    "50,000 terms": ("|".join(["[[:car:]]"] * WIDE), f"longer than {MAX_CHARACTERS} characters"),
    "a huge count": ("[[:car:]]{0,100000000000}", f"above the limit of {MAX_POSITIONS}"),
    "a 5,000-digit count": ("[[:car:]]{" + "9" * 5_000 + "}", f"above the limit of {MAX_POSITIONS}"),
    "repeats of repeats": ("(([[:car:]]{200}){200})", f"more than {MAX_POSITIONS} frame letters"),
    "a quadratic automaton": ("([[:car:]]?){0,5000}", f"more than {MAX_EDGES} transitions"),
}
"""Queries over a limit before any trace is read (a query without track binders has its
automaton built at compile time): one error line, exit 2."""

PER_TRACE = {
    "track binders over every car": ("E(x := [:car:])" * 15 + "[x]", f"more than {MAX_POSITIONS} frame letters"),
}
"""Limits of the automaton built per trace (track binders range over its objects): over files, a
failed row with the query's place (exit 3, the one execution path of dataset/files.py)."""

STREM = {
    "groups": ("(" * DEEP + "[[:car:]]" + ")" * DEEP, NESTS),
    "a concatenation": ("[[:car:]]" * 5_000, NESTS),
    "a conjunction": ("[" + "&".join(["[:car:]"] * 5_000) + "]", NESTS),
    "negations": ("[" + "!" * DEEP + "[:car:]]", NESTS),
}


def _run(args: list[str], capsys) -> tuple[int, list[str], float]:
    began = time.perf_counter()
    code = main(args)
    elapsed = time.perf_counter() - began
    return code, capsys.readouterr().err.splitlines(), elapsed


def _assert_one_line_error(code: int, lines: list[str], elapsed: float, message: str) -> None:
    assert code == 2
    assert lines[0].startswith("scenegrep: error: <query>:1:") and message in lines[0], lines[0][:300]
    assert len(lines) == 3 and all(len(line) < 120 for line in lines[1:]), "only a short caret display follows"
    assert "Traceback" not in "\n".join(lines)
    assert elapsed < 5, f"{elapsed:.1f} s"


@pytest.mark.parametrize("name", HUGE)
def test_a_huge_query_is_a_one_line_error(name, capsys):
    query, message = HUGE[name]
    _assert_one_line_error(*_run(["spre", "--space", "topdown", query, TRACE], capsys), message)


@pytest.mark.parametrize("name", PER_TRACE)
def test_a_per_trace_limit_is_a_one_line_error_of_the_lone_trace(name, capsys):
    query, message = PER_TRACE[name]
    code, lines, elapsed = _run(["spre", "--space", "topdown", query, TRACE], capsys)
    assert code == 2 and lines[0].startswith("scenegrep: error: ") and message in lines[0], lines[:1]
    assert "<query>:1:1: " in lines[0] and len(lines) == 1 and elapsed < 5


@pytest.mark.parametrize("name", STREM)
def test_a_huge_strem_query_is_a_one_line_error(name, capsys):
    query, message = STREM[name]
    _assert_one_line_error(*_run(["spre", "--compat", "strem", query, "-"], capsys), message)


INSIDE = MAX_NESTING - 6
WITHIN = {
    "groups": "(" * INSIDE + "[[:car:]]" + ")" * INSIDE,
    "formula groups": "[" + "(" * INSIDE + "[:car:]" + ")" * INSIDE + "]",
    "negations": "[" + "!" * (INSIDE - 1) + "[:car:]]",
    "complements": "[NE " + "~" * INSIDE + "[:car:]]",
    "minus signs": "[@area([:car:]) > " + "-" * INSIDE + "1]",
    "nested concatenations": "([[:car:]]" * INSIDE + ")" * INSIDE,
    "nested repeats": "(" * INSIDE + "[[:car:]]" + "){1}" * INSIDE,
    "{0,500}": "[[:car:]]{0,500}",
    "a wide formula": "[" + " | ".join(["[:car:]"] * 3_000) + "]",
}


@pytest.mark.parametrize("name", WITHIN)
def test_a_query_within_the_limits_answers(name, capsys):
    code, lines, elapsed = _run(["spre", "--space", "topdown", "-q", WITHIN[name], TRACE], capsys)
    assert code in (0, 1), lines[:1]
    assert elapsed < 10


ITEMS = ["[[:car:]]", "[[:car:]]?", "[[:car:]]*", "([[:car:]][[:bus:]]?)", ".", "([[:car:]]|[[:bus:]]*)"]


def _nested(item: str, count: int) -> str:
    return "" if count == 0 else f"({item}{_nested(item, count - 1)})?"


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(ITEMS), st.integers(0, 3), st.integers(1, 6))
def test_a_bounded_repeat_compiles_as_its_nested_spelling(item, low, extra):
    counted = compile_automaton(parse(f"{item}{{{low},{low + extra}}}"))
    spelled = compile_automaton(parse("".join([item] * low) + _nested(item, extra)))
    assert counted == spelled


REPO = Path(__file__).resolve().parents[2]
NUSCENES = "nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-0061.pkl"
NESTED = "[" + "E(x := [:car:]) " * 94 + "x]"
PEAK_RSS = """
import re, sys
from pathlib import Path
from scenegrep.cli.main import main
code = main(["spre", "--space", "topdown", sys.argv[1], sys.argv[2]])
print(code, int(re.search(r"VmHWM:\\s+(\\d+) kB", Path("/proc/self/status").read_text())[1]) // 1024)
"""
"""Runs a query and prints its exit code and the process's own peak RSS in MB (VmHWM: getrusage's
ru_maxrss would also count the forked test worker's pages from before the exec)."""


@pytest.mark.real_data
def test_nested_quantifiers_over_a_real_trace_are_a_bounded_one_line_error(real_data):
    """94 nested quantifiers over every car of a nuScenes scene: before any work, the
    quantifier whose object combinations pass the per-frame limit is named with the frame; a
    per-trace error, of the lone trace given: a user error (exit 2), in seconds and under 500 MB peak RSS."""
    began = time.perf_counter()
    run = subprocess.run(
        [sys.executable, "-c", PEAK_RSS, NESTED, str(real_data / NUSCENES)],
        capture_output=True,
        text=True,
        env={**os.environ, "PYTHONPATH": str(REPO / "src")},
        timeout=60,
    )
    elapsed = time.perf_counter() - began
    code, rss_mb = map(int, run.stdout.split())
    failed = [line for line in run.stderr.splitlines() if line.startswith("scenegrep: error:")]
    assert code == 2 and len(failed) == 1, run.stderr[:500]
    column = 1 + 4 * len("E(x := [:car:]) ") + 1
    assert f"<query>:1:{column}: nested quantifiers make more than {MAX_ROWS_PER_FRAME}" in failed[0]
    assert "(frame " in failed[0] and "Traceback" not in run.stderr
    assert rss_mb < 500 and elapsed < 20, (rss_mb, elapsed)


def test_nested_quantifiers_over_a_long_trace_answer():
    """Three nested quantifiers over a 100,000-frame trace with two cars per frame (every frame
    within the per-frame limit) answer: each frame matches."""
    cars = [[("car", 10, 10, 4, 4), ("car", 50, 50, 4, 4)]]
    trace = image_trace([cars] * 100_000 + [[[]]])
    query = "[E(x := [:car:]) (E(y := [:car:]) (E(z := [:car:]) (z & @dist(x, y) > 1)))]"
    assert frames_matching(query, trace) == list(range(100_000))


def test_the_per_frame_limit_is_exact():
    """A frame just within the limit (316 squared rows) answers; 317 squared is refused at the inner quantifier."""
    side = round(MAX_ROWS_PER_FRAME ** (1 / 2))
    query = compile_query("[E(x := [:car:]) (E(y := [:car:]) (x & y))]")
    trace = image_trace([[[("car", 10, 10, 4, 4)] * side]])
    assert [m.start for m in search(query, trace, online=True)] == [0]
    more = image_trace([[[("car", 10, 10, 4, 4)] * (side + 1)]])
    with pytest.raises(UserError, match=r"<query>:1:19: .* object combinations in one frame \(frame 0\)"):
        list(search(query, more, online=True))
