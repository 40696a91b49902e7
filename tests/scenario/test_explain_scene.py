"""Scenario ``--explain`` when the behaviours fit but the initial scene fails: it names the frame,
the program object and its label object, the failing features, and the tolerance that would
admit them; given back as an option, that tolerance makes the trace match."""

from __future__ import annotations

import re
from dataclasses import replace

import numpy as np

from scenegrep.cli.main import main
from scenegrep.scene.misses import SLACK
from scenegrep.writers.trace_json import write_trace_json
from scenegrep.writers.trace_parquet import write_map_parquet

from .worked_example import worked_map, worked_trace

FIG1 = "examples/queries/fig1_lane_change.scenic"


def test_explain_names_the_failing_feature_object_and_frame(tmp_path, capsys):
    """Table 2 with both cars turned 0.1 rad off their lane's direction: car2's behaviours still
    match from frame 0, but a Car's heading is its road's direction in Fig. 1's initial scene."""
    trace = worked_trace()
    trace = replace(trace, states=replace(trace.states, heading=np.full(len(trace.states), 0.1)))
    write_trace_json(trace, tmp_path / "turned.json")
    write_map_parquet(worked_map(), tmp_path / "map.parquet")
    base = [FIG1, str(tmp_path / "turned.json"), "--window", "5", "--map", str(tmp_path / "map.parquet")]
    assert main(["scenario", *base, "--explain"]) == 1
    out = capsys.readouterr().out
    found = re.search(
        r"at frame 0 \(t = 0\.00 s\), with ego = car2, it fails ego\.heading: "
        r"ego\.heading off by ([\d.]+) rad \(--tolerance-heading \1 would admit it\)",
        out,
    )
    assert found, out
    value = float(found[1])
    assert 0.1 <= value <= 0.1 * (1 + SLACK)
    assert main(["scenario", *base, "--tolerance-heading", found[1]]) == 0
    assert main(["scenario", *base, "--tolerance-heading", str(value * (1 - SLACK))]) == 1
