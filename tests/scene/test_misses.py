"""Nearest misses: the tolerances a miss reports admit its frame, the same with 0.2 % less of any
one of them do not, and on hand-built frames they equal the labels' offsets; on nuScenes, the
command-line suggestion, given back as options, makes the reported frame match."""

from __future__ import annotations

import math
import re
from dataclasses import fields, replace

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.scene import SceneOptions, Tolerance, compile_scene
from scenegrep.scene.misses import CAPS, SCALES, SLACK, UNITS, MissLimits, NearestMisses, nearest_miss, rounded
from tests.scene.frames import HEADER, MAP, ahead, right, trace_of

AT = compile_scene(HEADER + "ego = new Car at (2, 30), facing 0.3, with regionContainedIn None\n")
AHEAD = compile_scene(
    HEADER
    + "ego = new Car at (2, 30), facing 0, with regionContainedIn None\n"
    + "c = new Car ahead of ego by Range(4, 6), with regionContainedIn None\n"
)


def admits(query, frame: dict, tolerance: Tolerance) -> bool:
    return bool(query.match(trace_of(frame), MAP, SceneOptions(tolerance)).matched[0])


def miss_of(query, frame: dict):
    result = query.match(trace_of(frame), MAP, SceneOptions())
    assert not result.matched.any()
    return nearest_miss(result, np.array([0]))


def assert_smallest(query, frame: dict, miss) -> None:
    """The miss's tolerances admit the frame; lowering any one of them by SLACK does not."""
    tolerance = miss.tolerance(Tolerance())
    assert admits(query, frame, tolerance)
    for shortfall in miss.needed:
        lowered = replace(tolerance, **{shortfall.name: shortfall.value * (1 - SLACK)})
        assert not admits(query, frame, lowered), shortfall


offsets = st.one_of(st.just(0.0), st.floats(1e-3, 5.0), st.floats(-5.0, -1e-3))


@settings(max_examples=30, deadline=None)
@given(offsets, offsets, st.one_of(st.just(0.0), st.floats(-3.0, 3.0)))
def test_a_fixed_car_needs_its_offsets_and_no_less(dx, dy, dh):
    assume(abs(dx) > 1e-6 or abs(dy) > 1e-6 or abs(dh) > 1e-6)
    frame = {"ego": ("Car", 2 + dx, 30 + dy, 0.3 + dh)}
    miss = miss_of(AT, frame)
    expected = {"position": max(abs(dx), abs(dy)), "heading": abs(dh)}
    needed = {s.name: s.value for s in miss.needed}
    assert set(needed) == {name for name, value in expected.items() if value > 1e-6}
    for name, value in needed.items():
        assert expected[name] * (1 - 1e-9) <= value <= expected[name] * (1 + SLACK)
    assert_smallest(AT, frame, miss)


def test_a_random_gap_is_searched_and_the_offsets_blamed():
    """c may be 4..6 m ahead: the gap costs nothing, its 0.37 m lateral offset and 0.05 rad do (blamed on the
    features of c compared with each tolerance)."""
    x, y = right(*ahead(2, 30, 0, 4.5 + 5.0), 0, 0.37)
    frame = {"ego": ("Car", 2, 30, 0.0), "c": ("Car", x, y, 0.05)}
    miss = miss_of(AHEAD, frame)
    needed = {s.name: s for s in miss.needed}
    assert needed["position"].value == pytest.approx(0.37, rel=SLACK)
    assert needed["heading"].value == pytest.approx(0.05, rel=SLACK)
    assert needed["position"].blame == ["c.x", "c.y"] and needed["heading"].blame == ["c.heading"]
    assert miss.correspondence == {"ego": "ego", "c": "c"}
    assert_smallest(AHEAD, frame, miss)


def test_every_tolerance_is_searched():
    """A tolerance added to Tolerance needs its scale, cap and unit here, or misses would skip it."""
    assert {f.name for f in fields(Tolerance)} == set(SCALES) == set(CAPS) == set(UNITS)


def test_a_frame_beyond_the_caps_is_no_miss():
    misses = NearestMisses()
    result = AT.match(trace_of({"ego": ("Car", 2 + 30, 30, 0.3)}), MAP, SceneOptions())
    assert misses.add(result) is None and not misses.found
    assert "none is admitted" in misses.summary() and "position 20 m" in misses.summary()


