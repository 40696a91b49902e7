"""One test per semantic rule of SpRE evaluation (default and --compat strem)."""

import json
import math

import pytest

from scenegrep.errors import UserError
from scenegrep.readers.trace_json import decode as decode_trace
from scenegrep.spre import SearchOptions, compile_query, search


def image_trace(frames, channels=("cam",), objects=None):
    """A scenegrep-json trace of image boxes: frames[f] is a list of samples (one per
    channel name in ``channels``), each a list of boxes (class, cx, cy, w, h[, rotation[, object]])."""

    def box(b):
        out = {"class": b[0], "center": [b[1], b[2]], "size": [b[3], b[4]]}
        if len(b) > 5 and b[5] is not None:
            out["rotation"] = b[5]
        if len(b) > 6:
            out["object"] = b[6]
        return out

    doc = {
        "scenegrep": "trace",
        "version": 1,
        "objects": {o: {"class": c} for o, c in (objects or {}).items()},
        "frames": [
            {
                "samples": [
                    {"channel": ch, "image_size": [100, 100], "boxes": [box(b) for b in sample]}
                    for ch, sample in zip(channels, frame)
                ]
            }
            for frame in frames
        ],
    }
    return decode_trace(json.dumps(doc).encode(), "<test>", "t")


def frames_matching(query, trace, compat=False, **options):
    return [
        m.start
        for m in search(compile_query(query, compat=compat), trace, SearchOptions(**options), online=True)
        if m.end - m.start == 1
    ]


def spans(query, trace, compat=False, online=False, **options):
    return [
        (m.start, m.end)
        for m in search(compile_query(query, compat=compat), trace, SearchOptions(**options), online=online)
    ]


CAR = ("car", 10, 10, 4, 4)
PED = ("ped", 50, 50, 4, 4)


def test_frame_without_samples_satisfies_nothing_but_the_wildcard():
    trace = image_trace([[[CAR]], [], [[]]])
    assert frames_matching("[![:car:]]", trace) == [2]
    assert frames_matching("[1 > 0]", trace) == [0, 2]
    assert frames_matching(".", trace) == [0, 1, 2]


def test_a_frame_satisfies_a_formula_when_one_of_its_samples_does():
    trace = image_trace([[[CAR], [PED]], [[CAR, PED], []]], channels=("front", "back"))
    assert frames_matching("[[:car:] & [:ped:]]", trace) == [1]
    assert frames_matching("[![:car:]]", trace) == [0, 1]
    assert frames_matching("[[:car:]]", trace, channels=("back",)) == []


def test_comparisons_are_existential_and_empty_sides_are_false():
    trace = image_trace([[[("car", 10, 0, 2, 2), ("car", 90, 0, 2, 2)]], [[PED]]])
    assert frames_matching("[@x([:car:]) > 50]", trace) == [0]
    assert frames_matching("[@x([:car:]) < 50]", trace) == [0]
    assert frames_matching("[@x([:car:]) > 95]", trace) == []
    assert frames_matching("[@x([:car:]) < 1000]", trace) == [0]
    assert frames_matching("[@x([:car:]) == 90]", trace) == [0]
    assert frames_matching("[@x([:car:]) != 10]", trace) == [0]


def test_universal_quantifier_needs_an_assignment():
    trace = image_trace([[[CAR]], [[PED]], [[CAR, ("car", 80, 80, 4, 4)]]])
    assert frames_matching("[A(v := [:car:]) @x(v) < 50]", trace) == [0]
    assert frames_matching("[A(v := [:car:]) @x(v) > 0]", trace) == [0, 2]
    assert frames_matching("[E(v := [:car:]) @x(v) > 50]", trace) == [2]


