"""Names from data reach terminals and pages escaped: control characters in trace names, object
ids, class names and channels are printed as ``\\xNN`` by every command, and a class name such as
``<!--<script>`` cannot break the HTML view's script or the report."""

from __future__ import annotations

import json
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.writers.file_names import file_stem

TRACE = "evil\x1b]0;pwned\x07"
CAR = "car\x1b[2J"
ODD = "p\x9b31m"
ODD_CLASS = "<!--<script>\x1b[31m"
RAW = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f]")
"""Control characters that must never be printed (newline and tab are allowed)."""


@pytest.fixture
def evil(tmp_path):
    """A three-frame scenegrep JSON trace whose file name and names hold escape sequences and
    ``<!--<script>``."""
    box = {"center": [10, 10], "size": [5, 5]}
    frames = [
        {
            "objects": {CAR: {"position": [0, 5 * k], "heading": 0.0}, ODD: {"position": [3, 5 * k], "heading": 0.0}},
            "samples": [
                {
                    "channel": "cam\x1b[1m",
                    "image_size": [100, 100],
                    "boxes": [{"class": ODD_CLASS, **box, "object": ODD}, {"class": "car", **box, "object": CAR}],
                }
            ],
        }
        for k in range(3)
    ]
    document = {
        "scenegrep": "trace",
        "version": 1,
        "name": TRACE,
        "frame_interval": 0.1,
        "objects": {CAR: {"class": "Car", "size": [4.5, 2, 1.5]}, ODD: {"class": ODD_CLASS, "size": [0.5, 0.5, 1.8]}},
        "frames": frames,
    }
    path = tmp_path / "evil\x1b[2J.json"
    path.write_text(json.dumps(document))
    program = tmp_path / "q.scenic"
    program.write_text("ego = new Object\nother = new Object at ego offset by (3, 0)\n")
    return path, program


def _printed(capsys) -> str:
    captured = capsys.readouterr()
    text = captured.out + captured.err
    assert not RAW.search(text), repr(text)
    return text


@pytest.mark.parametrize(
    "command, shown",
    [
        (["info"], [TRACE, ODD_CLASS, "cam\x1b[1m"]),
        (["scene", "PROGRAM"], [CAR, ODD]),
        (["spre", "[[:car:]]"], [TRACE]),
    ],
)
def test_commands_print_names_escaped(evil, capsys, command, shown):
    path, program = evil
    argv = [str(program) if a == "PROGRAM" else a for a in command] + [str(path)]
    assert main(argv) == 0
    text = _printed(capsys)
    for name in shown:
        assert name.encode("unicode_escape").decode().replace("\\u009b", "\\x9b") in text


def test_an_error_line_quoting_the_input_is_escaped(tmp_path, capsys):
    path = tmp_path / "bad.json"
    path.write_bytes(b'{"version": "0.2.0", "frames": [\x1b[2J]}')
    assert main(["spre", "[[:car:]]", str(path)]) == 2  # the lone file fails; its error line is escaped
    assert "\\x1b" in _printed(capsys)


def _script_data(page: str) -> dict:
    data = re.search(r'<script id="scenegrep-data" type="application/json">(.*?)</script>', page, re.S)
    assert data is not None, "the data script is cut short"
    assert "<" not in data.group(1)
    return json.loads(data.group(1))


def test_the_view_page_keeps_its_script_whole(evil, tmp_path, capsys):
    path, _ = evil
    out = tmp_path / "v.html"
    assert main(["show", str(path), "-o", str(out), "-q"]) == 0
    page = out.read_text()
    assert json.dumps(ODD_CLASS)[1:-1] in json.dumps(_script_data(page))


def test_the_report_and_its_views_keep_their_markup(evil, tmp_path, capsys):
    path, program = evil
    dataset = tmp_path / "ds"
    assert main(["ingest", str(path), "--into", str(dataset), "-q"]) == 0
    assert main(["scene", str(program), "--dataset", str(dataset), "-q"]) == 0
    results = next(dataset.glob("runs/*/results.parquet"))
    report = tmp_path / "report.html"
    assert main(["report", str(results), "-o", str(report), "-q"]) == 0
    _printed(capsys)
    assert "<!--" not in report.read_text()
    views = list(tmp_path.glob("report_views/*.html"))
    assert views
    for view in views:
        _script_data(view.read_text())


@settings(max_examples=300, deadline=None)
@given(st.text(), st.integers(1, 200))
def test_file_stems_stay_in_their_folder(text, limit):
    """Any name from data becomes a file name part that is non-empty, at most ``limit`` characters,
    of safe characters only, and never hidden, ``.`` or ``..``."""
    stem = file_stem(text, limit)
    assert re.fullmatch(r"[A-Za-z0-9._-]+", stem)
    assert len(stem) <= max(limit, len("trace"))
    assert not stem.startswith(".") and stem not in (".", "..")
    if re.fullmatch(r"[A-Za-z0-9][A-Za-z0-9._-]*[A-Za-z0-9]", text) and len(text) <= limit:
        assert stem == text
