"""Label noise: each kind measured on many rows against what its parameters say, and seeded."""

import math

import numpy as np
import pytest

from scenegrep.model import BehaviourLabels, LabelTrace, ObjectTable, StateTable
from scenegrep.synth.noise import CONFUSABLE, LabelNoise, add_noise

FRAMES, OBJECTS = 4000, 3
LABELS = ("FollowLane", "Stationary", "WalkAlongLane")  # the last has nothing confusable


def clean_trace() -> LabelTrace:
    """FRAMES frames x OBJECTS objects at 10 Hz, headings spread over (-pi, pi], one label per object."""
    rng = np.random.default_rng(123)
    frame = np.repeat(np.arange(FRAMES), OBJECTS)
    obj = np.tile(np.arange(OBJECTS), FRAMES)
    n = len(frame)
    states = StateTable.build(
        frame, obj, rng.uniform(-100, 100, n), rng.uniform(-100, 100, n), math.pi - rng.uniform(0, 2 * math.pi, n)
    )
    member = np.zeros((n, len(LABELS)), dtype=bool)
    member[np.arange(n), obj] = True
    return LabelTrace.build(
        "clean",
        np.arange(FRAMES) + 1000,
        np.arange(FRAMES) * 0.1,
        ObjectTable.build(["ego", "car", "walker"], ["Car", "Car", "Pedestrian"]),
        states,
        behaviours=BehaviourLabels(LABELS, member),
        ego="ego",
        attributes={"seed": 7},
    )


@pytest.fixture(scope="module")
def clean():
    return clean_trace()


def angle_difference(a, b):
    return (a - b + math.pi) % (2 * math.pi) - math.pi


def test_zero_noise_changes_nothing_but_the_attributes(clean):
    noisy = add_noise(clean, LabelNoise(seed=5))
    assert noisy.states.equals(clean.states) and noisy.behaviours.equals(clean.behaviours)
    assert noisy.attributes["noise"]["seed"] == 5 and noisy.attributes["seed"] == 7


def test_jitter_has_the_stated_standard_deviation(clean):
    noisy = add_noise(clean, LabelNoise(position=0.5, heading=0.2, seed=1))
    for column in ("x", "y"):
        error = getattr(noisy.states, column) - getattr(clean.states, column)
        assert abs(error.std() - 0.5) < 0.02 and abs(error.mean()) < 0.02
    turn = angle_difference(noisy.states.heading, clean.states.heading)
    assert abs(turn.std() - 0.2) < 0.008 and abs(turn.mean()) < 0.008
    assert np.all((noisy.states.heading > -math.pi) & (noisy.states.heading <= math.pi))
    assert np.array_equal(noisy.frame_index, clean.frame_index) and noisy.behaviours.equals(clean.behaviours)


def test_dropped_frames_go_whole_and_at_the_stated_rate(clean):
    noisy = add_noise(clean, LabelNoise(drop_frames=0.25, seed=2))
    dropped = 1 - noisy.n_frames / clean.n_frames
    assert abs(dropped - 0.25) < 4 * math.sqrt(0.25 * 0.75 / FRAMES)
    assert noisy.present().all()  # a kept frame keeps every object
    kept = np.searchsorted(clean.frame_index, noisy.frame_index)
    assert np.array_equal(clean.frame_index[kept], noisy.frame_index)
    assert np.array_equal(noisy.frame_time, clean.frame_time[kept])
    assert np.array_equal(noisy.dense("x"), clean.dense("x")[kept])


@pytest.mark.parametrize("mode", ["replace", "augment"])
def test_confusion_rate_and_targets(clean, mode):
    noisy = add_noise(clean, LabelNoise(confuse_behaviours=0.3, confusion=mode, seed=3))
    before, after = clean.behaviours.sets(), noisy.behaviours.sets()
    objects = clean.states.object
    for k, label in enumerate(LABELS):
        rows = np.flatnonzero(objects == k)
        changed = [after[i] != before[i] for i in rows]
        if label not in CONFUSABLE:
            assert not any(changed)
            continue
        rate = np.mean(changed)
        assert abs(rate - 0.3) < 4 * math.sqrt(0.3 * 0.7 / len(rows))
        for i in rows:
            extra = after[i] - {label}
            assert extra <= set(CONFUSABLE[label]) and len(extra) <= 1
            assert (label in after[i]) == (mode == "augment" or not extra)


def test_noise_is_seeded_per_seed_and_stream(clean):
    noise = LabelNoise(position=0.3, heading=0.1, drop_frames=0.1, confuse_behaviours=0.2, seed=9)
    first = add_noise(clean, noise, stream=4)
    assert first.equals(add_noise(clean, noise, stream=4))
    assert not first.equals(add_noise(clean, noise, stream=5))
    assert not first.equals(add_noise(clean, LabelNoise(0.3, 0.1, 0.1, 0.2, seed=10), stream=4))


def test_confidences_follow_the_labels():
    trace = clean_trace()
    scored = BehaviourLabels(LABELS, trace.behaviours.member, np.where(trace.behaviours.member, 0.9, np.nan))
    noisy = add_noise(
        LabelTrace.build("scored", trace.frame_index, trace.frame_time, trace.objects, trace.states, behaviours=scored),
        LabelNoise(confuse_behaviours=1.0, confusion="augment"),
    )
    labels = noisy.behaviours
    assert labels.member[:, :3].sum() > trace.behaviours.member.sum()  # confused labels were added
    assert np.array_equal(~np.isnan(labels.confidence[:, :3]), trace.behaviours.member)  # only the old ones scored
    assert np.isnan(labels.confidence[:, 3:]).all()


@pytest.mark.parametrize(
    "kwargs",
    [{"position": -1}, {"heading": -0.1}, {"drop_frames": 1.0}, {"confuse_behaviours": 1.5}, {"confusion": "x"}],
)
def test_invalid_parameters(kwargs):
    with pytest.raises(ValueError):
        LabelNoise(**kwargs)