def test_touching_boxes_overlap_as_point_sets_but_not_in_strem_or_by_interiors():
    touching = image_trace([[[("car", 10, 10, 4, 4), ("ped", 14, 10, 4, 4)]]])
    assert frames_matching("[NE([:car:] & [:ped:])]", touching) == [0]
    assert frames_matching("[NE(<interior>([:car:]) & <interior>([:ped:]))]", touching) == []
    assert frames_matching("[NE([:car:] & [:ped:])]", touching, compat=True) == []
    overlapping = image_trace([[[("car", 10, 10, 4, 4), ("ped", 13, 10, 4, 4)]]])
    assert frames_matching("[NE(I([:car:]) & I([:ped:]))]", overlapping) == [0]
    assert frames_matching("[NE([:car:] & [:ped:])]", overlapping, compat=True) == [0]


def test_intersection_regions_are_clipped_but_strem_keeps_the_boxes():
    trace = image_trace([[[("car", 10, 10, 4, 4), ("ped", 13, 10, 4, 4)]]])
    assert frames_matching("[@area([:car:] & [:ped:]) == 4]", trace) == [0]  # a 1 x 4 overlap
    assert frames_matching("[@area([:car:] & [:ped:]) > 15]", trace) == []
    assert frames_matching("[@area([:car:] & [:ped:]) > 15]", trace, compat=True) == [0]
    assert frames_matching("[@x([:car:] & [:ped:]) == 11.5]", trace) == [0]


def test_complement_is_taken_within_the_image():
    small = image_trace([[[("car", 50, 50, 10, 10), ("ped", 5, 5, 4, 4)]]])
    assert frames_matching("[NE(~[:car:])]", small) == [0]
    assert frames_matching("[@area(~[:car:]) == 9900]", small) == [0]
    assert frames_matching("[[:ped:] <subset> ~[:car:]]", small) == [0]
    assert frames_matching("[[:car:] <subset> ~[:ped:]]", small) == [0]
    covering = image_trace([[[("car", 50, 50, 100, 100)]]])
    assert frames_matching("[NE(~[:car:])]", covering) == []


def test_subset_with_open_and_closed_regions():
    trace = image_trace([[[("car", 10, 10, 4, 4), ("bus", 10, 10, 8, 8), ("ped", 12, 10, 4, 4)]]])
    assert frames_matching("[[:car:] <= [:bus:]]", trace) == [0]
    assert frames_matching("[[:bus:] <= [:car:]]", trace) == []
    assert frames_matching("[[:ped:] <= [:bus:]]", trace) == [0]  # touches the bus edge from inside
    assert frames_matching("[[:ped:] <= <interior>([:bus:])]", trace) == []
    assert frames_matching("[[:car:] <= <interior>([:bus:])]", trace) == [0]


def test_oriented_boxes_intersect_exactly():
    diamond = ("car", 0, 0, 2 * math.sqrt(2), 2 * math.sqrt(2), math.pi / 4)  # a diamond with vertices at +-2
    corner = ("ped", 1.9, 1.9, 0.2, 0.2)  # inside the diamond's bounding box, outside the diamond
    inside = ("ped", 0.5, 0.5, 0.2, 0.2)
    trace = image_trace([[[diamond, corner]], [[diamond, inside]]])
    assert frames_matching("[NE([:car:] & [:ped:])]", trace) == [1]
    assert frames_matching("[@area([:car:]) > 7.99 & @area([:car:]) < 8.01]", trace) == [0, 1]
    assert frames_matching("[@area([:car:]) > 7.99]", trace, compat=True) == [0, 1]
    assert frames_matching("[NE([:car:] & [:ped:])]", trace, compat=True) == []  # STREM: AABB x OBB is empty
    both_rotated = image_trace([[[diamond, ("ped", 0, 0, 1, 1, 0.3)]]])
    with pytest.raises(UserError, match="two oriented boxes"):
        frames_matching("[NE([:car:] & [:ped:])]", both_rotated, compat=True)


