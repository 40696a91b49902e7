"""Perception-like noise on a label trace: position and heading jitter, dropped frames, confused
behaviour labels. Seeded, vectorised over state rows.

:func:`add_noise` draws from a generator seeded by ``(noise.seed, stream)``, so a set of traces
gets independent noise per trace (``stream`` = the run number) and the same noise every time.
Steps, in this order:

1. every frame is dropped (all its state rows, and the frame itself) with probability
   ``drop_frames``; frame indices and times of the others are kept, so the gaps show;
2. ``x`` and ``y`` each get Gaussian noise of standard deviation ``position`` (m), ``heading``
   Gaussian noise of standard deviation ``heading`` (rad), wrapped back into (-pi, pi];
3. with probability ``confuse_behaviours`` per state row, its behaviour label (the first of its
   set) is confused with one drawn uniformly from :data:`CONFUSABLE` of it: replaced by it
   (``confusion="replace"``) or added to the set (``confusion="augment"``, a label set as a
   thresholded behaviour predictor gives). Labels without confusable ones stay as they are.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, replace
from typing import Any, Literal

import numpy as np

from ..model import BehaviourLabels, LabelTrace
from ..model.geometry import normalize_angle

CONFUSABLE: dict[str, tuple[str, ...]] = {
    "FollowLane": ("LaneChange", "Stationary"),
    "LaneChange": ("FollowLane",),
    "Stationary": ("FollowLane",),
    "Turn": ("FollowLane",),
    "FollowTrajectory": ("Turn", "FollowLane"),
}
"""For each primitive behaviour, those a behaviour predictor confuses it with."""


@dataclass(frozen=True)
class LabelNoise:
    """Noise parameters (see the module docstring): standard deviations ``position`` (m) and
    ``heading`` (rad), probabilities ``drop_frames`` (per frame) and ``confuse_behaviours`` (per
    state row), the ``confusion`` mode and the noise's own ``seed``."""

    position: float = 0.0
    heading: float = 0.0
    drop_frames: float = 0.0
    confuse_behaviours: float = 0.0
    confusion: Literal["replace", "augment"] = "replace"
    seed: int = 0

    def __post_init__(self) -> None:
        if self.position < 0 or self.heading < 0:
            raise ValueError("noise standard deviations must not be negative")
        if not (0 <= self.drop_frames < 1 and 0 <= self.confuse_behaviours <= 1):
            raise ValueError("drop_frames must lie in [0, 1) and confuse_behaviours in [0, 1]")
        if self.confusion not in ("replace", "augment"):
            raise ValueError(f"confusion must be 'replace' or 'augment', got {self.confusion!r}")

    def as_dict(self) -> dict[str, Any]:
        """The parameters as plain data (for trace attributes and manifests)."""
        return asdict(self)


def add_noise(trace: LabelTrace, noise: LabelNoise, stream: int = 0) -> LabelTrace:
    """The trace with noise added (see the module docstring); ``trace`` is not changed. The
    result's attributes say ``noise`` (the parameters) and ``noise_stream``."""
    drop, jitter, confuse = (np.random.default_rng([noise.seed, stream, k]) for k in range(3))
    kept = trace.select_frames(drop.random(trace.n_frames) >= noise.drop_frames)
    s = kept.states
    n = len(s)
    states = replace(
        s,
        x=s.x + jitter.normal(0.0, noise.position, n),
        y=s.y + jitter.normal(0.0, noise.position, n),
        heading=normalize_angle(s.heading + jitter.normal(0.0, noise.heading, n)) if noise.heading else s.heading,
    )
    behaviours = kept.behaviours
    if behaviours is not None and noise.confuse_behaviours > 0:
        behaviours = _confused(behaviours, confuse.random(n) < noise.confuse_behaviours, confuse.random(n), noise)
    attributes = {**kept.attributes, "noise": noise.as_dict(), "noise_stream": stream}
    return replace(kept, states=states, behaviours=behaviours, attributes=attributes)


def _confused(labels: BehaviourLabels, chosen: np.ndarray, draw: np.ndarray, noise: LabelNoise) -> BehaviourLabels:
    """Labels with the ``chosen`` rows confused; ``draw`` (uniform in [0, 1) per row) picks
    among the confusable labels."""
    vocabulary = list(
        dict.fromkeys([*labels.vocabulary, *(c for v in labels.vocabulary for c in CONFUSABLE.get(v, ()))])
    )
    code = {name: k for k, name in enumerate(vocabulary)}
    member = np.zeros((len(labels), len(vocabulary)), dtype=bool)
    member[:, : len(labels.vocabulary)] = labels.member
    options = [[code[c] for c in CONFUSABLE.get(v, ())] for v in vocabulary]
    count = np.array([len(o) for o in options])
    table = np.full((len(vocabulary), max(count.max(initial=0), 1)), -1)
    for k, row in enumerate(options):
        table[k, : len(row)] = row
    source = np.argmax(member, axis=1)
    rows = np.flatnonzero(chosen & member.any(axis=1) & (count[source] > 0))
    target = table[source[rows], (draw[rows] * count[source[rows]]).astype(np.int64)]
    if noise.confusion == "replace":
        member[rows] = False
    member[rows, target] = True
    confidence = None
    if labels.confidence is not None:
        confidence = np.full(member.shape, np.nan, dtype=np.float32)
        confidence[:, : len(labels.vocabulary)] = labels.confidence
        confidence[~member] = np.nan
    return BehaviourLabels(tuple(vocabulary), member, confidence)
