"""Grammar of user-facing messages (:mod:`scenegrep.wording`): "1 object", "2 objects", "an
OpenDRIVE", never "(0 to -1)" nor "trace(s)"; held in the messages of the commands."""

import re
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

import scenegrep
from scenegrep.cli.main import main
from scenegrep.wording import article, counted, listed, numbered, plural, verb

SRC = Path(scenegrep.__file__).parent
REPO = SRC.parents[1]
BG1 = "examples/sample/bg1_following_traffic-000.parquet"


@pytest.mark.parametrize(
    ("noun", "one", "two"),
    [
        ("object", "1 object", "2 objects"),
        ("match", "1 match", "2 matches"),
        ("class", "1 class", "2 classes"),
        ("category", "1 category", "2 categories"),
        ("day", "1 day", "2 days"),
        ("trace view", "1 trace view", "2 trace views"),
    ],
)
def test_a_count_takes_its_noun_in_its_number(noun, one, two):
    assert (counted(1, noun), counted(2, noun), counted(0, noun)) == (one, two, "0 " + two[2:])


def test_verbs_articles_and_lists():
    assert [verb(1, "match"), verb(0, "match"), verb(1, "be"), verb(3, "be"), verb(1, "have"), verb(2, "lack")] == [
        "matches",
        "match",
        "is",
        "are",
        "has",
        "lack",
    ]
    words = ["OpenDRIVE road network", "MCAP file", "Parquet file", "CSV file", "animal", "user", "unknown"]
    assert [article(w) for w in words] == ["an", "an", "a", "a", "an", "a", "an"]
    assert listed([]) == "none" and listed(["b", "a"]) == "a, b" and listed(map(str, range(30))).endswith(", ...")


@given(st.integers(min_value=-3, max_value=10_000))
def test_a_numbered_range_is_never_empty_or_backwards(n):
    text = numbered(n, "frame")
    assert "-1" not in text and "(0 to 0)" not in text
    assert text == ("no frames" if n <= 0 else "1 frame (0)" if n == 1 else f"{n} frames (0 to {n - 1})")
    assert plural("frame", n) in text


def test_no_message_keeps_the_old_forms():
    """'(s)' plurals, 'a {...}' before a name of either sound and '0 to {n - 1}' ranges are gone."""
    bad = re.compile(r'f".*(\w\(s\)|\ba \{|0 to \{[^}]*- 1\})')
    found = [
        f"{p.relative_to(SRC)}:{k}"
        for p in SRC.rglob("*.py")
        if p.name != "wording.py"
        for k, line in enumerate(p.read_text().splitlines(), 1)
        if bad.search(line)
    ]
    assert found == []


def test_commands_say_1_trace_and_no_matches(capsys, monkeypatch, tmp_path):
    monkeypatch.chdir(REPO)
    assert main(["spre", "[[:car:]]", BG1]) == 0
    assert capsys.readouterr().err.splitlines()[-1] == "scenegrep: 1 of 1 trace matches, 0 pruned, 0 failed"
    table = tmp_path / "none.parquet"
    assert main(["spre", "[[:pedestrian:]]", BG1, "-o", str(table)]) == 1
    capsys.readouterr()
    assert main(["show", str(table), "--match", "0", "-o", str(tmp_path / "x.png")]) == 2
    assert capsys.readouterr().err.strip() == "scenegrep: error: --match 0: the results have no matches"
