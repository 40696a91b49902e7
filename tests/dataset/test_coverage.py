"""Coverage: the binning rules against brute-force references, the heading-window hull of the
closed-form intervals, unique names of random values, and ``scenegrep coverage`` over files, over
a dataset (the same tables), for a scenario's initial scene, with its outputs and bad options."""

from __future__ import annotations

import json
import math
import shutil

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.dataset.coverage import AMBIGUOUS, MAX_BINS, NO_VALUE, coverage_of
from scenegrep.scene import compile_scene
from scenegrep.scene.decide import Linear, _angle_gap, _angle_hull
from scenegrep.scene.evaluate import Affine
from scenegrep.scene.randoms import Declared, declared

from .conftest import REPO, SAMPLE

FIG3 = REPO / "examples" / "scenes" / "fig3_car_ahead.scenic"
FILES = [SAMPLE / "fig1_lane_change-000.parquet", SAMPLE / "s1_lane_change_stationary_car-000.parquet"]
TOLERANCES = ["--visible-distance", "50", "--tolerance-position", "1", "--tolerance-heading", "0.2618"]
RANGE = Declared("d", "range", 3, 2.0, 12.0)


def _rows(values: list[dict], sources: list[str] | None = None) -> list[dict]:
    """Match rows of a results table with these recovered values."""
    return [
        {
            "trace_id": f"t{k}",
            "name": f"t{k}",
            "source": (sources or ["s"] * len(values))[k],
            "match": 0,
            "start_frame": k,
            "end_frame": k,
            "intervals": json.dumps({"correspondences": 1, "values": v}),
        }
        for k, v in enumerate(values)
    ]


def _range(lo: float, hi: float) -> dict:
    return {"d": {"kind": "range", "lo": lo, "hi": hi}}


# ---------------------------------------------------------------------------- binning rules
@given(st.lists(st.tuples(st.floats(0, 14), st.floats(0, 1.5)), min_size=1, max_size=30), st.integers(1, 12))
def test_a_bin_is_covered_only_by_intervals_wholly_inside_it(intervals, bins):
    coverage = coverage_of(_rows([_range(lo, lo + w) for lo, w in intervals]), [RANGE], bins)
    edges = np.linspace(2, 12, bins + 1)
    for row, (lo, w) in enumerate(intervals):
        hi = lo + w
        inside = [
            k for k in range(bins) if edges[k] <= lo and (hi < edges[k + 1] or (k == bins - 1 and hi <= edges[-1]))
        ]
        assert coverage.assigned[row, 0] == (inside[0] if inside else AMBIGUOUS)
    expected = np.bincount([a for a in coverage.assigned[:, 0] if a >= 0], minlength=bins)
    assert coverage.counts(0).tolist() == expected.tolist()


def test_gaps_ambiguity_and_values_missing():
    rows = _rows([_range(4.2, 4.3), _range(4.9, 5.1), _range(11.5, 12.0), {}, _range(5.0, 5.0)])
    coverage = coverage_of(rows, [RANGE], 10)
    assert coverage.assigned[:, 0].tolist() == [2, AMBIGUOUS, 9, NO_VALUE, 3]
    assert coverage.counts(0).tolist() == [0, 0, 1, 1, 0, 0, 0, 0, 0, 1]
    assert coverage.ambiguous() == 1
    table = coverage.table().to_pylist()
    gaps = [r["label"] for r in table if r["variable2"] is None and r["source"] is None and r["gap"]]
    assert gaps == ["[2, 3)", "[3, 4)", "[6, 7)", "[7, 8)", "[8, 9)", "[9, 10)", "[10, 11)"]


def test_options_cover_an_alternative_only_when_one_alone_reproduces_the_frame():
    choice = Declared("gap", "options", 5, size=3)
    values = [{"gap": {"kind": "options", "chosen": c, "size": 3}} for c in ([1], [0, 2], [1], [2])]
    coverage = coverage_of(_rows(values), [choice], 10)
    assert coverage.axes[0].bins == 3
    assert coverage.assigned[:, 0].tolist() == [1, AMBIGUOUS, 1, 2]
    assert coverage.counts(0).tolist() == [0, 2, 1]


