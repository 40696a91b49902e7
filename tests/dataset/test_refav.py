"""RefAV: the submission export, the JSON form, and the balanced accuracies of ``scenegrep
evaluate`` against numbers computed by hand from RefAV's definition (and against a brute-force
reference on random cases)."""

from __future__ import annotations

import json
import math
import pickle

import numpy as np
import pytest
import shapely
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from scenegrep.cli.main import main
from scenegrep.dataset.queries import results_table
from scenegrep.dataset.refav_export import check_request, refav_sequences
from scenegrep.dataset.refav_format import FORMAT, UNSET, RefFrame, read_sequences, sequence_counts, write_sequences
from scenegrep.dataset.refav_score import evaluate, evaluate_files, filter_boxes
from scenegrep.errors import UserError
from scenegrep.dataset.results import Results
from scenegrep.model import LabelTrace, ObjectTable, StateTable
from tests.conftest import REPO


def frame(stamp: int, positive=UNSET, boxes=(), ego=(0.0, 0.0, 0.0)) -> RefFrame:
    """A frame; ``boxes`` are (x, y, label, track) with a 4 x 2 m box facing +x."""
    n = len(boxes)
    return RefFrame(
        stamp,
        np.array(ego, dtype=float),
        np.array([[x, y, 0.0] for x, y, _, _ in boxes]).reshape(n, 3),
        np.tile([4.0, 2.0, 1.5], (n, 1)),
        np.zeros(n),
        np.array([label for _, _, label, _ in boxes], dtype=np.int64),
        np.array([track for _, _, _, track in boxes], dtype=str).reshape(n),
        np.array(["REGULAR_VEHICLE"] * n, dtype=str).reshape(n),
        positive,
    )


def temporal(*answers) -> list[RefFrame]:
    """Frames at 0, 1, ... s saying ``is_positive`` (True, False or None)."""
    return [frame(k * 500_000_000, a) for k, a in enumerate(answers)]


# ----------------------------------------------------------------------------- hand-computed cases
T, F, A = True, False, None

TRUTH = {
    ("log-a", "p1"): temporal(T, T, F, F),
    ("log-b", "p1"): temporal(F, F),
    ("log-c", "p2"): temporal(A, T, F),
    ("log-e", "p2"): temporal(F, F),
    ("log-d", "p3"): temporal(A, A),
}
PREDICTIONS = {
    ("log-a", "p1"): temporal(T, F, F, T),
    ("log-b", "p1"): temporal(F, F),
    ("log-c", "p2"): temporal(T, F, F),  # positive only at the ambiguous frame
    ("log-e", "p2"): temporal(F, T),
    ("log-d", "p3"): temporal(T, T),
}


def test_balanced_accuracy_per_prompt_then_the_mean_by_hand():
    result = evaluate(PREDICTIONS, TRUTH)
    by_prompt = {p.prompt: p for p in result.prompts}
    # p1 frames: a: TP FN TN FP, b: TN TN -> TPR 1/2, TNR 3/4; logs: a TP, b TN
    p1 = by_prompt["p1"]
    assert (p1.timestamp.tp, p1.timestamp.fp, p1.timestamp.fn, p1.timestamp.tn) == (1, 1, 1, 3)
    assert p1.timestamp.balanced_accuracy() == pytest.approx(0.625)
    assert p1.log.balanced_accuracy() == 1.0
    # p2: c's ambiguous frame is not counted (FN, TN), e: TN FP -> TPR 0, TNR 2/3; logs: c is
    # predicted positive by its ambiguous frame (TP), e FP -> TPR 1, TNR 0
    p2 = by_prompt["p2"]
    assert (p2.timestamp.tp, p2.timestamp.fp, p2.timestamp.fn, p2.timestamp.tn) == (0, 1, 1, 2)
    assert p2.timestamp.balanced_accuracy() == pytest.approx(1 / 3)
    assert (p2.log.tp, p2.log.fp, p2.log.fn, p2.log.tn) == (1, 1, 0, 0)
    assert p2.log.balanced_accuracy() == 0.5
    # p3: its only pair is all ambiguous: nothing counted, both rates 1.0
    assert by_prompt["p3"].timestamp.balanced_accuracy() == by_prompt["p3"].log.balanced_accuracy() == 1.0
    assert result.timestamp_ba == pytest.approx((0.625 + 1 / 3 + 1.0) / 3)  # 0.65278
    assert result.log_ba == pytest.approx((1.0 + 0.5 + 1.0) / 3)  # 0.83333
    assert not result.filtered and result.unscored_pairs == 0


