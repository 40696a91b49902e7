"""``scenegrep serve``'s GET pages (``/``, ``/view/...``, ``/report/...``) need no token: they change
nothing, and the names a request gives (a trace id, a run id, raw, ``../``, absolute or
percent-encoded) reach no file outside the dataset, nor one of it that is not a run's or a trace's;
nor does a catalog that names files outside it (a stranger's dataset)."""

from __future__ import annotations

import hashlib
import json
import shutil
import threading
from pathlib import Path
from urllib.parse import quote

import pytest

from scenegrep.dataset import open_dataset
from scenegrep.dataset.catalog import Catalog
from scenegrep.dataset.ingest import ingest
from scenegrep.dataset.run import RunOptions
from scenegrep.errors import UserError
from scenegrep.view.serve import DatasetServer
from tests.conftest import REPO
from tests.view.conftest import fetch

TRACES = ("fig1_lane_change-000.parquet", "fig1_lane_change-001.parquet")


@pytest.fixture
def small(tmp_path: Path) -> tuple[Path, str, str]:
    """A dataset of two sample traces (their map beside them, as in examples/) with one SpRE run:
    its folder, a trace id and the run id; a results table lies at its top (not a run's)."""
    (tmp_path / "in" / "sample").mkdir(parents=True)
    shutil.copy(REPO / "examples" / "sample" / "Town06.xodr", tmp_path / "in" / "sample")
    for name in TRACES:
        shutil.copy(REPO / "examples" / "sample" / name, tmp_path / "in" / "sample")
    root = tmp_path / "fleet"
    assert not ingest([str(tmp_path / "in" / "sample")], root, jobs=1, label=False).failed
    run = open_dataset(root).spre("[[:car:]]+", run=RunOptions(jobs=1))
    shutil.copy(root / "runs" / run.run_id / "results.parquet", root / "results.parquet")
    trace_id = run.table["trace_id"][0].as_py()
    return root, trace_id, run.run_id


@pytest.fixture
def serving(small):
    """A server over the small dataset, in a thread of this process."""
    root = small[0]
    with DatasetServer(root, 0, jobs=1) as httpd:
        thread = threading.Thread(target=httpd.serve_forever, daemon=True)
        thread.start()
        yield httpd, *small
        httpd.shutdown()


def _snapshot(root: Path) -> dict[str, tuple[int, str]]:
    """Every file of the dataset folder: its modification time and content hash."""
    return {
        str(p.relative_to(root)): (p.stat().st_mtime_ns, hashlib.sha256(p.read_bytes()).hexdigest())
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _get(server: DatasetServer, path: str) -> tuple[int, bytes]:
    """A GET as any page may send it: without the token."""
    return fetch(server, path, headers={"X-Scenegrep-Token": None})


def test_get_pages_need_no_token_and_change_nothing(serving):
    server, root, trace_id, run_id = serving
    before = _snapshot(root)
    for path in ("", f"view/{quote(trace_id)}", f"view/{quote(trace_id)}?run={run_id}", f"report/{run_id}"):
        status, page = _get(server, path)
        assert status == 200 and page.startswith(b"<!DOCTYPE html>"), path
    for path in ("view/nope", "report/nope", f"view/{quote(trace_id)}?run=nope"):
        assert _get(server, path)[0] == 400, path
    assert _snapshot(root) == before


RUN_NAMES = ("..", ".", "../..", "../../etc", "/etc/passwd", "runs/..", "%2e%2e", "..%2F..", "%252e%252e", "")


@pytest.mark.parametrize("name", RUN_NAMES)
def test_a_run_name_reaches_only_the_runs_of_the_dataset(serving, name):
    """``..`` names the dataset's own folder, whose ``results.parquet`` is no run's: refused as every
    other name that is not a run of the catalog; the message names no absolute path."""
    server, root, trace_id, _ = serving
    encoded = quote(name, safe="%")
    for path in (f"report/{encoded}", f"view/{quote(trace_id)}?run={encoded}"):
        status, body = _get(server, path)
        if path.endswith("?run=") or path == "report/":
            assert status in (200, 404), path  # no run named: the plain view, or no such page
            continue
        assert status == 400 and "the dataset has no run" in json.loads(body)["error"], (path, body[:200])
        assert str(root).encode() not in body and str(root.parent).encode() not in body


@pytest.mark.parametrize("name", ["../x", "/etc/passwd", "..%2F..%2Fetc%2Fpasswd", "%2Fetc%2Fpasswd", "%252e%252e"])
def test_a_trace_name_is_only_looked_up_in_the_catalog(serving, name):
    """A trace id is a key of the catalog, never a path: unknown ids are refused (as are paths of
    more than two parts: no such page)."""
    server, *_ = serving
    status, body = _get(server, f"view/{name}")
    error = json.loads(body)["error"]
    assert (status == 400 and "the dataset has no trace" in error) or (status == 404 and "no page" in error), error


def _name_outside(root: Path, trace_id: str, where: str) -> None:
    """Make the catalog name a copy of a trace outside the dataset as the trace's file (a
    stranger's dataset): by its absolute path or by ``../``."""
    outside = root.parent / "outside.parquet"
    shutil.copy(REPO / "examples" / "sample" / TRACES[0], outside)
    named = str(outside) if where == "absolute" else "../outside.parquet"
    with Catalog(root) as catalog:
        catalog.db.execute("UPDATE traces SET file = ? WHERE trace_id = ?", [named, trace_id])


@pytest.mark.parametrize("where", ["absolute", "relative"])
def test_a_catalog_naming_a_file_outside_the_dataset_is_refused(serving, where):
    """The view refuses to read a trace file the catalog names outside the dataset, in one line
    that names no absolute path."""
    server, root, trace_id, _ = serving
    _name_outside(root, trace_id, where)
    status, body = _get(server, f"view/{quote(trace_id)}")
    assert status == 400 and "outside the dataset" in json.loads(body)["error"], body[:300]
    assert str(root.parent).encode() not in body


@pytest.mark.parametrize("where", ["absolute", "relative"])
def test_a_query_over_a_catalog_naming_a_file_outside_the_dataset_is_refused(small, where):
    root, trace_id, _ = small
    _name_outside(root, trace_id, where)
    with pytest.raises(UserError, match="the catalog names a file outside the dataset"):
        open_dataset(root).spre("[[:car:]]", run=RunOptions(jobs=1))
