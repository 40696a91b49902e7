"""The scenario query API (seed 000): compile a Scenic program once, find its windows in label traces.

>>> query = load_scenario("examples/queries/fig1_lane_change.scenic")   # doctest: +SKIP
>>> result = query.match(trace, window=50)                            # doctest: +SKIP
>>> result.matched, result.matches[0].correspondence                   # doctest: +SKIP

Compilation: parse (Scenic's parser) -> IR -> the scene program (seed 003's
resolution, used for the initial-scene check) -> one HFSM per program object
(:mod:`.translate`) and one lazy automaton per HFSM (:mod:`.automaton`); temporal
requirements become monitors (:mod:`.temporal`) run beside the HFSMs.
Matching: :mod:`.search` over one trace's :class:`~.observations.Observations`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import UserError, at
from ..model import LabelTrace, RoadMap
from ..model.layers import UnknownLayers
from ..scene.tolerance import Tolerance
from ..scene.dependencies import analyse, completed_groups
from ..scene.geometry import geometry_of
from ..scene.match import SceneOptions, labels_of, match_trace
from ..scene.needs import check_layers
from ..scene.query import SceneQuery, SceneResult, term_layers
from ..scene.resolve import Resolver
from ..scenic.adapter import parse_program
from ..scenic.parser import read_program
from .automaton import MAX_STATES, Automaton
from .explain import Explainer
from .hfsm import Hfsm
from .observations import Observations
from .search import Assignment, Outcome, Search
from .temporal import Monitor, TemporalRequirement, compile_requirement
from .translate import Guard, Translator
from .vocabulary import Vocabulary, load_vocabulary


@dataclass(frozen=True)
class ScenarioOptions:
    """How to match: tolerances of the initial-scene check and of guards, the visible distance (m)
    of the initial scene, whether to find every correspondence and window (``find_all``), and the
    user's choice for map layers the map does not publish (None: a guard or initial-scene part that
    needs one is an error)."""

    tolerance: Tolerance = field(default_factory=Tolerance)
    visible_distance: float | None = None
    find_all: bool = False
    unknown_layers: UnknownLayers | None = None


@dataclass(frozen=True)
class ScenarioMatch:
    """A correspondence (program object -> label object id) and the frame positions at which a
    matching window of the result's length starts."""

    correspondence: dict[str, str]
    starts: np.ndarray


@dataclass
class ScenarioResult:
    """The answer for one trace: the matches (the first only, unless ``find_all``) and explanations."""

    trace: LabelTrace
    window: int
    matches: list[ScenarioMatch]
    explainer: Explainer

    @property
    def matched(self) -> bool:
        return bool(self.matches)

    def windows(self) -> list[tuple[ScenarioMatch, int, int]]:
        """(match, first frame position, last frame position) of every matching window."""
        return [(m, int(s), int(s) + self.window - 1) for m in self.matches for s in m.starts]

    def explain(self, match: int = 0, start: int | None = None) -> list[str]:
        """The witness of a match: per step of its window, each object's label, guards and HFSM states."""
        found = self.matches[match]
        return self.explainer.witness(found.correspondence, int(found.starts[0] if start is None else start))

    def initial_scene(self, match: int) -> SceneResult:
        """The initial scene of match number ``match`` checked at each of its window starts with its
        correspondence (the scene engine's check that admitted its windows)."""
        found = self.matches[match]
        return self.explainer.scene_at(found.correspondence, np.asarray(found.starts))

    def why_not(self) -> str:
        """For a trace without a match: the furthest frame reached and what failed there."""
        return self.explainer.why_not()


