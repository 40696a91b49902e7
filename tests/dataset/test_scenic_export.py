"""``scenegrep export RESULTS --scenic DIR``: matches as Scenic programs.

The round trips (marked slow) query examples/sample and real recordings, export the matches,
compile every program once in the installed Scenic 3.1.1 (2-D mode), check its sampled initial
scene against the labels read from the recordings (position 1e-6 m, heading 1e-6 rad, size,
class, the exported objects), then simulate it in the Newtonian simulator for the window's
length at the trace's frame period and measure how far each object strays from its labels.

To keep them fast, the Scenic library's own modules (the driving model and behaviours) are
parsed and translated once per test process and their road network loaded once per map
(:func:`scenic_compiler`); every exported program itself is parsed, compiled and run by Scenic.
"""

from __future__ import annotations

import ast
import json
import math
import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from scenegrep import readers
from scenegrep.cli.main import main
from scenegrep.dataset.moments import Moment, ObjectPath, left_out
from scenegrep.dataset import openscenario_export as ox
from scenegrep.dataset.scenic_export import WrittenProgram, scenic_program, without_map_counts, write_scenic_programs
from scenegrep.errors import UserError
from scenegrep.dataset.ingest import trace_id_of
from scenegrep.dataset.queries import results_table
from scenegrep.model import LabelTrace, MapSource, ObjectTable, StateTable
from scenegrep.writers.trace_parquet import write_trace_parquet
from scenegrep.model.taxonomy import kind_of
from tests.conftest import REPO

SAMPLE = REPO / "examples" / "sample"
TOWN01 = REPO / "examples" / "sample" / "Town01.xodr"

CLASSES = {
    "car": "Car",
    "truck": "Truck",
    "bus": "Bus",
    "trailer": "Trailer",
    "motorcycle": "Motorcycle",
    "bicycle": "Bicycle",
    "pedestrian": "Pedestrian",
    "animal": "Animal",
    "static": "StaticObject",
    "other": "OtherObject",
}
"""The Scenic class each canonical kind must be exported as."""


def path_of(label: str, category: str, rows: list[tuple[float, float, float, float]], size=(4.0, 2.0, 1.5)):
    times, x, y, heading = (np.array(v, dtype=float) for v in zip(*rows))
    return ObjectPath(label, None, category, *size, times, x, y, np.zeros(len(rows)), heading)


def moment(objects, map_source=None, name="street", duration=0.2, trace_id="t1", match=0) -> Moment:
    return Moment(trace_id, name, match, 10, 12, 1.0, map_source, None, tuple(objects), duration, 0.1)


EVERY_KIND = [
    path_of(f"id-{kind}", category, [(0.0, 10.0 * i, 5.0, 0.1 * i), (0.2, 10.0 * i + 1.0, 5.5, 0.1 * i + 0.2)])
    for i, (kind, category) in enumerate(
        [
            ("car", "vehicle.car"),
            ("truck", "BOX_TRUCK"),
            ("bus", "vehicle.bus.rigid"),
            ("trailer", "vehicular_trailer"),
            ("motorcycle", "motorcyclist"),
            ("bicycle", "cyclist"),
            ("pedestrian", "human.pedestrian.adult"),
            ("animal", "dog"),
            ("static", "bollard"),
            ("other", "wheeled_device"),
        ]
    )
]


