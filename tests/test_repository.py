"""The repository holds sources only: no compiled or packaging artefacts, and the ones an
install or a test run makes are ignored (so a fresh clone stays clean after them)."""

import re
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
ARTEFACT = re.compile(r"\.(so|pyd|o|pyc|dylib|dll)$|(^|/)(build|dist|__pycache__|[^/]+\.egg-info)/")
MADE_BY_INSTALL_OR_TESTS = [
    "src/scenegrep/readers/_x.cpython-311-x86_64-linux-gnu.so",
    "src/scenegrep/readers/_x.cp311-win_amd64.pyd",
    "build/lib/scenegrep/__init__.py",
    "src/scenegrep.egg-info/PKG-INFO",
    "src/scenegrep/__pycache__/x.cpython-311.pyc",
    ".venv/bin/python",
    ".pytest_cache/README.md",
    ".hypothesis/examples/x",
    ".ruff_cache/CACHEDIR.TAG",
]

pytestmark = pytest.mark.skipif(
    shutil.which("git") is None or not (REPO / ".git").exists(), reason="not a git checkout"
)


def git(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(["git", *args], cwd=REPO, capture_output=True, text=True)


def test_no_compiled_or_packaging_artefacts_are_tracked():
    tracked = git("ls-files").stdout.splitlines()
    assert tracked and [path for path in tracked if ARTEFACT.search(path)] == []


def test_what_an_install_or_a_test_run_makes_is_ignored():
    ignored = git("check-ignore", "--no-index", *MADE_BY_INSTALL_OR_TESTS).stdout.splitlines()
    assert sorted(ignored) == sorted(MADE_BY_INSTALL_OR_TESTS)