def test_filters_and_kinds():
    trace = image_trace([[[("car", 1, 1, 1, 1), ("REGULAR_VEHICLE", 2, 2, 1, 1)]], [[("vehicle.car", 1, 1, 1, 1)]]])
    assert frames_matching("[[:car:]]", trace) == [0, 1]  # the canonical kind
    assert frames_matching("[[:car:]]", trace, compat=True) == [0]  # STREM: the exact class only
    assert frames_matching("[[:REGULAR_VEHICLE:]]", trace) == [0]
    scored = image_trace([[[("car", 1, 1, 1, 1)]]])
    assert frames_matching("[[:car:score>=1:]]", scored) == [0]
    assert frames_matching("[[:car:score<1:]]", scored) == []


def test_track_binder_binds_one_object_for_the_whole_group():
    """The same pedestrian is occluded by a car, then visible, then occluded again."""

    def occluded(ped):
        return [("car", 10, 10, 10, 10, None, "c"), ("pedestrian", 10, 10, 2, 2, None, ped)]

    def free(ped):
        return [("car", 10, 10, 10, 10, None, "c"), ("pedestrian", 50, 50, 2, 2, None, ped)]

    objects = {"c": "car", "p1": "pedestrian", "p2": "pedestrian"}
    same = image_trace([[occluded("p1")], [free("p1")], [occluded("p1")]], objects=objects)
    swapped = image_trace([[occluded("p1")], [free("p2")], [occluded("p1")]], objects=objects)
    query = "E(p := [:pedestrian:]) ([NE(p & [:car:])]+ [p & !NE(p & [:car:])]+ [NE(p & [:car:])]+)"
    assert spans(query, same) == [(0, 3)]
    assert spans(query, swapped) == []
    occlusion = "[NE([:pedestrian:] & [:car:])]+"
    plain = f"{occlusion} [[:pedestrian:] & !NE([:pedestrian:] & [:car:])]+ {occlusion}"
    assert spans(plain, swapped) == [(0, 3)]
    (match,) = search(compile_query(query), same)
    assert match.bound == {"p": "p1"}


def test_track_binder_needs_identities():
    trace = image_trace([[[PED]]])
    with pytest.raises(UserError, match="object identities"):
        spans("E(p := [:ped:]) ([p])", trace)


def test_topdown_relations_follow_the_reference_heading():
    doc = {
        "scenegrep": "trace",
        "version": 1,
        "ego": "ego",
        "objects": {"ego": {"class": "car", "size": [4, 2]}, "p": {"class": "pedestrian", "size": [0.5, 0.5]}},
        "frames": [
            {
                "objects": {
                    "ego": {"position": [0, 0], "heading": 0.0},  # facing north (+y)
                    "p": {"position": [-3, 10], "heading": 0.0},
                }
            },
            {
                "objects": {
                    "ego": {"position": [0, 0], "heading": math.pi / 2},  # facing west (-x)
                    "p": {"position": [-3, 10], "heading": 0.0},
                }
            },
        ],
    }
    trace = decode_trace(json.dumps(doc).encode(), "<test>", "t")
    assert frames_matching("[<frontof>([:pedestrian:])]", trace) == [0, 1]
    assert frames_matching("[<leftof>([:pedestrian:])]", trace) == [0]
    assert frames_matching("[<rightof>([:pedestrian:], [:ego:])]", trace) == [1]
    assert frames_matching("[@dist([:pedestrian:], [:ego:]) < 11]", trace) == [0, 1]
    assert frames_matching("[@gap([:pedestrian:], [:ego:]) < 7.5]", trace) == []


def test_offline_and_online_semantics():
    trace = image_trace([[[CAR]], [[CAR]], [[CAR]], [[PED]]])
    assert spans("[[:car:]]*", trace) == [(0, 3)]
    assert spans("[[:car:]]*", trace, online=True) == [(0, 1), (0, 2), (0, 3)]
    assert spans("[[:car:]]{2}", trace, online=True) == [(0, 2), (1, 3)]
    assert spans("[[:car:]]*|[[:ped:]]", trace) == [(0, 3), (3, 4)]  # no leftmost-first shadowing
    assert spans("[[:car:]]+.", trace) == [(0, 4)]
    assert spans("[[:car:]]?[[:ped:]]", trace) == [(2, 4)]
    assert spans("", trace) == []
