"""Behaviours -> HFSMs (seed 000 Fig. 2), the vocabulary file, and the errors of the fragment."""

import pytest

from scenegrep.errors import UserError
from scenegrep.scenario import compile_scenario, load_vocabulary
from scenegrep.scenario import hfsm as H
from scenegrep.scenario.vocabulary import read_vocabulary

HEADER = "model scenic.simulators.newtonian.driving_model\n"


def compile_ego(behaviours: str, call: str = "B()", extra: str = ""):
    text = HEADER + behaviours + f"ego = new Car with behavior {call}\nother = new Car ahead of ego by 5\n" + extra
    return compile_scenario(text, "prog.scenic")


def test_syntax_directed_translation_keeps_the_hierarchy():
    query = compile_ego(
        "behavior B():\n"
        "    do FollowLaneBehavior() until (distance to other) < 5\n"
        "    try:\n"
        "        do LaneChangeBehavior() for 2 seconds\n"
        "    interrupt when (distance to other) < 2:\n"
        "        do W()\n"
        "behavior W():\n"
        "    while True:\n"
        "        wait\n"
    )
    root = query.hfsms["ego"].root
    assert isinstance(root, H.Sequence) and len(root.children) == 2
    until, attempt = root.children
    assert isinstance(until, H.DoUntil) and until.child == H.BaseState("FollowLane", ends=False)
    assert isinstance(attempt, H.TryInterrupt)
    assert isinstance(attempt.body, H.DoFor) and (attempt.body.amount, attempt.body.unit) == (2.0, "seconds")
    assert attempt.body.child == H.BaseState("LaneChange", ends=True)
    assert attempt.handlers[0][1] == H.BaseState("W", ends=False)  # while True of take/wait: never ends
    assert len(query.guards) == 2 and query.guards[0].objects == ("ego", "other")
    assert query.hfsms["other"].root is None  # no behaviour: Stationary
    assert query.hfsms["other"].outputs() == ("Stationary",)


def test_the_same_condition_is_one_guard():
    query = compile_ego(
        "behavior B():\n"
        "    do FollowLaneBehavior() until (distance to other) < 5\n"
        "    do LaneChangeBehavior() until (distance to other) < 5\n"
    )
    assert len(query.guards) == 1


def test_parameters_bind_arguments_and_self():
    query = compile_ego(
        "behavior B(obstacle, gap=4):\n    do FollowLaneBehavior() until (distance from self to obstacle) < gap\n",
        call="B(other)",
    )
    guard = query.guards[0]
    assert guard.objects == ("ego", "other") and not guard.is_random


@pytest.mark.parametrize(
    ("behaviours", "call", "message", "line"),
    [
        ("behavior B():\n    do B()\n", "B()", "runs itself", 3),
        ("behavior B(d):\n    do Turn() until (distance to other) < d\n", "B(Range(1, 2))", "is random", 4),
        ("behavior B():\n    do Turn() for Range(1, 2) steps\n", "B()", "constant number", 3),
        ("behavior B():\n    take SetBrakeAction(1)\n", "B()", "whole primitive behaviour", 3),
        ("behavior B(x):\n    do Turn()\n", "B()", "needs a value for its parameter 'x'", 4),
        ("behavior B():\n    do Turn() until self.height > 1\n", "B()", "no property 'height'", 3),
    ],
)
def test_errors_point_at_the_place(behaviours, call, message, line):
    with pytest.raises(UserError) as caught:
        compile_ego(behaviours, call)
    assert message in caught.value.message
    assert caught.value.location.line == line


def test_vocabulary_maps_library_behaviours_to_dataset_labels(tmp_path):
    vocabulary = load_vocabulary()
    assert vocabulary.primitive("LaneChange").labels >= {"LaneChange", "LaneChangeLeft", "LaneChangeRight"}
    assert not vocabulary.primitive("FollowLane").ends
    assert "TurnLeft" not in vocabulary.primitive("FollowLane").labels
    unknown = vocabulary.primitive("Dance")
    assert unknown.labels == {"Dance"} and unknown.ends
    mine = tmp_path / "mine.toml"
    mine.write_text('[LaneChange]\nlabels = ["LC", "lane_change"]\n')
    merged = load_vocabulary(mine)
    assert merged.primitive("LaneChange").labels == {"LaneChange", "LC", "lane_change"}
    assert merged.primitive("FollowLane") == vocabulary.primitive("FollowLane")


@pytest.mark.parametrize(
    ("text", "message"),
    [("[A]\nlabels = 3\n", "list of strings"), ("[A]\nends = 1\n", "true or false"), ("[A\n", "not a TOML")],
)
def test_bad_vocabulary_files_are_user_errors(tmp_path, text, message):
    path = tmp_path / "bad.toml"
    path.write_text(text)
    with pytest.raises(UserError, match=message):
        read_vocabulary(path)
