"""``scenegrep export --openscenario``: every file validates against the OpenSCENARIO XSD, and read
back with plain XML parsing its entities, initial poses and trajectory vertices equal the labels
(headings converted from Scenic's convention to yaw from +x) within 1e-6; on the sample dataset
(OpenDRIVE maps: the road network is referenced) and on nuScenes (no OpenDRIVE: the limitation)."""

from __future__ import annotations

import datetime as dt
import functools
import math
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.dataset import openscenario_export as ox
from scenegrep.dataset.moments import Moment, ObjectPath, moments
from scenegrep.errors import UserError
from scenegrep.model.geometry import yaw_from_heading
from scenegrep.model.taxonomy import KINDS
from scenegrep.model.trace import MapSource
from scenegrep.view.sources import ResultsSource
from tests.conftest import REPO

CREATED = dt.datetime(2026, 1, 2, 3, 4, 5)
TOL = 1e-6


# ----------------------------------------------------------------------------- reading a file back
def read_back(path: Path) -> dict:
    """What a file says, by plain XML parsing: the header, the road file and, per entity, its
    type, category, properties, dimensions, initial pose and trajectory vertices (t, x, y, z, h)."""
    root = ET.parse(path).getroot()
    entities = {}
    for obj in root.iter("ScenarioObject"):
        (entity,) = [e for e in obj if e.tag in ("Vehicle", "Pedestrian", "MiscObject")]
        category = next(v for k, v in entity.attrib.items() if k.endswith("Category"))
        props = {p.get("name"): p.get("value") for p in entity.iter("Property")}
        dims = entity.find("BoundingBox/Dimensions").attrib
        entities[obj.get("name")] = {
            "type": entity.tag,
            "category": category,
            "props": props,
            "size": tuple(float(dims[k]) for k in ("length", "width", "height")),
            "centre": tuple(float(v) for v in entity.find("BoundingBox/Center").attrib.values()),
            "vertices": [],
        }
    for private in root.iter("Private"):
        pose = private.find("PrivateAction/TeleportAction/Position/WorldPosition")
        entities[private.get("entityRef")]["init"] = _pose(pose)
    for group in root.iter("ManeuverGroup"):
        (actor,) = [a.get("entityRef") for a in group.iter("EntityRef")]
        follow = group.find(".//FollowTrajectoryAction")
        timing = follow.find("TimeReference/Timing").attrib
        assert timing == {"domainAbsoluteRelative": "absolute", "scale": "1.0", "offset": "0.0"}
        assert follow.find("TrajectoryFollowingMode").get("followingMode") == "position"
        vertices = follow.findall(".//Polyline/Vertex")
        entities[actor]["vertices"] = [
            (float(v.get("time")), *_pose(v.find("Position/WorldPosition"))) for v in vertices
        ]
    road = root.find("RoadNetwork/LogicFile")
    header = root.find("FileHeader").attrib
    stop = root.find("Storyboard/StopTrigger//SimulationTimeCondition")
    return {
        "header": header,
        "road": None if road is None else road.get("filepath"),
        "entities": entities,
        "stop": stop,
    }


def _pose(element) -> tuple[float, float, float, float]:
    return tuple(float(element.get(k, "nan")) for k in ("x", "y", "z", "h"))


def same(a: float, b: float, angle: bool = False) -> bool:
    """Equal within 1e-6 (both absent/NaN counts as equal; angles modulo 2 pi)."""
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    gap = math.remainder(a - b, 2 * math.pi) if angle else a - b
    return abs(gap) <= TOL


