"""Ground truth for the scene query from Scenic itself: sampled scenes must match their program,
and scenes perturbed beyond the tolerance in a feature the program pins down must not.

:func:`check_program` samples ``count`` scenes with :func:`.scenic_scenes.sample_scenes`, runs
the program over them, and perturbs the labels in the ways a program declares in comments
(``# violate: OBJECT FEATURE AMOUNT``, e.g. ``# violate: otherCar lateral 0.05``): each such
perturbation breaks a constraint exactly (the feature has no slack in the program), so every
perturbed scene must be rejected. It also reports, for information, how often a random
perturbation of one feature of one object (0.1 m or 0.05 rad) is rejected: a program with
slack (``Range``) legitimately accepts some of those.

Features a violation may name: ``x``, ``y``, ``heading`` (added), ``lateral`` / ``forward``
(metres across / along the object's own heading), ``range`` (metres away from the ego).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..model import LabelTrace
from ..scene import SceneOptions, Tolerance, load_scene
from .scenic_scenes import sample_scenes

VIOLATION = re.compile(r"#\s*violate:\s*(\w+)\s+(\w+)\s+([-+0-9.eE]+)")
RANDOM_STEP = {"position": 0.1, "heading": 0.05}


@dataclass
class GroundTruth:
    """Outcome for one program: scenes sampled, scenes matched (all must), and per declared
    violation and for random perturbations, how many perturbed scenes were rejected."""

    program: str
    scenes: int
    matched: int
    violations: dict[str, tuple[int, int]]
    random_rejected: tuple[int, int]

    @property
    def false_negatives(self) -> int:
        return self.scenes - self.matched


def declared_violations(text: str) -> list[tuple[str, str, float]]:
    """The ``# violate: OBJECT FEATURE AMOUNT`` comments of a program."""
    return [(m.group(1), m.group(2), float(m.group(3))) for m in VIOLATION.finditer(text)]


def perturbed(
    trace: LabelTrace, label: str, feature: str, amount: float, frames: np.ndarray | None = None
) -> LabelTrace:
    """The trace with one feature of one label object changed in every frame (or in ``frames``)."""
    s = trace.states
    rows = s.object == trace.object_index(label)
    if frames is not None:
        rows &= np.isin(s.frame, frames)
    x, y, heading = s.x.copy(), s.y.copy(), s.heading.copy()
    if feature == "heading":
        heading[rows] += amount
    elif feature in ("x", "y"):
        (x if feature == "x" else y)[rows] += amount
    elif feature in ("lateral", "forward"):
        angle = heading[rows] if feature == "forward" else heading[rows] - math.pi / 2
        x[rows] += -np.sin(angle) * amount
        y[rows] += np.cos(angle) * amount
    elif feature == "range":
        ego = s.object == trace.object_index(trace.ego)
        ex, ey = s.x[ego][s.frame[rows]], s.y[ego][s.frame[rows]]
        distance = np.hypot(x[rows] - ex, y[rows] - ey)
        scale = (distance + amount) / distance
        x[rows], y[rows] = ex + (x[rows] - ex) * scale, ey + (y[rows] - ey) * scale
    else:
        raise ValueError(f"unknown feature {feature!r}")
    return replace(trace, states=replace(s, x=x, y=y, heading=heading))


def check_program(
    program: str | Path,
    count: int,
    map_path: Path,
    seed: int = 0,
    tolerance: Tolerance | None = None,
    random_perturbations: bool = True,
) -> GroundTruth:
    """Sample, match, perturb and match again (see the module docstring); ``random_perturbations``
    False skips the informative random part (``random_rejected`` is then (0, 0))."""
    program = Path(program)
    trace = sample_scenes(program, count, map_path=map_path, seed=seed)
    query = load_scene(program)
    options = SceneOptions(tolerance or Tolerance())
    names = _label_names(query, trace)
    matched = int(query.match(trace, None, options).matched.sum())
    violations = {}
    for obj, feature, amount in declared_violations(program.read_text()):
        changed = perturbed(trace, names[obj], feature, amount)
        rejected = int((~query.match(changed, None, options).matched).sum())
        violations[f"{obj} {feature} {amount:+g}"] = (rejected, trace.n_frames)
    random_rejected = _random_rejections(query, trace, options, seed) if random_perturbations else (0, 0)
    return GroundTruth(program.name, trace.n_frames, matched, violations, random_rejected)


def _label_names(query, trace: LabelTrace) -> dict[str, str]:
    """Program object name -> label object id: sample_scenes names the ego 'ego' and the others
    obj1, obj2, ... in creation order, which is the program's order."""
    others = [o.name for o in query.program.objects if o.name != "ego"]
    return {"ego": "ego", **{name: f"obj{k + 1}" for k, name in enumerate(others)}}


def _random_rejections(query, trace: LabelTrace, options: SceneOptions, seed: int) -> tuple[int, int]:
    """Each frame gets one random object's x, y or heading moved by a fixed step; count rejections."""
    rng = np.random.default_rng(seed)
    ids = trace.objects.id.tolist()
    rejected = 0
    frames = np.arange(trace.n_frames)
    labels = rng.choice(len(ids), trace.n_frames)
    features = rng.choice(["x", "y", "heading"], trace.n_frames)
    for k in range(len(ids)):
        for feature in ("x", "y", "heading"):
            chosen = frames[(labels == k) & (features == feature)]
            if not len(chosen):
                continue
            step = RANDOM_STEP["heading" if feature == "heading" else "position"]
            changed = perturbed(trace, ids[k], feature, step, chosen)
            rejected += int((~query.match(changed, None, options).matched[chosen]).sum())
    return rejected, trace.n_frames
