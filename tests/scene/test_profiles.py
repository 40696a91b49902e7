"""Tolerance profiles: their values are what benchmarks/label_noise.py measures on the real data,
explicit tolerances override them, and they work alike on the command line, in file and dataset
mode, and through a dataset query spec."""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import pytest

from scenegrep.cli.main import main
from scenegrep.dataset.queries import QuerySpec, match_trace
from scenegrep.errors import UserError
from scenegrep.scene import Tolerance
from scenegrep.scene.profiles import PROFILES, tolerance_of
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet
from tests.scene.frames import HEADER, MAP, trace_of

REPO = Path(__file__).resolve().parents[2]
PROGRAM = HEADER + "ego = new Car at (2, 30), facing 0, with regionContainedIn None\n"
# 1 m off in x (within every measured position tolerance but waymo's 0.83 m) and 0.06 rad off
# (within nuScenes' 0.084 rad, beyond waymo's and CommonRoad's)
TRACE = trace_of({"ego": ("Car", 3.0, 30.0, 0.06)})


def test_a_profile_gives_its_values_and_given_tolerances_replace_them():
    assert tolerance_of() == Tolerance() == PROFILES["exact"]
    assert tolerance_of("nuscenes") == PROFILES["nuscenes"] == Tolerance(1.4, 0.084, 0.011)
    assert tolerance_of("nuscenes", heading=0.5, position=None) == Tolerance(1.4, 0.5, 0.011)
    assert tolerance_of("waymo", speed=2.0) == Tolerance(0.83, 0.049, 2.0)
    assert tolerance_of(None, position=0.2) == Tolerance(0.2, 1e-6, 1e-6)


@pytest.mark.parametrize(
    ("profile", "given", "message"),
    [
        ("kitti", {}, "unknown tolerance profile 'kitti'; choose one of exact, av2, nuscenes, waymo, commonroad"),
        ("av2", {"heading": -1.0}, "tolerances must not be negative"),
        (None, {"speed_limit": 1.0}, "unknown tolerance 'speed_limit'"),
    ],
)
def test_bad_profiles_and_tolerances_are_user_errors(profile, given, message):
    with pytest.raises(UserError, match=message):
        tolerance_of(profile, **given)


@pytest.fixture
def files(tmp_path):
    (tmp_path / "at.scenic").write_text(PROGRAM)
    write_trace_json(TRACE, tmp_path / "trace.json")
    write_map_parquet(MAP, tmp_path / "map.parquet")
    return tmp_path


@pytest.mark.parametrize(
    ("options", "code"),
    [
        ([], 1),
        (["--tolerance-profile", "nuscenes"], 0),
        (["--tolerance-profile", "waymo"], 1),
        (["--tolerance-profile", "waymo", "--tolerance-position", "1.01", "--tolerance-heading", "0.061"], 0),
        (["--tolerance-profile", "nuscenes", "--tolerance-heading", "0.05"], 1),
        (["--tolerance-profile", "commonroad", "--tolerance-heading", "0.07"], 0),
    ],
)
def test_command_line_profiles_with_overrides(files, capsys, options, code):
    assert main(["scene", str(files / "at.scenic"), str(files / "trace.json"), "-q", *options]) == code


def test_an_unknown_profile_on_the_command_line_is_one_line(files, capsys):
    assert main(["scene", str(files / "at.scenic"), str(files / "trace.json"), "--tolerance-profile", "x"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("scenegrep: error: unknown tolerance profile 'x'")


@pytest.mark.parametrize(("options", "matched"), [({}, False), ({"tolerance_profile": "nuscenes"}, True)])
def test_dataset_query_specs_take_profiles(options, matched):
    spec = QuerySpec.of("scene", PROGRAM, **options)
    rows = match_trace(spec, TRACE, MAP)
    assert (rows[0]["status"] == "match") is matched


def test_dataset_specs_check_profiles_when_made():
    with pytest.raises(UserError, match="unknown tolerance profile"):
        QuerySpec.of("scenario", PROGRAM, window=5, tolerance_profile="nuScenes")


@pytest.mark.real_data
def test_profiles_are_the_measured_ones(real_data):
    """benchmarks/label_noise.py on ../shared/real_data gives exactly the profiles' values."""
    spec = importlib.util.spec_from_file_location("label_noise", REPO / "benchmarks" / "label_noise.py")
    noise = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(noise)
    for name, paths in noise.datasets(real_data).items():
        samples = noise.measure(paths)
        measured = noise.profile(samples)
        assert Tolerance(**measured) == PROFILES[name], name
        heading = samples["heading_vs_lane"]
        assert len(heading) > 1000 and math.isclose((heading <= PROFILES[name].heading).mean(), 0.9, abs_tol=0.01), name
