"""A catalog another process is writing is waited for (briefly), then a one-line user error."""

from __future__ import annotations

import subprocess
import sys
import time

import pytest

from scenegrep.dataset import catalog as catalog_module
from scenegrep.dataset.catalog import Catalog
from scenegrep.errors import UserError

HOLD = """
import sys, time, duckdb
db = duckdb.connect(sys.argv[1])
print("held", flush=True)
time.sleep(float(sys.argv[2]))
db.close()
"""


def _holder(path, seconds: float) -> subprocess.Popen:
    """A process that holds a writing connection to ``path`` for ``seconds`` (once it printed)."""
    holder = subprocess.Popen([sys.executable, "-c", HOLD, str(path), str(seconds)], stdout=subprocess.PIPE, text=True)
    assert holder.stdout.readline().strip() == "held"
    return holder


def test_a_catalog_held_briefly_by_another_process_opens_when_it_is_released(tmp_path):
    Catalog(tmp_path, create=True).close()
    holder = _holder(tmp_path / "catalog.duckdb", 1.0)
    began = time.monotonic()
    with Catalog(tmp_path, read_only=True) as catalog:
        assert catalog.db.execute("SELECT 1").fetchone() == (1,)
    assert time.monotonic() - began >= 0.5  # it waited for the holder
    holder.wait(10)


def test_a_catalog_held_past_the_wait_is_a_one_line_error(tmp_path, monkeypatch):
    Catalog(tmp_path, create=True).close()
    monkeypatch.setattr(catalog_module, "LOCK_WAIT", 0.3)
    holder = _holder(tmp_path / "catalog.duckdb", 5.0)
    try:
        with pytest.raises(UserError, match="cannot open the catalog: .*lock") as caught:
            Catalog(tmp_path)
        assert "\n" not in caught.value.one_line()
    finally:
        holder.kill()
        holder.wait()
