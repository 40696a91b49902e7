"""Checks across every reader on every real recording: detection, Parquet round trips,
headings against motion, maps."""

import numpy as np
import pytest

from scenegrep import readers
from scenegrep.errors import UserError
from scenegrep.model.kinematics import heading_motion_error
from scenegrep.readers.trace_parquet import read_trace as read_parquet
from scenegrep.writers import write_map_parquet, write_trace_parquet
from tests.readers.real_inputs import REAL_MAPS, REAL_TRACES

pytestmark = pytest.mark.real_data


@pytest.mark.parametrize("relative, expected", REAL_TRACES + REAL_MAPS)
def test_detect_format(real_data, relative, expected):
    assert readers.detect_format(real_data / relative) == expected


@pytest.mark.parametrize("relative, expected", REAL_TRACES)
def test_parquet_round_trip_is_equal(real_data, tmp_path, relative, expected):
    for k, trace in enumerate(readers.read_traces(real_data / relative)):
        assert read_parquet(write_trace_parquet(trace, tmp_path / f"{k}.parquet")).equals(trace)


@pytest.mark.parametrize("relative, expected", REAL_TRACES)
def test_vehicle_headings_agree_with_motion(real_data, relative, expected):
    """Moving vehicles (> 2 m/s) point the way they move: 90 % within 30 degrees in every
    recording (the rest are reversing or noisy tracks); this checks every reader's yaw conversion."""
    for trace in readers.read_traces(real_data / relative):
        error = heading_motion_error(trace.states, trace.frame_time)
        vehicles = np.isin(trace.objects.kinds()[trace.states.object], ["car", "truck", "bus"])
        moving = error[vehicles & ~np.isnan(error)]
        assert len(moving) > 50
        assert np.mean(moving < np.radians(30)) > 0.9


@pytest.mark.parametrize("relative, expected", REAL_TRACES)
def test_maps_load_and_round_trip(real_data, tmp_path, relative, expected):
    from scenegrep.readers.trace_parquet import read_map as read_map_parquet

    trace = next(iter(readers.read_traces(real_data / relative)))
    road_map = readers.read_map(trace.map_source)
    assert len(road_map.lanes) > 10
    assert read_map_parquet(write_map_parquet(road_map, tmp_path / "m.parquet")).equals(road_map)


def test_unknown_and_missing_inputs(tmp_path):
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(UserError, match="unrecognised input format"):
        readers.detect_format(tmp_path / "notes.txt")
    with pytest.raises(UserError, match="no such file"):
        readers.detect_format(tmp_path / "absent.json")
    with pytest.raises(UserError, match="neither an Argoverse 2 log or scenario nor holds trace files"):
        readers.detect_format(tmp_path)


def test_map_only_file_holds_no_trace(real_data):
    path, _ = REAL_MAPS[0]
    with pytest.raises(UserError, match="holds no label trace"):
        readers.read_trace(real_data / path)
