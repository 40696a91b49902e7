"""The scene query API: compile a Scenic program once, match it against labeled frames.

>>> query = compile_scene(open("fig3.scenic").read(), "fig3.scenic")   # doctest: +SKIP
>>> result = query.match(trace)                                        # doctest: +SKIP
>>> result.frames()                                                    # doctest: +SKIP

Compilation is parse (Scenic's parser) -> IR (adapter) -> resolution into
feature terms -> dependency groups. Matching runs Algorithm 1 over every frame
of a trace (:mod:`.match`). The road map is the trace's own, else ``map`` given
here, else the program's ``param map``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import UserError, at
from ..model import LabelTrace, RoadMap
from ..scenic.adapter import parse_program
from ..scenic.parser import read_program
from .dependencies import Group, analyse
from .geometry import MapGeometry, geometry_of
from .evaluate import Labels
from .explain import soft_requirements, witness_values
from .projection import FrameValues, frame_values
from .needs import check_layers, free_fields, term_regions
from .match import SceneOptions, TraceMatches, labels_of, match_trace
from .program import Requirement, SceneProgram
from .resolve import Resolver
from .terms import Term


@dataclass
class SceneResult:
    """The answer for one trace: which frames match, with what correspondence, why the others fail,
    the random values that reproduce a matched frame, and which soft requirements hold there."""

    trace: LabelTrace
    query: SceneQuery
    matches: TraceMatches
    labels: Labels
    geometry: MapGeometry
    options: SceneOptions

    @property
    def matched(self) -> np.ndarray:
        return self.matches.matched

    def frames(self) -> np.ndarray:
        """Positions of the matching frames."""
        return np.flatnonzero(self.matches.matched)

    def correspondence(self, frame: int) -> dict[str, str] | None:
        """Program object -> label object id, for a matched frame."""
        return self.matches.correspondence[frame]

    def failure(self, frame: int) -> str | None:
        """For a frame that does not match, the first features (or requirement) no correspondence satisfied."""
        g = int(self.matches.failed_group[frame])
        if self.matches.matched[frame] or g < 0:
            return None
        if g >= len(self.matches.groups):
            return "the frame has label objects the program does not account for (exact match)"
        return self.query.describe_group(self.matches.groups[g])

    def values(self, frame: int) -> dict[str, Any]:
        """Random values reproducing a matched frame (see :func:`.explain.witness_values`)."""
        survivor = int(np.searchsorted(self.matches.survivors.frame, frame))
        return witness_values(
            self.query.program, self.matches, self.labels, self.geometry, self.options.tolerance, survivor
        )

    @cached_property
    def recovered(self) -> list[FrameValues]:
        """Every value of each random variable that reproduces a matched frame, as intervals, per
        matched frame in frame order (see :mod:`.projection`)."""
        return frame_values(self.query.program, self.matches, self.labels, self.geometry, self.options.tolerance)

    @cached_property
    def soft(self) -> dict[str, np.ndarray]:
        """Soft requirement description -> whether it holds, per matched frame (in frame order)."""
        return soft_requirements(self.query.program, self.matches, self.labels, self.geometry, self.options.tolerance)


@dataclass
class SceneQuery:
    """A compiled scene program: resolved features, their groups in order, soft requirements, and
    the visible distance (m) it was compiled with."""

    program: SceneProgram
    groups: list[Group]
    soft: list[Requirement]
    visible_distance: float | None = None
    _variants: dict[frozenset[str], SceneQuery] = field(default_factory=dict, repr=False)

    def describe_group(self, group: Group) -> str:
        """Why a frame fails at a group: the objects no label object can be, and what fails."""
        checks = group.describe()
        if not group.introduces:
            return f"no correspondence satisfies {checks}"
        names = []
        for name in group.introduces:
            obj = self.program.object(name)
            names.append(f"{name} ({obj.class_name}, line {obj.span.line})")
        return f"no labeled object can be {' and '.join(names)}: {checks}"

    def uses_map(self) -> bool:
        return bool(self.map_layers)

    @cached_property
    def map_layers(self) -> set[str]:
        """The map layers the program's features and requirements read."""
        return _layers(self.program)

    def frames_matching(
        self, trace: LabelTrace, geometry: MapGeometry, options: SceneOptions, groups: list[Group]
    ) -> np.ndarray:
        """Per frame, whether ``groups`` (a sub-list of this query's groups, see
        :func:`.dependencies.completed_groups`) hold, on an already resolved map geometry."""
        return match_trace(self.program, groups, trace, geometry, options).matched

    def match(
        self, trace: LabelTrace, road_map: RoadMap | None = None, options: SceneOptions | None = None
    ) -> SceneResult:
        """Match every frame of ``trace`` (see :mod:`.match`)."""
        options = options or SceneOptions()
        road_map = self._map_for(trace, road_map)
        geometry = geometry_of(road_map, options.unknown_layers)
        check_layers(self.program, geometry)
        query = self.for_map(geometry)
        groups = query.groups_for(trace)
        matches = match_trace(query.program, groups, trace, geometry, options)
        return SceneResult(trace, query, matches, labels_of(trace), geometry, options)

    def for_map(self, geometry: MapGeometry) -> SceneQuery:
        """The query to match on ``geometry``'s map: this one, except where the program reads a
        sidewalk or crossing direction the map does not give and the user chose ``--unknown-layers
        permissive``: then the program resolved again with those directions free headings (built
        once per set of such fields)."""
        free = free_fields(self.program, geometry)
        if not free:
            return self
        if free not in self._variants:
            scene = Resolver(self.program.program, self.visible_distance, free).run()
            soft = [r for r in scene.requirements if r.soft]
            self._variants[free] = SceneQuery(scene, analyse(scene), soft, self.visible_distance)
        return self._variants[free]

    def _map_for(self, trace: LabelTrace, road_map: RoadMap | None) -> RoadMap | None:
        return self.map_for(trace, road_map, self.uses_map())

    def map_for(self, trace: LabelTrace, road_map: RoadMap | None, needed: bool) -> RoadMap | None:
        """The road map to use: ``road_map`` if given, else (when ``needed``) the trace's own map,
        else the program's ``param map``; an error when a needed map is missing."""
        if road_map is not None or not needed:
            return road_map
        from ..readers import read_map

        if trace.map_source is not None:
            return read_map(trace.map_source)
        if self.program.map_path is not None:
            return read_map(self.program.map_path, "opendrive")
        raise UserError(
            f"the program uses road regions but trace {trace.name!r} has no road map; give one with --map",
            at(self.program.program.filename),
        )

    def groups_for(self, trace: LabelTrace) -> list[Group]:
        """The groups, without parameter checks for attributes the trace does not have."""
        dropped = {
            r for r in self.program.requirements if r.parameter is not None and r.parameter not in trace.attributes
        }
        if not dropped:
            return self.groups
        return analyse(self.program, [r for r in self.program.requirements if not r.soft and r not in dropped])


