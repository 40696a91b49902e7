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
seeded with ``seed`` before the first scene.

Scenic parses OpenDRIVE in seconds and caches the result in a ``.snet`` file beside the map. So
that the cache is never written beside the user's file (which may be read-only), Scenic reads
a copy of the map kept in the user cache (``scenic-maps/<digest>-scenic<version>/``), where its
``.snet`` lands; later compiles of any program on the same map load it in a fraction of a second.

Scenic is imported on the first call (about a second), not when this module is imported.
"""

from __future__ import annotations

import contextlib
import math
import random
import shutil
import warnings
from collections.abc import Iterator, Mapping, Sequence
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np

from ..cache import cache_dir, file_digest
from ..errors import UserError, at
from ..model import LabelTrace, MapSource, ObjectTable, StateTable
from ..model.geometry import normalize_angle

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
    program, map_path = Path(program), Path(map_path)
    _check_file(program, "a Scenic program")
    _check_file(map_path, "an OpenDRIVE map")
    if map_path.suffix.lower() != ".xodr":
        raise UserError("not an OpenDRIVE map: expected a .xodr file", at(map_path))
    scenes = _generate(program, count, seed, max_iterations, {**_map_params(map_path), **(params or {})})
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
            "generator": f"scenic {version('scenic')} scenario.generate",
        },
        map_source=MapSource(str(map_path.absolute()), "opendrive"),
    )


def _check_file(path: Path, what: str) -> None:
    if not path.is_file():
        raise UserError(f"no such file (expected {what})", at(path))


def _map_params(map_path: Path) -> dict[str, Any]:
    """The global parameters that give Scenic the map: the cached copy, or (when the cache
    cannot be written) the map itself with Scenic's ``.snet`` cache writing turned off."""
    try:
        return {"map": str(_cached_map(map_path))}
    except OSError:
        return {"map": str(map_path), "map_options": {"writeCache": False}}


def _cached_map(map_path: Path) -> Path:
    """A copy of the map in the user cache, beside which Scenic may write its ``.snet`` cache."""
    from ..writers.atomic import atomic_path  # the writers package imports pyarrow and shapely

    folder = cache_dir() / "scenic-maps" / f"{file_digest(map_path)[:20]}-scenic{version('scenic')}"
    copy = folder / f"{map_path.stem}.xodr"
    if not copy.is_file():
        with atomic_path(copy) as tmp:
            shutil.copyfile(map_path, tmp)
    return copy


def _generate(program: Path, count: int, seed: int, max_iterations: int, params: dict[str, Any]) -> list[Any]:
    """Compile the program and draw ``count`` Scenic scenes, seeded."""
    import scenic
    from scenic.formats.opendrive.xodr_parser import OpenDriveWarning

    with _scenic_errors(program), warnings.catch_warnings():
        warnings.simplefilter("ignore", OpenDriveWarning)
        scenario = scenic.scenarioFromFile(str(program), mode2D=True, params=params)
        random.seed(seed)
        np.random.seed(seed)
        return [scenario.generate(maxIterations=max_iterations, verbosity=0)[0] for _ in range(count)]


@contextlib.contextmanager
def _scenic_errors(program: Path) -> Iterator[None]:
    """Turn Scenic's errors (compilation, rejected scenes) into one-line :class:`UserError`\\ s."""
    from scenic.core.distributions import RejectionException
    from scenic.core.errors import ScenicError

    try:
        yield
    except RejectionException as exc:
        raise UserError(f"Scenic could not generate a scene: {_first_line(exc)}", at(program)) from None
    except ScenicError as exc:
        message = f"Scenic rejected the program: {type(exc).__name__}: {_first_line(exc)}"
        raise UserError(message, at(program, _line_in(exc, program))) from None


def _first_line(exc: BaseException) -> str:
    text = str(exc).strip()
    return text.splitlines()[0] if text else type(exc).__name__


def _line_in(exc: BaseException, program: Path) -> int | None:
    """The error's line number when it points into the program (not into a library model)."""
    filename = getattr(exc, "filename", None)
    if filename is not None and Path(filename).resolve() != program.resolve():
        return None
    return getattr(exc, "lineno", None)


def _objects(scenes: Sequence[Any], program: Path) -> tuple[list[str], list[str]]:
    """Object ids and categories, the same for every scene (ValueError otherwise)."""
    signatures = {(s.egoObject is not None, tuple(type(o).__name__ for o in s.objects)) for s in scenes}
    if len(signatures) > 1:
        raise ValueError(f"the scenes of {program} differ in their objects (number or classes)")
    has_ego, categories = signatures.pop()
    n_others = len(categories) - 1 if has_ego else len(categories)
    return (["ego"] if has_ego else []) + [f"obj{k}" for k in range(1, n_others + 1)], list(categories)


def _heading(value: float) -> float:
    """A Scenic heading in (-pi, pi]; values already there are kept bit for bit."""
    return float(value) if -math.pi < value <= math.pi else float(normalize_angle(value))


def _states(scenes: Sequence[Any]) -> StateTable:
    """One state row per (scene, object) with Scenic's exact values."""
    rows = [
        (k, j, o.position.x, o.position.y, _heading(o.heading), o.length, o.width, o.height)
        for k, scene in enumerate(scenes)
        for j, o in enumerate(scene.objects)
    ]
    frame, obj, x, y, heading, length, width, height = np.array(rows, dtype=np.float64).reshape(-1, 8).T
    return StateTable.build(frame, obj, x, y, heading, length=length, width=width, height=height)