# ----------------------------------------------------------------------------- Scenic, fast
@pytest.fixture(scope="module")
def scenic_compiler(scenic_cache):
    """Compile a program file as ``scenic --2d`` would, on the map its ``param map`` names (read
    from scenegrep's cached copy of it, so no ``.snet`` lands beside the map): a Scenic scenario."""
    import scenic
    import scenic.syntax.translator as translator
    from scenic.domains.driving.roads import Network

    from scenegrep.synth._scenic import compile_program, map_params

    library = str(Path(scenic.__file__).parent)
    parse, translate, load = translator.parse_string, translator.compileScenicAST, Network.fromFile
    trees: dict[tuple, object] = {}
    translated: dict[int, object] = {}
    networks: dict[tuple, object] = {}

    def parse_once(source, mode, filename=None):
        if not str(filename).startswith(library):
            return parse(source, mode, filename=filename)
        key = (source, mode, str(filename))
        if key not in trees:
            trees[key] = parse(source, mode, filename=filename)
        return trees[key]

    def translate_once(tree, *args, **kwargs):
        if not any(tree is t for t in trees.values()):
            return translate(tree, *args, **kwargs)
        if id(tree) not in translated:
            translated[id(tree)] = translate(tree, *args, **kwargs)
        return translated[id(tree)]

    def load_once(path, **options):
        key = (str(path), tuple(sorted(options.items())))
        if key not in networks:
            networks[key] = load(path, **options)
        return networks[key]

    def compile_file(program: Path):
        reference = map_reference(program)
        return compile_program(program, {} if reference is None else map_params(reference))

    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(translator, "parse_string", parse_once)
        patch.setattr(translator, "compileScenicAST", translate_once)
        patch.setattr(Network, "fromFile", staticmethod(load_once))
        yield compile_file


def map_reference(program: Path) -> Path | None:
    """The map a program's ``param map = localPath(...)`` names, resolved as Scenic resolves it."""
    found = re.search(r"^param map = localPath\((.*)\)$", program.read_text(), re.MULTILINE)
    return None if found is None else (program.parent / ast.literal_eval(found.group(1))).resolve()


def scene_of(scenario):
    scene, _ = scenario.generate(maxIterations=1)
    return scene


def test_every_kind_is_its_class_at_its_pose_in_a_program_without_a_map(tmp_path, scenic_compiler):
    program = tmp_path / "kinds.scenic"
    program.write_text(scenic_program(moment(EVERY_KIND), None, "the trace has no road map"))
    scene = scene_of(scenic_compiler(program))
    found = {o.name: o for o in scene.objects}
    assert list(found) == [p.label_id for p in EVERY_KIND] and scene.egoObject is scene.objects[0]
    for path in EVERY_KIND:
        obj = found[path.label_id]
        assert type(obj).__name__ == CLASSES[kind_of(path.category)]
        assert (obj.position.x, obj.position.y) == (path.x[0], path.y[0])
        assert abs(obj.heading - path.heading[0]) <= 1e-12
        assert (obj.length, obj.width, obj.height) == (4.0, 2.0, 1.5)


def test_hostile_names_and_paths_stay_literals_and_files_stay_in_the_folder(tmp_path, scenic_compiler):
    evil = 'x"""\n\u2028import os; os.system("touch PWNED") #\''
    objects = [
        path_of(evil, evil, [(0.0, 1.0, 2.0, 0.5)], size=(math.nan, 2.0, math.nan)),
        path_of("\\n'), ego = (", "car\r\nmodel evil", [(0.0, 9.0, 9.0, 0.0)]),
    ]
    source = MapSource(str(tmp_path / f"missing{evil}.xodr"), "opendrive")
    folder = tmp_path / "out"
    written = write_scenic_programs(
        [
            moment(objects, source, name=f"../../{evil}", trace_id="a"),
            moment(objects, source, name=f"../../{evil}", trace_id="b"),
            moment(objects[1:], None, name="..", trace_id="c"),
        ],
        folder,
    )
    files = [w.path for w in written]
    assert all(f.parent == folder for f in files) and len(set(files)) == 3
    assert files[0].name.startswith("x_import_os") and files[2].name == "trace-0.scenic"
    assert sorted(p.name for p in folder.iterdir()) == sorted(f.name for f in files)
    assert (
        written[0].without_map.startswith("its OpenDRIVE map") and written[2].without_map == "the trace has no road map"
    )
    (odd,) = write_scenic_programs([moment(objects, MapSource("m", "x\n\u2028y"), trace_id="d")], tmp_path / "odd")
    assert all("\n" not in w.without_map and "\u2028" not in w.without_map for w in [*written[:2], odd])
    scene = scene_of(scenic_compiler(files[0]))
    assert [o.name for o in scene.objects] == [evil, "\\n'), ego = ("]
    assert scene.objects[0].length == 1  # the labels give no length: Scenic's default
    assert not (Path.cwd() / "PWNED").exists() and not (folder / "PWNED").exists()


