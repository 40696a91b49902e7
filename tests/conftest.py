"""Shared fixtures: where the real data is, and skipping when it is absent.

Tests that read ``../shared/real_data`` or ``../shared/maps`` use the fixtures here;
they skip with a message when the folder is absent (CI always has it, and
``.ci/run`` fails without it).
"""

from __future__ import annotations

import os
import signal
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

settings.register_profile("scenegrep", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "scenegrep"))

if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
    # A suite started in the background by a non-interactive shell (`cmd &`, nohup) ignores Ctrl-C,
    # and its subprocesses would inherit that; the tests that stop a command with SIGINT need the default.
    signal.signal(signal.SIGINT, signal.default_int_handler)

REPO = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("SCENEGREP_SHARED", REPO.parent / "shared"))


def _folder(name: str) -> Path:
    folder = SHARED / name
    if not folder.is_dir():
        pytest.skip(f"{folder} is absent: real-data tests need ../shared beside the repository")
    return folder


@pytest.fixture(scope="session")
def real_data() -> Path:
    """../shared/real_data (skips the test when absent)."""
    return _folder("real_data")


@pytest.fixture(scope="session")
def maps_dir() -> Path:
    """../shared/maps (skips the test when absent)."""
    return _folder("maps")


@pytest.fixture(scope="session")
def conformance_dir() -> Path:
    """../shared/conformance (skips the test when absent)."""
    return _folder("conformance")


@pytest.fixture(scope="session")
def scenic_cache(tmp_path_factory):
    """A fresh scenegrep cache (``$SCENEGREP_CACHE``) for the tests that simulate with Scenic, so each
    CARLA town is parsed by Scenic once per test process (seconds) rather than once per test."""
    folder = tmp_path_factory.mktemp("scenic-cache")
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("SCENEGREP_CACHE", str(folder))
        yield folder


@pytest.fixture(scope="session")
def real_dataset(real_data: Path, tmp_path_factory) -> Path:
    """../shared/real_data and examples/sample ingested with two workers, once per test process
    (do not modify it: tests that change a dataset copy it first). The labeller takes the crosswalks
    nuScenes maps do not publish as absent (``unknown_layers="strict"``)."""
    from scenegrep.dataset.ingest import ingest

    root = tmp_path_factory.mktemp("dataset") / "fleet"
    report = ingest([str(real_data), str(REPO / "examples" / "sample")], root, jobs=2, unknown_layers="strict")
    assert not report.failed, report.failed
    return root


@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Test files holding a ``slow`` test run first, each file's tests kept together (their
    module fixtures are built once): under ``pytest -n 2`` the long tests then start while the
    many short ones are still queued to fill in around them, instead of one long test at the end
    of the run leaving the other worker idle. (xdist's ``--dist loadgroup`` sends a group, such
    as tests/library's, before single tests.) The sort is stable: otherwise collection order.

    The tests that use :func:`real_dataset` (directly or through another fixture) form one xdist
    group: the ingest, and the session fixtures and per-process caches built on it (the view's
    query runs, tests/dataset/test_run.py's trace-by-trace reference), are then made by one
    worker, not by both."""
    slow_files = {item.path for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: item.path not in slow_files)
    for item in items:
        if "real_dataset" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.xdist_group("real_dataset"))
    _name_xdist_groups(config, items)


def _name_xdist_groups(config: pytest.Config, items: list[pytest.Item]) -> None:
    """On an xdist worker under ``--dist loadgroup``, end the node id of each test marked
    ``xdist_group(NAME)`` with ``@NAME``, which is how the controller sends a group to one worker.

    pytest-xdist 3.8 does this by setting ``item._nodeid``, which pytest 9 no longer reads (the
    node id is ``item._id``): without this the groups are silently ignored and their tests spread
    over both workers, each repeating the per-process work the group exists to share."""
    if not getattr(config.option, "loadgroup", False):
        return
    from _pytest.nodeid import NodeId

    for item in items:
        names = {
            str(m.args[0] if m.args else m.kwargs.get("name", "default")) for m in item.iter_markers("xdist_group")
        }
        suffix = "@" + "_".join(sorted(names))
        if names and not item.nodeid.endswith(suffix):
            item._id = NodeId.parse(item.nodeid + suffix)