def test_boxes_beyond_50_m_of_the_ego_do_not_count_in_a_tracking_submission():
    truth = {
        ("log", "p"): [
            frame(0, boxes=[(10, 0, 0, "t1")]),  # referred, 10 m: positive
            frame(1, boxes=[(60, 0, 0, "t1"), (5, 0, 1, "t2")]),  # referred only at 60 m: negative
            frame(2, boxes=[(5, 0, 1, "t2")]),  # a box that is not referred: negative
            frame(3, ego=(100, 100, 0), boxes=[(130, 140, 0, "t1")]),  # exactly 50 m: positive
        ]
    }
    predicted = {
        ("log", "p"): [
            frame(0, boxes=[(10, 0, 0, "t1")]),  # TP
            frame(1, boxes=[(60, 0, 0, "t1")]),  # filtered: TN
            frame(2, boxes=[(0, 49.9, 0, "t3")]),  # FP
            frame(3),  # FN
        ]
    }
    result = evaluate(predicted, truth)
    counts = result.prompts[0].timestamp
    assert result.filtered
    assert (counts.tp, counts.fp, counts.fn, counts.tn) == (1, 1, 1, 1)
    assert counts.balanced_accuracy() == 0.5
    wider = evaluate(predicted, truth, max_range_m=100).prompts[0].timestamp
    assert (wider.tp, wider.fp, wider.fn, wider.tn) == (2, 1, 1, 0)


def test_a_predicted_referred_box_is_positive_whatever_is_positive_says():
    truth = {("log", "p"): temporal(T, F)}
    predicted = {("log", "p"): [frame(0, F, boxes=[(1, 0, 0, "t")]), frame(500_000_000, F)]}
    counts = evaluate(predicted, truth).prompts[0].timestamp
    assert (counts.tp, counts.tn) == (1, 1)


def test_the_drivable_area_filter_keeps_boxes_with_a_corner_within_5_m():
    area = shapely.box(0, 0, 10, 10)
    # 4 x 2 m boxes facing +x: corners at x +- 2, y +- 1
    kept = filter_boxes(frame(0, boxes=[(16.9, 5, 0, "near"), (17.1, 5, 0, "far"), (5, 5, 0, "in")]), 50, area)
    assert kept.track_id.tolist() == ["near", "in"]  # 14.9 m and 15.1 m: 4.9 m and 5.1 m from the area
    turned = frame(0, boxes=[(16.5, 5, 0, "turned")])
    turned = RefFrame(
        *[getattr(turned, f) for f in ("timestamp_ns", "ego_translation_m", "translation_m", "size")],
        np.array([math.pi / 2]),
        *[getattr(turned, f) for f in ("label", "track_id", "name")],
    )
    assert filter_boxes(turned, 50, area).track_id.tolist() == []  # its long side across x: 15.5 m


def test_evaluate_uses_each_logs_drivable_area():
    truth = {("log", "p"): temporal(F)}
    predicted = {("log", "p"): [frame(0, boxes=[(30, 5, 0, "t")])]}
    assert evaluate(predicted, truth).prompts[0].timestamp.fp == 1
    areas = {"log": shapely.box(0, 0, 10, 10)}
    assert evaluate(predicted, truth, drivable=areas.__getitem__).prompts[0].timestamp.tn == 1


# ----------------------------------------------------------------------------- brute force
answers = st.sampled_from([True, False, None])


@st.composite
def cases(draw):
    pairs = draw(st.lists(st.tuples(st.sampled_from(["p", "q", "r"]), st.integers(1, 6)), min_size=1, max_size=6))
    truth, predicted = {}, {}
    for k, (prompt, n) in enumerate(pairs):
        truth[(f"log{k}", prompt)] = draw(st.lists(answers, min_size=n, max_size=n))
        predicted[(f"log{k}", prompt)] = draw(st.lists(st.booleans(), min_size=n, max_size=n))
    return truth, predicted