def assert_matches_moment(path: Path, moment: Moment) -> dict:
    """The file at ``path`` validates and says exactly ``moment``'s objects, poses and paths."""
    assert ox.schema().is_valid(str(path))
    back = read_back(path)
    assert len(back["entities"]) == len(moment.objects)
    by_label = {e["props"]["label_id"]: e for e in back["entities"].values()}
    for obj in moment.objects:
        entity = by_label[ox._xml_text(obj.label_id)]
        assert entity["props"]["category"] == ox._xml_text(obj.category)
        kind, category = ox.osc_category(obj.category)
        assert (entity["type"], entity["category"]) == ({"miscObject": "MiscObject"}.get(kind, kind.title()), category)
        for got, labeled, default in zip(
            entity["size"], (obj.length, obj.width, obj.height), ox.DEFAULT_SIZE[category], strict=True
        ):
            assert same(got, labeled if labeled > 0 else default)
        assert entity["centre"] == (0.0, 0.0, 0.0)
        keep = np.isfinite(obj.x) & np.isfinite(obj.y)
        expected = list(
            zip(obj.times[keep], obj.x[keep], obj.y[keep], obj.z[keep], obj.heading[keep] + math.pi / 2, strict=True)
        )
        assert all(same(g, e) for g, e in zip(entity["init"][:3], expected[0][1:4], strict=True))
        assert same(entity["init"][3], expected[0][4], angle=True)
        assert -math.pi < entity["init"][3] <= math.pi or math.isnan(entity["init"][3])
        if len(expected) < 2:
            assert entity["vertices"] == []
            continue
        assert len(entity["vertices"]) == len(expected)
        for got, want in zip(entity["vertices"], expected, strict=True):
            assert all(same(g, w) for g, w in zip(got[:4], want[:4], strict=True))
            assert same(got[4], want[4], angle=True)
        yaws = np.array([v[4] for v in entity["vertices"]])
        assert np.all(np.abs(np.diff(yaws[np.isfinite(yaws)])) <= math.pi + TOL)  # unwrapped: no spin
    return back


# ----------------------------------------------------------------------------- units
def test_heading_convention_becomes_yaw_from_x():
    # Scenic: 0 faces +y, pi/2 faces -x (counter-clockwise), -pi/2 faces +x; OpenSCENARIO h: yaw from +x
    assert yaw_from_heading([0.0, math.pi / 2, -math.pi / 2, math.pi]) == pytest.approx(
        [math.pi / 2, math.pi, 0.0, -math.pi / 2]
    )
    east = path("car", heading=[-math.pi / 2] * 3, x=[0.0, 1.0, 2.0], y=[5.0] * 3)
    with tempfile.TemporaryDirectory() as folder:
        back = read_back(ox.write_openscenario([moment(east)], folder, CREATED).files[0])
    (entity,) = back["entities"].values()
    assert entity["init"][3] == pytest.approx(0.0)  # moving along +x, facing +x
    assert [v[4] for v in entity["vertices"]] == pytest.approx([0.0] * 3)


@pytest.mark.parametrize(
    ("category", "expected"),
    [
        ("REGULAR_VEHICLE", ("vehicle", "car")),
        ("vehicle.car", ("vehicle", "car")),
        ("vehicle.bus.rigid", ("vehicle", "bus")),
        ("BOX_TRUCK", ("vehicle", "truck")),
        ("vehicle.trailer", ("vehicle", "trailer")),
        ("vehicle.motorcycle", ("vehicle", "motorbike")),
        ("BICYCLIST", ("vehicle", "bicycle")),
        ("Van", ("vehicle", "van")),
        ("RAILED_VEHICLE", ("vehicle", "train")),
        ("human.pedestrian.adult", ("pedestrian", "pedestrian")),
        ("WHEELCHAIR", ("pedestrian", "wheelchair")),
        ("DOG", ("pedestrian", "animal")),
        ("BOLLARD", ("miscObject", "obstacle")),
        ("no such class", ("miscObject", "none")),
    ],
)
def test_categories_map_to_openscenario_categories(category, expected):
    assert ox.osc_category(category) == expected


def test_every_kind_has_a_category_with_a_default_size():
    from scenariogeneration import xosc

    enums = {
        "vehicle": xosc.VehicleCategory,
        "pedestrian": xosc.PedestrianCategory,
        "miscObject": xosc.MiscObjectCategory,
    }
    for kind in KINDS:
        entity, category = ox.osc_category(kind)
        assert hasattr(enums[entity], category) and category in ox.DEFAULT_SIZE