def test_unbounded_domains_and_points_bin_over_the_recovered_extent():
    normal = Declared("n", "range", 4, -math.inf, math.inf)
    point = Declared("p", "point", 2)
    values = [
        {"n": {"kind": "range", "lo": v, "hi": v}, "p": {"kind": "point", "x": [x, x], "y": [0.0, 0.0]}}
        for v, x in ((-1.0, 10.0), (3.0, 20.0), (1.0, 30.0))
    ]
    coverage = coverage_of(_rows(values), [normal, point], 4)
    assert [a.name for a in coverage.axes] == ["n", "p.x", "p.y"]
    assert [a.basis for a in coverage.axes] == ["recovered"] * 3
    assert coverage.axes[0].edges.tolist() == [-1.0, 0.0, 1.0, 2.0, 3.0]
    assert coverage.assigned[:, 0].tolist() == [0, 3, 2]
    assert coverage.axes[2].bins == 1 and coverage.assigned[:, 2].tolist() == [0, 0, 0]


def test_joint_and_per_source_counts():
    other = Declared("e", "range", 4, 0.0, 1.0)
    values = [_range(2.5, 2.5) | {"e": {"kind": "range", "lo": e, "hi": e}} for e in (0.1, 0.9, 0.1)]
    coverage = coverage_of(_rows(values, ["a", "b", "a"]), [RANGE, other], 2)
    assert coverage.joint(0, 1).tolist() == [[2, 1], [0, 0]]
    assert coverage.joint(0, 1, "a").tolist() == [[2, 0], [0, 0]]
    assert coverage.counts(1, "b").tolist() == [0, 1]
    cells = [r for r in coverage.table().to_pylist() if r["variable2"] == "e" and r["source"] is None]
    assert [(r["bin"], r["bin2"], r["matches"]) for r in cells] == [(0, 0, 2), (0, 1, 1), (1, 0, 0), (1, 1, 0)]


# ---------------------------------------------------------------------------- closed-form hull
@given(
    st.floats(-3, 3).filter(lambda a: abs(a) > 0.05),
    st.floats(-5, 5),
    st.floats(-8, 8),
    st.floats(0.1, 8),
    st.floats(-4, 4),
    st.floats(0.05, 1.0),
)
def test_heading_window_hull_equals_brute_force(coef, const, low, width, target, half):
    one = np.ones(1)
    c = Linear(Affine(const * one, {}), (target - half) * one, (target + half) * one, angle=True)
    u = np.linspace(low, low + width, 20001)
    feasible = _angle_gap(coef * u + const, coef * u + const, np.full(len(u), target)) <= half
    if not feasible.any():
        return
    lo, hi = _angle_hull(c, coef * one, low * one, (low + width) * one)
    step = width / 20000 + 1e-9
    assert lo[0] - step <= u[feasible].min() <= lo[0] + step
    assert hi[0] - step <= u[feasible].max() <= hi[0] + step


# ---------------------------------------------------------------------------- names and domains
def test_default_positions_of_several_objects_get_distinct_names():
    query = compile_scene(
        "model scenic.domains.driving.model\nego = new Car\nother = new Car\nthird = new Car at 0 @ Range(1, 2)\n"
    )
    names = [(d.name, d.kind, d.low, d.high) for d in declared(query.groups)]
    points = [n for n, kind, _, _ in names if kind == "point"]
    assert len(points) == 2 and len(set(points)) == 2 and points[1] == points[0] + " #2"
    assert ("Range(1, 2)@4:24", "range", 1.0, 2.0) in names