def brute_force(truth: dict, predicted: dict) -> tuple[float, float]:
    """RefAV's definition, written out directly."""
    stats = {}
    for (log, prompt), gt in truth.items():
        s = stats.setdefault(prompt, {"t": [0, 0, 0, 0], "l": [0, 0, 0, 0]})  # tp fp fn tn
        if all(a is None for a in gt):
            continue
        for a, b in zip(gt, predicted[(log, prompt)]):
            if a is not None:
                s["t"][0 if a and b else 1 if b else 2 if a else 3] += 1
        a, b = any(x is True for x in gt), any(predicted[(log, prompt)])
        s["l"][0 if a and b else 1 if b else 2 if a else 3] += 1

    def ba(c):
        tpr = c[0] / (c[0] + c[2]) if c[0] + c[2] else 1.0
        tnr = c[3] / (c[3] + c[1]) if c[3] + c[1] else 1.0
        return (tpr + tnr) / 2

    return sum(ba(s["t"]) for s in stats.values()) / len(stats), sum(ba(s["l"]) for s in stats.values()) / len(stats)


@settings(max_examples=200, deadline=None)
@given(cases())
def test_balanced_accuracies_equal_a_brute_force_reference(case):
    truth, predicted = case
    result = evaluate({k: temporal(*v) for k, v in predicted.items()}, {k: temporal(*v) for k, v in truth.items()})
    assert (result.timestamp_ba, result.log_ba) == pytest.approx(brute_force(truth, predicted))


# ----------------------------------------------------------------------------- files and the CLI
def write_json(path, sequences) -> str:
    write_sequences(sequences, path)
    return str(path)


def test_json_round_trips_and_the_pickle_is_refavs_layout(tmp_path):
    sequences = {("log", "p"): [frame(5, boxes=[(1, 2, 0, "t")]), frame(6, A), frame(7, T)]}
    again = read_sequences(write_json(tmp_path / "s.json", sequences))
    assert list(again) == [("log", "p")]
    for a, b in zip(again[("log", "p")], sequences[("log", "p")]):
        assert a.as_json() == b.as_json()
    write_sequences(sequences, tmp_path / "s.pkl")
    with open(tmp_path / "s.pkl", "rb") as stream:  # scenegrep wrote this file in this test
        data = pickle.load(stream)
    first = data[("log", "p")][0]
    assert first["translation_m"].shape == (1, 3) and first["translation_m"][:, :2].tolist() == [[1.0, 2.0]]
    assert first["label"].tolist() == [0] and first["track_id"].tolist() == ["t"] and first["score"].tolist() == [1.0]
    assert "is_positive" not in first and data[("log", "p")][1]["is_positive"] is None


def run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_evaluate_prints_both_balanced_accuracies(tmp_path, capsys):
    predictions, truth = write_json(tmp_path / "p.json", PREDICTIONS), write_json(tmp_path / "t.json", TRUTH)
    code, out, _ = run(["evaluate", predictions, truth], capsys)
    assert code == 0
    assert "timestamp-level balanced accuracy: 0.6528" in out and "log-level balanced accuracy: 0.8333" in out
    assert "p1: timestamp 0.6250 (TP 1 FP 1 FN 1 TN 3); log 1.0000 (TP 1 FP 0 FN 0 TN 1)" in out
    code, out, _ = run(["evaluate", predictions, truth, "--json"], capsys)
    document = json.loads(out)
    assert document["log_balanced_accuracy"] == pytest.approx(2.5 / 3)
    assert [p["prompt"] for p in document["prompts"]] == ["p1", "p2", "p3"]


def test_evaluate_files_gives_the_documented_record(tmp_path, capsys):
    """The Python API's record is what ``evaluate --json`` prints; its counts are the hand-computed ones."""
    predictions, truth = write_json(tmp_path / "p.json", PREDICTIONS), write_json(tmp_path / "t.json", TRUTH)
    document = evaluate_files(predictions, truth, max_range_m=30).document()
    assert document["max_range_m"] == 30 and document["drivable_area_filter"] is False
    first = document["prompts"][0]
    assert first["prompt"] == "p1" and [first["timestamp"][k] for k in ("tp", "fp", "fn", "tn")] == [1, 1, 1, 3]
    assert first["timestamp"]["balanced_accuracy"] == pytest.approx(0.625)
    code, out, _ = run(["evaluate", predictions, truth, "--json", "--max-range", "30"], capsys)
    printed = json.loads(out)  # floats to 6 significant digits (scenegrep.json_lines)
    assert code == 0 and printed.keys() == document.keys() and printed["prompts"][0] == first
    assert printed["timestamp_balanced_accuracy"] == pytest.approx(document["timestamp_balanced_accuracy"], abs=1e-6)