def test_programs_on_an_opendrive_map_name_it_relative_to_their_folder(tmp_path):
    source = MapSource(str(TOWN01), "opendrive")
    (written,) = write_scenic_programs([moment(EVERY_KIND[:1], source)], tmp_path / "deep" / "er")
    assert written.without_map is None and map_reference(written.path) == TOWN01.resolve()
    text = written.path.read_text()
    assert "model scenic.simulators.newtonian.driving_model" in text and "../" in text
    for other in ("av2-map", "scenarionet"):
        (no_map,) = write_scenic_programs([moment(EVERY_KIND[:1], MapSource("m", other))], tmp_path)
        assert no_map.without_map == f"Scenic reads no {other} map, only OpenDRIVE"
        assert "model scenic.simulators.newtonian.model" in no_map.path.read_text()


@pytest.mark.parametrize(
    "programs, trace_ego, expected",
    [(("ego", None), "b", "a"), ((None, None), "b", "b"), ((None, "car"), None, "a"), (("car", "ego"), "a", "b")],
)
def test_scenics_ego_is_the_programs_ego_else_the_traces_else_the_first(programs, trace_ego, expected):
    objects = [
        replace(path_of(label, "car", [(0.0, 0.0, 0.0, 0.0)]), program_name=name) for label, name in zip("ab", programs)
    ]
    text = scenic_program(replace(moment(objects), ego=trace_ego), None)
    assert re.search(r"^ego = new Car .*with name '(\w)'", text, re.MULTILINE).group(1) == expected
    assert len(re.findall(r"^\w+ = new ", text, re.MULTILINE)) == 2


def test_a_moment_without_objects_is_a_user_error(tmp_path):
    with pytest.raises(UserError, match="no labeled object"):
        write_scenic_programs([moment([])], tmp_path)


def run(args, capsys) -> tuple[int, str]:
    code = main([str(a) for a in args])
    return code, capsys.readouterr().err


def test_cli_refuses_bad_options_and_targets(tmp_path, capsys):
    trace = tmp_path / "walk.parquet"
    write_trace_parquet(street_trace(), trace)
    row = {"trace_id": trace_id_of(str(trace), "walk", 0), "name": "walk", "source": str(trace), "status": "match"}
    row |= {"match": 0, "correspondence": '{"ego": "ego", "p": "w"}', "start_frame": 0, "end_frame": 2}
    results = tmp_path / "r.parquet"
    pq.write_table(results_table([row]), results)
    for bad, message in [
        (["--mcap", tmp_path / "m.mcap", "--context", "5"], "--context goes with --openscenario or --scenic"),
        (["--scenic", tmp_path / "o", "--context", "nan"], "--context nan"),
        (["--scenic", tmp_path / "o", "--context", "-1"], "--context -1"),
        (["--scenic", tmp_path / "o", "--context", "1e400"], "--context inf"),
        (["--scenic", tmp_path / "o", "--prompt", "p"], "--prompt and --referred go with --refav"),
        (["--scenic", results], "not a directory"),
        (["--scenic", " "], "--scenic: give the folder"),
    ]:
        code, err = run(["export", results, *bad], capsys)
        assert code == 2 and message in err and "Traceback" not in err, (bad, err)
    code, err = run(["export", results, "--scenic", tmp_path / "o", "--context", "3"], capsys)
    assert code == 0 and "1 match written as Scenic programs" in err
    assert "1 program without a road map (the trace has no road map)" in err
    (program,) = (tmp_path / "o").iterdir()
    assert program.name == "walk-0.scenic" and "with name 'c'" in program.read_text()  # c: 2 m from w