# ---------------------------------------------------------------------------- the command
@pytest.fixture(scope="module")
def outputs(tmp_path_factory):
    folder = tmp_path_factory.mktemp("coverage")
    argv = ["coverage", str(FIG3), *map(str, FILES), *TOLERANCES, "--bins", "6"]
    pictures = ["--html", str(folder / "page.html"), "--png", str(folder / "plots.png")]
    code = main([*argv, "-o", str(folder / "c.parquet"), *pictures, "-q"])
    code_json = main([*argv, "-o", str(folder / "c.json"), "-q"])
    return folder, code, code_json


def test_command_writes_the_table_in_both_formats(outputs):
    folder, code, code_json = outputs
    assert code == code_json == 0
    table = pq.read_table(folder / "c.parquet").to_pylist()
    assert json.loads((folder / "c.json").read_text()) == table
    singles = [r for r in table if r["variable2"] is None and r["source"] is None]
    assert {r["variable"] for r in singles} >= {"Range(4, 10)@11:36"}
    assert [r["label"] for r in singles if r["variable"].startswith("Range")][0] == "[4, 5)"


def test_page_links_each_covered_bin_to_its_matches_views(outputs):
    folder, _, _ = outputs
    page = (folder / "page.html").read_text()
    table = pq.read_table(folder / "c.parquet").to_pylist()
    covered = [r for r in table if r["variable2"] is None and r["source"] is None and r["matches"]]
    assert covered
    axes = list(dict.fromkeys(r["variable"] for r in table if r["variable2"] is None))
    for r in covered:
        anchor = f"bin-{axes.index(r['variable'])}-{r['bin']}"
        assert f'href="#{anchor}"' in page and f'<section id="{anchor}"' in page
    assert page.count('<section id="bin-') == len(covered)
    views = sorted(p.name for p in (folder / "page_views").iterdir())
    assert views and all(f"page_views/{name}#match=" in page for name in views)


def test_png_draws_a_bar_per_covered_bin_and_a_red_stripe_per_gap(outputs):
    from matplotlib.image import imread

    from scenegrep.view.charts import GAP_COLOUR
    from scenegrep.view.coverage_png import coverage_figure

    values = [
        _range(lo, lo) | {"e": {"kind": "range", "lo": e, "hi": e}} for lo, e in [(2.5, 0.1), (2.6, 0.9), (7, 0.1)]
    ]
    other = Declared("e", "range", 4, 0.0, 1.0)
    coverage = coverage_of(_rows([*values, _range(3.9, 4.1), {}]), [RANGE, other], 5)
    first, second, pair = coverage_figure(coverage).axes
    bars, gaps = first.containers
    assert [(round(b.get_x() + b.get_width() / 2), b.get_height()) for b in bars] == [(0, 2), (2, 1)]
    assert [round(b.get_x() + b.get_width() / 2) for b in gaps] == [1, 3, 4]
    assert "2 of 5 bins covered, 1 ambiguous, 1 without a value" in first.get_title(loc="left")
    assert [b.get_height() for b in second.containers[0]] == [2, 1]
    assert pair.get_images()[0].get_array().tolist() == coverage.joint(0, 1).tolist()
    folder, _, _ = outputs
    pixels = imread(folder / "plots.png")[:, :, :3]
    red = np.array([int(GAP_COLOUR[i : i + 2], 16) / 255 for i in (1, 3, 5)])
    table = pq.read_table(folder / "c.parquet").to_pylist()
    assert any(r["gap"] for r in table) == bool((np.abs(pixels - red).max(axis=2) < 0.02).any())


def test_a_failed_trace_makes_uncovered_bins_unknown_not_gaps(tmp_path, capsys):
    (tmp_path / "bad.parquet").write_text("not parquet")
    argv = ["coverage", str(FIG3), str(FILES[0]), str(tmp_path / "bad.parquet"), *TOLERANCES, "--bins", "6"]
    assert main([*argv, "-o", str(tmp_path / "c.json"), "--png", str(tmp_path / "c.png")]) == 3
    out = capsys.readouterr().out
    assert "unknown: 1 trace failed" in out and "uncovered in the data decided:" in out and "gaps:" not in out
    table = json.loads((tmp_path / "c.json").read_text())
    assert {r["gap"] for r in table if r["matches"] == 0} == {None}
    assert {r["gap"] for r in table if r["matches"]} == {False}


