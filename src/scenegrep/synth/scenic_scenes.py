"""Static scenes sampled from a Scenic program, as one label trace: ground truth for scene queries.

:func:`sample_scenes` compiles a Scenic program once (2-D compatibility mode, with the road map
passed in as the global parameter ``map``), draws ``count`` scenes with Scenic's rejection
sampler and returns them as a :class:`~scenegrep.model.LabelTrace` in which frame k is scene k
(index k, time k seconds). Frames are independent scenes, not a recording: nothing moves
between them.

Objects: Scenic lists the ego first in ``scene.objects`` and the others in their order of
creation; the ego is ``"ego"``, the others ``obj1``, ``obj2``, ... in that order, and each
object's category is its Scenic class name (``Car``, ``Pedestrian``). States: ``x``, ``y``
(metres, map frame), ``heading`` (radians, Scenic's convention, which is the data model's: 0 =
+y, counter-clockwise, in (-pi, pi]), ``length``, ``width``, ``height`` (metres); ``z``,
velocity and lane are unknown. Values are Scenic's float64 values unchanged (a heading is
wrapped only when it lies outside (-pi, pi]).

Sampling is reproducible: ``random`` and ``numpy.random`` (Scenic's sources of randomness) are
seeded with ``seed`` before the first scene. The map is handed to Scenic as described in
:mod:`._scenic` (its ``.snet`` cache goes to the user cache, never beside the user's map).

Scenic is imported on the first call (about a second), not when this module is imported.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..model import LabelTrace, MapSource, ObjectTable, StateTable
from ._scenic import (
    checked_inputs,
    compile_program,
    map_params,
    scenic_errors,
    scenic_headings,
    scenic_version,
    seed_scenic,
)

FRAME_INTERVAL = 1.0
"""Seconds between consecutive frames (scenes) of a sampled trace."""


def sample_scenes(
    program: str | Path,
    count: int,
    *,
    map_path: str | Path,
    seed: int = 0,
    max_iterations: int = 5000,
    params: Mapping[str, Any] | None = None,
) -> LabelTrace:
    """``count`` scenes of a Scenic program on an OpenDRIVE map, as one trace (see the module docstring).

    ``params`` are further global parameters of the program; ``max_iterations`` bounds Scenic's
    rejection sampling per scene. A missing file, a program Scenic cannot compile, or one whose
    scenes are rejected ``max_iterations`` times in a row is a :class:`UserError`; scenes that
    differ in their objects (number or classes) are a ValueError.
    """
    if count < 1:
        raise ValueError(f"count must be at least 1, got {count}")
    program, map_path = checked_inputs(program, map_path)
    scenario = compile_program(program, {**map_params(map_path), **(params or {})})
    with scenic_errors(program):
        seed_scenic(seed)
        scenes = [scenario.generate(maxIterations=max_iterations, verbosity=0)[0] for _ in range(count)]
    ids, categories = _objects(scenes, program)
    return LabelTrace.build(
        program.stem,
        np.arange(count),
        np.arange(count) * FRAME_INTERVAL,
        ObjectTable.build(ids, categories),
        _states(scenes),
        ego="ego" if scenes[0].egoObject is not None else None,
        attributes={
            "program": str(program),
            "seed": seed,
            "generator": f"scenic {scenic_version()} scenario.generate",
        },
        map_source=MapSource(str(map_path.absolute()), "opendrive"),
    )


def _objects(scenes: Sequence[Any], program: Path) -> tuple[list[str], list[str]]:
    """Object ids and categories, the same for every scene (ValueError otherwise)."""
    signatures = {(s.egoObject is not None, tuple(type(o).__name__ for o in s.objects)) for s in scenes}
    if len(signatures) > 1:
        raise ValueError(f"the scenes of {program} differ in their objects (number or classes)")
    has_ego, categories = signatures.pop()
    n_others = len(categories) - 1 if has_ego else len(categories)
    return (["ego"] if has_ego else []) + [f"obj{k}" for k in range(1, n_others + 1)], list(categories)


def _states(scenes: Sequence[Any]) -> StateTable:
    """One state row per (scene, object) with Scenic's exact values."""
    rows = [
        (k, j, o.position.x, o.position.y, o.heading, o.length, o.width, o.height)
        for k, scene in enumerate(scenes)
        for j, o in enumerate(scene.objects)
    ]
    frame, obj, x, y, heading, length, width, height = np.array(rows, dtype=np.float64).reshape(-1, 8).T
    return StateTable.build(frame, obj, x, y, scenic_headings(heading), length=length, width=width, height=height)