@pytest.mark.parametrize("target", ["--scenic", "--openscenario"])
def test_failed_traces_and_interrupted_runs_are_said_not_silently_skipped(target, tmp_path, capsys):
    from scenegrep.dataset.results import Results

    trace = tmp_path / "walk.parquet"
    write_trace_parquet(street_trace(), trace)
    row = {"trace_id": trace_id_of(str(trace), "walk", 0), "name": "walk", "source": str(trace), "status": "match"}
    row |= {"match": 0, "correspondence": '{"ego": "ego", "p": "w"}', "start_frame": 0, "end_frame": 2}
    failed = {"trace_id": "gone", "name": "gone", "source": str(tmp_path / "gone"), "status": "failed", "error": "x"}
    results = tmp_path / "r.parquet"
    Results(results_table([row, failed]), "run", "interrupted").write_parquet(results)
    code, err = run(["export", results, target, tmp_path / "out"], capsys)
    assert code == 0 and "1 match written" in err, err
    assert "1 trace failed" in err and "none exported" in err and "an interrupted run" in err
    assert len(list((tmp_path / "out").iterdir())) == 1
    assert left_out(Results(results_table([row, failed, failed | {"trace_id": "g2"}]), "run"), "R") == [
        "2 traces failed in R: their matches are unknown, none exported"
    ]
    assert left_out(Results(results_table([row]), "run", "interrupted"), "R") == [
        "R is an interrupted run: the traces it did not reach are not exported"
    ]
    assert left_out(Results(results_table([row]), "run"), "R") == []


def street_trace():
    """3 frames without a map: the ego, a walker 'w' and a car 'c' 2 m from it."""
    objects = ObjectTable.build(["ego", "w", "c"], ["car", "pedestrian", "car"])
    frame, obj = np.repeat(np.arange(3), 3), np.tile(np.arange(3), 3)
    x = np.tile([0.0, 20.0, 22.0], 3)
    states = StateTable.build(frame, obj, x, np.zeros(9), np.zeros(9))
    return LabelTrace.build("walk", np.arange(3), np.arange(3) / 10, objects, states, ego="ego")


# ----------------------------------------------------------------------------- round trips
def export(tmp_path: Path, query: list, data: list, keep: int, context: float | None, capsys) -> list[Path]:
    """Run a query (kind, program, options) over files, keep its first ``keep`` matches, export
    them: the programs and their rows."""
    tmp_path.mkdir()
    results = tmp_path / "results.parquet"
    code, err = run([*query[:2], *data, *query[2:], "--output", results, "-q"], capsys)
    assert code == 0, err
    table = pq.read_table(results)
    matches = table.filter(np.array([s == "match" for s in table["status"].to_pylist()]))
    assert matches.num_rows >= keep, matches.num_rows
    pq.write_table(matches.slice(0, keep), results)
    folder = tmp_path / "programs"
    extra = [] if context is None else ["--context", context]
    assert run(["export", results, "--scenic", folder, *extra], capsys)[0] == 0
    rows = matches.slice(0, keep).to_pylist()
    return [(folder / f"{r['name']}-{r['match']}.scenic", r) for r in rows]


