"""The library's tests share per-process work (each input ingested once per unknown-layers
choice, each query run once over all of them: tests/library/catalog.py), so they run in one
test process: one xdist group (``--dist loadgroup`` in pyproject.toml)."""

from __future__ import annotations

from pathlib import Path

import pytest

HERE = Path(__file__).parent


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    for item in items:
        if HERE in item.path.parents:
            item.add_marker(pytest.mark.xdist_group("library"))