@pytest.mark.parametrize("bad", [math.nan, math.inf, -1.0, 0.0])
def test_evaluate_refuses_a_bad_range_before_reading(tmp_path, bad):
    """The API refuses what the CLI refuses, with the same one-line message, before any file is read."""
    with pytest.raises(UserError, match=r"^--max-range \S+: give a positive number of metres$"):
        evaluate_files(tmp_path / "missing.json", tmp_path / "missing.json", bad)
    with pytest.raises(UserError, match="give a positive number"):
        evaluate(PREDICTIONS, TRUTH, bad)


def hostile(tmp_path):
    good = {
        "timestamp_ns": 0,
        "ego_translation_m": [0, 0, 0],
        "translation_m": [[1, 2, 3]],
        "size": [[4, 2, 1]],
        "yaw": [0],
        "label": [0],
        "track_id": ["t"],
        "name": ["CAR"],
    }

    def doc(**changes):
        return json.dumps({"format": FORMAT, "sequences": [{"log_id": "l", "prompt": "p", "frames": [good | changes]}]})

    return {
        "pickle.pkl": (pickle.dumps({("l", "p"): []}), "is a pickle, which can run code when loaded"),
        "disguised.json": (b"\x80\x04" + b"rest", "is a pickle"),
        "nan.json": (doc().replace("[1, 2, 3]", "[NaN, 2, 3]").encode(), "not JSON"),
        "huge.json": (doc().replace("[1, 2, 3]", "[1e999, 2, 3]").encode(), "not JSON"),
        "text.json": (b"hello", "not JSON"),
        "list.json": (b"[]", "not RefAV JSON"),
        "label.json": (doc(label=["x"]).encode(), "frames[0].label: must be a list of whole numbers"),
        "big.json": (doc(label=[2**64 - 1]).encode(), "frames[0].label: must be a list of whole numbers"),
        "deep.json": (b"[" * 100_000 + b"]" * 100_000, "not JSON"),
        "rows.json": (doc(translation_m=[[1, 2]]).encode(), "translation_m[0]: must be a list of 3 finite numbers"),
        "count.json": (doc(yaw=[0, 1]).encode(), "frames[0].yaw: must be a list of 1 finite numbers"),
        "stamp.json": (doc(timestamp_ns=-1).encode(), "timestamp_ns: must be a whole number"),
        "positive.json": (doc(is_positive="yes").encode(), "is_positive: must be true, false or null"),
        "ids.json": (doc(track_id=[None]).encode(), "track_id: must be a list of 1 ids"),
    }


def test_hostile_files_are_one_line_and_exit_2(tmp_path, capsys):
    truth = write_json(tmp_path / "t.json", {("l", "p"): [frame(0)]})
    for name, (content, message) in hostile(tmp_path).items():
        (tmp_path / name).write_bytes(content)
        for argv in (["evaluate", tmp_path / name, truth], ["evaluate", truth, tmp_path / name]):
            code, out, err = run(argv, capsys)
            assert (code, out) == (2, ""), name
            assert len(err.splitlines()) == 1 and message in err, (name, err)


