"""Progress bars are drawn only when standard error is a terminal (:mod:`scenegrep.progress`)."""

import io
import os
import subprocess
import sys
from pathlib import Path

import scenegrep
from scenegrep import progress

REPO = Path(__file__).resolve().parents[1]
SRC = Path(scenegrep.__file__).parent


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def drawn(stream: io.StringIO, quiet: bool, monkeypatch) -> str:
    monkeypatch.setattr(sys, "stderr", stream)
    for _ in progress.bar(range(3), quiet, desc="counting"):
        pass
    return stream.getvalue()


def test_a_bar_is_drawn_on_a_terminal_only(monkeypatch):
    assert "counting" in drawn(Terminal(), False, monkeypatch)
    assert drawn(Terminal(), True, monkeypatch) == ""
    assert drawn(io.StringIO(), False, monkeypatch) == ""


def test_every_bar_is_made_by_the_helper():
    users = [p.relative_to(SRC) for p in SRC.rglob("*.py") if "tqdm" in p.read_text() and p.name != "progress.py"]
    assert users == []


def test_label_writes_no_progress_into_a_redirected_stderr(tmp_path):
    """Labelling the 42 sample traces takes over a second: long enough for the bar's half-second
    delay, which before wrote ``\\rlabelling: 25 traces ...`` into the file."""
    log = tmp_path / "log.txt"
    with log.open("w") as stderr:
        done = subprocess.run(
            [
                sys.executable,
                "-m",
                "scenegrep",
                "label",
                str(REPO / "examples" / "sample"),
                "-o",
                str(tmp_path / "out"),
            ],
            stdout=subprocess.DEVNULL,
            stderr=stderr,
            env={**os.environ, "PYTHONPATH": str(SRC.parent)},
            check=False,
        )
    assert done.returncode == 0
    text = log.read_text()
    assert "\r" not in text and "labelling" not in text and "traces/s" not in text
