"""The library of real-situation queries as a whole (issue 16): at least 25 situations, each file
with its header, each runs on every recording of ../shared/real_data and on examples/sample
without a failed row. What each query finds is checked against the raw data in the other test
files of this folder."""

from __future__ import annotations

import pytest

from tests.library.catalog import LIBRARY, RECORDINGS, library, matches, read_query

pytestmark = pytest.mark.real_data


def test_the_library_holds_at_least_25_situations_each_with_its_header():
    queries = library()
    assert len(queries) >= 25, [q.name for q in queries]
    for found in queries:
        assert len(found.finds) > 20, found.name
        assert found.spec.kind in ("scenario", "scene", "spre")


def test_a_query_without_its_header_is_refused(tmp_path):
    bad = tmp_path / "bad.scenic"
    bad.write_text("ego = new Car\n")
    with pytest.raises(ValueError, match="Finds"):
        read_query(bad)
    wrong = tmp_path / "wrong.spre"
    wrong.write_text("# Finds: something quite long enough\n# Run: scenario window=3s\n")
    with pytest.raises(ValueError, match="must be a .scenic file"):
        read_query(wrong)


def test_every_query_file_of_the_folder_is_a_query():
    names = {p.stem for p in LIBRARY.iterdir() if p.suffix in (".scenic", ".spre")}
    assert names == {q.name for q in library()}


@pytest.mark.slow
@pytest.mark.parametrize("name", [q.name for q in library()])
def test_every_query_runs_on_every_recording_and_the_sample(name):
    for recording in (*RECORDINGS, "examples/sample"):
        matches(name, recording)


def test_the_library_readme_lists_every_query_with_what_it_finds():
    readme = (LIBRARY / "README.md").read_text(encoding="utf-8")
    for found in library():
        assert f"[`{found.name}`]({found.path.name}) | {found.finds} |" in readme, found.name