def test_a_file_over_the_limit_is_refused_before_reading(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr("scenegrep.dataset.refav_format.MAX_BYTES", 10)
    truth = write_json(tmp_path / "t.json", {("l", "p"): [frame(0)]})
    code, _, err = run(["evaluate", truth, truth], capsys)
    assert code == 2 and "bytes is more than the 10 bytes scenegrep reads" in err and len(err.splitlines()) == 1


@pytest.mark.parametrize(
    "predicted, message",
    [
        ({("other", "p"): [frame(0)]}, "the predictions have no frames for log 'l' and prompt 'p'"),
        ({("l", "p"): [frame(0), frame(1)]}, "the predicted frames' timestamps are not the ground truth's"),
        ({("l", "p"): [frame(3)]}, "the predicted frames' timestamps are not the ground truth's"),
    ],
)
def test_predictions_that_do_not_cover_the_ground_truth_are_refused(tmp_path, capsys, predicted, message):
    truth = write_json(tmp_path / "t.json", {("l", "p"): [frame(0)]})
    code, _, err = run(["evaluate", write_json(tmp_path / "p.json", predicted), truth], capsys)
    assert code == 2 and message in err and len(err.splitlines()) == 1


def test_evaluate_option_errors(tmp_path, capsys):
    truth = write_json(tmp_path / "t.json", {("l", "p"): [frame(0)]})
    for argv, message in (
        (["--max-range", "nan"], "--max-range nan: give a positive number"),
        (["--max-range", "-1"], "give a positive number"),
        (["--av2", tmp_path], "no Argoverse 2 log 'l' with a map"),
    ):
        predicted = write_json(tmp_path / "p.json", {("l", "p"): [frame(0, boxes=[(1, 0, 0, "t")])]})
        code, _, err = run(["evaluate", predicted, truth, *argv], capsys)
        assert code == 2 and message in err and len(err.splitlines()) == 1, err
    code, _, err = run(["evaluate", tmp_path / "missing.json", truth], capsys)
    assert code == 2 and "cannot read" in err
    code, _, err = run(["evaluate", tmp_path, truth], capsys)
    assert code == 2 and "not a regular file" in err


# ----------------------------------------------------------------------------- export
def av2_like(name: str = "log-1", dataset: str = "argoverse2-sensor") -> LabelTrace:
    """12 frames at 10 Hz: the ego along +x at 1 m per frame, car 'c' 10 m north of it facing
    north, pedestrian 'w' from frame 6 on."""
    frames = np.arange(12)
    objects = ObjectTable.build(["c", "ego", "w"], ["REGULAR_VEHICLE", "REGULAR_VEHICLE", "PEDESTRIAN"])
    rows = [(f, 0, f, 10.0, 0.0) for f in frames] + [(f, 1, f, 0.0, -np.pi / 2) for f in frames]
    rows += [(f, 2, 5.0, 5.0, 0.0) for f in frames if f >= 6]
    f, o, x, y, h = (np.array(v) for v in zip(*rows))
    n = len(f)
    states = StateTable.build(
        frame=f,
        object=o,
        x=x,
        y=y,
        z=np.full(n, 0.5),
        heading=h,
        length=np.full(n, 4.0),
        width=np.full(n, 2.0),
        height=np.full(n, 1.5),
    )
    attributes = {"dataset": dataset, "log_id": name, "time_origin_ns": 1_000_000_000_000}
    return LabelTrace.build(name, frames + 100, frames / 10, objects, states, ego="ego", attributes=attributes)


def results_of(rows: list[dict], status: str = "finished") -> Results:
    base = {"trace_id": "t1", "name": "log-1", "source": "x", "time_origin_ns": 1_000_000_000_000}
    return Results(results_table([base | r for r in rows]), "run", status)


def match_row(objects: dict, first: int, last: int, number: int = 0) -> dict:
    span = {"start_frame": first, "end_frame": last, "start_time": (first - 100) / 10, "end_time": (last - 100) / 10}
    return {
        "status": "match",
        "match": number,
        "correspondence": json.dumps({k: v for k, v in objects.items()}),
        "objects": json.dumps({k: {"id": v, **span} for k, v in objects.items()}),
        **span,
    }


def test_export_puts_the_referred_track_at_each_2_hz_timestamp_of_its_frames():
    results = results_of(
        [match_row({"ego": "ego", "car": "c"}, 103, 107), match_row({"ego": "ego", "car": "w"}, 104, 111, 1)]
    )
    frames = refav_sequences(results, lambda _: av2_like(), "car north of ego")[("log-1", "car north of ego")]
    # positions 0, 5, 10 (dataset frames 100, 105, 110) at 1e12 ns + 0, 0.5 s, 1 s
    assert [f.timestamp_ns for f in frames] == [1_000_000_000_000, 1_000_500_000_000, 1_001_000_000_000]
    assert [f.track_id.tolist() for f in frames] == [[], ["c"], ["w"]]  # w is involved in 105 but unobserved
    middle = frames[1]
    assert middle.translation_m.tolist() == [[5.0, 10.0, 0.5]] and middle.ego_translation_m.tolist() == [5.0, 0.0, 0.5]
    assert middle.yaw.tolist() == pytest.approx([math.pi / 2])  # facing north: AV2 yaw pi/2
    assert middle.size.tolist() == [[4.0, 2.0, 1.5]] and middle.label.tolist() == [0]
    assert middle.name.tolist() == ["REGULAR_VEHICLE"]


def test_export_chooses_the_referred_object_by_a_documented_rule():
    two = results_of([match_row({"ego": "ego", "car": "c", "walker": "w"}, 105, 111)])
    with pytest.raises(
        Exception, match="besides ego are car, walker: name the one the prompt refers to with --referred"
    ):
        refav_sequences(two, lambda _: av2_like(), "p")
    frames = refav_sequences(two, lambda _: av2_like(), "p", referred="walker")[("log-1", "p")]
    assert [f.track_id.tolist() for f in frames] == [[], [], ["w"]]  # w is first observed at frame 106
    ego = refav_sequences(two, lambda _: av2_like(), "p", referred="ego")[("log-1", "p")]
    assert [f.track_id.tolist() for f in ego] == [[], ["ego"], ["ego"]]
    with pytest.raises(Exception, match="--referred bike: match 0 of log-1 has no such program object"):
        refav_sequences(two, lambda _: av2_like(), "p", referred="bike")


def test_a_trace_without_a_match_gives_negative_frames():
    frames = refav_sequences(results_of([{"status": "no match", "match": -1}]), lambda _: av2_like(), "p")
    assert [len(f.label) for f in frames[("log-1", "p")]] == [0, 0, 0]


@pytest.mark.parametrize(
    "results, trace, message",
    [
        (
            results_of([{"status": "no match", "match": -1}]),
            av2_like(dataset="nuscenes"),
            "is not an Argoverse 2 sensor log",
        ),
        (results_of([{"status": "failed", "match": -1}]), av2_like(), "trace log-1 failed, so its answer is unknown"),
        (results_of([{"status": "no match", "match": -1}], "interrupted"), av2_like(), "the run is interrupted"),
        (results_of([match_row({"car": "zz"}, 100, 101)]), av2_like(), "has no object 'zz' that the results name"),
        (results_of([match_row({"car": "c"}, 100, 101) | {"objects": "{"}]), av2_like(), "objects are not scenegrep's"),
        (results_of([match_row({"car": "c"}, 100, 101) | {"objects": '{"car": 3}'}]), av2_like(), "not scenegrep's"),
    ],
)
def test_export_refuses_what_refav_cannot_be_given(results, trace, message):
    with pytest.raises(Exception, match=message):
        refav_sequences(results, lambda _: trace, "p")


def test_export_then_evaluate_from_the_command_line(tmp_path, capsys, monkeypatch):
    """Over files: the sample's traces are not AV2 logs, so the export is a one-line error."""
    table = results_of([{"status": "no match", "match": -1}])
    table.write_parquet(tmp_path / "r.parquet")
    code, _, err = run(["export", tmp_path / "r.parquet", "--refav", tmp_path / "s.json", "--prompt", "p"], capsys)
    assert code == 2 and len(err.splitlines()) == 1
    for argv, message in (
        (["--refav", tmp_path / "s.txt", "--prompt", "p"], "write a .pkl (RefAV's pickle) or a .json file"),
        (["--refav", tmp_path / "s.json"], "--refav needs --prompt TEXT"),
        (["--mcap", tmp_path / "m.mcap", "--prompt", "p"], "--prompt, --referred and --dataset go with --refav"),
        (["--mcap", tmp_path / "m.mcap", "--refav", tmp_path / "s.json"], "not allowed with argument"),
    ):
        code, _, err = run(["export", tmp_path / "r.parquet", *argv], capsys)
        assert code == 2 and message in err and len(err.splitlines()) == 1, err


# ----------------------------------------------------------------------------- real AV2 logs
def quaternion_matrix(qw, qx, qy, qz) -> np.ndarray:
    """The rotation of a unit quaternion (the textbook formula)."""
    return np.array(
        [
            [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
            [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
            [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
        ]
    )


@pytest.mark.real_data
def test_export_of_real_av2_logs_has_their_timestamps_and_boxes(real_data, tmp_path, capsys):
    import pyarrow.feather as feather

    logs = sorted((real_data / "av2" / "sensor").iterdir())
    program = REPO / "examples" / "scenes" / "fig3_car_ahead.scenic"
    query = ["scene", program, *logs, "--tolerance-profile", "av2", "--visible-distance", "50"]
    code, _, _ = run([*query, "--output", tmp_path / "r.parquet", "-q"], capsys)
    assert code == 0
    out = tmp_path / "s.json"
    assert run(["export", tmp_path / "r.parquet", "--refav", out, "--prompt", "car ahead"], capsys)[0] == 0
    sequences = read_sequences(out)
    assert sorted(log for log, _ in sequences) == [log.name for log in logs]
    boxes = 0
    for (log_id, _), frames in sequences.items():
        ann = feather.read_table(real_data / "av2" / "sensor" / log_id / "annotations.feather").to_pandas()
        poses = feather.read_table(real_data / "av2" / "sensor" / log_id / "city_SE3_egovehicle.feather").to_pandas()
        stamps = sorted(set(ann["timestamp_ns"].tolist()))
        assert [f.timestamp_ns for f in frames] == stamps[::5]  # every 5th annotation timestamp: 2 Hz
        for f in frames:
            pose = poses[poses["timestamp_ns"] == f.timestamp_ns].iloc[0]
            rotation = quaternion_matrix(pose.qw, pose.qx, pose.qy, pose.qz)
            assert f.ego_translation_m == pytest.approx([pose.tx_m, pose.ty_m, pose.tz_m])
            for k, track in enumerate(f.track_id.tolist()):
                raw = ann[(ann["timestamp_ns"] == f.timestamp_ns) & (ann["track_uuid"] == track)].iloc[0]
                city = rotation @ [raw.tx_m, raw.ty_m, raw.tz_m] + [pose.tx_m, pose.ty_m, pose.tz_m]
                assert f.translation_m[k] == pytest.approx(city, abs=1e-6)
                assert f.size[k] == pytest.approx([raw.length_m, raw.width_m, raw.height_m])
                box_yaw = 2 * math.atan2(raw.qz, raw.qw)  # boxes rotate about z only
                ego_yaw = math.atan2(rotation[1, 0], rotation[0, 0])
                assert math.cos(f.yaw[k] - box_yaw - ego_yaw) == pytest.approx(1.0)
                assert f.label[k] == 0 and f.name[k] == raw.category
                boxes += 1
    assert boxes > 0
    # the export scores perfectly against itself, with the logs' own drivable areas
    code, text, _ = run(["evaluate", out, out, "--av2", real_data / "av2" / "sensor", "--json"], capsys)
    assert code == 0 and json.loads(text)["timestamp_balanced_accuracy"] == 1.0
    assert json.loads(text)["drivable_area_filter"] is True


@pytest.mark.real_data
def test_export_of_a_dataset_run_equals_the_export_over_files(real_data, tmp_path, capsys):
    logs = real_data / "av2" / "sensor"
    program = REPO / "examples" / "scenes" / "fig3_car_ahead.scenic"
    options = ["--tolerance-profile", "av2", "--visible-distance", "50", "-q"]
    assert run(["ingest", logs, "--into", tmp_path / "ds", "-q"], capsys)[0] == 0
    assert run(["scene", program, "--dataset", tmp_path / "ds", *options], capsys)[0] == 0
    (run_dir,) = (tmp_path / "ds" / "runs").iterdir()
    assert run(["scene", program, logs, *options, "--output", tmp_path / "r.parquet"], capsys)[0] == 0
    for results, out in ((run_dir, "ds.json"), (tmp_path / "r.parquet", "files.json")):
        assert run(["export", results, "--refav", tmp_path / out, "--prompt", "p", "-q"], capsys)[0] == 0
    assert json.loads((tmp_path / "ds.json").read_text()) == json.loads((tmp_path / "files.json").read_text())


def test_the_readmes_pickle_conversion_gives_refav_json(tmp_path, monkeypatch):
    """The README's snippet, run on a pickle scenegrep wrote, gives what ``--refav OUT.json`` gives."""
    readme = (REPO / "README.md").read_text()
    snippet = readme.split("To convert a pickle you trust", 1)[1].split("```python\n", 1)[1].split("```", 1)[0]
    sequences = {("0" * 36, "a prompt"): [frame(0, boxes=[(1, 2, 0, "t")]), frame(500_000_000, A)]}
    write_sequences(sequences, tmp_path / "gt.pkl")
    monkeypatch.chdir(tmp_path)
    exec(snippet, {})  # scenegrep wrote gt.pkl in this test
    converted = read_sequences(tmp_path / "gt.json")
    assert list(converted) == list(sequences)
    for a, b in zip(converted[("0" * 36, "a prompt")], sequences[("0" * 36, "a prompt")]):
        assert a.as_json() == b.as_json()


def test_a_row_written_before_the_objects_column_involves_its_objects_in_the_whole_match():
    old = results_of([match_row({"ego": "ego", "car": "c"}, 104, 111) | {"objects": None}])
    frames = refav_sequences(old, lambda _: av2_like(), "p")[("log-1", "p")]
    assert [f.track_id.tolist() for f in frames] == [[], ["c"], ["c"]]


coordinate = st.floats(-80, 80, allow_nan=False)


@settings(max_examples=200, deadline=None)
@given(
    st.lists(
        st.tuples(coordinate, coordinate, st.floats(-4, 4), st.floats(0.5, 6), st.floats(0.5, 3)),
        min_size=1,
        max_size=8,
    )
)
def test_box_filters_equal_a_brute_force_reference(boxes):
    """Kept: centre within 50 m of the ego at (0, 0), and some corner within 5 m of the square
    [0, 20] x [0, 20] (the distance to a rectangle written out)."""
    n = len(boxes)
    given_frame = RefFrame(
        0,
        np.zeros(3),
        np.array([[x, y, 0.0] for x, y, *_ in boxes]),
        np.array([[length, width, 1.0] for *_, length, width in boxes]),
        np.array([yaw for _, _, yaw, _, _ in boxes]),
        np.zeros(n, dtype=np.int64),
        np.array([str(k) for k in range(n)]),
        np.array(["CAR"] * n),
    )
    kept = filter_boxes(given_frame, 50.0, shapely.box(0, 0, 20, 20)).track_id.tolist()
    expected = []
    for k, (x, y, yaw, length, width) in enumerate(boxes):
        near_corner = False
        for along, across in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            cx = x + along * length / 2 * math.cos(yaw) - across * width / 2 * math.sin(yaw)
            cy = y + along * length / 2 * math.sin(yaw) + across * width / 2 * math.cos(yaw)
            gap = math.hypot(max(0.0, -cx, cx - 20), max(0.0, -cy, cy - 20))
            assume(abs(gap - 5.0) > 1e-6)  # rounding decides exactly at the line
            near_corner |= gap <= 5.0
        assume(abs(math.hypot(x, y) - 50.0) > 1e-6)
        if math.hypot(x, y) <= 50.0 and near_corner:
            expected.append(str(k))
    assert kept == expected


def test_the_api_refuses_what_export_refav_refuses(tmp_path):
    """The Python API refuses a bad file name and an empty prompt with ``export --refav``'s one-line
    messages, before anything is written."""
    for name in ("s.txt", "s.pickle", "s"):
        with pytest.raises(UserError, match=r"^--refav \S+: write a \.pkl \(RefAV's pickle\) or a \.json file$"):
            write_sequences({}, tmp_path / name)
        assert not (tmp_path / name).exists()
    needs = r"^--refav needs --prompt TEXT: RefAV keys a submission by \(log id, prompt\)$"
    for prompt in ("", None):
        with pytest.raises(UserError, match=needs):
            check_request(tmp_path / "s.json", prompt)
    with pytest.raises(UserError, match=needs):
        refav_sequences(results_of([{"status": "no match", "match": -1}]), lambda _: None, "")
    check_request(tmp_path / "S.PKL", "p")  # the suffix in any case


def test_sequence_counts_counts_sequences_boxed_sequences_and_frames():
    boxed = [frame(0), frame(1, boxes=[(1, 0, 0, "t")])]
    assert sequence_counts({("a", "p"): boxed, ("b", "p"): [frame(0)], ("a", "q"): []}) == (3, 1, 3)
    assert sequence_counts({}) == (0, 0, 0)
