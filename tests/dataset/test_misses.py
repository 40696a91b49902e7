"""Nearest misses over a dataset: the same miss, with the same suggestion, as over the file, and
its options make the frame match in the dataset too."""

from __future__ import annotations

import json
import re

import pytest

from scenegrep.cli.main import main

pytestmark = pytest.mark.real_data

FIG3 = "examples/scenes/fig3_car_ahead.scenic"
ANYWHERE = ["--unknown-layers", "permissive"]
"""nuScenes publishes no crosswalks (the labeller's) or shoulders (the cars' default container)."""
MISS = re.compile(r"scenegrep: nearest miss: (\S+) frame (\d+) \((.*?)\): .* \((--tolerance.*) would admit it\)")


def test_dataset_mode_reports_the_file_modes_nearest_miss(real_data, tmp_path, capsys):
    trace = str(real_data / "nuscenes_mini_scenarionet" / "sd_nuscenes_v1.0-mini_scene-0061.pkl")
    dataset = str(tmp_path / "ds")
    assert main(["ingest", trace, "--into", dataset, "-j", "1", *ANYWHERE]) == 0
    capsys.readouterr()
    assert main(["scene", FIG3, trace, "--visible-distance", "50", *ANYWHERE]) == 1
    over_file = MISS.search(capsys.readouterr().err)
    assert main(["scene", FIG3, "--dataset", dataset, "--visible-distance", "50", "-j", "1", "--json", *ANYWHERE]) == 1
    out, err = capsys.readouterr()
    over_dataset = MISS.search(err)
    assert over_file and over_dataset, err
    assert over_dataset[1] == "scene-0061" and over_dataset.groups()[1:] == over_file.groups()[1:]
    record = [json.loads(line) for line in out.splitlines() if '"nearest_miss"' in line]
    assert len(record) == 1 and record[0]["frame"] == int(over_dataset[2])
    options = over_dataset[4].split()
    assert main(["scene", FIG3, "--dataset", dataset, "--visible-distance", "50", "-j", "1", *options, *ANYWHERE]) == 0
    assert f"scene-0061:{over_dataset[2]}-{over_dataset[2]}" in capsys.readouterr().out
