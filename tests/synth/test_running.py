"""Primitive behaviour labels from behaviour stacks (the stacks themselves are checked on real
simulations in test_simulate.py)."""

import pytest

from scenegrep.synth.running import behaviour_stack, primitive_label


@pytest.mark.parametrize(
    "stack, label",
    [
        ((), "Stationary"),
        (("EgoBehavior", "FollowLaneBehavior"), "FollowLane"),
        (("EgoBehavior", "FollowTrajectoryBehavior", "TurnBehavior"), "Turn"),
        (("WalkAlongLaneBehavior",), "WalkAlongLane"),
        (("EgoBehavior", "Wander"), "Wander"),
        (("Behavior",), "Behavior"),
    ],
)
def test_primitive_label(stack, label):
    assert primitive_label(stack) == label


def test_object_without_behaviour_has_an_empty_stack():
    class Thing:
        behavior = None

    assert behaviour_stack(Thing()) == ()
    assert behaviour_stack(object()) == ()
