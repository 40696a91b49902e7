"""Fixtures of the synthetic-data tests: one user cache for the simulation tests, so each
CARLA town is parsed by Scenic once per run (seconds) rather than once per test."""

import pytest

from tests.conftest import REPO

SCENARIOS = REPO / "examples" / "scenarios"


@pytest.fixture(scope="package")
def scenic_cache(tmp_path_factory):
    """A fresh scenegrep cache (``$SCENEGREP_CACHE``) for the tests that ask for it."""
    folder = tmp_path_factory.mktemp("scenic-cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SCENEGREP_CACHE", str(folder))
        yield folder