def check_round_trip(program: Path, row: dict, context: float | None, compile_file) -> float:
    """Check the program's initial scene against the labels; simulate it; the largest error (m)."""
    trace = readers.read_trace(row["source"])
    window = np.flatnonzero((trace.frame_index >= row["start_frame"]) & (trace.frame_index <= row["end_frame"]))
    s = trace.states
    in_window = np.isin(s.frame, window)
    ids = list(trace.objects.id)
    anchors = {trace.ego, *json.loads(row["correspondence"]).values()} - {None}
    expected = set(anchors)
    if context is not None:
        for i in np.flatnonzero(in_window):
            same = in_window & (s.frame == s.frame[i])
            for j in np.flatnonzero(same):
                if ids[s.object[j]] in anchors and math.hypot(s.x[i] - s.x[j], s.y[i] - s.y[j]) <= context:
                    expected.add(ids[s.object[i]])
    speeds = program.with_name(program.stem + "-speeds.scenic")
    names = re.findall(r"^(\w+) = new ", program.read_text(), re.MULTILINE)
    speeds.write_text(program.read_text() + "".join(f"record {n}.speed as {n}\n" for n in names))
    scene = scene_of(compile_file(speeds))
    assert sorted(o.name for o in scene.objects) == sorted(expected)
    assert scene.egoObject.name == json.loads(row["correspondence"]).get("ego", trace.ego)
    period = float(np.median(np.diff(trace.frame_time)))
    for obj in scene.objects:
        k = np.flatnonzero(in_window & (s.object == ids.index(obj.name)))
        first = k[0]
        assert abs(obj.position.x - s.x[first]) <= 1e-6 and abs(obj.position.y - s.y[first]) <= 1e-6
        assert abs(math.remainder(obj.heading - s.heading[first], math.tau)) <= 1e-6
        for prop in ("length", "width", "height"):
            label = np.median(getattr(s, prop)[k][np.isfinite(getattr(s, prop)[k])])
            assert math.isnan(label) or getattr(obj, prop) == pytest.approx(label, abs=1e-9)
        assert type(obj).__name__ == CLASSES[kind_of(str(trace.objects.category[ids.index(obj.name)]))]
    from scenic.simulators.newtonian import NewtonianSimulator

    simulation = NewtonianSimulator(render=False).simulate(
        scene, maxSteps=len(window) + 2, timestep=period, maxIterations=1
    )
    trajectory = simulation.result.trajectory
    assert len(trajectory) == len(window)  # the program ends with the window
    error = 0.0
    times = trace.frame_time[window] - trace.frame_time[window[0]]
    steps = np.arange(len(window)) * period
    for j, (obj, name) in enumerate(zip(scene.objects, names)):
        k = np.flatnonzero(in_window & (s.object == ids.index(obj.name)))
        seen = times[np.searchsorted(window, s.frame[k])]
        x, y = np.interp(steps, seen, s.x[k]), np.interp(steps, seen, s.y[k])
        expected = np.hypot(np.diff(x), np.diff(y)) / period  # the recording's finite-difference speeds
        first = (
            math.hypot(s.x[k[1]] - s.x[k[0]], s.y[k[1]] - s.y[k[0]]) / (seen[1] - seen[0])
            if seen[0] == 0 and len(k) > 1
            else 0.0
        )
        simulated = [speed for _, speed in simulation.result.records[name]]
        np.testing.assert_allclose(simulated, [first, *expected], rtol=1e-9, atol=1e-6)
        for step, position in enumerate(window):
            here = np.flatnonzero((s.frame == position) & (s.object == ids.index(obj.name)))
            if len(here):
                at = trajectory[step][j]
                error = max(error, math.hypot(at.x - s.x[here[0]], at.y - s.y[here[0]]))
    return error


def export_dataset_run(tmp_path: Path, query: list, data: list, context: float, capsys) -> list[Path]:
    """Ingest ``data``, run a query (kind, program, options) over the dataset, export the run
    directory: the programs and their rows."""
    dataset = tmp_path / "dataset"
    assert run(["ingest", *data, "--into", dataset, "-q"], capsys)[0] == 0
    code, err = run([*query, "--dataset", dataset, "-j", "1", "-q"], capsys)
    assert code == 0, err
    (run_dir,) = (dataset / "runs").iterdir()
    folder = tmp_path / "programs"
    assert run(["export", run_dir, "--scenic", folder, "--context", context], capsys)[0] == 0
    rows = [r for r in pq.read_table(run_dir / "results.parquet").to_pylist() if r["status"] == "match"]
    return [(folder / f"{r['name']}-{r['match']}.scenic", r) for r in rows]