def test_unknown_data_names_failed_traces_and_an_interrupted_run():
    from scenegrep.dataset.coverage import unknown_data
    from scenegrep.dataset.queries import results_table
    from scenegrep.dataset.results import Results

    failed = [{"trace_id": t, "name": t, "source": t, "status": "failed"} for t in ("a", "b", "b")]
    assert unknown_data(Results(results_table(failed[:1]), "r", "interrupted")) == (
        "1 trace failed; the run was interrupted before every trace was queried"
    )
    assert unknown_data(Results(results_table(failed))) == "2 traces failed"
    assert unknown_data(Results(results_table([]))) == ""
    coverage = coverage_of(_rows([_range(2.5, 2.5)]), [RANGE], 2, unknown="the run was interrupted")
    assert [r["gap"] for r in coverage.table().to_pylist() if r["source"] is None] == [False, None]


def test_summary_names_gaps_and_ambiguous_matches(capsys):
    code = main(["coverage", str(FIG3), str(FILES[0]), *TOLERANCES, "--bins", "3"])
    out = capsys.readouterr().out
    assert code == 0
    assert "coverage of" in out and "gaps:" in out and "ambiguous" in out
    assert "declared [4, 10]" in out


def test_coverage_over_a_dataset_equals_coverage_over_its_files(tmp_path, outputs):
    from scenegrep.dataset.ingest import ingest

    folder, _, _ = outputs
    data = tmp_path / "data"
    data.mkdir()
    for f in FILES:
        shutil.copy(f, data / f.name)
    for town in ("Town01.xodr", "Town06.xodr"):
        shutil.copy(REPO / "examples" / "sample" / town, data / town)
    ingest([str(data)], tmp_path / "ds", jobs=1)
    code = main(
        [
            "coverage",
            str(FIG3),
            "--dataset",
            str(tmp_path / "ds"),
            *TOLERANCES,
            "--bins",
            "6",
            "-q",
            "-o",
            str(tmp_path / "d.parquet"),
            "-j",
            "1",
        ]
    )
    assert code == 0
    over_files = [r for r in pq.read_table(folder / "c.parquet").to_pylist() if r["source"] is None]
    over_dataset = [r for r in pq.read_table(tmp_path / "d.parquet").to_pylist() if r["source"] is None]
    assert over_dataset == over_files


SCENARIO = """model scenic.simulators.newtonian.driving_model
ego = new Car with behavior FollowLaneBehavior(), with roadDeviation Range(-30, 30) deg
other = new Car with behavior FollowLaneBehavior(), with roadDeviation Range(-30, 30) deg
require (distance from ego to other) < 50
"""