def path(label, category="car", program=None, times=None, x=None, y=None, z=None, heading=None, size=(4.0, 2.0, 1.5)):
    """An ObjectPath with the given observations (defaults: three frames 0.1 s apart)."""
    n = len(x if x is not None else times if times is not None else [0, 0, 0])
    column = lambda v, d: np.array(v if v is not None else d, dtype=float)  # noqa: E731
    return ObjectPath(
        label_id=label,
        program_name=program,
        category=category,
        length=size[0],
        width=size[1],
        height=size[2],
        times=column(times, 0.1 * np.arange(n)),
        x=column(x, np.arange(n)),
        y=column(y, np.zeros(n)),
        z=column(z, np.full(n, np.nan)),
        heading=column(heading, np.zeros(n)),
    )


def moment(*objects, trace_id="t-1", name="t", map_source=None, match=0) -> Moment:
    return Moment(trace_id, name, match, 0, 5, 0.0, map_source, None, tuple(objects))


def test_partly_observed_objects_start_at_their_first_observation_and_nan_sizes_get_defaults(tmp_path):
    late = path("late", "PEDESTRIAN", times=[0.2, 0.3, 0.5], x=[7.0, 7.5, 8.0], size=(np.nan, np.nan, 1.8))
    once = path("once", "BOLLARD", times=[0.4], x=[3.0])
    gap = path("gap", "BUS", x=[1.0, np.nan, 3.0])  # an observation without a position is left out
    shown = moment(path("ego", program="ego"), late, once, gap)
    summary = ox.write_openscenario([shown], tmp_path, CREATED)
    back = assert_matches_moment(summary.files[0], shown)
    walker = back["entities"]["obj_late"]
    assert walker["init"][0] == 7.0 and walker["vertices"][0][0] == pytest.approx(0.2)
    assert walker["size"] == (0.5, 0.5, 1.8)  # the pedestrian default where no size, the labeled height kept
    assert back["entities"]["obj_once"]["vertices"] == []
    assert [v[:2] for v in back["entities"]["obj_gap"]["vertices"]] == [(0.0, 1.0), (pytest.approx(0.2), 3.0)]
    assert (summary.default_size, summary.without_trajectory, summary.without_road_network) == (1, 1, 1)
    description = back["header"]["description"]
    assert "category's default for a dimension not labeled: obj_late" in description
    assert "observed at one frame, no trajectory: obj_once" in description
    assert "no road network: the trace has no map" in description
    assert float(back["stop"].get("value")) == pytest.approx(0.5)  # the storyboard stops after the last observation


def test_hostile_names_stay_in_the_folder_and_in_valid_xml(tmp_path):
    out = tmp_path / "out"
    odd = path("<a&b>\x01$x", category="car\x1b[2J", program=None)
    twin = path("[a|b]\x01$x")  # the same safe name: made unique
    shown = moment(odd, twin, trace_id="../../evil/\x00..", name="evil\x1b]0;\x07")
    (written,) = ox.write_openscenario([shown], out, CREATED).files
    assert written.parent == out and not written.name.startswith(".")
    assert sorted(p.name for p in out.iterdir()) == [written.name]
    assert set(written.name) <= set("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_.-")
    back = assert_matches_moment(written, shown)
    assert sorted(back["entities"]) == ["obj__a_b___x", "obj__a_b___x_2"]
    assert back["entities"]["obj__a_b___x"]["props"]["label_id"] == "<a&b>\ufffd$x"
    other = moment(odd, trace_id="../../evil/_..")  # sanitises to the same stem: the hash keeps them apart
    assert ox.file_name(other) != written.name


def test_a_file_that_does_not_validate_is_not_written(tmp_path, monkeypatch):
    real = ox.scenario_element

    def broken(*args):
        element, counts = real(*args)
        element.remove(element.find("Storyboard"))
        return element, counts

    monkeypatch.setattr(ox, "scenario_element", broken)
    good = moment(path("ego", program="ego"))
    with pytest.raises(UserError, match=r"does not validate against OpenSCENARIO_1_3_1\.xsd .*not written"):
        ox.write_openscenario([good], tmp_path / "out", CREATED)
    assert not (tmp_path / "out").exists() or not any((tmp_path / "out").iterdir())