@pytest.mark.slow
def test_round_trip_on_the_sample_dataset(tmp_path, scenic_compiler, capsys):
    """20 matches on Town01: 8 of a scene (a car following the ego's road) and 6 of the left turn
    over files, 6 of the pedestrian scenario over an ingested dataset (with context)."""
    left, walk = (
        [str(SAMPLE / f"{p}-00{i}.parquet") for i in range(6)]
        for p in ("s2_unprotected_left_turn", "s3_pass_pedestrian")
    )
    scene = ["scene", REPO / "examples/ground_truth/following.scenic", "--tolerance-position", "2",
             "--tolerance-heading", "0.5"]  # fmt: skip
    turn = ["scenario", REPO / "examples/queries/s2_unprotected_left_turn.scenic", "--window", "20"]
    passing = ["scenario", REPO / "examples/queries/s3_pass_pedestrian.scenic", "--window", "20"]
    programs = [(p, r, None) for p, r in export(tmp_path / "scene", scene, left[3:4], 8, None, capsys)]
    programs += [(p, r, 30.0) for p, r in export(tmp_path / "turn", turn, left, 6, 30.0, capsys)]
    programs += [(p, r, 30.0) for p, r in export_dataset_run(tmp_path / "walk", passing, walk, 30.0, capsys)]
    assert len(programs) == 20
    errors = [check_round_trip(p, row, context, scenic_compiler) for p, row, context in programs]
    print(f"sample: {len(errors)} programs, largest position error {max(errors):.3g} m")
    assert max(errors) <= 0.5


@pytest.mark.slow
def test_every_kind_on_an_opendrive_map(tmp_path, scenic_compiler):
    shutil.copy(TOWN01, tmp_path / "Town01.xodr")
    program = tmp_path / "kinds.scenic"
    program.write_text(scenic_program(moment(EVERY_KIND), "Town01.xodr"))
    scene = scene_of(scenic_compiler(program))
    assert [type(o).__name__ for o in scene.objects] == [CLASSES[kind_of(p.category)] for p in EVERY_KIND]
    assert [(o.position.x, o.position.y) for o in scene.objects] == [(p.x[0], p.y[0]) for p in EVERY_KIND]


@pytest.mark.slow
def test_round_trip_on_real_recordings(tmp_path, real_data, scenic_compiler, capsys):
    """5 matches: 3 nuScenes scenes (ScenarioNet) and 2 Argoverse 2 sensor logs, with context."""
    nuscenes = [
        real_data / f"nuscenes_mini_scenarionet/sd_nuscenes_v1.0-mini_scene-{n}.pkl" for n in ("0103", "0655", "0796")
    ]
    av2 = sorted((real_data / "av2" / "sensor").iterdir())
    oncoming = ["scenario", REPO / "examples/queries/real/oncoming_vehicle.scenic", "--unknown-layers", "permissive",
                "--window", "3s"]  # fmt: skip
    facing = ["scenario", REPO / "examples/queries/real/vehicle_facing_toward_ego.scenic", "--unknown-layers",
              "permissive", "--window", "1s"]  # fmt: skip
    programs = [(p, r, 10.0) for p, r in export(tmp_path / "nuscenes", oncoming, nuscenes, 3, 10.0, capsys)]
    programs += [(p, r, 10.0) for p, r in export(tmp_path / "av2", facing, av2, 2, 10.0, capsys)]
    errors = [check_round_trip(p, row, context, scenic_compiler) for p, row, context in programs]
    for program, _, _ in programs:
        assert "# No road map: Scenic reads no" in program.read_text()
    print(f"real: {len(errors)} programs, largest position error {max(errors):.3g} m")
    assert max(errors) <= 0.5


@pytest.mark.parametrize(
    ("write", "option"), [(write_scenic_programs, "--scenic"), (ox.write_openscenario, "--openscenario")]
)
def test_writers_refuse_what_export_refuses_before_reading_a_moment(write, option, tmp_path):
    """Both exporters' Python API refuses a blank folder name or a file with the CLI's one-line
    message, before it asks for the first moment."""

    def no_moments():
        raise AssertionError("a moment was read")
        yield

    (tmp_path / "file").write_text("")
    with pytest.raises(UserError, match=rf"^{option}: give the folder to write to$"):
        write(no_moments(), " ")
    with pytest.raises(UserError, match=rf"^{option} \S+file: not a directory \(one file per match is written"):
        write(no_moments(), tmp_path / "file")


def test_without_map_counts_group_by_reason_in_order(tmp_path):
    written = [WrittenProgram(tmp_path / f"{n}.scenic", reason) for n, reason in enumerate(["z", None, "a", "z"])]
    assert list(without_map_counts(written).items()) == [("a", 1), ("z", 2)]
    assert without_map_counts([]) == {}
