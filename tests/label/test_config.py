"""The thresholds file: the shipped one loads, a user's file is checked key by key."""

from __future__ import annotations

import pytest

from scenegrep.errors import UserError
from scenegrep.label import DEFAULT_CONFIG, load_config


def test_the_shipped_thresholds_load():
    config = load_config()
    assert config.vehicle.stationary_speed_mps == (0.8, 0.3)
    assert 0 < config.labels.min_confidence < 1


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: t.replace("smooth_s = 1.0", ""), "missing key tracks.smooth_s"),
        (
            lambda t: t.replace("brake_accel_mps2 = [-0.8, -1.5]", "brake_accel_mps2 = 3"),
            "vehicle.brake_accel_mps2 must be",
        ),
        (lambda t: t.replace("speed_mps = [0.8, 0.3]", "speed_mps = [0.5, 0.5]"), "two different ends"),
        (lambda t: t + "\nsurprise = 1\n", "unknown key pedestrian.surprise"),
        (lambda t: t + "\n[extra]\n", "unknown table [extra]"),
        (lambda t: t.replace("[labels]", "[labels"), "not a TOML file"),
    ],
)
def test_a_bad_thresholds_file_is_a_user_error(tmp_path, edit, message):
    path = tmp_path / "thresholds.toml"
    path.write_text(edit(DEFAULT_CONFIG.read_text()))
    with pytest.raises(UserError) as error:
        load_config(path)
    assert message in str(error.value) and str(path) in error.value.one_line()