def term_layers(term: Term) -> set[str]:
    """The map layers a term reads, through its regions and random points."""
    return {layer for region in term_regions(term) for layer in region.layers()}


def _layers(program: SceneProgram) -> set[str]:
    layers: set[str] = set()
    for obj in program.objects:
        for feature in obj.features:
            layers |= term_layers(feature.term)
    for requirement in program.requirements:
        layers |= term_layers(requirement.condition)
    return layers


def compile_scene(text: str, filename: str = "<program>", visible_distance: float | None = None) -> SceneQuery:
    """Compile Scenic source text into a :class:`SceneQuery` (errors are one-line :class:`UserError`)."""
    program = parse_program(text, filename)
    resolver = Resolver(program, visible_distance=visible_distance)
    scene = resolver.run()
    if resolver.temporal:
        raise resolver.error(
            "temporal requirements need a scenario query (scenegrep scenario): a scene is one frame",
            resolver.temporal[0][0].condition,
        )
    soft = [r for r in scene.requirements if r.soft]
    return SceneQuery(scene, analyse(scene), soft, visible_distance)


def load_scene(path: str | Path, visible_distance: float | None = None) -> SceneQuery:
    """Compile a ``.scenic`` file."""
    return compile_scene(read_program(path), str(path), visible_distance)
