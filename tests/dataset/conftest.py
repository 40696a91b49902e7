"""Fixtures of the dataset tests (the ingested real dataset is in tests/conftest.py)."""

from __future__ import annotations

from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
SAMPLE = REPO / "examples" / "sample"
SAMPLE_TRACES = 42