def test_misses_are_kept_nearest_first_and_traces_past_the_limit_counted():
    misses = NearestMisses(MissLimits(traces=3, kept=2))
    for dx in (0.5, 0.1, 0.3, 0.01):
        misses.add(AT.match(trace_of({"ego": ("Car", 2 + dx, 30, 0.3)}), MAP, SceneOptions()), source=f"dx={dx}")
    assert [m.source for m in misses.found] == ["dx=0.1", "dx=0.3"]
    assert "3 traces" in misses.summary() and "1 more trace not examined" in misses.summary()


def test_a_trace_where_the_scene_holds_is_counted_not_searched():
    misses = NearestMisses()
    result = AT.match(trace_of({"ego": ("Car", 2, 30, 0.3)}, {"ego": ("Car", 3, 30, 0.3)}), MAP, SceneOptions())
    assert misses.add(result, np.array([1])) is not None and misses.holding == 0
    assert misses.add(result) is None and misses.holding == 1
    assert "the scene holds in 1 of them" in misses.summary()


@pytest.mark.parametrize("value", [0.08007, 1e-6, 3.064, 0.123456, 7.0, 1.0000001, 0.1 + 1e-12])
@pytest.mark.parametrize("up", [True, False])
def test_rounding_gives_four_digits_on_the_asked_side(value, up):
    found = rounded(value, up)
    assert (found >= value if up else found <= value) and float(f"{found:.4g}") == found
    assert abs(found - value) < 10 ** (math.floor(math.log10(value)) - 3) * 1.0001


@pytest.mark.real_data
def test_nuscenes_suggestion_makes_the_frame_match(real_data, capsys):
    """fig3 on nuScenes scene-0061 matches nothing with exact tolerances; the options the nearest
    miss suggests make its frame match, with the correspondence it names. nuScenes publishes no
    shoulders, which the cars' default container reads: taken as anywhere."""
    trace = real_data / "nuscenes_mini_scenarionet" / "sd_nuscenes_v1.0-mini_scene-0061.pkl"
    base = ["scene", "examples/scenes/fig3_car_ahead.scenic", str(trace), "--visible-distance", "50"]
    base += ["--unknown-layers", "permissive"]
    assert main(base) == 1
    err = capsys.readouterr().err
    found = re.search(
        r"nearest miss: \S+ frame (\d+) \(ego=ego, otherCar=(\w+)\): .* \((--tolerance.*) would admit it\)", err
    )
    assert found, err
    frame, other, options = int(found[1]), found[2], found[3].split()
    assert "position" in options[0] and "heading" in options[2]
    assert main([*base, *options]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert any(line.startswith(f"{trace}#scene-0061:{frame}-{frame}  ego=ego  otherCar={other}") for line in lines)


@pytest.mark.real_data
def test_scenario_miss_of_the_initial_scene_is_admitted_by_its_suggestion(real_data, capsys):
    """fig1 on nuScenes scene-0061 (3 s windows) matches nothing; the nearest miss of its initial
    scene names a window start that the suggested tolerances make an initial scene (nuScenes'
    unknown shoulders and crosswalks taken as anywhere)."""
    from scenegrep import readers
    from scenegrep.model.layers import UnknownLayers
    from scenegrep.scenario import ScenarioOptions, load_scenario

    path = real_data / "nuscenes_mini_scenarionet" / "sd_nuscenes_v1.0-mini_scene-0061.pkl"
    program = "examples/queries/fig1_lane_change.scenic"
    assert main(["scenario", program, str(path), "--window", "3s", "--unknown-layers", "permissive"]) == 1
    err = capsys.readouterr().err
    found = re.search(r"nearest miss of the initial scene: \S+ frame (\d+) .*\((--tolerance.*) would admit it\)", err)
    assert found, err
    options = found[2].split()
    tolerance = Tolerance(**{options[k][len("--tolerance-") :]: float(options[k + 1]) for k in (0, len(options) - 2)})
    trace = next(iter(readers.read_traces(path)))
    query = load_scenario(program)
    anywhere = UnknownLayers("permissive")
    result, starts = query.initial_scene(trace, "3s", None, ScenarioOptions(tolerance, unknown_layers=anywhere))
    exact, _ = query.initial_scene(trace, "3s", None, ScenarioOptions(unknown_layers=anywhere))
    frame = int(np.flatnonzero(trace.frame_index == int(found[1]))[0])
    assert frame in starts and result.matched[frame] and not exact.matched.any()