def test_the_road_file_is_relative_to_the_output_file_and_output_is_deterministic(tmp_path):
    town = REPO / "examples" / "sample" / "Town06.xodr"
    shown = moment(path("ego", program="ego"), map_source=MapSource(str(town), "opendrive"))
    first = ox.write_openscenario([shown], tmp_path / "a" / "b", CREATED).files[0]
    road = read_back(first)["road"]
    assert not os.path.isabs(road)
    assert (first.parent / road).resolve() == town.resolve()
    again = ox.write_openscenario([shown], tmp_path / "c", CREATED).files[0]
    assert again.read_bytes() == first.read_bytes().replace(road.encode(), read_back(again)["road"].encode())
    (tmp_path / "link").symlink_to(tmp_path / "a" / "b")  # a folder reached through a link: ".." is physical
    linked = ox.write_openscenario([shown], tmp_path / "link", CREATED).files[0]
    assert (linked.parent / read_back(linked)["road"]).resolve() == town.resolve()


FINITE = st.floats(-1e5, 1e5, allow_nan=False)
HEADINGS = st.one_of(
    st.floats(-4 * math.pi, 4 * math.pi), st.sampled_from([math.pi, -math.pi, 0.0, 3.14159265, -3.1416, math.nan])
)
SIZES = st.one_of(st.just(float("nan")), st.floats(0.1, 30.0))
CATEGORIES = st.sampled_from(["REGULAR_VEHICLE", "vehicle.truck", "PEDESTRIAN", "DOG", "BOLLARD", "Van", "thing"])


@st.composite
def object_paths(draw, label: str) -> ObjectPath:
    n = draw(st.integers(1, 6))
    gaps = draw(st.lists(st.floats(0.01, 2.0), min_size=n, max_size=n))
    start = draw(st.floats(0.0, 3.0))
    return ObjectPath(
        label_id=label,
        program_name=draw(st.sampled_from([None, label])),
        category=draw(CATEGORIES),
        length=draw(SIZES),
        width=draw(SIZES),
        height=draw(SIZES),
        times=start + np.cumsum(gaps) - gaps[0],
        x=np.array(draw(st.lists(FINITE, min_size=n, max_size=n))),
        y=np.array(draw(st.lists(FINITE, min_size=n, max_size=n))),
        z=np.array(draw(st.lists(st.one_of(st.just(float("nan")), FINITE), min_size=n, max_size=n))),
        heading=np.array(draw(st.lists(HEADINGS, min_size=n, max_size=n))),
    )


@settings(max_examples=40)
@given(st.integers(1, 4).flatmap(lambda n: st.tuples(*[object_paths(f"o{k}") for k in range(n)])))
def test_random_moments_round_trip_within_1e6(objects):
    shown = moment(*objects)
    with tempfile.TemporaryDirectory() as folder:
        assert_matches_moment(ox.write_openscenario([shown], folder, CREATED).files[0], shown)


# ----------------------------------------------------------------------------- end to end
SAMPLE = sorted(str(p) for p in (REPO / "examples" / "sample").glob("fig1_lane_change-00[0-2].parquet"))


@pytest.fixture(scope="module")
def sample_results(tmp_path_factory) -> dict[str, Path]:
    """Results of a scene query (Fig. 3, 1 m and 15 deg tolerances) and a scenario query (Fig. 1 lane
    change, 3 s windows) over three sample traces."""
    folder = tmp_path_factory.mktemp("sample-results")
    queries = {
        "scene": [
            "scene",
            str(REPO / "examples/scenes/fig3_car_ahead.scenic"),
            *SAMPLE,
            "--tolerance-position",
            "1",
            "--tolerance-heading",
            "0.2618",
        ],
        "scenario": ["scenario", str(REPO / "examples/queries/fig1_lane_change.scenic"), *SAMPLE, "--window", "3s"],
    }
    for name, query in queries.items():
        assert main([*query, "--output", str(folder / f"{name}.parquet"), "-q"]) == 0
    return {name: folder / f"{name}.parquet" for name in queries}


def export(results: Path, out: Path, context: float | None, capsys) -> tuple[list[Moment], str]:
    """Export ``results`` to ``out`` with the CLI; the moments it exported and its stderr."""
    capsys.readouterr()
    extra = [] if context is None else ["--context", str(context)]
    assert main(["export", str(results), "--openscenario", str(out), *extra]) == 0
    source = ResultsSource.open(results)
    return list(moments(source.results, lambda trace_id: source.load(trace_id)[0], context)), capsys.readouterr().err


