"""A dataset of every real recording and the sample traces, ingested once per test process."""

from __future__ import annotations

from pathlib import Path

import pytest

from scenegrep.dataset.ingest import ingest

REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "examples" / "sample"
SAMPLE_TRACES = 42


@pytest.fixture(scope="session")
def real_dataset(real_data: Path, tmp_path_factory) -> Path:
    """../shared/real_data and examples/sample ingested with two workers (do not modify it:
    tests that change a dataset copy it first)."""
    root = tmp_path_factory.mktemp("dataset") / "fleet"
    report = ingest([str(real_data), str(SAMPLE)], root, jobs=2)
    assert not report.failed, report.failed
    return root