@dataclass
class ScenarioQuery:
    """A compiled scenario program: its scene query, HFSMs, guards (behaviour conditions and the
    conditions of temporal requirements), vocabulary and temporal requirements."""

    scene: SceneQuery
    hfsms: dict[str, Hfsm]
    guards: list[Guard]
    vocabulary: Vocabulary
    requirements: list[TemporalRequirement] = field(default_factory=list)
    state_budget: int = MAX_STATES
    """Per HFSM, the most DFA states before its windows are simulated on configuration sets instead."""
    _automata: dict[tuple[str, float], Automaton] = field(default_factory=dict)
    _monitors: dict[str, Monitor] = field(default_factory=dict)

    def uses_map(self) -> bool:
        return self.scene.uses_map() or any(term_layers(g.condition) for g in self.guards)

    def automata(self, period: float) -> dict[str, Automaton]:
        """One automaton per HFSM for a frame period (s); kept, so transitions are computed once."""
        found = {}
        for name, hfsm in self.hfsms.items():
            key = (name, round(period, 9))
            if key not in self._automata:
                self._automata[key] = Automaton(hfsm, len(self.guards), period, self.state_budget)
            found[name] = self._automata[key]
        return found

    def monitors(self) -> dict[str, Monitor]:
        """One monitor per temporal requirement, named by its text and line; kept."""
        if len(self._monitors) < len(self.requirements):
            for r in self.requirements:
                name = f"{r.text} (line {r.span.line})"
                self._monitors[name] = Monitor(r, name, self.state_budget)
        return self._monitors

    def match(
        self,
        trace: LabelTrace,
        window: int | str,
        road_map: RoadMap | None = None,
        options: ScenarioOptions | None = None,
    ) -> ScenarioResult:
        """Find windows of ``trace`` the program can produce (see :func:`window_frames` for ``window``)."""
        options = options or ScenarioOptions()
        if trace.behaviours is None:
            raise UserError("the trace has no behaviour labels; label it first (scenegrep label)", at(trace.name))
        m = window_frames(window, trace)
        road_map = self.scene.map_for(trace, road_map, self.uses_map())
        geometry = geometry_of(road_map, options.unknown_layers)
        guards = ((g.condition, f"the guard '{g.text}'", g.span) for g in self.guards)
        check_layers(self.scene.program, geometry, guards)
        objects = {o.name: o for o in self.scene.program.objects}
        obs = Observations(trace, geometry, self.vocabulary, objects, options.tolerance)
        automata = self.automata(obs.period)
        ids = trace.objects.id

        scene = self.scene.for_map(geometry)
        groups = scene.groups_for(trace)

        def scene_options(correspondence: dict[str, str], starts: np.ndarray) -> SceneOptions:
            return SceneOptions(
                options.tolerance,
                visible_distance=options.visible_distance,
                correspondence=correspondence,
                frames=starts,
            )

        def scene_starts(assignment: Assignment, starts: np.ndarray, newest: str) -> np.ndarray:
            decided = completed_groups(groups, set(assignment), newest)
            if not decided:
                return starts
            correspondence = {name: str(ids[row]) for name, row in assignment.items()}
            matching = scene.frames_matching(trace, geometry, scene_options(correspondence, starts), decided)
            return starts[matching[starts]]

        def scene_at(correspondence: dict[str, str], starts: np.ndarray) -> SceneResult:
            scene_options_at = scene_options(correspondence, starts)
            matches = match_trace(scene.program, groups, trace, geometry, scene_options_at)
            return SceneResult(trace, scene, matches, labels_of(trace), geometry, scene_options_at)

        kinds = {name: objects[name].kinds for name in self.hfsms}
        search = Search(
            self.hfsms, kinds, self.guards, automata, obs, m, scene_starts, options.find_all, self.monitors()
        )
        outcome: Outcome = search.run()
        matches = [
            ScenarioMatch({name: str(ids[row]) for name, row in assignment.items()}, starts)
            for assignment, starts in outcome.matches
        ]
        return ScenarioResult(
            trace, m, matches, Explainer(self.hfsms, self.guards, self.scene.program, search, outcome, scene_at)
        )

    def initial_scene(
        self,
        trace: LabelTrace,
        window: int | str,
        road_map: RoadMap | None = None,
        options: ScenarioOptions | None = None,
    ) -> tuple[SceneResult, np.ndarray]:
        """The initial scene matched at every window start (any correspondence), and the starts
        (frame positions); the other frames are reported as not matching."""
        options = options or ScenarioOptions()
        starts = np.arange(max(trace.n_frames - window_frames(window, trace) + 1, 0))
        road_map = self.scene.map_for(trace, road_map, self.uses_map())
        scene_options = SceneOptions(
            options.tolerance,
            visible_distance=options.visible_distance,
            frames=starts,
            unknown_layers=options.unknown_layers,
        )
        return self.scene.match(trace, road_map, scene_options), starts


def window_frames(window: int | str, trace: LabelTrace) -> int:
    """The window length m in frames: an int (frames), ``"all"`` (the whole trace), ``"N"`` frames,
    ``"Ns"`` seconds (rounded to whole frames at the trace's median frame period)."""
    if isinstance(window, int):
        m = window
    elif window == "all":
        m = trace.n_frames
    elif window.endswith("s"):
        try:
            seconds = float(window[:-1])
        except ValueError:
            raise UserError(f"bad window {window!r}: give frames (50), seconds (5s) or 'all'") from None
        m = int(round(seconds / trace.frame_period))
    else:
        try:
            m = int(window)
        except ValueError:
            raise UserError(f"bad window {window!r}: give frames (50), seconds (5s) or 'all'") from None
    if m < 1:
        raise UserError(f"the window must be at least one frame (got {window!r})")
    return m


def compile_scenario(
    text: str,
    filename: str = "<program>",
    vocabulary: Vocabulary | None = None,
    visible_distance: float | None = None,
) -> ScenarioQuery:
    """Compile Scenic source text into a :class:`ScenarioQuery` (errors are one-line :class:`UserError`)."""
    program = parse_program(text, filename)
    resolver = Resolver(program, visible_distance=visible_distance)
    scene = resolver.run()
    soft = [r for r in scene.requirements if r.soft]
    translator = Translator(resolver, vocabulary or load_vocabulary())
    hfsms = {obj.name: translator.hfsm(obj) for obj in scene.objects}
    requirements = [compile_requirement(translator, node, scope) for node, scope in resolver.temporal]
    scene_query = SceneQuery(scene, analyse(scene), soft, visible_distance)
    return ScenarioQuery(scene_query, hfsms, translator.guards, translator.vocabulary, requirements)


def load_scenario(
    path: str | Path, vocabulary: Vocabulary | None = None, visible_distance: float | None = None
) -> ScenarioQuery:
    """Compile a ``.scenic`` file."""
    return compile_scenario(read_program(path), str(path), vocabulary, visible_distance)
