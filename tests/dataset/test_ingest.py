"""Ingest: every real input and the generated sample, incremental, atomic, bad sources reported."""

from __future__ import annotations

import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from scenegrep import readers
from scenegrep.dataset.catalog import Catalog
from scenegrep.dataset.ingest import COMMIT_EVERY, discover, ingest
from scenegrep.label import LABELLER_VERSION, label_trace

from ..readers.real_inputs import REAL_TRACES
from .conftest import SAMPLE, SAMPLE_TRACES

pytestmark = pytest.mark.real_data

CATALOG_COLUMNS = "trace_id, name, source_path, file, map_id, frames, objects, observations, has_behaviours"


def catalog_state(root: Path) -> dict[str, list]:
    """The catalog's content without times: traces, and the per-trace tables' row counts."""
    with Catalog(root, read_only=True) as catalog:
        return {
            "traces": catalog.rows(f"SELECT {CATALOG_COLUMNS} FROM traces ORDER BY trace_id"),
            "sources": catalog.rows("SELECT path, format, checksum, traces FROM sources ORDER BY path"),
            "counts": catalog.rows(
                "SELECT (SELECT count(*) FROM objects), (SELECT sum(count) FROM frame_counts), "
                "(SELECT sum(observations) FROM labels)"
            ),
        }


def test_discovers_every_real_recording_and_sample_trace(real_data: Path):
    sources, errors = discover([str(real_data), str(SAMPLE)])
    assert errors == []
    found = {(s.path, s.format) for s in sources}
    for path, format_name in REAL_TRACES:
        assert (str((real_data / path).resolve()), format_name) in found
    assert sum(1 for s in sources if s.path.startswith(str(SAMPLE))) == SAMPLE_TRACES
    assert len(sources) == len(REAL_TRACES) + SAMPLE_TRACES  # no README, checksum file, map or manifest


def test_every_trace_is_ingested_with_its_statistics(real_dataset: Path, real_data: Path):
    with Catalog(real_dataset, read_only=True) as catalog:
        traces = catalog.sql("SELECT * FROM traces").to_pylist()
        assert len(traces) == len(REAL_TRACES) + SAMPLE_TRACES
        for path, _ in REAL_TRACES[:3] + REAL_TRACES[-1:]:
            source = str((real_data / path).resolve())
            (row,) = [t for t in traces if t["source_path"] == source]
            original = readers.read_trace(source)
            stored = readers.read_trace(real_dataset / row["file"])
            assert (row["frames"], row["objects"], row["observations"]) == (
                original.n_frames,
                original.n_objects,
                len(original.states),
            )
            road_map = readers.read_map(
                real_dataset / catalog.rows("SELECT file FROM maps WHERE map_id = ?", [row["map_id"]])[0][0]
            )
            assert stored.equals(label_trace(original, readers.read_map(original.map_source)).trace)
            assert len(road_map.lanes) == len(readers.read_map(original.map_source).lanes)
            per_frame = catalog.rows(
                "SELECT frame, sum(count) FROM frame_counts WHERE trace_id = ? AND layer = 'objects' GROUP BY frame "
                "ORDER BY frame",
                [row["trace_id"]],
            )
            present = original.present().sum(axis=1)
            assert per_frame == [(f, int(c)) for f, c in enumerate(present.tolist()) if c]


def test_reingest_skips_unchanged_sources(real_dataset: Path, real_data: Path, tmp_path: Path):
    root = tmp_path / "copy"
    shutil.copytree(real_dataset, root)
    before = catalog_state(root)
    report = ingest([str(real_data), str(SAMPLE)], root, jobs=1)
    assert (report.ingested, report.unchanged, report.failed) == (0, len(REAL_TRACES) + SAMPLE_TRACES, [])
    assert catalog_state(root) == before