@functools.lru_cache(maxsize=8)
def raw_states(source: str) -> list[dict]:
    table = pq.read_table(source, columns=["kind", "frame", "time", "object", "x", "y", "heading"])
    return [r for r in table.to_pylist() if r["kind"] == "state"]


def assert_raw_states(back: dict, source: str, start: int, end: int) -> None:
    """The file's poses and vertices are the raw Parquet rows of each entity's label over frames
    ``start..end`` (read with pyarrow, not scenegrep): time from the window's first frame, x, y
    and yaw = heading + pi/2."""
    rows = [r for r in raw_states(source) if start <= r["frame"] <= end]
    first = min(r["time"] for r in rows)
    for entity in back["entities"].values():
        mine = [r for r in rows if r["object"] == entity["props"]["label_id"]]
        want = [(r["time"] - first, r["x"], r["y"], r["heading"] + math.pi / 2) for r in mine]
        got = entity["vertices"] or [(want[0][0], *entity["init"][:2], entity["init"][3])]
        assert len(got) == len(want)
        for g, w in zip(got, want, strict=True):
            assert all(same(a, b) for a, b in zip((g[0], g[1], g[2]), w[:3], strict=True))
            assert same(g[-1], w[3], angle=True)


def test_sample_scene_and_scenario_matches_reference_the_opendrive_map(sample_results, tmp_path, capsys):
    town = (REPO / "examples" / "sample" / "Town06.xodr").resolve()
    for name, results in sample_results.items():
        out = tmp_path / name
        shown, err = export(results, out, 30.0, capsys)
        assert shown and f"{len(shown)} matches written as OpenSCENARIO 1.3" in err
        assert sorted(out.iterdir()) == sorted(out / ox.file_name(m) for m in shown)
        sources = {(r["trace_id"], r["match"]): r["source"] for r in pq.read_table(results).to_pylist()}
        for m in shown:
            back = assert_matches_moment(out / ox.file_name(m), m)
            assert (out / back["road"]).resolve() == town
            assert "no road network" not in back["header"]["description"]
            assert_raw_states(back, sources[m.trace_id, m.match], m.start_frame, m.end_frame)
    assert any(len(o.times) == 30 for o in shown[0].objects)  # the scenario's 3 s window: 30 vertices


@pytest.mark.slow
def test_nuscenes_matches_say_there_is_no_opendrive_road_network(tmp_path, capsys, real_data):
    scenes = [str(real_data / f"nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{n}.pkl") for n in (1077, 1094)]
    query = ["scenario", str(REPO / "examples/queries/real/ego_following_vehicle.scenic"), *scenes]
    query += ["--window", "3s", "--unknown-layers", "permissive"]
    assert main([*query, "--output", str(tmp_path / "r.parquet"), "-q"]) == 0
    shown, err = export(tmp_path / "r.parquet", tmp_path / "xosc", 10.0, capsys)
    assert len(shown) == 2 and "2 files have no road network" in err
    for m in shown:
        back = assert_matches_moment(tmp_path / "xosc" / ox.file_name(m), m)
        assert back["road"] is None
        assert "the trace's map is scenarionet, not OpenDRIVE" in back["header"]["description"]
        assert {e["category"] for e in back["entities"].values()} >= {"car"}
        assert any(np.isfinite(o.z).all() for o in m.objects)  # nuScenes gives z: written and read back


def test_cli_errors(sample_results, tmp_path, capsys):
    results = sample_results["scene"]
    (tmp_path / "file").write_text("")
    for argv, message in (
        (["--mcap", "m.mcap", "--context", "3"], "--context goes with --openscenario"),
        (["--openscenario", str(tmp_path / "file")], "not a directory"),
        (["--openscenario", ""], "--openscenario: give the folder to write to"),
        (["--openscenario", str(tmp_path / "d"), "--prompt", "p"], "--prompt and --referred go with --refav"),
        (["--openscenario", str(tmp_path / "d"), "--mcap", "m"], "not allowed with argument"),
        (["--openscenario", str(tmp_path / "d"), "--context", "-1"], "--context -1.0: give a radius from 0"),
    ):
        code = main(["export", str(results), *argv])
        assert code == 2 and message in capsys.readouterr().err
