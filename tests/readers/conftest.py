"""Fixtures of the reader tests: the AV2 log 7fab2350 written once as a ROS 2 bag."""

from __future__ import annotations

from pathlib import Path

import pytest

from scenegrep import readers
from scenegrep.model import LabelTrace

from scenegrep.writers.ros_bag import ORIGIN_NS, write_tracked

AV2_LOG = "av2/sensor/7fab2350-7eaf-3b7e-a39d-6937a4c1bede"


@pytest.fixture(scope="session")
def av2_bag(real_data, tmp_path_factory) -> tuple[LabelTrace, Path]:
    """The AV2 log's trace and its bag (TrackedObjects + /tf, one message of each per frame)."""
    trace = readers.read_trace(real_data / AV2_LOG)
    path = tmp_path_factory.mktemp("bags") / "av2.mcap"
    write_tracked(trace, path, ORIGIN_NS)
    return trace, path