def test_a_changed_source_replaces_its_traces(real_data: Path, tmp_path: Path):
    source = tmp_path / "scene.xml"
    shutil.copy(real_data / "commonroad_ngsim/USA_Peach-4_8_T-1.xml", source)
    root = tmp_path / "ds"
    assert ingest([str(source)], root, jobs=1).ingested == 1
    first = catalog_state(root)
    source.write_text(source.read_text() + "\n<!-- edited -->\n")
    report = ingest([str(source)], root, jobs=1)
    assert (report.ingested, report.unchanged) == (1, 0)
    second = catalog_state(root)
    assert second["traces"] == first["traces"]
    assert second["sources"][0][2] != first["sources"][0][2]
    assert sorted(p.name for p in (root / "traces").iterdir()) == [Path(first["traces"][0][3]).name]


def test_a_newer_labeller_labels_an_ingested_source_again(real_data: Path, tmp_path: Path, monkeypatch):
    source = tmp_path / "scene.xml"
    shutil.copy(real_data / "commonroad_ngsim/USA_Peach-4_8_T-1.xml", source)
    root = tmp_path / "ds"
    assert ingest([str(source)], root, jobs=1).ingested == 1
    assert ingest([str(source)], root, jobs=1).unchanged == 1
    monkeypatch.setattr("scenegrep.label.LABELLER_VERSION", LABELLER_VERSION + 1)
    report = ingest([str(source)], root, jobs=1)
    assert (report.ingested, report.unchanged) == (1, 0)
    assert catalog_state(root)["sources"][0][2].endswith(f"labeller {LABELLER_VERSION + 1}")
    # without labelling, the labeller's version does not matter
    assert ingest([str(source)], tmp_path / "plain", jobs=1, label=False).ingested == 1
    assert ingest([str(source)], tmp_path / "plain", jobs=1, label=False).unchanged == 1


def test_bad_sources_are_reported_and_the_rest_ingested(real_data: Path, tmp_path: Path):
    broken = tmp_path / "broken.xml"
    broken.write_text("<commonRoad><obstacle>")
    good = real_data / "commonroad_ngsim/USA_Peach-4_8_T-1.xml"
    root = tmp_path / "ds"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "scenegrep",
            "ingest",
            str(broken),
            str(tmp_path / "missing.json"),
            str(good),
            "--into",
            str(root),
        ],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 3
    errors = [line for line in result.stderr.splitlines() if line.startswith("scenegrep: error:")]
    assert len(errors) == 2
    assert str(broken) in errors[0] or str(broken) in errors[1]
    assert "Traceback" not in result.stderr
    state = catalog_state(root)
    assert [t[1] for t in state["traces"]] == ["USA_Peach-4_8_T-1"]
    with Catalog(root, read_only=True) as catalog:
        assert len(catalog.rows("SELECT * FROM source_errors")) == 2


@pytest.mark.slow
def test_kill_during_ingest_leaves_an_openable_dataset_that_a_rerun_completes(tmp_path: Path):
    root = tmp_path / "ds"
    command = [sys.executable, "-m", "scenegrep", "ingest", str(SAMPLE), "--into", str(root), "-j", "1", "-q"]
    process = subprocess.Popen(command, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and len(list((root / "traces").glob("*.parquet"))) < COMMIT_EVERY + 4:
        time.sleep(0.01)
    process.send_signal(signal.SIGKILL)
    process.wait()
    with Catalog(root, read_only=True) as catalog:
        visible = catalog.rows("SELECT file FROM traces")
    assert 0 < len(visible) < SAMPLE_TRACES, "the kill must come in the middle of the ingest"
    assert all((root / f).is_file() for (f,) in visible)
    assert readers.read_trace(root / visible[0][0]).n_frames > 0
    assert subprocess.run(command).returncode == 0
    fresh = tmp_path / "fresh"
    ingest([str(SAMPLE)], fresh, jobs=2)
    assert catalog_state(root) == catalog_state(fresh)
    assert not list((root / "traces").glob(".*.tmp"))