def test_scenario_coverage_is_that_of_the_initial_scenes(tmp_path):
    from scenegrep import readers
    from scenegrep.dataset import QuerySpec
    from scenegrep.dataset.files import query_files

    program = tmp_path / "follow.scenic"
    program.write_text(SCENARIO)
    path = SAMPLE / "bg1_following_traffic-000.parquet"
    options = {"window": "2s", "all": True, "unknown_layers": "permissive"}
    plain = query_files([str(path)], QuerySpec.from_file("scenario", program, **options)).matches
    spec = QuerySpec.from_file("scenario", program, intervals=True, **options)
    matches = query_files([str(path)], spec).matches.to_pylist()
    assert len(matches) == plain.num_rows > 0
    trace = readers.read_trace(path)
    states = trace.states
    ego = states.object == trace.object_index("ego")
    for row in matches:
        point = json.loads(row["intervals"])["values"]["point on: on road (default Vehicle.position)"]
        at = ego & (states.frame == int(np.searchsorted(trace.frame_index, row["start_frame"])))
        (x0, x1), (y0, y1) = point["x"], point["y"]
        assert x0 - 1e-6 <= states.x[at][0] <= x1 + 1e-6 and y0 - 1e-6 <= states.y[at][0] <= y1 + 1e-6
    argv = ["coverage", str(program), str(path), "--window", "2s", "--unknown-layers", "permissive", "-q"]
    assert main([*argv, "-o", str(tmp_path / "s.json")]) == 0
    table = json.loads((tmp_path / "s.json").read_text())
    axis = "point on: on road (default Vehicle.position).x"
    assert sum(
        r["matches"] for r in table if r["variable"] == axis and r["variable2"] is None and not r["source"]
    ) == len(matches)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--bins", "0"], "--bins must be between 1"),
        (["--bins", str(MAX_BINS + 1)], "--bins must be between 1"),
        (["-o", "table.csv"], "a .parquet or .json file"),
        (["--html", "page.pdf"], "an .html file"),
        (["--png", "plots.svg"], "a .png file"),
        (["--png", "folder.png"], "a directory"),
        (["-o", "folder.json"], "a directory"),
        (["--window", "0"], "at least one frame"),
    ],
)
def test_bad_options_are_user_errors(extra, message, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "folder.png").mkdir()
    (tmp_path / "folder.json").mkdir()
    code = main(["coverage", str(FIG3), str(FILES[0]), *extra])
    assert code == 2
    assert message in capsys.readouterr().err


# ---------------------------------------------------------------------------- recovered sets
def _recovered(program: str, frame: dict, position: float = 1e-6):
    from scenegrep.scene import SceneOptions, Tolerance
    from tests.scene.frames import HEADER, MAP, trace_of

    query = compile_scene(HEADER + program, "test.scenic")
    result = query.match(trace_of(frame), MAP, SceneOptions(Tolerance(position, 1e-6)))
    assert result.matched.tolist() == [True]
    return result.recovered[0]


PLACED = "ego = new Car at 0 @ 0, facing 0, with regionContainedIn everywhere\n"


def test_an_options_value_is_the_set_of_alternatives_that_reproduce_the_frame():
    program = PLACED + "other = new Car at 0 @ Uniform(5, 10, 15), facing 0, with regionContainedIn everywhere\n"
    frame = {"ego": ("Car", 0.0, 0.0, 0.0), "car": ("Car", 0.0, 10.0, 0.0)}
    (exact,) = _recovered(program, frame).options.values()
    (loose,) = _recovered(program, frame, position=6.0).options.values()
    assert exact == ([1], 3) and loose == ([0, 1, 2], 3)


def test_several_correspondences_give_the_hull_of_their_values_and_are_counted():
    program = PLACED + "other = new Car at 0 @ Range(5, 20), facing 0, with regionContainedIn everywhere\n"
    frame = {"ego": ("Car", 0.0, 0.0, 0.0), "a": ("Car", 0.0, 8.0, 0.0), "b": ("Car", 0.0, 12.0, 0.0)}
    found = _recovered(program, frame)
    assert found.correspondences == 2
    ((lo, hi),) = found.ranges.values()
    assert lo == pytest.approx(8.0, abs=1e-5) and hi == pytest.approx(12.0, abs=1e-5)


def test_witness_values_name_each_default_position_apart():
    from scenegrep import readers
    from scenegrep.scene import SceneOptions

    query = compile_scene("model scenic.domains.driving.model\nego = new Car\nother = new Car\n", "two.scenic")
    trace = readers.read_trace(FILES[0])
    result = query.match(trace, options=SceneOptions())
    (frame,) = result.frames().tolist()
    values = result.values(frame)
    name = "point on: on road (default Vehicle.position)"
    ids = trace.objects.id.tolist()
    for key, label in ((name, "ego"), (name + " #2", result.correspondence(frame)["other"])):
        at = (trace.states.object == ids.index(label)) & (trace.states.frame == frame)
        assert values[key] == pytest.approx([trace.states.x[at][0], trace.states.y[at][0]], abs=1e-5)
