"""Paths of the synthetic-data tests (the shared Scenic cache fixture is in tests/conftest.py)."""

from tests.conftest import REPO

SCENARIOS = REPO / "examples" / "scenarios"
